"""Kind ``escape`` (paper Fig 8): at too large a load the rod folds over (U-bend) or a
loop of it leaves the pore instead of forming a helix; the thresholds against L/R, R and
the pore entrance.

The pore entrance (docs/model.md, 'Fig 8').  With the entrance at the top of the unloaded
rod (the default) the loaded end is inside the pore, and the rod can only fold inside it.
For a loop to leave, rod must lie above the entrance; a free loaded end up there tips over
the rim at any load, an artefact.  So the open entrance is modelled as the paper's pore with
a pusher: the loaded end slides in a guide of radius R (``ends: guided``), a free span
g = L - pore_length above the entrance, and the solid around the pore (its wall and its
frictionless top face) below it.  "Escape" is a link end above the entrance more than
0.1 R outside the pore's radius.

Scenes are run by the rule ``load_path``: ``fold_threshold`` scenes find the load above
which a fresh run folds (L_z < L/2) or escapes, by bisection (confined_rod.sim.load_paths.fold_threshold,
which records which of the two happened just above it); the one ``event`` scene is a run
with shapes at doubling simulated times, followed past an escape (confined_rod.sim.load_paths.event).
The frames are picked by what the rod does: for an escape (a) the last shape before the
loop crosses the pore radius, (b) the loop out at the entrance, (c) the end of the run; for
a fold (a) the last shape with L_z >= 0.8 L, (b) the first with L_z < L/2, (c) the end state.
Thresholds are drawn in units of EI/R^2 against L/R for two R (the paper's 1/R^2 claim is
read off directly) and against the free span g/R, beside Euler's load of the span
pi^2 EI/g^2, the largest load a helix on the wall can carry, 4/(3 sqrt 3) EI/R^2, and the
paper's load.
"""
from __future__ import annotations

import numpy as np
import xarray as xr

from ... import theory
from ...errors import ConfigError
from ...limits import ESCAPE_RADIUS
from .. import plotting as P
from ..error_budget import Headline, euler_discretisation
from ..figure_quantities import label, variable
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
START, FOLDED = 0.8, 0.5  # L_z/L of the fold's frames (a) and (b)
VIEW = 24.0  # R: the frames show the top of the pore, this far below the entrance, and what is above it


def path_spec(fig_cfg, scene: str) -> dict:
    return {"run": fig_cfg["runs"][scene], "precision": float(fig_cfg.get("precision", 1e-2))}


def varied(fig_cfg) -> tuple[str, ...]:
    return ("L", "R", "l0", "k_ph", "k_w", "load", "friction_cap", "perturbation", "kick", "dx_max", "t_max",
            "pore_length", "ends")


def validate(figure, fig_cfg, built) -> None:
    runs = fig_cfg.get("runs", {})
    check_scene_keys(figure, "runs", runs, built)
    missing = [n for n in built if n not in runs]
    if missing:
        raise ConfigError(f"figures.{figure}.runs: no run given for the scene(s) {', '.join(missing)}")
    for n, sc in built.items():
        if sc.free_span() > 0 and sc.ends != "guided":
            raise ConfigError(f"figures.{figure}.scenes.{n}: pore_length = {sc.pore_length:g} < L = {sc.L:g} "
                              f"with ends = {sc.ends!r}: the unguided loaded end above the entrance tips over the "
                              "rim at any load; use ends: guided (the pusher's guide)")
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


def _geometry(sc) -> str:
    g = sc.free_span() / sc.R
    return "entrance at the top of the rod" if g == 0 else f"guided end, free span g = {g:g} R"


