"""Measures of the rod's states: the wall force, the buckling thresholds and the straight branch,
planar against helical, detached ends, defects, the fold and the escape (Figs 2, 3, 5, 8)."""
from __future__ import annotations

import math

import numpy as np

from ...analysis.measure import force_at_links
from ...layout import dataset_path
from ..evidence import ClaimError
from ._base import Measured, measure


def _bulk(mask: np.ndarray, frac: float = 0.25) -> np.ndarray:
    """Links of the contact stretch away from its ends (middle 1 - 2 frac)."""
    idx = np.flatnonzero(mask)
    if idx.size < 8:
        return np.zeros(0, dtype=int)
    lo, hi = idx[0], idx[-1]
    n = hi - lo
    return np.arange(lo + int(frac * n), hi - int(frac * n) + 1)


@measure
def wall_force_coefficient(ev, spec, claim):
    """K EI/(R F_z^2) in the bulk (middle half of the contact stretch) of the longest
    frictionless rod of the figure, against the paper's 1/2 (the tolerance), and in the note
    against the lowest order 1/4 and the exact constant-pitch value 1/(4(1 - R^2 w^2)) with the
    measured pitch rate w = dphi/ds of each link (docs/model.md, "The paper's simple model")."""
    key, sim = ev.sim(spec["figure"], -1, claim)
    if float(sim.attrs["k_fr"]) != 0.0:
        raise ClaimError(f"claim {claim!r}: {ev.file(key)} has k_fr = {sim.attrs['k_fr']}, needs 0")
    R, EI = float(sim.attrs["R"]), float(sim.attrs["EI"])
    K = np.asarray(sim.wall_force_density.values)
    F = force_at_links(sim)
    bulk = _bulk(np.asarray(sim.contact.values) > 0)
    if bulk.size == 0:
        raise ClaimError(f"claim {claim!r}: {ev.file(key)} has no helix on the wall")
    s_link = np.asarray(sim.s_link.values)[bulk]
    w = np.interp(s_link, np.asarray(sim.s_helix.values), np.abs(np.asarray(sim.dphi_ds.values)))
    ratio = K[bulk] * EI / (R * F[bulk] ** 2)
    value = float(np.median(ratio))
    # one frictionless rod: no seeds, so the error is how far the bulk's two halves differ
    halves = np.array_split(ratio, 2)
    error = 0.5 * abs(float(np.median(halves[0])) - float(np.median(halves[1])))
    exact = float(np.median(1.0 / (4.0 * (1.0 - (R * w) ** 2))))
    dev_exact, dev_lowest = value / exact - 1.0, value / 0.25 - 1.0
    confirmed = ("the exact constant-pitch relation" if abs(dev_exact) < abs(dev_lowest)
                 else "the lowest order")
    note = (f"exact constant pitch 1/(4(1 - R^2 w^2)) = {exact:.4g} (median R w = {float(np.median(R * w)):.3g}): "
            f"{100 * dev_exact:+.2f} %; lowest order 1/4: {100 * dev_lowest:+.3g} %; the paper's 1/2: "
            f"{100 * (value / 0.5 - 1):+.3g} %. The data confirm {confirmed}")
    return Measured(value, True, (f"{ev.file(key)}:wall_force_density, F_z, dphi_ds "
                         "(medians over the middle half of the contact)"),
                    note + "; error: half the difference of the medians of the two halves of the bulk", error=error)


@measure
def capped_fraction(ev, spec, claim):
    """Fraction of the links on the wall where the friction cap is below k_fr N."""
    key, sim = ev.sim(spec["figure"], spec["scene"], claim)
    k_fr, cap = (float(sim.attrs[k]) for k in ("k_fr", "friction_cap"))
    N = np.asarray(sim.wall_force.values)
    on = N > 0
    capped = on & (cap > 0) & (k_fr * N > cap)
    value = float(capped.sum() / max(on.sum(), 1))
    return Measured(value, value <= float(spec["max"]), f"{ev.file(key)}:wall_force, attrs k_fr, friction_cap", \
        f"{int(capped.sum())} of {int(on.sum())} links")


