"""simulate(scene) -> xarray.Dataset: run a scene and collect its observables."""
from __future__ import annotations

import time

import numpy as np
import xarray as xr

from ..io import finalize
from ..limits import equilibrium_tol, state_violations
from ..quantities import RUN_STATUS, variable
from . import observables as obs
from .scenes import Scene
from .solvers import SOLVERS

#: how a run ended (the dataset's ``status`` flag; ``status_reason`` says why)
STATUS = RUN_STATUS
WORK_COUNTERS = ("newton_iterations", "gradients", "factorisations", "rejected_steps", "saddle_kicks")


def _snapshot_variables(scene: Scene, st) -> dict[str, xr.Variable]:
    """Per snapshot (dimension ``time``): the shape, the axial force at the joints and the wall
    and friction forces on the links, evaluated on the stored state as at the end of a run
    (links from the loaded end)."""
    snaps = [obs.compute(scene, r, t, a) for r, t, a in zip(st.snapshot_r, st.snapshot_t, st.snapshot_anchor)]
    data = {f"snap_{c}": variable(("t", "s_link"), np.array([o.r[:, i] for o in snaps]), f"snap_{c}")
            for i, c in enumerate("xyz")}
    data["snap_F_z"] = variable(("t", "s"), np.array([o.F_z for o in snaps]), "snap_F_z")
    for key in ("wall_force", "friction_z", "friction_phi"):
        data[f"snap_{key}"] = variable(("t", "s_link"), np.array([getattr(o, key) for o in snaps]), f"snap_{key}")
    return data