def caption(figure, fig_cfg, built) -> str:
    runs = fig_cfg["runs"]
    ev = next(sc for n, sc in built.items() if runs[n] == "event")
    thr = [sc for n, sc in built.items() if runs[n] == "fold_threshold"]
    pts = "; ".join(f"L/R = {sc.L / sc.R:g}, R = {sc.R:g}, {_geometry(sc)}" for sc in thr)
    paper = fig_cfg.get("paper_load")
    closed = [sc for sc in thr if sc.free_span() == 0]
    text = "At too large a load the rod does not form a helix."
    if paper and closed:
        text += (f" The paper's escape (a U-bend leaving the cylinder at L/R = 320 under {paper:g} EI/R^2) is not "
                 "reproduced at the conditions it states: with the pore entrance at the top of the rod (the paper "
                 f"does not describe its entrance) {paper:g} EI/R^2 lies below the fold thresholds of the closed "
                 "entrance in (d), and below them the rods form helices inside the pore (docs/model.md, Fig 8). A "
                 "loop escapes only through an open entrance with a free span of rod above it, whose length we "
                 "chose.")
    at = f"the paper's load {paper:g} EI/R^2" if paper and abs(ev.load - paper) <= 1e-12 * paper else \
        f"{ev.load:g} EI/R^2"
    built_by_us = (" (our construction: the open entrance, the guide of the loaded end, a pusher in a sleeve, "
                   "and the span, chosen so that the load lies above the span's loop-out threshold in (e))"
                   if ev.free_span() > 0 else "")
    return text + (
        f" (a)-(c) Our constructed event, not the paper's result: a rod of L/R = {ev.L / ev.R:g} under {at}, "
        f"k_fr = {ev.k_fr:g}, from the straight start, {_geometry(ev)}{built_by_us}. For a loop that leaves the "
        f"pore (a) the last shape before it crosses the pore radius above the entrance, (b) the loop out of the "
        f"pore (a link end {ESCAPE_RADIUS:g} R from the axis), (c) the end of the run, followed on to 4x the "
        "crossing time (its title says whether the loop is still out: an escape, or drawn back in: a transient); "
        f"for a fold (a) the last shape with L_z >= {START:g} L, (b) the first with L_z < {FOLDED:g} L, (c) the "
        f"end state. Side views of the top {VIEW:g} R of the pore, z along it, x across it (wall at +-R, the "
        "solid around the pore hatched), shaded by depth. (d) Threshold times R^2/EI by bisection (fresh runs; "
        "filled: a loop crossed the escape radius just above it, a run stopped there and not followed on; open: "
        "the rod folded inside the pore) against L/R, and (e) "
        f"against the free span g between the guided loaded end and the entrance, for {pts}; beside Euler's "
        "load of the span pi^2 EI/g^2 and the largest load a helix on the wall can carry, 4/(3 sqrt 3) EI/R^2"
        + (f", and the paper's load {paper:g} EI/R^2" if paper else "")
        + ". The paper's frames show the upper half of the pore; here its top only, where the event happens.")


def escape_outcome(ev: xr.Dataset, R: float) -> tuple[bool, bool, float]:
    """Of an event run: (a loop crossed the escape radius ESCAPE_RADIUS R above the entrance
    during the run, the rod is still out at the end of the run, the largest distance from the
    axis of a link end above the entrance over the run / R). Out at the end: the last
    snapshot's farthest link end above the entrance beyond the escape radius."""
    rho = np.asarray(ev["snap_outside_radius"].values, dtype=float) / R
    crossed = bool(int(ev["escaped"]))
    return crossed, bool(rho[-1] > ESCAPE_RADIUS), float(rho.max())


def _frames(ds: xr.Dataset, L: float) -> list[int]:
    if int(ds["escaped"]):
        rho = ds["snap_outside_radius"].values / float(ds.attrs["R"])
        out = int(np.flatnonzero(rho > ESCAPE_RADIUS - 1e-9)[0])
        before = np.flatnonzero(rho[:out] <= 1.0)
        return [int(before[-1]) if before.size else 0, out, len(rho) - 1]
    L_z = ds["snap_L_z"].values
    if not L_z[-1] < FOLDED * L:
        raise ValueError(f"the event run neither escaped nor folded (final L_z = {L_z[-1]:.4g} >= {FOLDED:g} L): "
                         "its load lies below the threshold; raise it above the thresholds found")
    start = int(np.flatnonzero(L_z >= START * L)[-1])
    folded = int(np.flatnonzero(L_z < FOLDED * L)[0])
    return [start, folded, len(L_z) - 1]


