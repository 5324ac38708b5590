"""Stability stress test, simulation side: run one point of a sweep and record how it ended.

The map that collects the points is post-processing: analysis/figures/stability_map.py.

Each point either reaches equilibrium, runs into its time cap or its step budget
(``max_steps``: the map's probes have one, so an explicit run at a stiff setting
costs at most that many steps and records exactly that), escapes, diverges
(:class:`DivergenceError`, with the solver's message naming step and time), ends
in a state that violates the model (a link through the wall, a torn bond), or
is rejected as an invalid scene (:class:`SceneError`, naming the parameter:
limits.py refuses what cannot be computed).
Nothing is raised and nothing is NaN: the status is a flag (CF ``flag_values``)
and the force is stored only where the run produced one (0 and ``has_force`` = 0
otherwise).
"""
from __future__ import annotations

import time
from typing import Any, Mapping

import numpy as np
import xarray as xr

from ..errors import DivergenceError, ResourceLimitError
from ..quantities import PROBE_STATUS, variable
from .scenes import Scene, SceneError
from .simulation import simulate

STATUS = PROBE_STATUS
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
        except ResourceLimitError as e:  # names the parameter (snapshot_interval), like a refused scene
            status, message = "invalid", str(e)
        else:
            status = ds.attrs["status"]     # the run's own status and reason (quantities.RUN_STATUS)
            message, steps = ds.attrs["status_reason"], int(ds.n_steps)
            if status != "model_violated":  # a state outside the model carries no force worth storing
                F, has_force = float(ds.F_transmitted), 1
                shape = {k: ds[k] for k in ("x", "y", "z", "s_link")}  # the final shape: its state class
    wall = time.perf_counter() - t0
    out = xr.Dataset({
        "status": xr.Variable((), np.int8(STATUS.index(status)),
                              attrs={"long_name": "how the run ended", "units": "1", **STATUS_ATTRS}),
        "F_transmitted": variable((), F, "F_transmitted"),
        "has_force": variable((), np.int8(has_force), "has_force"),
        "wall_time": variable((), wall, "wall_time"),
        "n_steps": variable((), steps, "n_steps"),
    })
    if has_force:
        out = out.assign({k: v.variable for k, v in shape.items() if k != "s_link"}).assign_coords(
            s_link=shape["s_link"].variable)
        out.attrs["R"] = float(scene.R)
    out.attrs.update({"message": message, "status_name": status,
                      "scene": str(params.get("name", "")), "solver": str(params.get("solver", "implicit"))})
    return out
