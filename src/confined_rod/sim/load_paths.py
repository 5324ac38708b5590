"""Load paths and thresholds: sequences of equilibria along the load (simulation side).

A *load path* relaxes one scene at a sequence of loads, either by continuation (each
load starts from the previous equilibrium, nudged by the scene's perturbation: sweeps
up or down, which can show hysteresis; the first load runs the scene's protocol) or afresh (each load runs the
scene's protocol from its own perturbed initial state).  Per load it keeps what a
bifurcation diagram needs: L_z, the transmitted force, the deflection from the chord
and the out-of-plane size of the shape (which tell straight, planar and 3-D states
apart), the wall contacts, how the run ended, and the shape (a few dozen numbers).

A *threshold* is located by bisection over the load between a load below it and one
above it, to a stated relative precision, with a classifier of the final state.

The saddle caveat applies: a run started near an unstable state can stop on it when
the residual falls below tol before the instability has grown.  Near a threshold the
growth rate vanishes, so a threshold found by fresh runs is resolved only to about
tol L/(a pi^2) relative (a the perturbation): use a small tol (1e-8) for thresholds.
"""
from __future__ import annotations

import dataclasses
from typing import Callable, Iterable

import numpy as np
import xarray as xr

from .. import theory
from ..io import finalize
from ..limits import equilibrium_tol
from ..quantities import variable
from . import observables as obs
from . import perturbation
from .scenes import Scene
from .solvers import explicit, implicit
from .solvers.base import RunState, relax, run_protocol

STEPPERS = {"implicit": implicit.ImplicitStepper, "explicit": explicit.ExplicitStepper}
MODES = ("continuation", "fresh")
STRAIGHT_MAX = 0.05  # R: a state with a smaller deflection from its chord is straight
PLANAR_MAX = 0.05  # R: a buckled state with a smaller rms distance from its plane is planar
CLASSES = ("straight", "planar", "three_d")


def classify(deflection: float, out_of_plane: float) -> str:
    """straight, planar (buckled in a plane) or three_d (e.g. a helix), from shape_measures."""
    if deflection < STRAIGHT_MAX:
        return "straight"
    return "planar" if out_of_plane < PLANAR_MAX else "three_d"


def at_load(scene: Scene, load: float) -> Scene:
    return dataclasses.replace(scene, load=float(load), name=f"{scene.name}@{load:g}")


def relax_at(scene: Scene, st: RunState) -> RunState:
    """Relax the state st under the scene (its load) with the scene's solver."""
    st.converged, st.escaped = False, False
    st.time, st.snapshot_times, st.snapshot_r = 0.0, [], []
    return relax(scene, st, STEPPERS[scene.solver](scene), progress=False)


def nudge(scene: Scene, st: RunState, step: int) -> None:
    """Continuation: displace the link centres of the previous equilibrium by the scene's
    perturbation (a continuous function of the height, seeded per load step; in x only for the
    planar protocol), so that an equilibrium that has become unstable is left rather than
    tracked: without it the sweep stays on a saddle, whose instability grows from round-off only."""
    z = (np.arange(scene.N) + 0.5) * scene.l0
    d = perturbation.lateral(z, scene.L, scene.R, scene.perturbation, [scene.seed, step],
                             stream=perturbation.NUDGE)
    st.r[:, 0] += d[:, 0]
    if scene.protocol != "planar":
        st.r[:, 1] += d[:, 1]


def start(scene: Scene) -> RunState:
    """The scene's perturbed initial state."""
    r, t = scene.initial_state()
    return RunState(r=r, t=t)


def fresh(scene: Scene) -> RunState:
    """The scene's protocol from its own perturbed initial state (both stages of
    planar_then_3d)."""
    return run_protocol(scene, STEPPERS[scene.solver], progress=False)