def _aspect_R(ds, i):
    """R of threshold row i: from L^2/EI and L/R (Fig. 3) or the stored R (Fig. 8)."""
    if "aspect_R" in ds:
        return float(ds.aspect_R.values[i])
    L = math.sqrt(float(ds.L2_over_EI.values[i]) * float(ds.attrs["EI"]))
    return L / float(ds.aspect.values[i])


@measure
def threshold_R_dependence(ev, spec, claim):
    """Largest relative difference, R = 2 against R = 1 at equal L/R (and equal kind of
    threshold), of the threshold midpoints in units of EI/R^2."""
    worst, n, files = 0.0, 0, []
    for fig in spec["figures"]:
        ds = ev.dataset(fig, claim)
        files.append(f"{dataset_path(fig)}")
        names = [str(s) for s in ds.aspect_scene.values]
        mid = 0.5 * (np.asarray(ds.threshold_lo.values) + np.asarray(ds.threshold_hi.values))
        mid = mid.reshape(len(names), -1)
        for i, name in enumerate(names):
            R = _aspect_R(ds, i)
            if abs(R - 1.0) < 1e-12:
                continue
            base = name.rsplit("_R", 1)[0]
            if base not in names:
                continue
            j = names.index(base)
            EI = float(ds.attrs.get("EI", 1.0))
            worst = max(worst, float(np.max(np.abs(mid[i] * R**2 / EI - mid[j] * _aspect_R(ds, j)**2 / EI)
                                            / (mid[j] * _aspect_R(ds, j)**2 / EI))))
            n += 1
    if n == 0:
        raise ClaimError(f"claim {claim!r}: no threshold at R != 1 with an R = 1 partner in {files}")
    return Measured(worst, True, ", ".join(f + ":threshold_lo, threshold_hi" for f in files), f"{n} pairs")


@measure
def first_threshold_over_estimate(ev, spec, claim):
    ds = ev.dataset(spec["figure"], claim)
    i = int(ds.attrs["main_index"])
    lo, hi = (float(ds[v].values[i, 0]) for v in ("threshold_lo", "threshold_hi"))
    est = float(ds.threshold_estimate.values[i, 0])
    return Measured(0.5 * (lo + hi) / est, True, (f"{dataset_path(spec['figure'])}:threshold_lo, threshold_hi, "
                                         "threshold_estimate[first]"), \
        f"bracket [{lo:.6g}, {hi:.6g}], estimate {est:.6g} EI/R^2 at L/R = {float(ds.aspect.values[i]):g}")


@measure
def two_thresholds(ev, spec, claim):
    ds = ev.dataset(spec["figure"], claim)
    i = int(ds.attrs["main_index"])
    lo, hi = np.asarray(ds.threshold_lo.values[i]), np.asarray(ds.threshold_hi.values[i])
    holds = bool(hi[0] < lo[1])
    return Measured(float(lo[1] / hi[0]), holds, f"{dataset_path(spec['figure'])}:threshold_lo, threshold_hi", \
        f"second/first = {lo[1] / hi[0]:.3g}")


def _straight_points(ds, claim) -> tuple[np.ndarray, np.ndarray]:
    """(load, L_z) of every straight state (class 'straight') on the frictionless sweeps with
    protocol 'straight' (up and down), by load."""
    classes = ds.state_class.attrs["flag_meanings"].split()
    k = classes.index("straight")
    F, Lz = [], []
    for i, (p, kf) in enumerate(zip(ds.branch_protocol.values, ds.branch_k_fr.values)):
        if str(p) == "straight" and float(kf) == 0:
            m = (np.asarray(ds.state_class.values[i]) == k) & (np.asarray(ds.converged.values[i]) == 1)
            F += list(np.asarray(ds["load"].values)[m])
            Lz += list(np.asarray(ds.L_z.values[i])[m])
    if not F:
        raise ClaimError(f"claim {claim!r}: the bifurcation figure has no straight state on a frictionless sweep")
    order = np.argsort(F)
    return np.asarray(F)[order], np.asarray(Lz)[order]


