"""What a scene can compute: limits checked before a run and on its final state.

A scene is *refused up front* (``SceneError`` naming the parameter to change and
its valid range) when one of these limits can be computed from its parameters:

* magnitudes: every dimensional parameter, in units of R and EI, lies within
  ``[1/MAGNITUDE, MAGNITUDE]`` (and R, EI themselves within ``SCALE_RANGE``), so
  no product of them (R^4/EI, k L, ...) over- or underflows float64;
* size: at most ``MAX_LINKS`` links (memory and time; checked in scenes.py);
* resolution: the shortest bending length the load can excite, the Euler
  wavelength 2 pi sqrt(EI/load), spans at least ``MIN_LINKS_PER_WAVELENGTH`` links;
* inextensibility: the axial strain load/k_ph is at most ``MAX_STRAIN``;
* a hard wall: the estimated penalty penetration max(load, R load^2 l0/(8 EI))/k_w
  (an end pressed with the full load, or a link of a helix on the wall,
  K = R F^2/(4 EI) per length) is at most ``MAX_PENETRATION`` R;
* round-off: float64 resolves the equilibrium to ``roundoff_tol``; a scene whose
  floor lies more than ``ROUNDOFF_MARGIN`` times above the tol it asks for is
  refused (within the margin the run is tested at the floor, and the floor is
  stored as ``tol_effective``); ``tol`` itself is at most ``TOL_MAX``;
* snapshots: the shapes it would store fit in ``MAX_SNAPSHOT_BYTES`` (where t_max
  bounds their number).

A run whose *final state* violates the model (a link end deeper than
MAX_PENETRATION R in the wall or the floor, a bond stretched beyond
MAX_BOND_GAP l0) ends as not converged with the reason (:func:`state_violations`).

The cost of a run is estimated from measured timings (:func:`estimated_wall_time`);
the command line refuses a scene above its budget unless told otherwise.
"""
from __future__ import annotations

import functools
import json
import math
import re
from pathlib import Path
from typing import Callable

import numpy as np

ROUNDOFF_FACTOR = 4.0  # see roundoff_force
ROUNDOFF_MARGIN = 100.0  # a scene's round-off floor may lie this far above its tol (it is then used instead)
TOL_MAX = 0.1  # eps = 1 is a residual force density as large as the load spread over the rod
MAGNITUDE = 1e12  # dimensionless parameters (in units of R, EI) within [1/MAGNITUDE, MAGNITUDE]
SCALE_RANGE = (1e-30, 1e30)  # R and EI themselves (SI or any other unit system)
MAX_LINKS = 100_000
MIN_LINKS_PER_WAVELENGTH = 4.0
MAX_STRAIN = 0.05
MAX_PENETRATION = 0.05  # R
#: R: a link end above the open pore entrance this far from the axis has left the pore (the run ends
#: 'escaped'; the kernels get it in the scene's parameter vector, the escape figure's frames use it)
ESCAPE_RADIUS = 1.1
MAX_BOND_GAP = 0.1  # l0, in the final state
SEED_MAX = 2**63 - 1  # stored as a 64-bit integer
MIN_DT_FACTOR = 1e-3
MAX_DT_FACTOR = 10.0  # explicit: stable up to ~1.2 x the Gershgorin estimate; beyond, for stress tests only
K_FR_MAX = 1e3  # Coulomb coefficients of real surfaces are O(1); beyond this everything sticks anyway
MAX_SNAPSHOT_BYTES = 512 * 2**20
DEFAULT_BUDGET_S = 3600.0  # command line: refuse an estimated wall time above this unless --budget says more

_EPS = float(np.finfo(float).eps)
_UNIT_TOKEN = re.compile(r"^(R|EI|beta_ph)(-?\d+)?$")

Fail = Callable[[str, str], None]


def unit_scale(units: str, R: float, EI: float) -> float | None:
    """The scene's unit of a quantity, as a number (``'EI R-2'`` -> EI/R^2); None
    for dimensionless or categorical units ('1', 'rad', 'mixed')."""
    scale, dimensional = 1.0, False
    for token in units.split():
        m = _UNIT_TOKEN.match(token)
        if not m:
            return None
        base = {"R": R, "EI": EI, "beta_ph": 1.0}[m.group(1)]
        scale *= base ** int(m.group(2) or 1)
        dimensional = dimensional or m.group(1) != "beta_ph"
    return scale if dimensional else None


