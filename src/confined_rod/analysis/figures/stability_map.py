"""Kind ``stability_map``: how every point of a one-at-a-time sweep ended, for both solvers.

Post-processing side of the stability stress test: the points are run by the rule
``probe`` (confined_rod.sim.probe.probe, simulation side), which never fails and
records the status as a CF flag; this module collects and draws them.
"""
from __future__ import annotations

from typing import Any, Mapping

import numpy as np
import xarray as xr

from ...errors import ConfigError
from .. import ensembles
from .. import plotting as P
from ..figure_quantities import QUANTITIES, label

SOURCE = "probe"
OPTIONS = {
    "solvers": {"type": "array", "minItems": 1, "items": {"enum": ["implicit", "explicit"]},
                "description": "the solvers swept"},
    "reference_tolerance": {"type": "number", "exclusiveMinimum": 0, "default": 0.05,
                            "description": "a converged point of a numerical parameter's sweep reached the "
                                           "reference state if it has the base point's state class and its "
                                           "|F_z(L)| lies within this fraction of the base point's"},
    "sweeps": {"type": "object", "minProperties": 1,
               "additionalProperties": {"type": "array", "minItems": 1, "items": {"type": "number"}},
               "description": "Scene field -> values, each varied alone about the figure's defaults for every "
                              "solver (dt_factor only for the explicit, dx_max only for the implicit solver); the "
                              "points become the figure's scenes. Values need not be valid: an invalid or "
                              "diverging point is recorded with its message."},
}
SWEEP_ONLY = {"dt_factor": "explicit", "dx_max": "implicit"}  # step knobs that exist for one solver only


def expand_sweeps(fig_cfg: dict) -> None:
    """Turn the figure's ``sweeps`` into scenes, in place: for every solver a base point
    ('<solver>-base', the figure's defaults) and one point per swept value
    ('<solver>-<parameter>-<value>'); dt_factor is swept for the explicit and dx_max for
    the implicit solver only."""
    if not fig_cfg.get("sweeps"):
        return
    out = fig_cfg.setdefault("scenes", {}) or {}
    for solver in fig_cfg.get("solvers", ["implicit", "explicit"]):
        out.setdefault(f"{solver}-base", {"solver": solver})
        for param, values in fig_cfg["sweeps"].items():
            if SWEEP_ONLY.get(param, solver) != solver:
                continue
            for v in values:
                tag = f"{v:g}".replace(".", "p").replace("-", "m").replace("+", "")
                out.setdefault(f"{solver}-{param}-{tag}", {"solver": solver, param: v})
    fig_cfg["scenes"] = out


def validate_config(figure, fig_cfg, scene_fields) -> None:
    """Its points may be invalid on purpose (the probes record that): only the sweeps are checked."""
    if not fig_cfg.get("scenes") and not fig_cfg.get("sweeps"):
        raise ConfigError(f"figures.{figure}: a stability map needs sweeps (or scenes)")
    for p in fig_cfg.get("sweeps", {}):
        if p not in scene_fields:
            raise ConfigError(f"figures.{figure}.sweeps: {p!r} is not a Scene field")


def caption(figure, fig_cfg, built=None) -> str:
    d = fig_cfg.get("defaults") or {}
    return ("How every point of a one-at-a-time sweep about " + ", ".join(f"{k} = {v}" for k, v in d.items())
            + " ended, for the solvers " + ", ".join(fig_cfg.get("solvers", [])) + ", by its physics as well as "
            "its status: the base point's state (its state class, and |F_z(L)| within "
            + f"{100 * float(fig_cfg.get('reference_tolerance', 0.05)):g} % of the base point's), another state "
            "(named in the cell), converged where the sweep varies the physics, a time or step cap, an escape, a "
            "divergence, refused input, or a state outside the model (messages in the dataset); the legend "
            "gives the count of each. Sweeps: "
            + "; ".join(f"{k}: {', '.join(f'{x:g}' for x in v)}" for k, v in fig_cfg.get("sweeps", {}).items())
            + ". Parameters: see the dataset.")