@measure
def straight_branch_compliance(ev, spec, claim):
    """dL_z/dF on the straight branch (linear fit over its loads) over -L/k_ph, the compliance
    of the bonds alone (for the tilted rod, L_z = sqrt(L'^2 - 4R^2) with L' = L(1 - T/k_ph) and
    the tension T = F L/L_z along it: dL_z/dF = -(L/k_ph)(L/L_z)^2, 1 % more at L/R = 20)."""
    ds = ev.dataset(spec["figure"], claim)
    i = int(ds.attrs["main_index"])
    L, R = float(ds.aspect.values[i]) * _aspect_R(ds, i), _aspect_R(ds, i)
    k_ph = float(ds.attrs["k_ph"])
    F, Lz = _straight_points(ds, claim)
    loads = np.unique(F)
    if loads.size < 2:
        return Measured(0.0, None, f"{dataset_path(spec['figure'])}:L_z, state_class", \
            f"only {loads.size} load on the straight branch: no slope")
    slope = float(np.polyfit(F, Lz, 1)[0])
    tilt = L**2 / (L**2 - 4 * R**2)
    return Measured(slope / (-L / k_ph), True, \
        f"{dataset_path(spec['figure'])}:L_z[straight states of the frictionless straight-protocol sweeps]", \
        (f"dL_z/dF = {slope:.4g} R^3/EI over {loads.size} loads ({loads.min():.3g}-{loads.max():.3g} EI/R^2); "
         f"-L/k_ph = {-L / k_ph:.4g}; the tilted rod's -(L/k_ph) L^2/L_z^2 = {-L / k_ph * tilt:.4g}"))


@measure
def straight_branch_tilt(ev, spec, claim):
    """Our finding: with both ends free sideways the straight rod lies diagonally across the pore;
    the offset L - L_z extrapolated to zero load over L - sqrt(L^2 - 4R^2) (1 for the tilted rod,
    0 for a rod on the axis)."""
    ds = ev.dataset(spec["figure"], claim)
    i = int(ds.attrs["main_index"])
    L, R = float(ds.aspect.values[i]) * _aspect_R(ds, i), _aspect_R(ds, i)
    F, Lz = _straight_points(ds, claim)
    Lz0 = float(np.polyval(np.polyfit(F, Lz, 1), 0.0)) if np.unique(F).size >= 2 else float(Lz[0])
    ratio = (L - Lz0) / (L - math.sqrt(L**2 - 4 * R**2))
    return Measured(ratio, abs(ratio - 1) <= float(spec["rel"]), \
        f"{dataset_path(spec['figure'])}:L_z[straight states]", \
        f"L - L_z(F -> 0) = {L - Lz0:.4g} R; tilted rod L - sqrt(L^2 - 4R^2) = {L - math.sqrt(L**2 - 4 * R**2):.4g} R")


def _classes(ds, protocol: str, frictional: bool, claim: str) -> np.ndarray:
    """State classes along the first branch (config order) run with this protocol, with or
    without friction."""
    for i, (p, k) in enumerate(zip(ds.branch_protocol.values, ds.branch_k_fr.values)):
        if str(p) == protocol and (float(k) > 0) == frictional:
            return np.asarray(ds.state_class.values[i])
    raise ClaimError(f"claim {claim!r}: the bifurcation figure has no {'frictional' if frictional else 'frictionless'} "
                     f"sweep with protocol {protocol!r} (branches: {', '.join(map(str, ds.branch.values))})")


