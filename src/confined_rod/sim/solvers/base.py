"""What every integrator shares: the run state, the stopping rules and the
protocol driver.

Stopping rules (the same for every solver, so "converged" means the same thing):

* equilibrium: eps_F = max_i |F_i| L / (l0 load) < tol and
  eps_M = max_i |M_i x t_i| L / (l0 load R) < tol, friction included (a stuck
  link has zero tangential residual).  eps = 1 means a force density equal to the
  load spread evenly over the rod; tol bounds the error of the force profile
  F_z(s) by tol * load;
  The round-off floor (limits.equilibrium_tol) can lift the tolerance above tol
  for long, stiff rods, by at most limits.ROUNDOFF_MARGIN (larger floors are
  refused when the scene is made); the value used is stored with the run;
* time cap: reaching t_max ends the run with ``converged = False``;
* escape: a link end above the open pore entrance and more than 0.1 R outside
  the pore's radius stops the run (``escaped = True``);
* divergence: non-finite values, a bond gap above l0/2 or a link end more than
  100 R from the axis raise :class:`DivergenceError` naming scene, step and time.

A solver supplies a *stepper*: an object whose ``advance(st, t_stop)`` moves the
state forward by some work (a chunk of explicit steps, one implicit step) without
passing t_stop and returns a kernel stop code; the checks run between calls.
"""
from __future__ import annotations

import dataclasses
import sys
import time as _time
from dataclasses import dataclass, field
from typing import Callable, Protocol

import numpy as np

from ... import limits
from ...errors import DivergenceError, ResourceLimitError
from ...limits import equilibrium_tol, snapshot_limit
from ..model import kernels as K
from ..model.forces import Workspace, evaluate
from ..scenes import Scene

PROGRESS_AFTER_S = 3.0  # report progress on stderr once a run has taken this long ...
PROGRESS_EVERY_S = 2.0  # ... and then this often


@dataclass
class RunState:
    """Everything a run carries from stage to stage."""

    r: np.ndarray
    t: np.ndarray
    time: float = 0.0
    steps: int = 0
    converged: bool = False
    escaped: bool = False
    step_capped: bool = False  # the run used up the scene's max_steps
    eps_F: float = np.inf
    eps_M: float = np.inf
    snapshot_times: list = field(default_factory=list)
    snapshot_r: list = field(default_factory=list)
    snapshot_t: list = field(default_factory=list)
    snapshot_anchor: list = field(default_factory=list)  # the stick anchors at each snapshot (or None)
    stage_converged: list = field(default_factory=list)
    work: dict = field(default_factory=dict)  # solver counters (Newton iterations, rejected steps, ...)
    anchor: np.ndarray | None = None  # stick anchors: per link centre, or per link end (2N, friction_at "ends")
    capped_in: str = ""  # the stage of a protocol that used up the time cap or the step budget ("" if none did)

    def take_snapshot(self, limit: int | None = None, scene_name: str = "") -> None:
        if limit is not None and len(self.snapshot_times) >= limit:
            raise ResourceLimitError(
                f"scene {scene_name!r}: invalid value for 'snapshot_interval': the run reached t = {self.time:.6g} "
                f"with {limit} snapshots stored, the memory cap of {limits.MAX_SNAPSHOT_BYTES / 2**20:g} MiB; "
                "raise snapshot_interval (or lower t_max)")
        self.snapshot_times.append(self.time)
        self.snapshot_r.append(self.r.copy())
        self.snapshot_t.append(self.t.copy())
        self.snapshot_anchor.append(None if self.anchor is None else self.anchor.copy())

    def count(self, key: str, n: int = 1) -> None:
        self.work[key] = self.work.get(key, 0) + n


class Stepper(Protocol):
    step_hint: str  # which setting to change when a run diverges

    def advance(self, st: RunState, t_stop: float) -> int: ...


def normalised_residuals(scene: Scene, t: np.ndarray, ws: Workspace) -> tuple[float, float]:
    fmax, mmax = K.residuals(t, ws.F, ws.M)
    scale = scene.l0 * scene.load / scene.L
    return fmax / scale, mmax / (scale * scene.R)