def build(fig_cfg, sims, context=None) -> xr.Dataset:
    runs = fig_cfg["runs"]
    ev_name = next(n for n in sims if runs[n] == "event")
    thr = [n for n in sims if runs[n] == "fold_threshold"]
    ev = sims[ev_name]
    L, R, EI, load = (float(ev.attrs[k]) for k in ("L", "R", "EI", "load"))
    frames = _frames(ev, L)
    data = {f"frame_{c}": variable(("frame", "s_link"), ev[f"snap_{c}"].values[frames], c) for c in "xyz"}
    data["frame_time"] = variable(("frame",), ev["snap_time"].values[frames], "t")
    data["frame_L_z"] = variable(("frame",), ev["snap_L_z"].values[frames], "L_z")
    data["frame_outside_radius"] = variable(("frame",), ev["snap_outside_radius"].values[frames], "outside_radius")
    R_thr = np.array([float(sims[n].attrs["R"]) for n in thr])
    scale = R_thr**2 / np.array([float(sims[n].attrs["EI"]) for n in thr])
    lo = np.array([float(sims[n]["threshold_lo"].values[0]) for n in thr])
    hi = np.array([float(sims[n]["threshold_hi"].values[0]) for n in thr])
    data["threshold_lo"] = variable(("aspect",), lo, "threshold_lo")
    data["threshold_hi"] = variable(("aspect",), hi, "threshold_hi")
    data["threshold_R2_over_EI"] = variable(("aspect",), scale, "R2_over_EI")
    data["escaped_above"] = variable(("aspect",), np.array([int(sims[n]["escaped_above"].values[0]) for n in thr],
                                                           dtype=np.int8), "escaped_above")
    data["aspect_R"] = variable(("aspect",), R_thr, "R")
    data["free_span"] = variable(("aspect",), [float(sims[n].attrs["free_span"]) for n in thr], "free_span")
    data["aspect_scene"] = scene_coord("aspect", thr)
    data["aspect_l0"] = variable(("aspect",), [float(sims[n].attrs["l0"]) / float(sims[n].attrs["R"]) for n in thr],
                                 "l0_over_R")
    coords = {"frame": variable(("frame",), np.array(["a", "b", "c"], dtype=object), "frame"),
              "aspect": variable(("aspect",), [float(sims[n].attrs["L"]) / float(sims[n].attrs["R"]) for n in thr],
                                 "aspect"),
              "s_link": variable(("s_link",), ev["s_link"].values, "s_link")}
    ds = xr.Dataset(data, coords=coords)
    closed = data["free_span"].values == 0
    crossed, out_end, rho_max = escape_outcome(ev, R)
    ds.attrs.update({"event_load": load, "event_L": L, "event_R": R,
                     # an escape: a loop crossed the escape radius and the rod is still out at the end
                     # of the run (followed on to FOLLOW_ESCAPE x the crossing time); a loop drawn
                     # back in is a transient, not an escape
                     "event_escaped": int(crossed and out_end), "event_loop_crossed": int(crossed),
                     "event_max_outside_radius": rho_max,
                     "event_final_outside_radius": float(ev["snap_outside_radius"].values[-1]) / R,
                     "event_final_L_z": float(ev["snap_L_z"].values[-1]),
                     "event_escape_radius": ESCAPE_RADIUS,
                     "event_pore_length": float(ev.attrs["pore_length"]),
                     "event_free_span": float(ev.attrs["free_span"]),
                     "helix_limit": theory.helix_load_limit(1.0, 1.0),
                     "paper_load": float(fig_cfg.get("paper_load", 0.0)),
                     "fold_threshold_range": ([float((lo * scale)[closed].min()), float((hi * scale)[closed].max())]
                                              if closed.any() else "none")})
    # what the caption says: the paper's load lies below every fold threshold of the closed entrance
    paper = float(fig_cfg.get("paper_load", 0.0))
    below = bool(closed.any()) and 0 < paper < float((lo * scale)[closed].min())
    ds.attrs["paper_load_below_fold_thresholds"] = int(below)
    return ds