# -- round-off -------------------------------------------------------------------
def roundoff_force(scene) -> float:
    """Residual force per link below which float64 cannot resolve a balance.

    Positions up to L are representable only to about eps L, and a bond turns a
    position error into a force k = k_ph/l0 times it; the wall and the load add
    eps k_w R and eps load.  Measured: the implicit Newton iteration stalls at
    1.6 eps k L (L/R = 320, k_ph = 1e4, l0 = 0.5 R), hence ROUNDOFF_FACTOR = 4."""
    c = scene.constants()
    return ROUNDOFF_FACTOR * _EPS * (c.k * scene.L + scene.k_w * scene.R + scene.load)


def roundoff_tol(scene, load: float | None = None) -> float:
    """The round-off floor in the normalisation of the equilibrium test
    (eps_F = max|F_i| L/(l0 load)), with a factor 2 of headroom; at another load if given
    (the stages of a load ramp)."""
    if load is None:
        return 2.0 * roundoff_force(scene) * scene.L / (scene.l0 * scene.load)
    c = scene.constants()
    force = ROUNDOFF_FACTOR * _EPS * (c.k * scene.L + scene.k_w * scene.R + load)
    return 2.0 * force * scene.L / (scene.l0 * load)


def equilibrium_tol(scene) -> float:
    """Tolerance of the equilibrium test: scene.tol, or the round-off floor where
    that is larger (at most ROUNDOFF_MARGIN x tol: larger floors are refused).
    The floor grows as L^2 k_ph/l0^2: 1.2e-4 at L/R = 640, k_ph = 1e4, l0 = 0.5 R,
    load 0.25, where tol = 1e-5 cannot be reached in float64."""
    return max(scene.tol, roundoff_tol(scene))


# -- checks before a run -----------------------------------------------------------
def check_magnitudes(scene, quantities, fail: Fail) -> None:
    """Every dimensional parameter within [1/MAGNITUDE, MAGNITUDE] in the scene's units."""
    lo, hi = SCALE_RANGE
    for key in ("R", "EI"):
        v = getattr(scene, key)
        if not lo <= v <= hi:
            fail(key, f"must lie within [{lo:g}, {hi:g}]; any unit system works, the internal units are R = EI = 1")
    R, EI = scene.R, scene.EI
    for q in quantities:
        v = getattr(scene, q.name, None)
        scale = unit_scale(q.units, R, EI)
        if scale is None or v is None or isinstance(v, (bool, str)):
            continue
        values = v if isinstance(v, (tuple, list)) else (v,)
        for x in values:
            if x == 0:
                continue
            y = abs(x) / scale
            if not 1.0 / MAGNITUDE <= y <= MAGNITUDE:
                fail(q.name, f"{y:.3g} {q.units.replace('-', '^-')} in the scene's units R = {R:g}, EI = {EI:g}; "
                             f"must lie within [{1 / MAGNITUDE:g}, {MAGNITUDE:g}] of them")