def load_path(scene: Scene, loads: Iterable[float], mode: str = "continuation") -> xr.Dataset:
    """Equilibria of ``scene`` at each load, in the given order (see the module doc)."""
    if mode not in MODES:
        raise ValueError(f"mode must be one of {MODES}, got {mode!r}")
    loads = [float(F) for F in loads]
    rows: dict[str, list] = {k: [] for k in ("L_z", "F_transmitted", "deflection", "out_of_plane", "tol_effective",
                                             "n_contact", "converged", "escaped", "state_class", "x", "y", "z")}
    st = None
    for F in loads:
        sc = at_load(scene, F)
        if st is None or mode == "fresh":
            st = fresh(sc)
        else:
            nudge(sc, st, len(rows["L_z"]))
            relax_at(sc, st)
        o = obs.compute(sc, st.r, st.t, st.anchor)
        dfl, oop = obs.shape_measures(st.r, sc.R)
        for k, v in (("L_z", o.L_z), ("F_transmitted", o.F_transmitted), ("deflection", dfl),
                     ("out_of_plane", oop), ("tol_effective", equilibrium_tol(sc)),
                     ("n_contact", int(o.contact.sum())), ("converged", st.converged),
                     ("escaped", st.escaped), ("state_class", CLASSES.index(classify(dfl, oop))),
                     ("x", o.r[:, 0]), ("y", o.r[:, 1]), ("z", o.r[:, 2])):
            rows[k].append(v)
    data = {k: variable(("load",), np.asarray(rows[k]), k) for k in ("L_z", "F_transmitted", "deflection",
                                                                      "out_of_plane", "tol_effective")}
    data["n_contact"] = variable(("load",), np.asarray(rows["n_contact"], dtype=np.int32), "n_contact")
    for flag in ("converged", "escaped"):
        data[flag] = variable(("load",), np.asarray(rows[flag], dtype=np.int8), flag)
        data[flag].attrs.update(flag_values=np.array([0, 1], dtype=np.int8), flag_meanings="false true")
    data["state_class"] = variable(("load",), np.asarray(rows["state_class"], dtype=np.int8), "state_class")
    data["state_class"].attrs.update(flag_values=np.arange(len(CLASSES), dtype=np.int8),
                                     flag_meanings=" ".join(CLASSES))
    for c in ("x", "y", "z"):
        data[c] = variable(("load", "s_link"), np.asarray(rows[c]), c)
    coords = {"load": variable(("load",), np.asarray(loads), "load"),
              "s_link": variable(("s_link",), (np.arange(scene.N) + 0.5) * scene.l0, "s_link")}
    ds = xr.Dataset(data, coords=coords)
    params = dict(scene.to_dict())
    params.update({"mode": mode, "straight_max": STRAIGHT_MAX, "planar_max": PLANAR_MAX})
    title = (f"Load path of '{scene.name}' ({mode}): L/R = {scene.L / scene.R:g}, k_fr = {scene.k_fr:g}, "
             f"protocol {scene.protocol}")
    return finalize(ds, title, params)


def bisect_threshold(scene: Scene, above: Callable[[Scene, RunState], bool], lo: float, hi: float,
                     precision: float) -> tuple[float, float, int]:
    """Bracket [lo, hi] of the load at which ``above(scene, final state)`` turns true,
    narrowed by bisection until (hi - lo) <= precision * hi; each load is a fresh run.
    Raises ValueError unless lo is below and hi above the threshold."""
    def test(F: float) -> bool:
        sc = at_load(scene, F)
        return above(sc, fresh(sc))

    n = 2
    if test(lo) or not test(hi):
        raise ValueError(f"scene {scene.name!r}: the loads {lo:g} and {hi:g} do not bracket the threshold")
    while hi - lo > precision * hi:
        mid = 0.5 * (lo + hi)
        n += 1
        if test(mid):
            hi = mid
        else:
            lo = mid
    return lo, hi, n


def buckled(scene: Scene, st: RunState) -> bool:
    """The final state is not straight (deflection from its chord above STRAIGHT_MAX)."""
    return obs.shape_measures(st.r, scene.R)[0] >= STRAIGHT_MAX


def three_dimensional(scene: Scene, st: RunState) -> bool:
    """The final state is buckled out of its plane (e.g. a helix)."""
    d, o = obs.shape_measures(st.r, scene.R)
    return classify(d, o) == "three_d"


# -- what a figure asks of one scene (the pipeline's rule `load_path`) ---------------------
RUNS = ("up", "down", "fresh", "thresholds", "transition", "fold_threshold", "event")


