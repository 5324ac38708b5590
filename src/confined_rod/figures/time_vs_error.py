"""Kind ``time_vs_error``: wall time against the error of |F_z(L)| for both solvers over
ladders of their accuracy knob and of l0, against a reference scene (the finest numerics).
"""
from __future__ import annotations

from typing import Any, Mapping

import numpy as np
import xarray as xr

from .. import plotting as P
from ..errors import ConfigError
from ..io import variable
from ..quantities import attrs, label
from ._common import same_except

OPTIONS = {"reference": {"type": "string", "description": "the scene whose |F_z(L)| is the reference of the error"}}
KNOB = {"explicit": "tol", "implicit": "dx_max"}  # each solver's accuracy knob (explicit: dt is pinned)


def varied(fig_cfg) -> tuple[str, ...]:
    return ("solver", "l0", "dx_max", "dt_factor", "tol", "t_max")


def validate(figure, fig_cfg, built) -> None:
    ref = fig_cfg.get("reference")
    if ref not in built:
        raise ConfigError(f"figures.{figure}.reference: {ref!r} is not one of its scenes ({', '.join(built)})")
    same_except(figure, built, varied(fig_cfg), "the runs of a time-vs-error figure differ only in their numerics")


def caption(figure, fig_cfg, built) -> str:
    sc = next(iter(built.values()))
    return (f"Wall time against the error of |F_z(L)|, L/R = {sc.L:g}, k_fr = {sc.k_fr:g}, both solvers "
            f"over ladders of their step knob and of l0; error against the reference run '{fig_cfg['reference']}'.")


def build(fig_cfg: Mapping[str, Any], sims: Mapping[str, xr.Dataset], context=None) -> xr.Dataset:
    """Wall time and error of every scene against the reference scene's |F_z(L)|."""
    ref_name = fig_cfg["reference"]
    ref = sims[ref_name]
    F_ref = float(ref["F_transmitted"])
    names = [n for n in sims if n != ref_name]
    F = np.array([float(sims[n]["F_transmitted"]) for n in names])
    data = {
        "wall_time": variable(("run",), [float(sims[n]["wall_time"]) for n in names], "wall_time"),
        "F_transmitted": variable(("run",), F, "F_transmitted"),
        "error": variable(("run",), np.maximum(np.abs(F - F_ref) / F_ref, 1e-16), "error"),
        "converged": variable(("run",), [np.int8(sims[n]["converged"]) for n in names], "converged"),
        "n_contact": variable(("run",), [int(sims[n]["contact"].sum()) for n in names], "n_contact"),
    }
    knob = KNOB
    coords = {
        "run": xr.Variable(("run",), np.array(names, dtype=object), attrs=attrs("scene")),
        "solver": xr.Variable(("run",), np.array([sims[n].attrs["solver"] for n in names], dtype=object),
                              attrs=attrs("solver")),
        "run_l0": variable(("run",), [float(sims[n].attrs["l0"]) for n in names], "run_l0"),
        "run_knob": xr.Variable(("run",), np.array([float(sims[n].attrs[knob[sims[n].attrs["solver"]]])
                                                    for n in names]), attrs=attrs("run_knob")),
    }
    ds = xr.Dataset(data, coords=coords)
    ds.attrs.update({"reference": ref_name, "F_reference": F_ref, "reference_wall_time": float(ref["wall_time"]),
                     "reference_solver": ref.attrs["solver"], "reference_l0": float(ref.attrs["l0"]),
                     "reference_knob": f"{knob[ref.attrs['solver']]} = {float(ref.attrs[knob[ref.attrs['solver']]]):g}",
                     "error_definition": "|F_z(L) - F_ref| / F_ref, F_ref from the reference scene: the same rod "
                                         "with the finest numerics of the ladder (see reference_*)",
                     "timing": "wall time of each simulate job, one core per job"})
    return ds
def plot(ds: xr.Dataset):
    """Wall time against error, log-log, one line per solver and link length."""
    fig, ax = P.plt.subplots(figsize=(4.8, 3.6), label=ds.attrs["title"])
    err = ds["error"].values
    wall = ds["wall_time"].values
    solver = ds["solver"].values
    l0 = ds["run_l0"].values
    knob = ds["run_knob"].values
    marker = {"implicit": "o", "explicit": "s"}
    colours = P.plt.rcParams["axes.prop_cycle"].by_key()["color"]
    groups = sorted({(str(a), float(b)) for a, b in zip(solver, l0)})
    for j, (sv, lk) in enumerate(groups):
        m = (solver == sv) & np.isclose(l0, lk)
        order = np.argsort(knob[m])
        ax.plot(err[m][order], wall[m][order], marker=marker[sv], ms=5, color=colours[j % len(colours)],
                label=rf"{sv}, $l_0 = {lk:g}\,R$")
        # neighbouring rungs can nearly coincide: labels alternate above and below
        for n, (e, w, kv) in enumerate(zip(err[m][order], wall[m][order], knob[m][order])):
            ax.annotate(f"{kv:g}", (e, w), xytext=(4, 3 if n % 2 == 0 else -9), textcoords="offset points",
                        fontsize=P.SMALL, color=colours[j % len(colours)])
    ax.set_xscale("log")
    ax.set_yscale("log")
    P.plain_log_ticks(ax.yaxis)
    ax.set_xlabel(label("error"))
    ax.set_ylabel(label("wall_time", "s"))
    ax.set_title(P.params_text(ds, ("L", "load", "k_fr")), fontsize=9)
    fig.text(0.02, -0.02, "error $\\epsilon = |F_z(L) - F_{ref}|/F_{ref}$; reference: "
             f"{ds.attrs['reference_solver']}, $l_0 = {float(ds.attrs['reference_l0']):g}\\,R$, "
             f"{ds.attrs['reference_knob']} ({float(ds.attrs['reference_wall_time']):.3g} s).\n"
             "Point labels: $dx_{max}$ [R] (implicit), tol (explicit). Wall time of one simulate job.",
             ha="left", va="top", fontsize=P.SMALL)
    ax.legend(loc="best")
    return fig