def meta(fig_cfg, sims) -> dict:
    """The probes vary everything; the figure's defaults are the base point."""
    return {**(fig_cfg.get("defaults") or {}), "solvers": list(fig_cfg.get("solvers", []))}


def build(fig_cfg: Mapping[str, Any], probes: Mapping[str, xr.Dataset], context=None) -> xr.Dataset:
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
    state, outcome = classify(fig_cfg, names, probes, solver, param)
    ds["state"] = xr.Variable(("point",), np.array(state, dtype=object),
                              attrs={"long_name": "final state class of a run that gave a force "
                                                  "(ensembles.final_class; '-' otherwise)", "units": "1"})
    ds["outcome"] = xr.Variable(("point",), np.array([OUTCOMES.index(o) for o in outcome], dtype=np.int8),
                                attrs={"long_name": "how the run ended, by its physics as well as its status",
                                       "units": "1", "flag_values": np.arange(len(OUTCOMES), dtype=np.int8),
                                       "flag_meanings": " ".join(OUTCOMES)})
    ds.attrs["sweeps"] = repr(dict(fig_cfg.get("sweeps", {})))
    ds.attrs["outcome_counts"] = ", ".join(f"{o.replace('_', ' ')}: {outcome.count(o)}" for o in OUTCOMES)
    ds.attrs["reference_tolerance"] = float(fig_cfg.get("reference_tolerance", 0.05))
    return ds


#: a point's outcome: its status, and for a converged point of a numerical parameter whether it
#: reached the base point's state (class and |F_z(L)| within reference_tolerance)
OUTCOMES = ("reference_state", "other_state", "converged", "capped", "escaped", "diverged", "refused",
            "model_violated")
#: parameters of the numerics (the equilibrium should not depend on them); the others (load,
#: k_fr, L) change the physics, so their points are classified by state only ("converged")
NUMERICAL = {"base", "dt_factor", "dx_max", "tol", "k_ph", "k_w", "l0", "t_max", "max_steps"}


def classify(fig_cfg, names, probes, solver, param) -> tuple[list[str], list[str]]:
    """(state class, outcome) of every point. The reference of a solver's points is its base
    point, if that converged (else the other solver's)."""
    meanings = probes[names[0]]["status"].attrs["flag_meanings"].split()
    status = [meanings[int(probes[n]["status"])] for n in names]
    state = [ensembles.final_class(probes[n]) if "x" in probes[n] else "-" for n in names]
    F = [float(probes[n]["F_transmitted"]) for n in names]
    base = {sv: i for i, (sv, p) in enumerate(zip(solver, param)) if p == "base" and status[i] == "converged"}
    tol = float(fig_cfg.get("reference_tolerance", 0.05))
    outcome = []
    for i, st in enumerate(status):
        if st != "converged":
            outcome.append({"time_cap": "capped", "step_cap": "capped", "invalid": "refused"}.get(st, st))
            continue
        ref = base.get(solver[i], next(iter(base.values()), None))
        if param[i] not in NUMERICAL or ref is None:
            outcome.append("converged")
        elif state[i] == state[ref] and abs(F[i] - F[ref]) <= tol * abs(F[ref]):
            outcome.append("reference_state")
        else:
            outcome.append("other_state")
    return state, outcome


OUTCOME_COLOURS = {"reference_state": "#4daf4a", "other_state": "#f781bf", "converged": "#b3de69",
                   "capped": "#ffd92f", "escaped": "#80b1d3", "diverged": "#e41a1c", "refused": "0.75",
                   "model_violated": "#ff7f00"}
OUTCOME_LABELS = {"reference_state": "base point's state", "other_state": "another state (named)",
                  "converged": "converged (physics varied)", "capped": "time or step cap",
                  "escaped": "escaped", "diverged": "diverged", "refused": "refused input",
                  "model_violated": "outside the model"}