def thresholds(scene: Scene, precision: float) -> xr.Dataset:
    """Both thresholds by bisection with fresh runs: the first (straight -> buckled,
    protocol planar, classifier buckled), the second (planar -> 3-D, protocol
    planar_then_3d, classifier three_dimensional), from the brackets of
    theory.threshold_brackets (a bracket that does not hold raises ValueError)."""
    br = theory.threshold_brackets(scene.L, scene.C_l0())
    out = {}
    for name, protocol, above in (("first", "planar", buckled), ("second", "planar_then_3d", three_dimensional)):
        sc = dataclasses.replace(scene, protocol=protocol)
        out[name] = bisect_threshold(sc, above, *br[name], precision)
    return _threshold_dataset(scene, out, {"precision": precision, "straight_max": STRAIGHT_MAX,
                                           "planar_max": PLANAR_MAX},
                              f"Thresholds of '{scene.name}': L/R = {scene.L / scene.R:g}")


def _threshold_dataset(scene: Scene, found: dict[str, tuple[float, float, int]], extra: dict,
                       title: str) -> xr.Dataset:
    """Dataset of bisection results: threshold name -> (lo, hi, runs)."""
    names = list(found)
    data = {
        "threshold_lo": variable(("threshold",), [found[n][0] for n in names], "threshold_lo"),
        "threshold_hi": variable(("threshold",), [found[n][1] for n in names], "threshold_hi"),
        "threshold_runs": variable(("threshold",), np.array([found[n][2] for n in names], dtype=np.int32),
                                   "threshold_runs"),
    }
    ds = xr.Dataset(data, coords={"threshold": variable(("threshold",), np.array(names, dtype=object),
                                                        "threshold")})
    return finalize(ds, title, dict(scene.to_dict()) | extra)


def run_spec(scene: Scene, spec: dict) -> xr.Dataset:
    """One job of a path figure: spec = {"run": up | down | fresh | thresholds | transition,
    "loads": [...] (sweeps), "precision": relative precision (thresholds), "reduced":
    load fractions (transition)}."""
    run = spec["run"]
    if run == "thresholds":
        return thresholds(scene, float(spec["precision"]))
    if run == "transition":
        return transition(scene, spec.get("reduced", ()))
    if run == "fold_threshold":
        return fold_threshold(scene, float(spec["precision"]))
    if run == "event":
        return event(scene)
    loads = sorted(float(F) for F in spec["loads"])
    if run == "down":
        loads = loads[::-1]
    ds = load_path(scene, loads, mode="fresh" if run == "fresh" else "continuation")
    ds.attrs["run"] = run
    return ds


# -- a transition in time: planar state -> 3-D (Fig 2) -------------------------------------
SNAP_GROWTH = 2.0  # second stage: a snapshot each time the simulated time doubles


def _relax_with_shapes(scene: Scene, st: RunState, stepper) -> list[tuple[float, np.ndarray, np.ndarray]]:
    """Relax st to equilibrium (or escape, or t_max), keeping (time, r, t) at simulated
    times growing by SNAP_GROWTH from 10 explicit steps after the start: a few dozen
    shapes, not a trajectory."""
    shapes = []
    t_start = st.time
    t_next = t_start + 10.0 * scene.dt()
    while True:
        relax(scene, st, stepper, t_end=min(t_next, scene.t_max), progress=False)
        shapes.append((st.time, st.r.copy(), st.t.copy()))
        if st.converged or st.escaped or st.time >= scene.t_max * (1 - 1e-12):
            return shapes
        t_next = t_start + (t_next - t_start) * SNAP_GROWTH


def _shape_variables(scene: Scene, shapes) -> dict[str, xr.Variable]:
    """snap_x, snap_y, snap_z (snapshot, link), links from the loaded end as in every dataset."""
    order = np.arange(scene.N)[::-1]
    return {f"snap_{c}": variable(("snapshot", "s_link"), np.array([r[order, i] for _, r, _ in shapes]), f"snap_{c}")
            for i, c in enumerate("xyz")}


def _stretch_rate(o: obs.Observables) -> tuple[np.ndarray, np.ndarray]:
    """(in_stretch, dphi/ds) per link from the loaded end (0 outside the contact stretch)."""
    sl = obs.contact_stretch(o.contact)
    inside = np.zeros(o.contact.size, dtype=np.int8)
    inside[sl] = 1
    rate = np.zeros(o.contact.size)
    rate[sl] = o.dphi_ds
    return inside, rate