def simulate(scene: Scene, *, progress: bool = True) -> xr.Dataset:
    """Relax the scene to equilibrium (or escape / time cap) and return its dataset.

    A final state that violates the model (limits.state_violations: a link deep in
    the wall or the floor, a torn bond) is never reported converged: ``status`` is
    ``model_violated`` and ``status_reason`` says why.  Raises DivergenceError if the
    run diverges, ResourceLimitError beyond the snapshot memory cap."""
    if not isinstance(scene, Scene):
        raise TypeError(f"simulate expects a Scene, got {type(scene).__name__}")
    t0 = time.perf_counter()
    st = SOLVERS[scene.solver](scene, progress=progress)
    wall = time.perf_counter() - t0
    o = obs.compute(scene, st.r, st.t, st.anchor)
    violations = state_violations(scene, st.r, st.t)
    # a ramp stage that used up the cap is relaxed to its own tolerance (solvers.base.ramp_stage)
    where = f" in {st.capped_in}" if st.capped_in else ""
    tol_text = "that stage's tolerance" if st.capped_in else f"tol = {equilibrium_tol(scene):.2e}"
    if violations:
        status, reason = "model_violated", "; ".join(violations)
        st.converged = False
    elif st.escaped:
        status, reason = "escaped", f"a link end left the pore through its entrance at t = {st.time:.6g}"
    elif st.converged:
        status, reason = "converged", (f"equilibrium: eps_F = {st.eps_F:.2e}, eps_M = {st.eps_M:.2e} below "
                                       f"tol = {equilibrium_tol(scene):.2e}")
    elif st.step_capped:
        status, reason = "step_cap", (f"step budget max_steps = {scene.max_steps} used up at t = {st.time:.6g}{where} "
                                      f"with eps_F = {st.eps_F:.2e}, eps_M = {st.eps_M:.2e} above {tol_text}")
    else:
        status, reason = "time_cap", (f"time cap t_max = {scene.t_max:.6g} reached{where} with eps_F = "
                                      f"{st.eps_F:.2e}, eps_M = {st.eps_M:.2e} above {tol_text}")
    data = {
        "F_z": variable(("s",), o.F_z, "F_z"),
        "x": variable(("s_link",), o.r[:, 0], "x"),
        "y": variable(("s_link",), o.r[:, 1], "y"),
        "z": variable(("s_link",), o.r[:, 2], "z"),
        "tx": variable(("s_link",), o.t[:, 0], "tx"),
        "ty": variable(("s_link",), o.t[:, 1], "ty"),
        "tz": variable(("s_link",), o.t[:, 2], "tz"),
        "wall_force": variable(("s_link",), o.wall_force, "wall_force"),
        "wall_force_density": variable(("s_link",), o.wall_force / scene.l0, "wall_force_density"),
        "contact": variable(("s_link",), o.contact, "contact"),
        "friction_force": variable(("s_link",), o.friction_force, "friction_force"),
        "friction_z": variable(("s_link",), o.friction_z, "friction_z"),
        "friction_phi": variable(("s_link",), o.friction_phi, "friction_phi"),
        "stuck": variable(("s_link",), o.stuck, "stuck"),
        "phi": variable(("s_helix",), o.phi, "phi"),
        "dphi_ds": variable(("s_helix",), o.dphi_ds, "dphi_ds"),
        "L_z": variable((), o.L_z, "L_z"),
        "F_transmitted": variable((), o.F_transmitted, "F_transmitted"),
        "face_force": variable(("s_link",), o.face_force, "face_force"),
        "body_force_z": variable((), o.body_force_z, "body_force_z"),
        "axial_balance": variable((), scene.load - o.F_transmitted - float(o.friction_z.sum())
                                  - float(o.face_force.sum()) - o.body_force_z, "axial_balance"),
        "converged": variable((), np.int8(st.converged), "converged"),
        "saddle": variable((), np.int8(obs.saddle(scene, o.r) if st.converged and not violations else 0), "saddle"),
        "escaped": variable((), np.int8(st.escaped), "escaped"),
        "status": variable((), np.int8(STATUS.index(status)), "status"),
        "residual_force": variable((), st.eps_F, "residual_force"),
        "residual_torque": variable((), st.eps_M, "residual_torque"),
        "t_final": variable((), st.time, "t_final"),
        "n_steps": variable((), np.int64(st.steps), "n_steps"),
        "wall_time": variable((), wall, "wall_time"),
    }
    coords = {
        "s": variable(("s",), o.s, "s"),
        "s_link": variable(("s_link",), o.s_link, "s_link"),
        "s_helix": variable(("s_helix",), o.s_helix, "s_helix"),
    }
    if st.snapshot_times:
        coords["t"] = variable(("t",), np.asarray(st.snapshot_times), "t")
        data.update(_snapshot_variables(scene, st))
    for flag in ("contact", "stuck", "converged", "escaped"):
        data[flag].attrs["flag_values"] = np.array([0, 1], dtype=np.int8)
        data[flag].attrs["flag_meanings"] = "false true"
    data["saddle"].attrs["flag_values"] = np.arange(len(obs.SADDLES), dtype=np.int8)
    data["saddle"].attrs["flag_meanings"] = " ".join(obs.SADDLES)
    data["status"].attrs["flag_values"] = np.arange(len(STATUS), dtype=np.int8)
    data["status"].attrs["flag_meanings"] = " ".join(STATUS)
    data["status"].attrs["reason"] = reason
    ds = xr.Dataset(data, coords=coords)
    c = scene.constants()
    params = dict(scene.to_dict())
    params.update({"N": c.N, "C": c.C, "k": c.k, "k_support": c.k_support, "beta": c.beta,
                   "gamma_r": c.gamma_r, "dt": scene.dt(), "dt_stable_estimate": c.dt_stable,
                   "tol_effective": equilibrium_tol(scene), "status": status, "status_reason": reason,
                   "stage_converged": [int(v) for v in st.stage_converged]})
    # the solver's work (implicit: Newton iterations, gradient evaluations, banded factorisations, rejected steps)
    params.update({f"work_{key}": int(st.work.get(key, 0)) for key in WORK_COUNTERS})
    title = (f"Confined elastic rod '{scene.name}': L/R = {scene.L / scene.R:g}, "
             f"load = {scene.load * scene.R**2 / scene.EI:g} EI/R^2, k_fr = {scene.k_fr:g}")
    return finalize(ds, title, params)
