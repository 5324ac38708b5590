"""Stability stress test: run one point of a sweep and record how it ended.

Each point either reaches equilibrium, runs into its time cap, escapes, diverges
(:class:`DivergenceError`, with the solver's message naming step and time) or
is rejected as an invalid scene (:class:`SceneError`, naming the parameter).
Nothing is raised and nothing is NaN: the status is a flag (CF ``flag_values``)
and the force is stored only where the run produced one (0 and ``has_force`` = 0
otherwise).
"""
from __future__ import annotations

import time
from typing import Any, Mapping

import numpy as np
import xarray as xr

from .errors import DivergenceError
from .io import variable
from .scenes import Scene, SceneError
from .simulation import simulate

STATUS = ("converged", "not_converged", "escaped", "diverged", "invalid")
STATUS_ATTRS = {"flag_values": np.arange(len(STATUS), dtype=np.int8), "flag_meanings": " ".join(STATUS)}


def probe(params: Mapping[str, Any]) -> xr.Dataset:
    """Run the scene given by ``params`` and return a one-point status dataset."""
    t0 = time.perf_counter()
    F, steps, has_force = 0.0, 0, 0
    try:
        scene = Scene.from_dict(dict(params))
    except (SceneError, TypeError) as e:
        status, message = "invalid", str(e)
    else:
        try:
            ds = simulate(scene, progress=False)
        except DivergenceError as e:
            status, message = "diverged", str(e)
        else:
            F, steps, has_force = float(ds.F_transmitted), int(ds.n_steps), 1
            if int(ds.escaped):
                status, message = "escaped", f"escaped from the pore at t = {float(ds.t_final):.4g}"
            elif int(ds.converged):
                status, message = "converged", f"equilibrium at t = {float(ds.t_final):.4g} ({steps} steps)"
            else:
                status, message = "not_converged", (f"time cap t_max = {float(ds.t_final):.4g} reached with "
                                                    f"eps_F = {float(ds.residual_force):.2e} > tol")
    wall = time.perf_counter() - t0
    out = xr.Dataset({
        "status": xr.Variable((), np.int8(STATUS.index(status)),
                              attrs={"long_name": "how the run ended", "units": "1", **STATUS_ATTRS}),
        "F_transmitted": variable((), F, "F_transmitted"),
        "has_force": variable((), np.int8(has_force), "has_force"),
        "wall_time": variable((), wall, "wall_time"),
        "n_steps": variable((), steps, "n_steps"),
    })
    out.attrs.update({"message": message, "status_name": status,
                      "scene": str(params.get("name", "")), "solver": str(params.get("solver", "implicit"))})
    return out


def stability_map(fig_cfg: Mapping[str, Any], probes: Mapping[str, xr.Dataset]) -> xr.Dataset:
    """Collect the probes of a sweep (scene entries {solver, <parameter>: value})."""
    names = list(probes)
    entries = [dict(fig_cfg["scenes"][n] or {}) for n in names]
    solver = [e.pop("solver", "implicit") for e in entries]
    param = [next(iter(e)) if e else "base" for e in entries]
    value = [float(e[p]) if p != "base" else 0.0 for e, p in zip(entries, param)]
    data = {k: xr.Variable(("point",), np.array([probes[n][k].values for n in names]),
                           attrs=probes[names[0]][k].attrs)
            for k in ("status", "F_transmitted", "has_force", "wall_time", "n_steps")}
    coords = {
        "point": xr.Variable(("point",), np.array(names, dtype=object), attrs={"long_name": "sweep point",
                                                                                "units": "1"}),
        "solver": xr.Variable(("point",), np.array(solver, dtype=object),
                              attrs={"long_name": "time integrator", "units": "1"}),
        "parameter": xr.Variable(("point",), np.array(param, dtype=object),
                                 attrs={"long_name": "swept parameter ('base': the defaults)", "units": "1"}),
        "value": xr.Variable(("point",), np.array(value), attrs={"long_name": "value of the swept parameter",
                                                                  "units": "1"}),
    }
    ds = xr.Dataset(data, coords=coords)
    ds["message"] = xr.Variable(("point",), np.array([probes[n].attrs["message"] for n in names], dtype=object),
                                attrs={"long_name": "how the run ended, in words", "units": "1"})
    ds.attrs["sweeps"] = repr(dict(fig_cfg.get("sweeps", {})))
    return ds