def check_state(scene: Scene, r: np.ndarray, t: np.ndarray, step: int, time: float,
                hint: str = "") -> None:
    """Raise DivergenceError on a diverged state."""
    where = f"scene {scene.name!r}: run diverged at step {step} (t = {time:.6g})"
    if not (np.all(np.isfinite(r)) and np.all(np.isfinite(t))):
        raise DivergenceError(f"{where}: non-finite positions or tangents; {hint or 'reduce the step'}, "
                              f"or check k_ph = {scene.k_ph}, k_w = {scene.k_w}")
    h = 0.5 * scene.l0
    rm, rp = r - h * t, r + h * t
    gap = np.linalg.norm(rm[1:] - rp[:-1], axis=1)
    if gap.size and gap.max() > h:
        raise DivergenceError(f"{where}: a bond gap of {gap.max():.3g} exceeds l0/2 = {h:.3g}; "
                              f"the joints have come apart (k_ph = {scene.k_ph} too small for the load"
                              f"{', or ' + hint if hint else ''})")
    ends = np.concatenate([rm, rp])
    rho = np.hypot(ends[:, 0], ends[:, 1])
    if rho.max() > 100.0 * scene.R:
        raise DivergenceError(f"{where}: a link end is {rho.max():.3g} from the axis (runaway)")


class Progress:
    """Readable progress of a relaxation on stderr (plain lines: they go to log files).

    The residual falls from its first value eps0 towards the tolerance over
    log10(eps0/tol) decades; the fraction done is the share of those decades
    covered by the best residual so far, and the time left is extrapolated from
    it (elapsed x (1 - f)/f).  A frictional helix creeps slowly at the end, so
    the estimate is a lower bound late in a run; the time cap bounds it from
    above, and the line says which applies."""

    def __init__(self, scene: Scene, tol: float, t_cap: float, label: str, enabled: bool):
        self.name, self.tol, self.t_cap, self.enabled = f"{scene.name}{label}", tol, t_cap, enabled
        self.t0 = self.last = _time.perf_counter()
        self.eps0: float | None = None
        self.best = np.inf
        self.time0: float | None = None

    def update(self, st: RunState) -> None:
        eps = max(st.eps_F, st.eps_M)
        if self.eps0 is None:
            self.eps0, self.time0 = max(eps, self.tol * 10.0), st.time
        self.best = min(self.best, eps)
        now = _time.perf_counter()
        if not self.enabled or now - self.t0 < PROGRESS_AFTER_S or now - self.last < PROGRESS_EVERY_S:
            return
        self.last = now
        elapsed = now - self.t0
        decades = np.log10(self.eps0 / self.tol)
        done = float(np.clip(np.log10(self.eps0 / max(self.best, self.tol)) / decades, 0.0, 1.0))
        left = elapsed * (1.0 - done) / done if done > 0 else np.inf
        rate = (st.time - self.time0) / elapsed  # simulated time per second
        to_cap = (self.t_cap - st.time) / rate if rate > 0 else np.inf
        eta = (f"~{_duration(left)} left" if left <= to_cap
               else f"at most {_duration(to_cap)} left (time cap t_max = {self.t_cap:.3g})")
        print(f"[{self.name}] {100 * done:3.0f} % of {decades:.1f} residual decades (eps = {eps:.2e}, tol "
              f"{self.tol:.1e}), t = {st.time:.4g}, {st.steps} steps, {_duration(elapsed)} elapsed, {eta}",
              file=sys.stderr, flush=True)


def _duration(seconds: float) -> str:
    if not np.isfinite(seconds):
        return "unknown"
    if seconds < 120:
        return f"{seconds:.0f} s"
    if seconds < 7200:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"


def next_snapshot(scene: Scene, last: float) -> float:
    """The snapshot time after ``last``: a fixed interval (snapshot_growth = 1), or from
    snapshot_interval on, each time the simulated time has grown by snapshot_growth."""
    g, dt = scene.snapshot_growth, scene.snapshot_interval
    if g > 1.0:
        return last * g if last >= dt else dt
    return last + dt


