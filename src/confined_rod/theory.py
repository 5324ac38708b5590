"""Analytic relations of the paper's "simple model" (a helix on the wall), corrected.

Derivations and the paper's errors: docs/model.md.  With free ends the axial
torque vanishes, which gives for a helix of pitch rate omega = dphi/ds on the
wall of a cylinder of radius R

    2 EI omega^2 sqrt(1 - R^2 omega^2) = |F_z|,      K = EI R omega^4,

so to lowest order K = R F_z^2 / (4 EI) (the paper's Eq. K-simple has 2 EI).
Coulomb friction k_fr K per unit length then gives d|F_z|/dl = -k_fr K, i.e.

    |F_z(s)| = (1/|F_z0| + k_fr R s / (4 EI))^-1                  (corrected)
    |F_z(s)| = (1/|F_z0| + k_fr R s / (2 EI))^-1                  (paper, Eq. Fz-simple)

with s measured from the start of the helix, where |F_z| = |F_z0|.
"""
from __future__ import annotations

import numpy as np

#: denominator of K = R F^2 / (DENOM EI): 4 from the torque balance, 2 in the paper
K_DENOMINATOR = 4.0
K_DENOMINATOR_PAPER = 2.0


def helix_frictionless(load: float, R: float = 1.0, EI: float = 1.0) -> tuple[float, float]:
    """Bulk pitch rate omega = dphi/ds and wall force per length K of a
    frictionless helix on the wall with no torque at the free ends:
        2 EI omega^2 sqrt(1 - R^2 omega^2) = |F_z|,   K = EI R omega^4.
    To lowest order omega^2 = |F_z|/(2EI) and K = R F_z^2/(4 EI)."""
    # solve 2 EI w^2 sqrt(1 - R^2 w^2) = F for the small root by bisection on u = (R w)^2
    f = load * R * R / (2.0 * EI)
    if f > 2.0 / (3.0 * np.sqrt(3.0)):
        raise ValueError(f"no helix on the wall for load {load} (max 4 EI/(3 sqrt(3) R^2))")
    lo, hi = 0.0, 2.0 / 3.0  # u sqrt(1-u) increases on [0, 2/3]
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid * np.sqrt(1.0 - mid) < f:
            lo = mid
        else:
            hi = mid
    omega = np.sqrt(0.5 * (lo + hi)) / R
    return float(omega), float(EI * R * omega**4)


def force_decay(s, F0: float, k_fr: float, R: float = 1.0, EI: float = 1.0, *, paper: bool = False):
    """|F_z(s)| of the simple model: a frictional helix from s = 0 on, where |F_z| = F0.

    ``paper=True`` gives the paper's Eq. (Fz-simple) with K = R F^2/(2 EI), 2x too
    much friction. Units: s in R, F0 in EI/R^2, result in EI/R^2."""
    if F0 <= 0:
        raise ValueError(f"F0 must be positive, got {F0!r}")
    denom = K_DENOMINATOR_PAPER if paper else K_DENOMINATOR
    return 1.0 / (1.0 / F0 + k_fr * R * np.asarray(s, dtype=float) / (denom * EI))


def critical_length(F0: float, k_fr: float, R: float = 1.0, EI: float = 1.0, *, paper: bool = False) -> float:
    """l_c = -4 EI / (k_fr R F0): the (negative) singular point of force_decay, so
    force_decay(s) = 4 EI/(k_fr R) / (s - l_c). The paper's Eq. (l_c) has 2 EI."""
    denom = K_DENOMINATOR_PAPER if paper else K_DENOMINATOR
    return -denom * EI / (k_fr * R * F0)


#: largest |F_z| a torque-free helix on the wall can carry: max of 2 EI w^2 sqrt(1 - R^2 w^2),
#: at (R w)^2 = 2/3, i.e. 4 EI/(3 sqrt(3) R^2)
HELIX_F_MAX = 4.0 / (3.0 * np.sqrt(3.0))


def helix_force(omega, R: float = 1.0, EI: float = 1.0):
    """|F_z| = 2 EI w^2 sqrt(1 - R^2 w^2) of a torque-free helix on the wall with pitch rate
    w = |dphi/ds| (docs/model.md); defined for R|w| <= 1 (0 beyond)."""
    u = (R * np.asarray(omega, dtype=float)) ** 2
    return 2.0 * EI / R**2 * u * np.sqrt(np.clip(1.0 - u, 0.0, None))


def helix_pitch_rate(F, R: float = 1.0, EI: float = 1.0):
    """Inverse of helix_force on its small-pitch branch: the w >= 0 with 2 EI w^2 sqrt(1 - R^2 w^2)
    = |F| and (R w)^2 <= 2/3 (vectorised bisection to 1e-15). |F| above HELIX_F_MAX EI/R^2
    has no helix on the wall: ValueError."""
    f = np.abs(np.asarray(F, dtype=float)) * R**2 / (2.0 * EI)
    if np.any(f > HELIX_F_MAX / 2.0 * (1 + 1e-12)):
        raise ValueError(f"|F_z| up to {float(np.max(f)) * 2 * EI / R**2:g} exceeds the largest force a helix on "
                         f"the wall carries, {HELIX_F_MAX * EI / R**2:.4g} EI/R^2")
    lo, hi = np.zeros_like(f), np.full_like(f, 2.0 / 3.0)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        below = mid * np.sqrt(1.0 - mid) < f
        lo = np.where(below, mid, lo)
        hi = np.where(below, hi, mid)
    return np.sqrt(0.5 * (lo + hi)) / R