@measure
def planar_unstable(ev, spec, claim):
    """Above the second threshold: the planar-only sweep stays planar (the state exists),
    the fresh runs with an out-of-plane perturbation end 3-D (it is unstable)."""
    ds = ev.dataset(spec["figure"], claim)
    i = int(ds.attrs["main_index"])
    loads = np.asarray(ds["load"].values)
    above = loads > float(ds.threshold_hi.values[i, 1])
    if not above.any():
        raise ClaimError(f"claim {claim!r}: no load above the second threshold in {dataset_path(spec['figure'])}")
    planar = float(np.mean(_classes(ds, "planar", False, claim)[above] == 1))
    three_d = float(np.mean(_classes(ds, "planar_then_3d", False, claim)[above] == 2))
    return Measured(three_d, planar >= 0.8 and three_d >= 0.8, \
        f"{dataset_path(spec['figure'])}:state_class[protocol planar, planar_then_3d]", \
        f"above the second threshold: {planar:.0%} of planar-only runs planar, {three_d:.0%} of fresh runs 3-D")


@measure
def friction_keeps_planar(ev, spec, claim):
    ds = ev.dataset(spec["figure"], claim)
    loads = np.asarray(ds["load"].values)
    both = (_classes(ds, "straight", False, claim) == 2) & (_classes(ds, "straight", True, claim) == 1)
    span = f"{loads[both].min():.3g}-{loads[both].max():.3g} EI/R^2" if both.any() else "none"
    return Measured(float(both.sum()), bool(both.any()), \
        f"{dataset_path(spec['figure'])}:state_class[protocol straight, k_fr = 0 and > 0]", \
        f"loads where the frictionless sweep is 3-D and the frictional one planar: {span}")


@measure
def ends_detach(ev, spec, claim):
    ds = ev.dataset(spec["figure"], claim)
    top = float(np.min(ds.detached_top.values))
    force = float(np.min(ds.end_contact_force.values))
    return Measured(top, top > 0 and force > 0, f"{dataset_path(spec['figure'])}:detached_top, end_contact_force", \
        f"tip wall force {force:.3g} EI/R^2")


@measure
def final_out_of_plane(ev, spec, claim):
    ds = ev.dataset(spec["figure"], claim)
    oop = np.asarray(ds.frame_out_of_plane.values)
    return Measured(float(oop[-1]), bool(oop[-1] > 0.05 and oop[-1] > oop[0]), \
        f"{dataset_path(spec['figure'])}:frame_out_of_plane", f"planar frame {oop[0]:.2g} R")


@measure
def defect_fraction(ev, spec, claim):
    ds = ev.dataset(spec["figure"], claim)
    n, of = int(ds.attrs["seeds_with_defects"]), int(ds.attrs["seeds"])
    return Measured(n / of, n > 0, f"{dataset_path(spec['figure'])}:attrs seeds_with_defects, seeds",
                    f"{n} of {of} seeds")


@measure
def defects_after_unloading(ev, spec, claim):
    ds = ev.dataset(spec["figure"], claim)
    per_state = np.asarray(ds.attrs["seeds_with_defects_per_state"]).ravel()
    loads = np.asarray(ds.state_load.values)
    converged = bool(np.all(ds.final_converged.values))
    holds = converged and per_state[0] > 0 and per_state[-1] < per_state[0]
    text = ", ".join(f"{int(n)} at {load:g}" for n, load in zip(per_state, loads))
    return Measured(float(per_state[-1]), holds, \
        f"{dataset_path(spec['figure'])}:attrs seeds_with_defects_per_state, state_load", \
        f"seeds with a defect: {text} EI/R^2")


@measure
def fold_threshold_exists(ev, spec, claim):
    ds = ev.dataset(spec["figure"], claim)
    lo, hi = (float(v) for v in np.asarray(ds.attrs["fold_threshold_range"]).ravel()[:2])
    limit = float(ds.attrs["helix_limit"])
    # the error: half the range of the thresholds over the rods measured (a single rod: its bracket)
    return Measured(0.5 * (lo + hi), hi < limit, \
        f"{dataset_path(spec['figure'])}:attrs fold_threshold_range, helix_limit", \
        f"fold thresholds {lo:.3g}-{hi:.3g} EI/R^2 (the value: the middle of that range +- half of it), helix "
        f"limit {limit:.3g}", error=0.5 * (hi - lo))


