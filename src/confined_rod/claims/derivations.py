"""Symbolic and dimensional checks of the paper's printed relations (sympy).

Each function re-derives one relation of the paper from its premises and returns a
:class:`Derivation`: what we derive, what the paper prints, and whether the two agree
(``agrees``, decided by sympy's simplification of their difference or ratio, never by
hand). The claims of ``paper/claims.yaml`` that are equations point here
(``method: derivation``); docs/model.md gives the same derivations in prose.

Notation as in the paper: arc length l, azimuth phi(l), w = dphi/dl, helix radius R,
bending stiffness EI, axial force F_z (|F| its magnitude), wall force per length K.
Post-processing only: nothing here imports the simulator.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import sympy as sp


@dataclass(frozen=True)
class Derivation:
    ours: str        # the relation as we derive it (plain text)
    paper: str       # as printed
    agrees: bool     # sympy: difference simplifies to 0 (or ratio to 1)
    detail: str      # how it was decided


l = sp.symbols("l")  # noqa: E741 (the paper's arc length)
R, EI, A, kfr, F0, L, l0 = sp.symbols("R EI A k_fr F_0 L l_0", positive=True)
w = sp.Function("w")(l)
phi = sp.Function("phi")(l)
_er = sp.Matrix([sp.cos(phi), sp.sin(phi), 0])
_ep = sp.Matrix([-sp.sin(phi), sp.cos(phi), 0])
_ez = sp.Matrix([0, 0, 1])
_ON_CURVE = {sp.Derivative(phi, l): w}


def _zero(expr) -> bool:
    return sp.simplify(expr) == 0


def _tangent():
    return R * w * _ep + sp.sqrt(1 - R**2 * w**2) * _ez


def _torque():
    t = _tangent()
    return EI * t.cross(t.diff(l).subs(_ON_CURVE))


def _constant_pitch(expr):
    return expr.subs({sp.Derivative(w, (l, 2)): 0}).subs({sp.Derivative(w, l): 0})


def _torque_balance(Fr, Fp, Fz):
    t = _tangent()
    return _torque().diff(l).subs(_ON_CURVE) + t.cross(Fr * _er + Fp * _ep + Fz * _ez)


def _project(vec, basis) -> sp.Expr:
    return sp.simplify((vec.T * basis)[0])


# -- the simple model (constant pitch, Sec. III A) -------------------------------------------
def helix_torque() -> Derivation:
    """Eq. (M-helix): M = EI t x dt/dl on the helix r = R, phi = w l."""
    c = sp.sqrt(1 - R**2 * w**2)
    printed = EI * R * w**2 * (-c * _ep + R * w * _ez)
    diff = (_constant_pitch(_torque()) - printed).applyfunc(sp.simplify)
    return Derivation("EI R w^2 [-sqrt(1-R^2w^2) e_phi + R w e_z]", "same", diff == sp.zeros(3, 1),
                      "componentwise difference simplified to 0")


def helix_torque_balance() -> Derivation:
    """Eq. (equi-components): the torque balance for constant w and constant F_r, F_phi,
    F_z in the rotating frame, projected on e_r, e_phi, e_z."""
    Fr, Fp, Fz = sp.symbols("F_r F_phi F_z")
    bal = _constant_pitch(_torque_balance(Fr, Fp, Fz))
    c = sp.sqrt(1 - R**2 * w**2)
    printed = (c * (EI * R * w**3 - Fp) + R * w * Fz, c * Fr, -R * w * Fr)
    ok = all(_zero(_project(bal, e) - p) for e, p in zip((_er, _ep, _ez), printed))
    return Derivation("[c(EI R w^3 - F_phi) + R w F_z] e_r + c F_r e_phi - R w F_r e_z = 0", "same", ok,
                      "each projection minus the printed component simplified to 0")


def azimuthal_force_constant_pitch() -> Derivation:
    """Eqs. (Fr-equi), (Fphi-equi): dF/dl + K = 0 with K = -K e_r and constant components."""
    Fr, Fp, Fz, K, wc = sp.symbols("F_r F_phi F_z K w")
    phic = wc * l
    er = sp.Matrix([sp.cos(phic), sp.sin(phic), 0])
    ep = sp.Matrix([-sp.sin(phic), sp.cos(phic), 0])
    balance = (Fr * er + Fp * ep + Fz * _ez).diff(l) - K * er
    sol = sp.solve([sp.simplify((balance.T * er)[0]), sp.simplify((balance.T * ep)[0])], [Fr, Fp], dict=True)
    ok = len(sol) == 1 and _zero(sol[0][Fr]) and _zero(sol[0][Fp] + K / wc)
    return Derivation("F_r = 0, F_phi = -K/w", "same", ok, "force balance solved for F_r, F_phi")


def helix_radial_equilibrium() -> Derivation:
    """Eq. (equilibrium): the e_r component of (equi-components) with F_phi = -K/w."""
    Fz, K, wc = sp.symbols("F_z K w")
    c = sp.sqrt(1 - R**2 * wc**2)
    radial = c * (EI * R * wc**3 + K / wc) + R * wc * Fz
    printed = c * (EI * R * wc**4 + K) + R * wc**2 * Fz
    return Derivation("sqrt(1-R^2w^2)(EI R w^4 + K) + R w^2 F_z = 0", "same", _zero(radial * wc - printed),
                      "w x (radial component with F_phi = -K/w) minus the printed form")


def _helix_K():
    """K of the frictionless helix with torque-free ends: M_z + (r x F)_z = 0 along the rod
    (the wall force is radial, so it exerts no torque about the axis)."""
    K = sp.symbols("K", positive=True)
    wc = sp.symbols("w", positive=True)
    Mz = EI * R**2 * wc**3                         # e_z component of Eq. (M-helix)
    rxF_z = R * (-K / wc)                          # r = R e_r, F_phi = -K/w
    return sp.solve(sp.Eq(Mz + rxF_z, 0), K)[0], wc


def pitch_lowest_order() -> Derivation:
    """Eq. (dotphi): minimising (EI/2) R^2 w^4 + |F| sqrt(1 - R^2 w^2) per length."""
    F = sp.symbols("F", positive=True)
    x = sp.symbols("x", positive=True)          # x = w^2
    energy = EI / 2 * R**2 * x**2 + F * sp.sqrt(1 - R**2 * x)
    stationary = sp.simplify(sp.diff(energy, x) / R**2)       # = 0 at the minimum
    exact_ok = _zero(stationary * 2 * sp.sqrt(1 - R**2 * x) - (2 * EI * x * sp.sqrt(1 - R**2 * x) - F))
    lowest = sp.solve(stationary.subs(R, 0), x)                # lowest order in R w
    ok = exact_ok and len(lowest) == 1 and _zero(lowest[0] - F / (2 * EI))
    return Derivation("w^2 = |F_z|/(2EI) (lowest order; exact: 2EI w^2 sqrt(1-R^2w^2) = |F_z|)", "w^2 = |F_z|/(2EI)",
                      ok, "energy minimised in x = w^2, then R -> 0")


def wall_force_lowest_order() -> Derivation:
    """Eq. (K-simple): with K = EI R w^4 (torque-free ends) and w^2 = |F|/(2EI)."""
    F = sp.symbols("F", positive=True)
    K_of_w, wc = _helix_K()
    ours = sp.simplify(K_of_w.subs(wc, sp.sqrt(F / (2 * EI))))
    printed = R * F**2 / (2 * EI)
    return Derivation(f"K = {sp.sstr(ours)}", "K = R*F**2/(2*EI)", _zero(ours - printed),
                      f"K = {sp.sstr(K_of_w)} from the conserved axial torque; ratio paper/ours = "
                      f"{sp.sstr(sp.simplify(printed / ours))}")


def helix_with_torque() -> Derivation:
    """A constant-pitch helix on the wall that carries an axial torque tau (M_z + (r x F)_z =
    tau instead of 0, our extension; docs/model.md, "The axial torque budget"): the wall force
    per length from the torque and F_phi = -K/w, then |F_z| from Eq. (equilibrium). Checked
    against the forms confined_rod.analysis.torque evaluates (the torque budget of the datasets)."""
    from ..analysis import torque

    tau, F = sp.symbols("tau F", real=True)
    wc = sp.symbols("w", positive=True)
    K = sp.symbols("K")
    c = sp.sqrt(1 - R**2 * wc**2)
    K_tau = sp.solve(sp.Eq(EI * R**2 * wc**3 + R * (-K / wc), tau), K)[0]
    F_tau = sp.solve(sp.Eq(c * (EI * R * wc**4 + K_tau) + R * wc**2 * (-F), 0), F)[0]   # F_z = -|F_z|
    ok = _zero(K_tau - (EI * R**2 * wc**4 - wc * tau) / R) and _zero(F_tau - c * (2 * EI * wc**2 - tau / (R**2 * wc)))
    ok = ok and _zero(F_tau.subs(tau, 0) - 2 * EI * wc**2 * c)
    # at a given force: eliminate tau; to lowest order in R w the wall force peaks at w^2 = F/(2EI)
    tau_F = sp.solve(sp.Eq(F_tau, F), tau)[0]
    K_F = sp.simplify(K_tau.subs(tau, tau_F))
    ok = ok and _zero(K_F - R * wc**2 * (F / c - EI * wc**2))
    x = sp.symbols("x", positive=True)                        # x = w^2, lowest order (c = 1)
    K_low = (R * x * (F - EI * x))
    peak = sp.solve(sp.diff(K_low, x), x)
    ok = ok and len(peak) == 1 and _zero(peak[0] - F / (2 * EI)) and _zero(K_low.subs(x, peak[0]) - R * F**2 / (4 * EI))
    for vals in ({R: 0.9, EI: 1.0, wc: 0.3, tau: 0.004}, {R: 1.0, EI: 2.0, wc: 0.1, tau: -0.01}):
        num = {str(k): float(v) for k, v in vals.items()}
        ok = ok and abs(float(K_tau.subs(vals)) - float(torque.helix_wall_force(num["R"], num["w"], num["tau"],
                                                                                num["EI"]))) < 1e-12
        ok = ok and abs(float(F_tau.subs(vals)) - float(torque.helix_force(num["R"], num["w"], num["tau"],
                                                                           num["EI"]))) < 1e-12
    return Derivation(f"K = {sp.sstr(sp.simplify(K_tau))}, |F_z| = {sp.sstr(sp.simplify(F_tau))}",
                      "(not in the paper: its helix is torque-free, tau = 0)", ok,
                      "axial torque M_z + R F_phi = tau with F_phi = -K/w, then Eq. (equilibrium); tau = 0 gives "
                      "the torque-free helix; at a given force K = R w^2 (F/c - EI w^2), to lowest order largest, "
                      "R F^2/(4EI), at the torque-free w^2 = F/(2EI); equal to confined_rod.analysis.torque's forms at two "
                      "points")


def wall_force_pitch_relation() -> Derivation:
    """The wall force at a given axial force as a function of the pitch (our finding): K = R w^2
    (F/c - EI w^2) (helix_with_torque: the torque eliminated), to lowest order in R w (c = 1) with
    w = x w0, w0^2 = F/(2EI): K/(R F^2/(4EI)) = x^2 (2 - x^2). Stationary only at the torque-free
    pitch x = 1, where it is largest (1, the corrected K); 0 at x = sqrt 2 and for x -> 0. Equal
    to confined_rod.analysis.torque.helix_wall_force_at_force (exact in c) at two points."""
    from ..analysis import torque

    F, x, wc = sp.symbols("F x w", positive=True)
    w0 = sp.sqrt(F / (2 * EI))
    K_exact = R * wc**2 * (F / sp.sqrt(1 - R**2 * wc**2) - EI * wc**2)
    ratio = sp.simplify(K_exact.subs(sp.sqrt(1 - R**2 * wc**2), 1).subs(wc, x * w0) / (R * F**2 / (4 * EI)))
    ok = _zero(ratio - x**2 * (2 - x**2))
    stationary = [r for r in sp.solve(sp.diff(ratio, x), x) if r.is_positive]
    ok = ok and stationary == [1] and _zero(ratio.subs(x, 1) - 1) and sp.diff(ratio, x, 2).subs(x, 1) < 0
    ok = ok and _zero(ratio.subs(x, sp.sqrt(2)))
    for vals in ({R: 0.9, EI: 1.0, wc: 0.3, F: 0.2}, {R: 1.0, EI: 2.0, wc: 0.1, F: 0.05}):
        num = {str(k): float(v) for k, v in vals.items()}
        ok = ok and abs(float(K_exact.subs(vals)) - float(torque.helix_wall_force_at_force(
            num["R"], num["w"], num["F"], num["EI"]))) < 1e-12
    return Derivation("K/(R F^2/(4EI)) = x^2 (2 - x^2), x = w/w0, w0^2 = F/(2EI)",
                      "(not in the paper: its helix is torque-free, x = 1)", ok,
                      "K = R w^2 (F/c - EI w^2) at c = 1, w = x w0; stationary only at x = 1 (a maximum, 1), zero at "
                      "x = sqrt 2; the exact form equal to confined_rod.analysis.torque.helix_wall_force_at_force at "
                      "two points")


def force_decay(paper_K: bool = False) -> sp.Expr:
    """Solve d|F|/dl = -k_fr K(|F|), |F|(0) = F0, with the derived (or printed) K."""
    F = sp.Function("F")
    K = R * F(l)**2 / ((2 if paper_K else 4) * EI)
    sol = sp.dsolve(sp.Eq(F(l).diff(l), -kfr * K), F(l), ics={F(0): F0})
    return sp.simplify(sol.rhs)


def transmitted_force_simple() -> Derivation:
    """Eq. (Fz-simple): |F_z(l)| = (1/|F_z0| + k_fr R l/(2EI))^-1."""
    ours = force_decay()
    printed = 1 / (1 / F0 + kfr * R * l / (2 * EI))
    return Derivation("|F_z(l)| = (1/|F_z0| + k_fr R l/(4EI))^-1", "(1/|F_z0| + k_fr R l/(2EI))^-1",
                      _zero(ours - printed), "dsolve of d|F|/dl = -k_fr R F^2/(4EI)")


def singular_point() -> Derivation:
    """Eq. (l_c): the pole of |F_z(l)|."""
    pole = sp.solve(sp.denom(sp.together(force_decay())), l)
    ours = pole[0] if pole else sp.nan
    printed = -2 * EI / (kfr * R * F0)
    return Derivation(f"l_c = {sp.sstr(ours)}", "l_c = -2*EI/(k_fr*R*F_0)", _zero(ours - printed),
                      "pole of the solution of the corrected decay law")


def universal_force_unit() -> Derivation:
    """Eq. (Fz-universal): the force unit F_0 that makes |F_z(l)|/F_0 = (F_0/|F_z0| + l/L)^-1."""
    Fu = sp.symbols("F_u", positive=True)
    ours = sp.solve(sp.Eq(sp.simplify(force_decay() / Fu), 1 / (Fu / F0 + l / L)), Fu)
    ours = ours[0] if ours else sp.nan
    printed = 2 * EI / (kfr * R * L)
    return Derivation(f"F_0 = {sp.sstr(ours)}", "F_0 = 2*EI/(k_fr*R*L)", _zero(ours - printed),
                      "force unit solved from the corrected decay law")


# -- the exact analysis (Sec. III B) -------------------------------------------------------
def _exact_balance():
    Fr, Fp, Fz = (sp.Function(n)(l) for n in ("F_r", "F_phi", "F_z"))
    return _torque_balance(Fr, Fp, Fz), Fr, Fp, Fz


def exact_torque_radial() -> Derivation:
    """Eq. (M-er)."""
    bal, Fr, Fp, Fz = _exact_balance()
    c2 = 1 - R**2 * w**2
    printed = (EI * R / c2 ** sp.Rational(3, 2)
               * (w**3 * c2**2 - w.diff(l, 2) * c2 - R**2 * w * w.diff(l) ** 2)
               - Fp * sp.sqrt(c2) + Fz * R * w)
    return Derivation("as printed", "Eq. (M-er)", _zero(_project(bal, _er) - printed),
                      "torque balance projected on e_r minus Eq. (M-er)")


def exact_torque_binormal() -> Derivation:
    """Eq. (M-e2)."""
    bal, Fr, Fp, Fz = _exact_balance()
    printed = -sp.Rational(3, 2) * EI * R * (w**2).diff(l) + Fr
    return Derivation("as printed", "Eq. (M-e2)", _zero(_project(bal, _tangent().cross(_er)) - printed),
                      "torque balance projected on t x e_r minus Eq. (M-e2)")


def exact_force_balance() -> Derivation:
    """Eqs. (F-er)-(F-ez): dF/dl + K = 0 with K = K(l)(-e_r + k_fr e_z)."""
    Fr, Fp, Fz, K = (sp.Function(n)(l) for n in ("F_r", "F_phi", "F_z", "K"))
    bal = (Fr * _er + Fp * _ep + Fz * _ez).diff(l).subs(_ON_CURVE) + K * (-_er + kfr * _ez)
    printed = (Fr.diff(l) - w * Fp - K, w * Fr + Fp.diff(l), Fz.diff(l) + kfr * K)
    ok = all(_zero(_project(bal, e) - p) for e, p in zip((_er, _ep, _ez), printed))
    return Derivation("as printed", "Eqs. (F-er)-(F-ez)", ok, "each projection minus the printed component")


def azimuthal_force_partial() -> Derivation:
    """The 'partial result' F_phi = A - EI w^3 from Eqs. (M-e2) and (F-ephi)."""
    Fr = sp.Rational(3, 2) * EI * R * (w**2).diff(l)         # Eq. (M-e2)
    Fp = sp.Function("F_phi")(l)
    sol = sp.dsolve(sp.Eq(Fp.diff(l), -w * Fr), Fp)           # Eq. (F-ephi)
    ours = sol.rhs
    printed = A - EI * w**3
    # the two agree if they differ by a constant only
    ok = _zero(sp.diff(ours - printed, l))
    return Derivation("F_phi = A - EI R w^3", "F_phi = A - EI w^3", ok,
                      f"dsolve gives {sp.sstr(ours)}; the printed form differs by a non-constant term")


# -- the discrete model (Sec. IV), by dimensions and the Euler limit ------------------------
# dimensions as powers of (force, length, time)
_FORCE, _LENGTH, _TIME = sp.symbols("force length time", positive=True)
DIMENSIONS = {
    "EI": _FORCE * _LENGTH**2, "l0": _LENGTH, "torque": _FORCE * _LENGTH, "force": _FORCE,
    "beta_ph": _FORCE * _TIME / _LENGTH**2,           # drag force per length per velocity
    "k_ph": _FORCE, "spring": _FORCE / _LENGTH,
}


def _dimensionless(expr) -> bool:
    return sp.simplify(expr) == 1


def bending_constant() -> Derivation:
    """C = EI/l0^2 (paper). C multiplies a dimensionless cross product in a torque, so it
    must be a torque; and the buckling load of a hinged chain of N links with joint
    stiffness C, F_c = (4C/l0) sin^2(pi/2N), must tend to pi^2 EI/L^2."""
    N = sp.symbols("N", positive=True, integer=True)
    d = DIMENSIONS
    euler = lambda C: sp.limit(4 * C / l0 * sp.sin(sp.pi / (2 * N)) ** 2 / (sp.pi**2 * EI / (N * l0) ** 2),  # noqa: E731
                               N, sp.oo)
    ours_ok = _dimensionless(d["EI"] / d["l0"] / d["torque"]) and _zero(euler(EI / l0) - 1)
    paper_ok = _dimensionless(d["EI"] / d["l0"] ** 2 / d["torque"]) and _zero(euler(EI / l0**2) - 1)
    assert ours_ok, "C = EI/l0 must pass both tests"
    return Derivation("C = EI/l0", "C = EI/l0^2", paper_ok,
                      "dimensions of EI/l0^2 over a torque: "
                      f"{sp.sstr(sp.simplify(d['EI'] / d['l0']**2 / d['torque']))}; "
                      f"continuum limit of the discrete Euler load over pi^2 EI/L^2: C = EI/l0 -> "
                      f"{sp.sstr(euler(EI / l0))}, C = EI/l0^2 -> {sp.sstr(euler(EI / l0**2))}")


def translational_drag() -> Derivation:
    """beta = l0 beta_ph: beta dr/dt must be a force."""
    d = DIMENSIONS
    ok = _dimensionless(d["l0"] * d["beta_ph"] * _LENGTH / _TIME / d["force"])
    return Derivation("beta = l0 beta_ph", "same", ok, "[l0 beta_ph dr/dt] / [force] = 1")


def bond_constant() -> Derivation:
    """k = k_ph/l0: per link, (k/2)(eps l0)^2 must equal (k_ph/2) eps^2 l0."""
    eps = sp.symbols("epsilon", positive=True)
    k = sp.solve(sp.Eq(sp.Symbol("k") / 2 * (eps * l0) ** 2, sp.Symbol("k_ph") / 2 * eps**2 * l0), sp.Symbol("k"))[0]
    ok = (_zero(k - sp.Symbol("k_ph") / l0)
          and _dimensionless(DIMENSIONS["k_ph"] / DIMENSIONS["l0"] / DIMENSIONS["spring"]))
    return Derivation(f"k = {sp.sstr(k)}", "k = k_ph/l0", ok, "strain energy per link; [k_ph/l0] = force/length")


def rotational_drag() -> Derivation:
    """Eq. (rot): beta dt/dt = M x t with the translational beta = l0 beta_ph."""
    d = DIMENSIONS
    lhs = d["l0"] * d["beta_ph"] / _TIME          # [beta dt/dt], t dimensionless
    ratio = sp.simplify(d["torque"] / lhs)
    return Derivation("rotational drag beta_ph l0 x (length^2): e.g. beta_ph l0^3/12 for a rigid link", "beta",
                      _dimensionless(ratio), f"[M x t] / [beta dt/dt] = {sp.sstr(ratio)}")


DERIVATIONS: dict[str, Callable[[], Derivation]] = {
    "helix_torque": helix_torque,
    "helix_torque_balance": helix_torque_balance,
    "helix_with_torque": helix_with_torque,
    "wall_force_pitch_relation": wall_force_pitch_relation,
    "azimuthal_force_constant_pitch": azimuthal_force_constant_pitch,
    "helix_radial_equilibrium": helix_radial_equilibrium,
    "pitch_lowest_order": pitch_lowest_order,
    "wall_force_lowest_order": wall_force_lowest_order,
    "transmitted_force_simple": transmitted_force_simple,
    "singular_point": singular_point,
    "universal_force_unit": universal_force_unit,
    "exact_torque_radial": exact_torque_radial,
    "exact_torque_binormal": exact_torque_binormal,
    "exact_force_balance": exact_force_balance,
    "azimuthal_force_partial": azimuthal_force_partial,
    "bending_constant": bending_constant,
    "translational_drag": translational_drag,
    "bond_constant": bond_constant,
    "rotational_drag": rotational_drag,
}