def check_computable(scene, fail: Fail) -> None:
    """The limits of the model and of float64 that follow from the parameters."""
    R, l0, load = scene.R, scene.l0, scene.load
    if scene.dt_factor < MIN_DT_FACTOR:
        fail("dt_factor", f"must be >= {MIN_DT_FACTOR:g} (the explicit step would be needlessly tiny)")
    if scene.dt_factor > MAX_DT_FACTOR:
        fail("dt_factor", f"must be <= {MAX_DT_FACTOR:g} (fraction of the explicit stability limit; the "
                          "scheme diverges above ~1.2, larger values exist only for stability stress tests)")
    if scene.k_fr > K_FR_MAX:
        fail("k_fr", f"must be <= {K_FR_MAX:g} (a Coulomb coefficient; at such values every contact sticks)")
    if scene.tol > TOL_MAX:
        fail("tol", f"must be <= {TOL_MAX:g}: eps = 1 is a residual force as large as the load spread over the "
                    "rod, so a larger tol accepts the unrelaxed start")
    EI_eff = scene.C_l0()  # the bending stiffness the joints represent (EI, or EI R/l0 as printed)
    wavelength = 2.0 * math.pi * math.sqrt(EI_eff / load)
    if wavelength < MIN_LINKS_PER_WAVELENGTH * l0:
        fail("load", f"bends the rod on the Euler wavelength 2 pi sqrt(EI/load) = {wavelength:.3g}, shorter than "
                     f"{MIN_LINKS_PER_WAVELENGTH:g} links of l0 = {l0:g}: lower the load or take "
                     f"l0 <= {wavelength / MIN_LINKS_PER_WAVELENGTH:.3g}")
    strain = load / scene.k_ph
    if strain > MAX_STRAIN:
        fail("k_ph", f"the load compresses the rod by load/k_ph = {strain:.3g} > {MAX_STRAIN:g}: not an "
                     f"inextensible rod; take k_ph >= {load / MAX_STRAIN:.3g}")
    pressing = max(load, R * load**2 * l0 / (8.0 * EI_eff))
    depth = pressing / scene.k_w / R
    if depth > MAX_PENETRATION:
        fail("k_w", f"the wall would give way by about {depth:.3g} R under the load (max(load, R load^2 l0/(8 EI))"
                    f"/k_w), more than {MAX_PENETRATION:g} R: not a hard wall; take "
                    f"k_w >= {pressing / (MAX_PENETRATION * R):.3g}")
    check_roundoff(scene, fail)
    check_snapshots(scene, fail)


def check_roundoff(scene, fail: Fail) -> None:
    floor = roundoff_tol(scene)
    if floor <= ROUNDOFF_MARGIN * scene.tol:
        return
    c = scene.constants()
    terms = {"k_ph": c.k * scene.L, "k_w": scene.k_w * scene.R, "load": scene.load}
    key = max(terms, key=terms.get)
    # the k_ph (or k_w) at which the floor would sit at the margin
    budget = ROUNDOFF_MARGIN * scene.tol * scene.l0 * scene.load / (2.0 * ROUNDOFF_FACTOR * _EPS * scene.L)
    if key == "k_ph":
        bound = (budget - terms["k_w"] - terms["load"]) * scene.l0 / scene.L
        hint = f"take k_ph <= {bound:.3g}, shorten L," if bound > 0 else "shorten L"
    elif key == "k_w":
        bound = (budget - terms["k_ph"] - terms["load"]) / scene.R
        hint = f"take k_w <= {bound:.3g}" if bound > 0 else "lower k_w"
    else:
        hint = "change the load"
    fail(key, f"float64 resolves this scene's equilibrium only to eps = {floor:.3g} (round-off floor), "
              f"{floor / scene.tol:.3g} x the tol = {scene.tol:g} asked for, beyond the margin of "
              f"{ROUNDOFF_MARGIN:g}: {hint} or raise tol to >= {floor / ROUNDOFF_MARGIN:.2g}")


def snapshot_bytes(scene, n_snapshots: float) -> float:
    """Memory of the snapshots of a run: per snapshot the link centres and tangents, and the
    axial force, the axial and azimuthal friction and the wall force derived from them."""
    return n_snapshots * scene.N * 10 * 8.0


def snapshot_count(scene) -> float:
    """The most snapshots a run can take before the scene's time cap (snapshot_interval > 0)."""
    if scene.snapshot_growth > 1.0:
        doublings = math.log(max(scene.t_max / scene.snapshot_interval, 1.0)) / math.log(scene.snapshot_growth)
        return math.floor(doublings) + 3
    return math.floor(scene.t_max / scene.snapshot_interval) + 2


