"""Kind ``escape`` (paper Fig 8): at too large a load the rod folds over (U-bend)
instead of forming a helix; the threshold against L/R and R.

Scenes are run by the rule ``load_path``: ``fold_threshold`` scenes find the load above
which a fresh run folds (L_z < L/2) or leaves the pore, by bisection
(confined_rod.paths.fold_threshold); the one ``event`` scene is a run with shapes at
doubling simulated times (confined_rod.paths.event), from which the figure picks its
frames by what the rod does: (a) the last shape with L_z >= 0.8 L (the fold starting),
(b) the first with L_z < L/2 (the U-bend), (c) the end state.  The threshold is drawn
in units of EI/R^2 against L/R for two R, so the paper's claim that it scales as 1/R^2
is read off directly, beside the largest load a helix on the wall can carry,
4/(3 sqrt 3) EI/R^2, and the paper's load 0.5 EI/R^2.
"""
from __future__ import annotations

import numpy as np
import xarray as xr

from .. import plotting as P
from .. import theory
from ..errors import ConfigError
from ..io import variable
from ..quantities import label
from ._common import check_scene_keys, scene_coord
from .helix_views import side_strip

SOURCE = "path"
OPTIONS = {
    "runs": {"type": "object", "minProperties": 2, "additionalProperties": {"enum": ["fold_threshold", "event"]},
             "description": "scene id -> fold_threshold (bisection) or event (the run drawn; exactly one)"},
    "precision": {"type": "number", "exclusiveMinimum": 0, "maximum": 0.1,
                  "description": "relative precision of the threshold bisection"},
    "paper_load": {"type": "number", "exclusiveMinimum": 0,
                   "description": "the load (EI/R^2) at which the paper shows the event"},
}
START, FOLDED = 0.8, 0.5  # L_z/L of frames (a) and (b)


def path_spec(fig_cfg, scene: str) -> dict:
    return {"run": fig_cfg["runs"][scene], "precision": float(fig_cfg.get("precision", 1e-2))}


def varied(fig_cfg) -> tuple[str, ...]:
    return ("L", "R", "l0", "k_ph", "k_w", "load", "friction_cap", "perturbation", "kick", "dx_max", "t_max")


def validate(figure, fig_cfg, built) -> None:
    runs = fig_cfg.get("runs", {})
    check_scene_keys(figure, "runs", runs, built)
    missing = [n for n in built if n not in runs]
    if missing:
        raise ConfigError(f"figures.{figure}.runs: no run given for the scene(s) {', '.join(missing)}")
    events = [n for n in built if runs[n] == "event"]
    thr = [n for n in built if runs[n] == "fold_threshold"]
    if len(events) != 1 or len(thr) < 3:
        raise ConfigError(f"figures.{figure}.runs: needs exactly one event and at least three fold_threshold "
                          f"scenes, got {len(events)} and {len(thr)}")
    kfr = {built[n].k_fr for n in built}
    if len(kfr) != 1:
        raise ConfigError(f"figures.{figure}.scenes: all scenes need the same k_fr (got {sorted(kfr)})")
    if len({(built[n].R, built[n].L / built[n].R) for n in thr}) < 3 or len({built[n].R for n in thr}) < 2:
        raise ConfigError(f"figures.{figure}.scenes: the thresholds need at least three aspect ratios and two R")


def caption(figure, fig_cfg, built) -> str:
    runs = fig_cfg["runs"]
    ev = next(sc for n, sc in built.items() if runs[n] == "event")
    thr = [sc for n, sc in built.items() if runs[n] == "fold_threshold"]
    pts = ", ".join(f"L/R = {sc.L / sc.R:g} (R = {sc.R:g})" for sc in thr)
    paper = fig_cfg.get("paper_load")
    return (f"At too large a load the rod folds over instead of forming a helix: a rod of L/R = {ev.L / ev.R:g} "
            f"under {ev.load:g} EI/R^2, k_fr = {ev.k_fr:g}, from the straight start. (a) the fold starting "
            f"(last shape with L_z >= {START:g} L), (b) the U-bend (first shape with L_z < {FOLDED:g} L), (c) the "
            "end state; side views, z along the pore, x across it (wall at +-R), shaded by depth. "
            f"(d) Fold threshold times R^2/EI by bisection (fresh runs, L_z < L/2 or escape) for {pts}, "
            "beside the largest load a helix on the wall can carry, 4/(3 sqrt 3) EI/R^2"
            + (f", and the paper's load {paper:g} EI/R^2, at which the paper shows the event; the event is "
               "drawn at the load given here, which the build checks lies above the thresholds found" if paper else "")
            + ". The default pore geometry (entrance at the top of the unloaded rod, loaded end free inside the "
            "pore) contains the fold: the rod does not leave the pore.")


def _frames(L_z: np.ndarray, L: float) -> list[int]:
    if not L_z[-1] < FOLDED * L:
        raise ValueError(f"the event run did not fold (final L_z = {L_z[-1]:.4g} >= {FOLDED:g} L): its load lies "
                         "below the fold threshold; raise it above the thresholds found")
    start = int(np.flatnonzero(L_z >= START * L)[-1])
    folded = int(np.flatnonzero(L_z < FOLDED * L)[0])
    return [start, folded, len(L_z) - 1]