def relax(scene: Scene, st: RunState, stepper: Stepper, *, t_end: float | None = None,
          progress: bool = True, label: str = "", follow_escape: bool = False) -> RunState:
    """Advance until equilibrium, escape, or the time cap (t_end or scene.t_max);
    with ``follow_escape`` an escape is recorded but the run goes on to the cap (to
    show the rod leaving the pore: there is no equilibrium to reach).
    Snapshots (only if scene.snapshot_interval > 0) are taken at their exact times,
    at most limits.snapshot_limit(scene) of them (ResourceLimitError beyond)."""
    par = scene.params()
    ws = Workspace.for_links(scene.N)
    t_cap = scene.t_max if t_end is None else t_end
    snap_dt = scene.snapshot_interval
    snap_limit = snapshot_limit(scene)
    next_snap = next_snapshot(scene, st.snapshot_times[-1]) if (snap_dt > 0 and st.snapshot_times) else st.time
    st.converged = False
    tol = equilibrium_tol(scene)
    if progress and tol > scene.tol:
        print(f"[{scene.name}{label}] tol = {scene.tol:.1e} is below the round-off floor of this scene "
              f"(L = {scene.L:g}, k_ph = {scene.k_ph:g}, l0 = {scene.l0:g}); equilibrium is tested at {tol:.2e}",
              file=sys.stderr, flush=True)
    bar = Progress(scene, tol, t_cap, label, progress)
    while True:
        if snap_dt > 0 and st.time >= next_snap - 1e-12:
            st.take_snapshot(snap_limit, scene.name)
            while next_snap <= st.time + 1e-12:
                next_snap = next_snapshot(scene, next_snap)
        t_stop = min(t_cap, next_snap) if snap_dt > 0 else t_cap
        code = stepper.advance(st, t_stop)
        check_state(scene, st.r, st.t, st.steps, st.time, stepper.step_hint)
        st.escaped = st.escaped or code == K.STOP_ESCAPED
        ends = st.anchor if scene.friction_at == "ends" and st.anchor is not None else None
        evaluate(par, st.r, st.t, ws, ends, scene.k_t)
        st.eps_F, st.eps_M = normalised_residuals(scene, st.t, ws)
        bar.update(st)
        if st.escaped and not follow_escape:
            break
        if st.eps_F < tol and st.eps_M < tol:
            st.converged = True
            break
        if st.time >= t_cap * (1 - 1e-12):
            break
        if scene.max_steps and st.steps >= scene.max_steps:
            st.step_capped = True
            break
    if snap_dt > 0 and (not st.snapshot_times or st.snapshot_times[-1] < st.time):
        st.take_snapshot(snap_limit + 1, scene.name)
    st.stage_converged.append(st.converged)
    return st


def ramp_stage(scene: Scene, load: float) -> Scene:
    """An intermediate stage of protocol 'ramp': the scene at a smaller load, relaxed to its tol
    or to the round-off floor at that load, whichever is larger (the floor, normalised by the
    load, grows as 1/load; intermediate stages only set the path, and the last stage, at the
    full load, is relaxed to the scene's own tolerance)."""
    return dataclasses.replace(scene, load=load, tol=min(max(scene.tol, limits.roundoff_tol(scene, load)),
                                                         limits.TOL_MAX))


def run_protocol(scene: Scene, make_stepper: Callable[[Scene], Stepper], *,
                 progress: bool = True) -> RunState:
    """Run the scene's protocol from its initial state with the given solver."""
    r, t = scene.initial_state()
    st = RunState(r=r, t=t)
    stepper = make_stepper(scene)
    if scene.protocol == "planar_then_3d":
        relax(scene, st, stepper, progress=progress, label=" planar stage")
        if st.escaped:
            return st
        scene.perturb_3d(st.r)
        stepper = make_stepper(scene)
        relax(scene, st, stepper, progress=progress, label=" 3-D stage")
    elif scene.protocol == "ramp":
        loads = scene.ramp_loads()
        for i, F in enumerate(loads):
            stage = scene if F == scene.load else ramp_stage(scene, float(F))
            relax(stage, st, make_stepper(stage), progress=progress,
                  label=f" ramp {i + 1}/{len(loads)}, load {F:.3g}")
            if st.escaped:
                return st
            if not st.converged and i + 1 < len(loads):
                # the time cap and the step budget are the run's, not the stage's: a stage that
                # used them up leaves nothing for the next, whose residual at a larger load would
                # describe a load the rod never felt; the run ends here and says where
                st.capped_in = f"ramp stage {i + 1} of {len(loads)} (load {F:.3g} EI/R^2; the full load never applied)"
                return st
    else:
        relax(scene, st, stepper, progress=progress)
    leave_saddles(scene, st, make_stepper, progress=progress)
    return st


def leave_saddles(scene: Scene, st: RunState, make_stepper: Callable[[Scene], Stepper], *,
                  progress: bool = True) -> None:
    """Up to scene.saddle_kicks times: a run that stopped on a known saddle (observables.saddle)
    is displaced laterally by a continuous random rod of amplitude scene.kick (its own stream,
    seeded per kick) and relaxed again; counted in st.work['saddle_kicks']."""
    from .. import observables, perturbation

    for i in range(scene.saddle_kicks):
        if not st.converged or st.escaped or observables.saddle(scene, st.r) == 0:
            return
        z = (np.arange(scene.N) + 0.5) * scene.l0
        st.r[:, :2] += perturbation.lateral(z, scene.L, scene.R, scene.kick, [scene.seed, i],
                                            stream=perturbation.SADDLE)
        st.count("saddle_kicks")
        st.converged = False
        relax(scene, st, make_stepper(scene), progress=progress, label=f" after saddle kick {i + 1}")