def transition(scene: Scene, reduced: Iterable[float] = ()) -> xr.Dataset:
    """Protocol planar_then_3d with shapes chosen by the run, not by fixed steps: the end
    of the planar stage, then the second stage at simulated times growing by
    SNAP_GROWTH from the first step (a few dozen shapes: the figure picks the growing
    instability among them), and the final state.  Then the load is reduced to each
    fraction in ``reduced`` in turn (continuation) to test whether the final state's
    defects survive; per state the dataset keeps the shape and dphi/ds along the
    contact stretch (defects are counted by post-processing, measure.defects)."""
    if scene.protocol != "planar_then_3d":
        raise ValueError(f"scene {scene.name!r}: a transition runs protocol planar_then_3d, not {scene.protocol!r}")
    make = STEPPERS[scene.solver]
    st = start(scene)
    relax(scene, st, make(scene), progress=False)
    planar = [(st.time, st.r.copy(), st.t.copy())]
    planar_converged = st.converged
    scene.perturb_3d(st.r)
    snaps = planar + _relax_with_shapes(scene, st, make(scene))
    stages = [0] + [1] * (len(snaps) - 1)
    states = [("final", scene, st.r.copy(), st.t.copy(), st.converged)]
    for frac in reduced:
        sc = at_load(scene, scene.load * float(frac))
        relax_at(sc, st)
        states.append((f"reduced_{frac:g}", sc, st.r.copy(), st.t.copy(), st.converged))
    data = _shape_variables(scene, snaps)
    data["snap_stage"] = variable(("snapshot",), np.array(stages, dtype=np.int8), "snap_stage")
    data["snap_out_of_plane"] = variable(("snapshot",), [obs.shape_measures(r, scene.R)[1] for _, r, _ in snaps],
                                         "out_of_plane")
    per_state: dict[str, list] = {k: [] for k in ("x", "y", "z", "contact", "in_stretch", "dphi_ds", "L_z",
                                                   "F_transmitted", "converged", "state_load")}
    for _, sc, rr, tt, conv in states:
        o = obs.compute(sc, rr, tt)
        inside, rate = _stretch_rate(o)
        for k, v in (("x", o.r[:, 0]), ("y", o.r[:, 1]), ("z", o.r[:, 2]), ("contact", o.contact),
                     ("in_stretch", inside), ("dphi_ds", rate), ("L_z", o.L_z), ("F_transmitted", o.F_transmitted),
                     ("converged", conv), ("state_load", sc.load)):
            per_state[k].append(v)
    for k in ("x", "y", "z", "dphi_ds"):
        data[k] = variable(("state", "s_link"), np.array(per_state[k]), k)
    for k in ("contact", "in_stretch"):
        data[k] = variable(("state", "s_link"), np.array(per_state[k], dtype=np.int8), k)
    for k in ("L_z", "F_transmitted"):
        data[k] = variable(("state",), per_state[k], k)
    data["converged"] = variable(("state",), np.array(per_state["converged"], dtype=np.int8), "converged")
    data["state_load"] = variable(("state",), per_state["state_load"], "load")
    coords = {"snap_time": variable(("snapshot",), [s[0] for s in snaps], "t"),
              "state": variable(("state",), np.array([s[0] for s in states], dtype=object), "state"),
              "s_link": variable(("s_link",), (np.arange(scene.N) + 0.5) * scene.l0, "s_link")}
    ds = xr.Dataset(data, coords=coords)
    params = dict(scene.to_dict())
    params.update({"planar_stage_converged": int(planar_converged), "snap_growth": SNAP_GROWTH,
                   "reduced_fractions": [float(f) for f in reduced] or "none"})
    return finalize(ds, f"Planar to 3-D transition of '{scene.name}': L/R = {scene.L / scene.R:g}, "
                        f"load {scene.load:g}, k_fr = {scene.k_fr:g}, seed {scene.seed}", params)