def build(fig_cfg, sims, context=None) -> xr.Dataset:
    runs = fig_cfg["runs"]
    ev_name = next(n for n in sims if runs[n] == "event")
    thr = [n for n in sims if runs[n] == "fold_threshold"]
    ev = sims[ev_name]
    L, R, EI, load = (float(ev.attrs[k]) for k in ("L", "R", "EI", "load"))
    frames = _frames(ev["snap_L_z"].values, L)
    data = {f"frame_{c}": variable(("frame", "link"), ev[f"snap_{c}"].values[frames], c) for c in "xyz"}
    data["frame_time"] = variable(("frame",), ev["snap_time"].values[frames], "time")
    data["frame_L_z"] = variable(("frame",), ev["snap_L_z"].values[frames], "L_z")
    scale = np.array([float(sims[n].attrs["R"]) ** 2 / float(sims[n].attrs["EI"]) for n in thr])
    lo = np.array([float(sims[n]["threshold_lo"].values[0]) for n in thr])
    hi = np.array([float(sims[n]["threshold_hi"].values[0]) for n in thr])
    if load * R**2 / EI < (hi * scale).max():
        raise ValueError(f"event load {load * R**2 / EI:g} EI/R^2 lies below a fold threshold found "
                         f"({(hi * scale).max():.4g} EI/R^2); raise it")
    data["threshold_lo"] = variable(("aspect",), lo, "threshold_lo")
    data["threshold_hi"] = variable(("aspect",), hi, "threshold_hi")
    data["threshold_R2_over_EI"] = variable(("aspect",), scale, "R2_over_EI")
    data["aspect_R"] = variable(("aspect",), [float(sims[n].attrs["R"]) for n in thr], "R")
    data["aspect_scene"] = scene_coord("aspect", thr)
    coords = {"frame": variable(("frame",), np.array(["a", "b", "c"], dtype=object), "frame"),
              "aspect": variable(("aspect",), [float(sims[n].attrs["L"]) / float(sims[n].attrs["R"]) for n in thr],
                                 "aspect"),
              "s_link": variable(("link",), ev["s_link"].values, "s_link")}
    ds = xr.Dataset(data, coords=coords)
    ds.attrs.update({"event_load": load, "event_L": L, "event_R": R, "event_escaped": int(ev["escaped"]),
                     "helix_limit": theory.helix_load_limit(1.0, 1.0),
                     "paper_load": float(fig_cfg.get("paper_load", 0.0)),
                     "fold_threshold_range": [float((lo * scale).min()), float((hi * scale).max())]})
    return ds


def plot(ds: xr.Dataset):
    from matplotlib.gridspec import GridSpec

    R = float(ds.attrs["event_R"])
    L = float(ds.attrs["event_L"])
    fig = P.plt.figure(figsize=(7.2, 6.8))
    gs = GridSpec(4, 1, figure=fig, height_ratios=[1, 1, 1, 2.0], hspace=0.8)
    titles = {"a": "the fold starting", "b": "the U-bend", "c": "end state"}
    for i, f in enumerate(ds["frame"].values):
        ax = fig.add_subplot(gs[i, 0])
        x, y, z = (ds[f"frame_{c}"].values[i] for c in "xyz")
        side_strip(ax, x, y, z, R, -R, L + R, lw=1.6)
        ax.set_title(f"({f}) {titles[f]}: $t = {float(ds.frame_time.values[i]):.4g}$, "
                     rf"$L_z = {float(ds.frame_L_z.values[i]):.1f}\,R$", fontsize=8.5, loc="left")
        if i == 2:
            ax.set_xlabel(r"$z$ [$R$]")
    bx = fig.add_subplot(gs[3, 0])
    a = ds["aspect"].values
    s = ds["threshold_R2_over_EI"].values
    lo, hi = ds.threshold_lo.values * s, ds.threshold_hi.values * s
    for Rv, mk in zip(sorted(set(ds.aspect_R.values)), ("o", "s", "D")):
        m = ds.aspect_R.values == Rv
        bx.errorbar(a[m], 0.5 * (lo[m] + hi[m]), yerr=0.5 * (hi[m] - lo[m]), fmt=mk, color="black", ms=5,
                    mfc="white" if mk != "o" else "black", capsize=2, label=f"fold threshold, $R = {Rv:g}$")
    bx.axhline(ds.attrs["helix_limit"], **P.MODEL, label=r"largest helix load $4/(3\sqrt{3})\,EI/R^2$")
    if ds.attrs["paper_load"]:
        bx.axhline(ds.attrs["paper_load"], **P.PAPER, label="the paper's load of the event")
    bx.plot([L / R], [ds.attrs["event_load"] * R**2], "*", color="tab:red", ms=10, label="the run drawn above")
    bx.set_xscale("log")
    P.plain_log_ticks(bx.xaxis)
    bx.set_ylim(0.3, 1.2)
    bx.set_xlabel(label("aspect"))
    bx.set_ylabel(r"load $\times\ R^2/EI$")
    bx.set_title("(d) fold threshold against L/R", fontsize=8.5, loc="left")
    bx.legend(fontsize=7, ncol=2, loc="upper left")
    return fig
