"""Paper-faithful explicit (forward Euler) integrator of the overdamped dynamics,
with the stopping rules shared by every run:

* equilibrium: eps_F = max_i |F_i| L / (l0 load) < tol and
  eps_M = max_i |M_i x t_i| L / (l0 load R) < tol, friction included (a stuck
  link has zero tangential residual).  eps = 1 means a force density equal to the
  load spread evenly over the rod; tol bounds the error of the force profile
  F_z(s) by tol * load;
* time cap: reaching t_max ends the run with ``converged = False``;
* escape: a link end above the open pore entrance and more than 0.1 R outside
  the pore's radius stops the run (``escaped = True``);
* divergence: non-finite values, a bond gap above l0/2 or a link end more than
  100 R from the axis raise :class:`DivergenceError` naming scene, step and time.

The kernels do the steps in chunks of about 0.1 s of work; the checks run
between chunks.
"""
from __future__ import annotations

import sys
import time as _time
from dataclasses import dataclass, field

import numpy as np

from ..errors import DivergenceError
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
    eps_F: float = np.inf
    eps_M: float = np.inf
    snapshot_times: list = field(default_factory=list)
    snapshot_r: list = field(default_factory=list)
    stage_converged: list = field(default_factory=list)

    def take_snapshot(self) -> None:
        self.snapshot_times.append(self.time)
        self.snapshot_r.append(self.r.copy())


def normalised_residuals(scene: Scene, t: np.ndarray, ws: Workspace) -> tuple[float, float]:
    fmax, mmax = K.residuals(t, ws.F, ws.M)
    scale = scene.l0 * scene.load / scene.L
    return fmax / scale, mmax / (scale * scene.R)


def check_state(scene: Scene, r: np.ndarray, t: np.ndarray, step: int, time: float) -> None:
    """Raise DivergenceError on a diverged state."""
    where = f"scene {scene.name!r}: run diverged at step {step} (t = {time:.6g})"
    if not (np.all(np.isfinite(r)) and np.all(np.isfinite(t))):
        raise DivergenceError(f"{where}: non-finite positions or tangents; "
                              f"reduce dt_factor (now {scene.dt_factor}) or check k_ph, k_w")
    h = 0.5 * scene.l0
    rm, rp = r - h * t, r + h * t
    gap = np.linalg.norm(rm[1:] - rp[:-1], axis=1)
    if gap.size and gap.max() > h:
        raise DivergenceError(f"{where}: a bond gap of {gap.max():.3g} exceeds l0/2 = {h:.3g}; "
                              f"the joints have come apart (k_ph = {scene.k_ph} too small for the load, "
                              f"or dt_factor = {scene.dt_factor} too large)")
    ends = np.concatenate([rm, rp])
    rho = np.hypot(ends[:, 0], ends[:, 1])
    if rho.max() > 100.0 * scene.R:
        raise DivergenceError(f"{where}: a link end is {rho.max():.3g} from the axis (runaway)")


def relax(scene: Scene, st: RunState, *, t_end: float | None = None, progress: bool = True,
          label: str = "") -> RunState:
    """Integrate until equilibrium, escape, or the time cap (t_end or scene.t_max)."""
    par = scene.params()
    dt = scene.dt()
    n = scene.N
    ws = Workspace.for_links(n)
    t_cap = scene.t_max if t_end is None else t_end
    chunk = int(max(20, min(200_000, 2_000_000 // n)))
    snap_dt = scene.snapshot_interval
    next_snap = (st.snapshot_times[-1] + snap_dt) if (snap_dt > 0 and st.snapshot_times) else st.time
    t0 = _time.perf_counter()
    last_report = t0
    st.converged = False
    while True:
        if snap_dt > 0 and st.time >= next_snap - 1e-12:
            st.take_snapshot()
            next_snap += snap_dt * max(1, np.floor((st.time - next_snap) / snap_dt) + 1)
        t_stop = min(t_cap, next_snap) if snap_dt > 0 else t_cap
        nsteps = int(min(chunk, max(1, np.ceil((t_stop - st.time) / dt - 1e-9))))
        done, code = K.explicit_steps(st.r, st.t, par, dt, nsteps, ws.Fm, ws.Fp, ws.F, ws.M, ws.Nw,
                                      ws.Ff, ws.stuck)
        st.steps += done
        st.time += done * dt
        check_state(scene, st.r, st.t, st.steps, st.time)
        st.escaped = code == K.STOP_ESCAPED
        evaluate(par, st.r, st.t, ws)
        st.eps_F, st.eps_M = normalised_residuals(scene, st.t, ws)
        now = _time.perf_counter()
        if progress and now - t0 > PROGRESS_AFTER_S and now - last_report > PROGRESS_EVERY_S:
            last_report = now
            print(f"[{scene.name}{label}] t = {st.time:.4g} / {t_cap:.4g}, steps = {st.steps}, "
                  f"eps_F = {st.eps_F:.2e}, eps_M = {st.eps_M:.2e} (tol {scene.tol:.1e}), "
                  f"{now - t0:.0f} s", file=sys.stderr, flush=True)
        if st.escaped:
            break
        if st.eps_F < scene.tol and st.eps_M < scene.tol:
            st.converged = True
            break
        if st.time >= t_cap * (1 - 1e-12):
            break
    if snap_dt > 0 and (not st.snapshot_times or st.snapshot_times[-1] < st.time):
        st.take_snapshot()
    st.stage_converged.append(st.converged)
    return st


def run(scene: Scene, *, progress: bool = True) -> RunState:
    """Run the scene's protocol from its initial state."""
    r, t = scene.initial_state()
    st = RunState(r=r, t=t)
    if scene.protocol == "planar_then_3d":
        relax(scene, st, progress=progress, label=" planar stage")
        if st.escaped:
            return st
        scene.perturb_3d(st.r)
        relax(scene, st, progress=progress, label=" 3-D stage")
    else:
        relax(scene, st, progress=progress)
    return st