def headlines(figure: str, ds: xr.Dataset) -> list[Headline]:
    """The error budget's numbers: each fold or loop-out threshold in units of EI/R^2, with the
    bisection's bracket as its bias and, for an escape through a free span g, the discretisation
    of the span's Euler load; one frictional seed, so no statistical error. A rod repeated in
    other units (R = 2) is counted once."""
    out, seen = [], set()
    folds = {}          # the fold threshold's bracket per rod (L/R, l0/R), in EI/R^2
    for i, aspect in enumerate(ds["aspect"].values):
        if float(ds["free_span"].values[i]) == 0.0:
            scale = float(ds["threshold_R2_over_EI"].values[i])
            folds[(float(aspect), float(ds["aspect_l0"].values[i]))] = (float(ds["threshold_lo"].values[i]) * scale,
                                                                        float(ds["threshold_hi"].values[i]) * scale)
    for i, aspect in enumerate(ds["aspect"].values):
        lo, hi = float(ds["threshold_lo"].values[i]), float(ds["threshold_hi"].values[i])
        scale = float(ds["threshold_R2_over_EI"].values[i])
        span = float(ds["free_span"].values[i]) / float(ds["aspect_R"].values[i])
        rod = (float(aspect), span, float(ds["aspect_l0"].values[i]))
        if rod in seen:         # the same rod in other units (R = 2): a units check, counted once
            continue
        seen.add(rod)
        scene = str(ds["aspect_scene"].values[i])
        terms = {"bracket": ((hi - lo) / (hi + lo), "half the bisection's bracket")}
        fold = folds.get((float(aspect), float(ds["aspect_l0"].values[i])))
        # a span whose escape brackets overlap the fold's: the rod folds before the span buckles, so
        # the span's Euler load does not set the number
        folds_first = span > 0 and fold is not None and lo * scale <= fold[1] and hi * scale >= fold[0]
        if span > 0 and not folds_first:
            terms["discretisation"] = (euler_discretisation(float(ds["aspect_l0"].values[i]), span),
                                       "Euler load of the discrete free span (theory)")
        what = (f"loop-out threshold, span g/R = {span:g}" + (" (folds first)" if folds_first else "")
                if span > 0 else "fold threshold")
        out.append(Headline(f"{figure}.threshold.{scene}", figure, f"{what} [EI/R^2], L/R = {aspect:g} ({scene})",
                            0.5 * (lo + hi) * scale, None, 1, "threshold", float(aspect), 0.5 * (lo + hi),
                            float(ds.attrs.get("k_fr", 0.0)), terms=terms,
                            note="bisection of one frictional seed: seed spread not measured"))
    return out


def _strip(ax, ds, i, R, L, top):
    x, y, z = (ds[f"frame_{c}"].values[i] for c in "xyz")
    side_strip(ax, x, y, z, R, top - VIEW * R, max(L, float(z.max())) + R, lw=1.6,
               entrance=top if ds.attrs["event_free_span"] > 0 else None)