def discrete_helix(F: float, l0: float, R: float = 1.0, EI: float = 1.0) -> dict[str, float]:
    """The torque-free helix of the discrete chain (links of length l0, bending C = EI/l0, joints on
    the wall at radius R) under the axial force |F| (docs/model.md, "The discrete helix").

    Its energy per link is EI l0 u^4/(2 R^2) + |F| l0 sqrt(1 - u^2) exactly, u the sine of a link's
    angle to the axis, the continuum's energy per length times l0 with u = R w: the relation
    2 EI w^2 sqrt(1 - R^2 w^2) = |F| and the wall force K = EI R w^4 hold for any l0 in the chord
    variable w = u/R. The only l0 term is the azimuth a link spans, theta = 2 arcsin(u l0/(2R)), not
    u l0/R: dphi/ds = theta/l0 and the pitch 2 pi l0 sqrt(1 - u^2)/theta are off the continuum's by
    the factors arcsin(x)/x and x/arcsin(x), x = w l0/2, i.e. +-(w l0)^2/24 to lowest order; the
    link centres sit at R cos(theta/2) ~ R (1 - (w l0)^2/8).

    Returns w (chord variable, 1/R), dphi_ds (1/R), pitch (R), K (EI/R^3), rho_centre (R) and
    theta (rad). Dimensions: u and theta are numbers, l0 and R lengths."""
    if l0 <= 0:
        raise ValueError(f"l0 must be positive, got {l0!r}")
    w = float(helix_pitch_rate(F, R, EI))
    u = R * w
    x = w * l0 / 2.0
    if x >= 1.0:
        raise ValueError(f"a link of l0 = {l0} cannot span a helix of pitch rate {w:g} on radius {R}")
    theta = 2.0 * float(np.arcsin(x))
    return {"w": w, "dphi_ds": theta / l0, "pitch": 2.0 * np.pi * l0 * np.sqrt(1.0 - u * u) / theta,
            "K": EI * R * w**4, "rho_centre": R * np.cos(theta / 2.0), "theta": theta}


# -- the thresholds of the bifurcation diagram (docs/model.md, "Transitions") ----------------
def first_threshold(L: float, R: float, l0: float, EI: float) -> float:
    """Euler's load of the discrete rod lying diagonally across the pore:
    (4 EI/l0^2) sin^2(pi l0/(2L)) sqrt(1 - 4R^2/L^2); pi^2 EI/L^2 sqrt(1 - 4R^2/L^2) as l0 -> 0."""
    return 4.0 * EI / l0**2 * np.sin(np.pi * l0 / (2.0 * L)) ** 2 * np.sqrt(max(0.0, 1.0 - 4.0 * R**2 / L**2))


def second_threshold_estimate(L: float, EI: float) -> float:
    """The second Euler mode 4 pi^2 EI/L^2: the two halves of an arc resting on the wall
    at mid-span buckle again, out of the plane (measured: 3.69, 3.93, 3.98 x pi^2 EI/L^2
    at L/R = 10, 20, 40)."""
    return 4.0 * np.pi**2 * EI / L**2


def threshold_brackets(L: float, EI: float) -> dict[str, tuple[float, float]]:
    """Load brackets the bisection starts from: (0.5, 1.5) x pi^2 EI/L^2 for the first
    threshold, (2.4, 4.8) x pi^2 EI/L^2 for the second."""
    F_E = np.pi**2 * EI / L**2
    return {"first": (0.5 * F_E, 1.5 * F_E), "second": (2.4 * F_E, 4.8 * F_E)}


def helix_load_limit(R: float, EI: float) -> float:
    """Largest axial load a torque-free helix on the wall can carry:
    max over omega of 2 EI omega^2 sqrt(1 - R^2 omega^2) = 4/(3 sqrt 3) EI/R^2 (at R^2 omega^2 = 2/3)."""
    return 4.0 / (3.0 * np.sqrt(3.0)) * EI / R**2


def span_euler_load(EI: float, span: float) -> float:
    """pi^2 EI/g^2: Euler's load of a free span of length g between two laterally
    guided points (pinned-pinned), the rod between the guided loaded end and the pore
    entrance g below it.  Above it the span bows out of the pore: the escape of Fig 8
    (measured 0.90-1.02 times this for g = 4-8 R, docs/model.md, 'Fig 8')."""
    return np.pi**2 * EI / span**2


def fold_bracket(R: float, EI: float, span: float = 0.0) -> tuple[float, float]:
    """Load bracket of the fold (U-bend) or escape threshold's bisection: (0.3, 1.2) EI/R^2,
    about the helix limit 0.77 EI/R^2 (measured fold thresholds 0.61-0.67 EI/R^2,
    docs/model.md, 'Fig 8'); with a free span g above the entrance, its lower end is
    lowered to half the span's Euler load where that is smaller."""
    lo = 0.3 * EI / R**2
    if span > 0:
        lo = min(lo, 0.5 * span_euler_load(EI, span))
    return lo, 1.2 * EI / R**2