@measure
def event_escapes(ev, spec, claim):
    """Whether the constructed event escapes: a loop crosses the escape radius above the open
    entrance and the rod is still out at the end of the run (followed on past the crossing). A
    loop that crosses and is drawn back in is a transient bulge, not an escape. Value: the
    distance from the axis of the farthest link end above the entrance at the end of the run,
    in R (an escape: above the escape radius)."""
    ds = ev.dataset(spec["figure"], claim)
    a = ds.attrs
    esc, crossed = int(a["event_escaped"]) == 1, int(a["event_loop_crossed"]) == 1
    rho_end, rho_max, lim = (float(a[k]) for k in ("event_final_outside_radius", "event_max_outside_radius",
                                                   "event_escape_radius"))
    where = (f"L/R = {float(a['event_L']) / float(a['event_R']):g}, load {float(a['event_load']):g} EI/R^2, "
             f"free span {float(a['event_free_span']) / float(a['event_R']):g} R")
    if esc:
        what = f"a loop left the pore (farthest link end {rho_max:.3g} R from the axis) and is still out at the end"
    elif crossed:
        what = (f"a loop crossed the escape radius {lim:g} R (farthest link end {rho_max:.4g} R from the axis) and "
                f"was drawn back in: at the end of the run the farthest link end above the entrance lies "
                f"{rho_end:.3g} R from the axis and L_z = {float(a['event_final_L_z']) / float(a['event_R']):.4g} R; "
                "a transient bulge, not an escape")
    else:
        what = f"no loop crossed the escape radius {lim:g} R (farthest link end {rho_max:.3g} R from the axis)"
    return Measured(rho_end, esc, \
        (f"{dataset_path(spec['figure'])}:attrs event_escaped, event_loop_crossed, event_final_outside_radius, "
         "event_max_outside_radius"), f"{where}: {what}")


@measure
def escape_at_stated_conditions(ev, spec, claim):
    """At the paper's conditions (the rod in the pore from its top, the entrance closed above it):
    the paper's load lies below every measured fold threshold, so the rod coils instead of
    folding or escaping. Value: the paper's load over the smallest fold threshold."""
    ds = ev.dataset(spec["figure"], claim)
    lo, hi = (float(v) for v in np.asarray(ds.attrs["fold_threshold_range"]).ravel()[:2])
    load = float(ds.attrs["paper_load"])
    below = int(ds.attrs["paper_load_below_fold_thresholds"]) == 1
    escaped_open = int(ds.attrs["event_escaped"]) == 1
    crossed_open = int(ds.attrs["event_loop_crossed"]) == 1
    # the paper does not describe its entrance: closed, the rod coils; open, a loop can leave the
    # pore; whether it stays out depends on what holds the loaded end above the entrance (our
    # guide lets it follow the rod into the pore), which the paper does not describe either
    holds = (None if crossed_open else False) if below else True
    return Measured(load / lo, holds, \
        (f"{dataset_path(spec['figure'])}:attrs paper_load, fold_threshold_range, "
         "paper_load_below_fold_thresholds"), \
        (f"load {load:g} EI/R^2 against fold thresholds {lo:.3g}-{hi:.3g} EI/R^2 (closed entrance): "
         + ("below them, the rod coils into a helix" if below else "above the smallest")
         + ("; with an open entrance and a free span of "
            f"{float(ds.attrs.get('event_free_span', 0)):g} R (not stated in the paper) the rod escapes at this load: "
            "the answer depends on the entrance" if escaped_open and below else "")
         + ("; with an open entrance and a free span of "
            f"{float(ds.attrs['event_free_span']):g} R (not stated in the paper) a loop leaves the pore at this load "
            "and is drawn back in as the guided loaded end follows the rod into the pore: whether the rod escapes "
            "depends on the entrance and on what holds the loaded end above it" if crossed_open and not escaped_open
            and below else "")))