def plot(ds: xr.Dataset):
    from matplotlib.gridspec import GridSpec

    R, L, top = (float(ds.attrs[k]) for k in ("event_R", "event_L", "event_pore_length"))
    escaped = bool(ds.attrs["event_loop_crossed"])
    fig = P.plt.figure(figsize=(7.0, 5.6))
    gs = GridSpec(4, 2, figure=fig, height_ratios=[1, 1, 1, 2.6], hspace=0.9, wspace=0.32,
                  bottom=0.2, top=0.96, left=0.09, right=0.98)
    back = escaped and not bool(ds.attrs["event_escaped"])
    titles = ({"a": "our constructed event: the span bowing", "b": "a loop out of the pore",
               "c": "end of the run" + (", the loop drawn back in" if back else ", the loop still out")} if escaped
              else {"a": "our constructed event: the fold starting", "b": "the U-bend", "c": "end state"})
    for i, f in enumerate(ds["frame"].values):
        ax = fig.add_subplot(gs[i, :])
        _strip(ax, ds, i, R, L, top)
        ax.set_title(f"({f}) {titles[f]}: $t = {float(ds.frame_time.values[i]):.4g}$, "
                     rf"$L_z = {float(ds.frame_L_z.values[i]):.1f}\,R$, "
                     rf"$\rho_{{out}} = {float(ds.frame_outside_radius.values[i]):.2f}\,R$", fontsize=8.5, loc="left")
        if i == 2:
            ax.set_xlabel(r"$z$ [$R$]")
    s = ds["threshold_R2_over_EI"].values
    mid = 0.5 * (ds.threshold_lo.values + ds.threshold_hi.values) * s
    err = 0.5 * (ds.threshold_hi.values - ds.threshold_lo.values) * s
    g = ds["free_span"].values / ds["aspect_R"].values
    esc = ds["escaped_above"].values.astype(bool)
    g_ev = ds.attrs["event_free_span"] / R

    def points(ax, xv, m, mk, lab):
        for e, fill in ((True, "black"), (False, "white")):
            k = m & (esc == e)
            if k.any():
                ax.errorbar(xv[k], mid[k], yerr=err[k], fmt=mk, color="black", mfc=fill, ms=5, capsize=2,
                            label=lab + (", loop out" if e else ", fold"))

    bx = fig.add_subplot(gs[3, 0])
    a = ds["aspect"].values
    for (gv, Rv), mk in zip(sorted({(gi, Ri) for gi, Ri in zip(g, ds.aspect_R.values)
                                    if gi == 0 or np.isclose(gi, g_ev)}), "osD^v<>"):
        m = np.isclose(g, gv) & (ds.aspect_R.values == Rv)
        points(bx, a, m, mk, f"$g={gv:g}R$, $R={Rv:g}$")
    bx.axhline(ds.attrs["helix_limit"], **P.MODEL, label=r"largest helix load $4/(3\sqrt{3})$")
    if g_ev > 0:
        bx.axhline(np.pi**2 / g_ev**2, color="tab:green", ls="--", lw=1.1, label=rf"$\pi^2 EI/g^2$, $g = {g_ev:g}R$")
    if ds.attrs["paper_load"]:
        bx.axhline(ds.attrs["paper_load"], **P.PAPER, label="the paper's load")
    bx.plot([L / R], [ds.attrs["event_load"] * R**2], "*", color="tab:red", ms=10, label="(a)-(c), our construction")
    bx.set_xscale("log")
    P.plain_log_ticks(bx.xaxis)
    bx.set_ylim(0.2, 1.6)
    bx.set_xlabel(label("aspect"))
    bx.set_ylabel(r"threshold $\times\ R^2/EI$")
    bx.set_title("(d) against L/R", fontsize=8.5, loc="left")

    cx = fig.add_subplot(gs[3, 1])
    scan = g > 0
    if scan.any():
        aspect = a[scan][np.argmax(np.bincount(np.unique(a[scan], return_inverse=True)[1]))]
        m = np.isclose(a, aspect) & (ds.aspect_R.values == R)
        points(cx, g, m & scan, "^", f"$L/R = {aspect:g}$")
        gg = np.geomspace(0.7 * g[scan].min(), 1.4 * g[scan].max(), 100)
        cx.plot(gg, np.pi**2 / gg**2, color="tab:green", ls="--", lw=1.1, label=r"$\pi^2 EI/g^2$")
        fold = m & (g == 0)
        if fold.any():
            cx.axhspan((mid - err)[fold].min(), (mid + err)[fold].max(), color="0.8", label="fold threshold, $g = 0$")
        cx.axhline(ds.attrs["helix_limit"], **P.MODEL)
        if ds.attrs["paper_load"]:
            cx.axhline(ds.attrs["paper_load"], **P.PAPER)
        cx.set_xscale("log")
        cx.set_yscale("log")
        P.plain_log_ticks(cx.xaxis)
    cx.set_xlabel(r"free span $g$ [$R$]")
    cx.set_ylabel(r"threshold $\times\ R^2/EI$")
    cx.set_title("(e) against the free span", fontsize=8.5, loc="left")
    # one legend for (d) and (e), below them: inside the panels it covered their points
    handles, labels = P.legend_entries((bx, cx))
    fig.legend(handles, labels, loc="lower center", ncol=3, fontsize=P.SMALL, bbox_to_anchor=(0.5, 0.0),
               columnspacing=1.2, handletextpad=0.4)
    return fig