def plot(ds: xr.Dataset):
    """One panel per solver: a row per swept parameter, a cell per value, coloured by how
    the run ended; the cell text is the value (and |F_z(L)| where the run gave one)."""
    from matplotlib.patches import Patch, Rectangle

    meanings = ds["outcome"].attrs["flag_meanings"].split()
    solvers = [s for s in ("implicit", "explicit") if s in set(ds["solver"].values)]
    params = list(dict.fromkeys(ds["parameter"].values))
    ncol = max(int(np.sum((ds["solver"].values == sv) & (ds["parameter"].values == p)))
               for sv in solvers for p in params)
    rows = [len({p for p in params if np.any((ds["solver"].values == sv) & (ds["parameter"].values == p))})
            for sv in solvers]
    # printed at its natural size: at most the text width (plotting.TEXT_WIDTH_IN), rows of 0.27 in
    size = (min(P.TEXT_WIDTH_IN, 0.85 * ncol + 1.7), 0.27 * sum(rows) + 1.3)
    fig, axes = P.plt.subplots(len(solvers), 1, figsize=size, squeeze=False, label=ds.attrs["title"],
                               gridspec_kw={"height_ratios": rows})
    row_label = {"base": "defaults", "dx_max": r"$dx_{max}$ [$R$]", "dt_factor": r"$\Delta t/\Delta t_{stab}$",
                 "tol": r"tol ($\epsilon_F$, $\epsilon_M$)"}
    for ax, sv in zip(axes[:, 0], solvers):
        params = [p for p in dict.fromkeys(ds["parameter"].values)
                  if np.any((ds["solver"].values == sv) & (ds["parameter"].values == p))]
        for row, p in enumerate(params):
            m = np.flatnonzero((ds["solver"].values == sv) & (ds["parameter"].values == p))
            m = m[np.argsort(ds["value"].values[m])]
            for col, i in enumerate(m):
                st = meanings[int(ds["outcome"].values[i])]
                ax.add_patch(Rectangle((col, row), 0.95, 0.9, color=OUTCOME_COLOURS[st]))
                txt = "defaults" if p == "base" else f"{float(ds['value'].values[i]):g}"
                if int(ds["has_force"].values[i]):
                    txt += f"\n{float(ds['F_transmitted'].values[i]):.3g}"
                if st in ("other_state", "converged"):
                    txt += f" {ds['state'].values[i]}"
                ax.text(col + 0.475, row + 0.45, txt, ha="center", va="center", fontsize=P.SMALL, linespacing=1.0)
        ax.set_xlim(0, ncol)
        ax.set_ylim(len(params), 0)
        ax.set_yticks(np.arange(len(params)) + 0.45)
        ax.set_yticklabels([row_label.get(p) or (label(p) if p in QUANTITIES else p) for p in params])
        ax.set_xticks([])
        ax.tick_params(axis="y", length=0, right=False)
        for side in ("top", "right", "bottom", "left"):
            ax.spines[side].set_visible(False)
        ax.set_title(f"{sv} solver (cell: value of the swept parameter; below it $|F_z(L)|$ [$EI/R^2$])",
                     fontsize=8, loc="left")
    counts = [int(np.sum(ds["outcome"].values == i)) for i in range(len(meanings))]
    handles = [Patch(color=OUTCOME_COLOURS[k], label=f"{OUTCOME_LABELS[k]} ({c})")
               for k, c in zip(meanings, counts) if c]
    base = ", ".join(f"{k} = {ds.attrs[k]}" for k in ("L", "load", "k_fr", "l0", "t_max") if k in ds.attrs)
    fig.suptitle(f"stability stress map, one parameter at a time about {base}")
    fig.tight_layout()
    # below the panels (the saved figure's tight bounding box takes it in)
    fig.legend(handles=handles, loc="upper center", ncol=(len(handles) + 1) // 2, bbox_to_anchor=(0.5, 0.0))
    return fig
