"""Kind ``time_vs_error``: wall time against the error of |F_z(L)| for both solvers over
ladders of their accuracy knob and of l0, against a reference scene (the finest numerics).
"""
from __future__ import annotations

from typing import Any, Mapping

import numpy as np
import xarray as xr

from ...errors import ConfigError
from .. import plotting as P
from ..figure_quantities import attrs, label, param_text, variable
from ._common import same_except

OPTIONS = {"reference": {
    "anyOf": [{"type": "string"}, {"type": "array", "items": {"type": "string"}, "minItems": 1}],
    "description": "the scene whose |F_z(L)| is the reference of the error, or one such scene per bond "
                   "stiffness k_ph (each run is compared with the reference of its own k_ph)"}}
KNOB = {"explicit": "tol", "implicit": "dx_max"}  # each solver's accuracy knob (explicit: dt is pinned)


def varied(fig_cfg) -> tuple[str, ...]:
    return ("solver", "l0", "dx_max", "dt_factor", "tol", "t_max", "k_ph")


def references(fig_cfg) -> list[str]:
    ref = fig_cfg.get("reference")
    return [ref] if isinstance(ref, str) else list(ref or [])


def reference_of(built, refs) -> dict[float, str]:
    """k_ph -> the reference scene of that bond stiffness."""
    return {float(built[r].k_ph): r for r in refs}


def validate(figure, fig_cfg, built) -> None:
    refs = references(fig_cfg)
    for ref in refs:
        if ref not in built:
            raise ConfigError(f"figures.{figure}.reference: {ref!r} is not one of its scenes ({', '.join(built)})")
    by_k = reference_of(built, refs)
    if len(by_k) != len(refs):
        raise ConfigError(f"figures.{figure}.reference: {refs} has two scenes of the same k_ph; give one per k_ph")
    for name, sc in built.items():
        if float(sc.k_ph) not in by_k:
            raise ConfigError(f"figures.{figure}.scenes.{name}: k_ph = {sc.k_ph:g} has no reference scene "
                              f"(the references {refs} have k_ph = {', '.join(f'{k:g}' for k in by_k)})")
    same_except(figure, built, varied(fig_cfg), "the runs of a time-vs-error figure differ only in their numerics")


def caption(figure, fig_cfg, built) -> str:
    sc = next(iter(built.values()))
    refs = references(fig_cfg)
    ks = sorted({float(b.k_ph) for b in built.values()})
    per_k = (f" at k_ph = {' and '.join(f'{k:g}' for k in ks)} EI/R^2 (one panel each, k_w = {sc.k_w:g})"
             if len(ks) > 1 else "")
    return (f"Wall time against the error of |F_z(L)|, L/R = {sc.L:g}, k_fr = {sc.k_fr:g}, both solvers "
            f"over ladders of their step knob and of l0{per_k}; error against the reference run"
            f"{'s' if len(refs) > 1 else ''} {', '.join(repr(r) for r in refs)} of the same k_ph.")


def build(fig_cfg: Mapping[str, Any], sims: Mapping[str, xr.Dataset], context=None) -> xr.Dataset:
    """Wall time and error of every scene against the reference scene of its k_ph."""
    refs = references(fig_cfg)
    ref_of = {float(sims[r].attrs["k_ph"]): r for r in refs}
    names = [n for n in sims if n not in refs]
    k_ph = np.array([float(sims[n].attrs["k_ph"]) for n in names])
    F_ref = np.array([float(sims[ref_of[k]]["F_transmitted"]) for k in k_ph])
    F = np.array([float(sims[n]["F_transmitted"]) for n in names])
    data = {
        "wall_time": variable(("run",), [float(sims[n]["wall_time"]) for n in names], "wall_time"),
        "F_transmitted": variable(("run",), F, "F_transmitted"),
        "F_reference": variable(("run",), F_ref, "F_reference"),
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
        "run_k_ph": variable(("run",), k_ph, "run_k_ph"),
        "run_knob": xr.Variable(("run",), np.array([float(sims[n].attrs[knob[sims[n].attrs["solver"]]])
                                                    for n in names]), attrs=attrs("run_knob")),
    }
    ds = xr.Dataset(data, coords=coords)
    first = sims[refs[0]]
    ref_knob = knob[first.attrs["solver"]]
    ds.attrs.update({"reference": ", ".join(refs),
                     "reference_k_ph": [float(k) for k in ref_of],
                     "reference_wall_time": [float(sims[r]["wall_time"]) for r in refs],
                     "reference_solver": first.attrs["solver"], "reference_l0": float(first.attrs["l0"]),
                     "reference_knob": f"{ref_knob} = {float(first.attrs[ref_knob]):g}",
                     "error_definition": "|F_z(L) - F_ref| / F_ref, F_ref from the reference scene of the run's k_ph: "
                                         "the same rod with the finest numerics of the ladder (see reference_*)",
                     "timing": "wall time of each simulate job, one core per job"})
    return ds


def plot(ds: xr.Dataset):
    """Wall time against error, log-log, one line per solver and link length; one panel per k_ph."""
    ks = sorted({float(k) for k in np.atleast_1d(ds["run_k_ph"].values)})
    fig, axes = P.plt.subplots(1, len(ks), figsize=(4.8 if len(ks) == 1 else 7.2, 3.6), sharey=True,
                               squeeze=False, label=ds.attrs["title"])
    err = ds["error"].values
    wall = ds["wall_time"].values
    solver = ds["solver"].values
    l0 = ds["run_l0"].values
    k_ph = ds["run_k_ph"].values
    knob = ds["run_knob"].values
    marker = {"implicit": "o", "explicit": "s"}
    colours = P.plt.rcParams["axes.prop_cycle"].by_key()["color"]
    groups = sorted({(str(a), float(b)) for a, b in zip(solver, l0)})  # one colour per group in every panel
    for ax, kp in zip(axes[0], ks):
        for j, (sv, lk) in enumerate(groups):
            m = (solver == sv) & np.isclose(l0, lk) & np.isclose(k_ph, kp)
            if not m.any():
                continue
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
        ax.set_title(param_text("k_ph", kp), fontsize=9)
        ax.legend(loc="best")
    axes[0][0].set_ylabel(label("wall_time", "s"))
    fig.suptitle(P.params_text(ds, ("L", "load", "k_fr", "k_w")), fontsize=9)
    ref_t = ", ".join(f"{float(w):.3g} s" for w in np.atleast_1d(ds.attrs["reference_wall_time"]))
    fig.text(0.02, -0.02, "error $\\epsilon = |F_z(L) - F_{ref}|/F_{ref}$ against the reference of the same $k_{ph}$: "
             f"{ds.attrs['reference_solver']}, $l_0 = {float(ds.attrs['reference_l0']):g}\\,R$, "
             f"{ds.attrs['reference_knob']} ({ref_t}).\n"
             "Point labels: $dx_{max}$ [R] (implicit), tol (explicit). Wall time of one simulate job.",
             ha="left", va="top", fontsize=P.SMALL)
    return fig