# -- the fold (U-bend) and the escape at large loads (Fig 8) ------------------------------------
FOLDED_LZ = 0.5  # a rod whose L_z has fallen below this fraction of L has folded (or escaped)
FOLLOW_ESCAPE = 4.0  # an escaping event run goes on to this multiple of its escape time


def folded(scene: Scene, st: RunState) -> bool:
    """The final state has folded over (L_z < FOLDED_LZ L) or left the pore."""
    return st.escaped or obs.compute(scene, st.r, st.t).L_z < FOLDED_LZ * scene.L


def fold_threshold(scene: Scene, precision: float) -> xr.Dataset:
    """The load above which a fresh run of the scene folds or escapes, by bisection from
    theory.fold_bracket; records which of the two the run just above the threshold did."""
    outcome = {}

    def above(sc: Scene, st: RunState) -> bool:
        outcome[sc.load] = st.escaped
        return folded(sc, st)

    span = scene.free_span()
    lo, hi, n = bisect_threshold(scene, above, *theory.fold_bracket(scene.R, scene.EI, span), precision)
    ds = _threshold_dataset(scene, {"fold": (lo, hi, n)},
                            {"precision": precision, "folded_L_z": FOLDED_LZ, "free_span": span},
                            f"Fold / escape threshold of '{scene.name}': L/R = {scene.L / scene.R:g}, "
                            f"free span {span / scene.R:g} R above the entrance")
    ds["escaped_above"] = variable(("threshold",), np.array([outcome[hi]], dtype=np.int8), "escaped_above")
    return ds


def outside_radius(scene: Scene, r: np.ndarray, t: np.ndarray) -> float:
    """Largest distance from the axis of a link end above the pore entrance (0 if none),
    the guided loaded end (in its guide) aside: beyond R the rod has left the pore."""
    h = 0.5 * scene.l0
    ends = np.concatenate([r - h * t, r + h * t])
    if scene.ends == "guided":
        ends = ends[:-1]
    above = ends[:, 2] > scene.pore_length
    return float(np.hypot(ends[above, 0], ends[above, 1]).max()) if above.any() else 0.0


def event(scene: Scene) -> xr.Dataset:
    """A fresh run of the scene with shapes at simulated times doubling from its first
    step (a few dozen), with L_z and outside_radius of each: the figure picks its frames
    by what the rod does.  A run that escapes is followed on, past the escape, to
    FOLLOW_ESCAPE times its escape time (the rod leaving the pore)."""
    st = start(scene)
    stepper = STEPPERS[scene.solver](scene)
    snaps = [(0.0, st.r.copy(), st.t.copy())] + _relax_with_shapes(scene, st, stepper)
    t_escape = st.time if st.escaped else np.nan
    if st.escaped:
        t_next = t_escape
        while t_next < FOLLOW_ESCAPE * t_escape * (1 - 1e-12) and not st.converged:
            t_next = min(SNAP_GROWTH * t_next, FOLLOW_ESCAPE * t_escape)
            relax(scene, st, stepper, t_end=t_next, progress=False, follow_escape=True)
            snaps.append((st.time, st.r.copy(), st.t.copy()))
    data = _shape_variables(scene, snaps)
    data["snap_L_z"] = variable(("snapshot",), [obs.compute(scene, s[1], s[2]).L_z for s in snaps], "L_z")
    data["snap_outside_radius"] = variable(("snapshot",), [outside_radius(scene, s[1], s[2]) for s in snaps],
                                           "outside_radius")
    data["converged"] = variable((), np.int8(st.converged), "converged")
    data["escaped"] = variable((), np.int8(st.escaped), "escaped")
    coords = {"snap_time": variable(("snapshot",), [s[0] for s in snaps], "t"),
              "s_link": variable(("s_link",), (np.arange(scene.N) + 0.5) * scene.l0, "s_link")}
    ds = xr.Dataset(data, coords=coords)
    extra = {"snap_growth": SNAP_GROWTH, "free_span": scene.free_span(), "follow_escape": FOLLOW_ESCAPE,
             "escape_time": float(t_escape) if st.escaped else "none"}
    return finalize(ds, f"Run of '{scene.name}' with shapes along the way: L/R = {scene.L / scene.R:g}, "
                        f"load {scene.load:g}", dict(scene.to_dict()) | extra)
