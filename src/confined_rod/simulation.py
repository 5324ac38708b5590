"""simulate(scene) -> xarray.Dataset: run a scene and collect its observables."""
from __future__ import annotations

import time

import numpy as np
import xarray as xr

from . import observables as obs
from .io import finalize, variable
from .scenes import Scene
from .solvers import SOLVERS
from .solvers.base import equilibrium_tol


def simulate(scene: Scene, *, progress: bool = True) -> xr.Dataset:
    """Relax the scene to equilibrium (or escape / time cap) and return its dataset.

    Raises DivergenceError if the run diverges; SceneError for bad input."""
    if not isinstance(scene, Scene):
        raise TypeError(f"simulate expects a Scene, got {type(scene).__name__}")
    t0 = time.perf_counter()
    st = SOLVERS[scene.solver](scene, progress=progress)
    wall = time.perf_counter() - t0
    o = obs.compute(scene, st.r, st.t)
    data = {
        "F_z": variable(("joint",), o.F_z, "F_z"),
        "x": variable(("link",), o.r[:, 0], "x"),
        "y": variable(("link",), o.r[:, 1], "y"),
        "z": variable(("link",), o.r[:, 2], "z"),
        "tx": variable(("link",), o.t[:, 0], "tx"),
        "ty": variable(("link",), o.t[:, 1], "ty"),
        "tz": variable(("link",), o.t[:, 2], "tz"),
        "wall_force": variable(("link",), o.wall_force, "wall_force"),
        "wall_force_density": variable(("link",), o.wall_force / scene.l0, "wall_force_density"),
        "contact": variable(("link",), o.contact, "contact"),
        "friction_force": variable(("link",), o.friction_force, "friction_force"),
        "friction_z": variable(("link",), o.friction_z, "friction_z"),
        "stuck": variable(("link",), o.stuck, "stuck"),
        "phi": variable(("helix",), o.phi, "phi"),
        "dphi_ds": variable(("helix",), o.dphi_ds, "dphi_ds"),
        "L_z": variable((), o.L_z, "L_z"),
        "F_transmitted": variable((), o.F_transmitted, "F_transmitted"),
        "converged": variable((), np.int8(st.converged), "converged"),
        "escaped": variable((), np.int8(st.escaped), "escaped"),
        "residual_force": variable((), st.eps_F, "residual_force"),
        "residual_torque": variable((), st.eps_M, "residual_torque"),
        "t_final": variable((), st.time, "t_final"),
        "n_steps": variable((), np.int64(st.steps), "n_steps"),
        "wall_time": variable((), wall, "wall_time"),
    }
    coords = {
        "s": variable(("joint",), o.s, "s"),
        "s_link": variable(("link",), o.s_link, "s_link"),
        "s_helix": variable(("helix",), o.s_helix, "s_helix"),
    }
    if st.snapshot_times:
        order = np.arange(scene.N)[::-1]
        snaps = np.asarray(st.snapshot_r)[:, order, :]
        coords["time"] = variable(("time",), np.asarray(st.snapshot_times), "time")
        for c, name in enumerate(("snap_x", "snap_y", "snap_z")):
            data[name] = variable(("time", "link"), snaps[:, :, c], name)
    for flag in ("contact", "stuck", "converged", "escaped"):
        data[flag].attrs["flag_values"] = np.array([0, 1], dtype=np.int8)
        data[flag].attrs["flag_meanings"] = "false true"
    ds = xr.Dataset(data, coords=coords)
    c = scene.constants()
    params = dict(scene.to_dict())
    params.update({"N": c.N, "C": c.C, "k": c.k, "k_support": c.k_support, "beta": c.beta,
                   "gamma_r": c.gamma_r, "dt": scene.dt(), "dt_stable_estimate": c.dt_stable,
                   "tol_effective": equilibrium_tol(scene),
                   "stage_converged": [int(v) for v in st.stage_converged]})
    title = (f"Confined elastic rod '{scene.name}': L/R = {scene.L / scene.R:g}, "
             f"load = {scene.load * scene.R**2 / scene.EI:g} EI/R^2, k_fr = {scene.k_fr:g}")
    return finalize(ds, title, params)