def check_snapshots(scene, fail: Fail) -> None:
    """With an explicit time cap the number of snapshots is bounded up front (the
    implicit solver's default cap, 1e9, bounds nothing: it is checked during the run)."""
    if scene.snapshot_interval <= 0.0:
        return
    n = snapshot_count(scene)
    size = snapshot_bytes(scene, n)
    if size > MAX_SNAPSHOT_BYTES and (scene.solver == "explicit" or scene.given("t_max")):
        least = scene.t_max * snapshot_bytes(scene, 1) / MAX_SNAPSHOT_BYTES
        fail("snapshot_interval", f"t_max/snapshot_interval = {n - 2:.3g} snapshots of {scene.N} links would take "
                                  f"{size / 2**20:.3g} MiB, more than {MAX_SNAPSHOT_BYTES / 2**20:g} MiB: raise "
                                  f"snapshot_interval to >= {least:.3g}")


def snapshot_limit(scene) -> int:
    """Most snapshots a run may store (MAX_SNAPSHOT_BYTES)."""
    return max(2, int(MAX_SNAPSHOT_BYTES // snapshot_bytes(scene, 1)))


# -- checks of the final state ----------------------------------------------------------
def state_violations(scene, r: np.ndarray, t: np.ndarray) -> list[str]:
    """Ways in which a final state leaves the model's validity (empty if none)."""
    out = []
    h = 0.5 * scene.l0
    ends = np.concatenate([r - h * t, r + h * t])
    inside = ends[ends[:, 2] <= scene.pore_length]  # above the entrance there is no wall
    depth = (np.hypot(inside[:, 0], inside[:, 1]).max() - scene.R) / scene.R if inside.size else 0.0
    if depth > MAX_PENETRATION:
        out.append(f"a link end lies {depth:.3g} R inside the wall (more than {MAX_PENETRATION:g} R: the penalty "
                   f"k_w = {scene.k_w:g} is too soft for this state)")
    if scene.floor:
        below = -ends[:, 2].min() / scene.R
        if below > MAX_PENETRATION:
            out.append(f"a link end lies {below:.3g} R below the floor (more than {MAX_PENETRATION:g} R: k_w = "
                       f"{scene.k_w:g} is too soft to hold the rod)")
    if r.shape[0] > 1:
        gap = np.linalg.norm((r - h * t)[1:] - (r + h * t)[:-1], axis=1).max() / scene.l0
        if gap > MAX_BOND_GAP:
            out.append(f"a bond is stretched by {gap:.3g} l0 (more than {MAX_BOND_GAP:g} l0: k_ph = "
                       f"{scene.k_ph:g} is too soft)")
    return out


# -- cost -------------------------------------------------------------------------------
#: what a job costs beyond its solver: the interpreter, the imports (xarray, numba), loading numba's
#: cache and Snakemake's script preamble, measured 1.8-2.0 s per job (benchmarks/bench_startup.py)
JOB_STARTUP_S = 2.0


#: the cost model fitted to a publication build's runs (tools/fit_cost_model.py writes it)
COST_MODEL_FILE = Path(__file__).with_name("cost_model.json")


def cost_class(scene) -> str:
    """The class of a run in the cost model: solver, protocol, with or without friction."""
    return f"{scene.solver}/{scene.protocol}/{'friction' if scene.k_fr > 0 else 'frictionless'}"


def explicit_cost_shape(scene) -> float:
    """How the explicit scheme's cost grows (a pure number, 1 at L/R = 80, l0 = R/2, k_ph = 1e3,
    dt_factor 0.8): the steps to settle grow as L^2 (diffusive relaxation) and the work per step as
    L, the step shrinks as l0^3 (bending) and 1/k_ph (the bonds)."""
    k_rel = max(1.0, scene.k_ph * scene.R**2 / scene.EI / 1e3)
    return (scene.L / scene.R / 80.0) ** 2.5 * (0.5 * scene.R / scene.l0) ** 3 * k_rel * (0.8 / scene.dt_factor)


@functools.lru_cache(maxsize=1)
def cost_model() -> dict:
    """The fitted cost model ({} if its file is missing: the prior model then answers alone)."""
    try:
        return json.loads(COST_MODEL_FILE.read_text())
    except FileNotFoundError:
        return {}


#: the hand model's growth with the rod's length (N^1.9), the least a fitted model extrapolates with
COST_PRIOR_L_EXPONENT = 1.9


def _prior_solver_time(scene) -> float:
    """The model before a fit (and for a class no fitted build has run): implicit at the
    publication numerics, L/R = 640 at l0 = 0.5 R (1280 links), k_fr = 0.8: 6.3 s, growing as
    N^1.9, times 1 + ramp_steps/20 for a ramp; explicit, L/R = 80 at l0 = 0.5 R, k_ph = 1e3: 7 min,
    growing as explicit_cost_shape."""
    if scene.solver == "implicit":
        ramp = 1.0 + scene.ramp_steps / 20.0 if scene.protocol == "ramp" else 1.0
        return 6.3 * (scene.L / scene.l0 / 1280.0) ** 1.9 * ramp
    return 420.0 * explicit_cost_shape(scene)


def cost_regressors(scene) -> tuple[float, dict[str, float]]:
    """(offset, {exponent: regressor}) of a run in its class's cost model, ln t = b + offset +
    sum of exponent x regressor: implicit, the logarithms of L/(640 R) and 0.5 R/l0 (apart: a
    finer l0 at a given N is cheaper than a longer rod, whose helix and slip fronts grow with
    it), 0.02 R/dx_max, the load over 0.25 EI/R^2, k_fr/0.8 (with friction) and
    ramp_steps/128 (a ramp); explicit, the offset ln explicit_cost_shape, a correction of its
    l0^-3 (the logarithm of 0.5 R/l0) and the logarithm of 1e-5/tol (explicit runs relax at the
    rate of their slowest mode, so the tolerance sets their length; too few of them to fit more)."""
    if scene.solver == "explicit":
        return math.log(explicit_cost_shape(scene)), {"l0": math.log(0.5 * scene.R / scene.l0),
                                                      "tol": math.log(1e-5 / scene.tol)}
    x = {"L": math.log(scene.L / (640.0 * scene.R)), "l0": math.log(0.5 * scene.R / scene.l0),
         "dx": math.log(0.02 * scene.R / scene.dx_max),
         "load": math.log(scene.load * scene.R**2 / scene.EI / 0.25)}
    if scene.k_fr > 0:
        x["k_fr"] = math.log(scene.k_fr / 0.8)
    if scene.protocol == "ramp":
        x["ramp"] = math.log(scene.ramp_steps / 128.0)
    return 0.0, x


def estimated_solver_time(scene) -> float:
    """Rough time of a run's solver on one core of the reference machine (seconds): the cost
    model fitted to a publication build's runs (COST_MODEL_FILE, tools/fit_cost_model.py) for
    the scene's class (cost_class, class_solver_time); a class the fit has not seen uses
    _prior_solver_time."""
    c = cost_model().get("classes", {}).get(cost_class(scene))
    return _prior_solver_time(scene) if c is None else class_solver_time(c, scene)


def class_solver_time(c: dict, scene) -> float:
    """A fitted class's prediction for a scene: exp(b + offset + sum of exponent x regressor) over
    cost_regressors; for a run with a step budget at most max_steps x N x the class's measured
    time per step and link (explicit runs: a capped stress probe); beyond the class's longest
    fitted rod (L_max) with a length exponent of at least COST_PRIOR_L_EXPONENT."""
    offset, x = cost_regressors(scene)
    ln_t = c["log_coef"] + offset + sum(c.get(f"{k}_exponent", 0.0) * v for k, v in x.items())
    L_max = c.get("L_max")
    if "L" in x and L_max and scene.L / scene.R > L_max:
        # the exponent itself grows with L (the long rods' slip fronts): an extrapolation never
        # cheaper than the hand model's, on which the command line's budget relies
        ln_t += max(0.0, COST_PRIOR_L_EXPONENT - c.get("L_exponent", 0.0)) * math.log(scene.L / scene.R / L_max)
    t = math.exp(ln_t)
    if scene.max_steps and c.get("step_s_per_link"):  # a step budget caps the run's steps
        t = min(t, scene.max_steps * scene.N * c["step_s_per_link"])
    return t


def estimated_wall_time(scene) -> float:
    """Rough wall time of a job that runs this scene alone (seconds): its solver and the job's
    start-up (JOB_STARTUP_S)."""
    return estimated_solver_time(scene) + JOB_STARTUP_S
