"""Kind ``transition`` (paper Fig 2): the planar confined state, its out-of-plane
instability, and the helix with a defect; over an ensemble of seeds.

Each scene is one seed of the same rod, run by the rule ``load_path`` as a transition
(confined_rod.sim.load_paths.transition: protocol planar_then_3d with shapes chosen by the run,
then the load reduced step by step).  The figure draws three shapes of the run of the
scene ``shown``: (a) the end of the planar stage, (b) the first shape of the second
stage whose out-of-plane size has reached half its final value (the instability
growing), (c) the final state with its defects (reversals of handedness between two
stretches of at least 3 links winding in opposite senses, measure.defects) marked;
and (d) the defects of every seed, in the final state and after each load reduction,
so the shown run is seen as typical or not, and the paper's claim that defects are
metastable "while the compressing force is not reduced" is tested.
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np
import xarray as xr

from ...errors import ConfigError, SceneError
from .. import plotting as P
from ..error_budget import Z95, Headline
from ..figure_quantities import variable
from ..measure import defects
from ._common import need_scenes, same_except, scene_coord
from .helix_views import side_strip

SOURCE = "path"
OPTIONS = {
    "shown": {"type": "string", "description": "scene id of the run whose shapes are drawn"},
    "reduced": {"type": "array", "items": {"type": "number", "exclusiveMinimum": 0, "exclusiveMaximum": 1},
                "description": "load fractions the final state is relaxed at in turn (continuation), to test "
                               "whether its defects survive a reduced load"},
}
MIN_DEFECT_LINKS = 3


def path_spec(fig_cfg, scene: str) -> dict:
    return {"run": "transition", "reduced": [float(f) for f in fig_cfg.get("reduced", [])]}


def varied(fig_cfg) -> tuple[str, ...]:
    return ("seed",)


def validate(figure, fig_cfg, built) -> None:
    same_except(figure, built, varied(fig_cfg), "a transition figure is an ensemble of seeds of one rod")
    need_scenes(figure, built, 3, "an ensemble of seeds")
    sc = next(iter(built.values()))
    if sc.protocol != "planar_then_3d":
        raise ConfigError(f"figures.{figure}: protocol {sc.protocol!r}; a transition runs planar_then_3d")
    shown = fig_cfg.get("shown")
    if shown not in built:
        raise ConfigError(f"figures.{figure}.shown: {shown!r} is not one of its scenes ({', '.join(built)})")
    for f in fig_cfg.get("reduced", []):
        try:
            dataclasses.replace(sc, load=sc.load * float(f))
        except SceneError as exc:
            raise ConfigError(f"figures.{figure}.reduced: fraction {f:g} makes an invalid scene: {exc}") from None


def caption(figure, fig_cfg, built) -> str:
    sc = next(iter(built.values()))
    seeds = ", ".join(str(s.seed) for s in built.values())
    red = ", ".join(f"{f:g}" for f in fig_cfg.get("reduced", [])) or "none"
    return (f"Planar confined state and its out-of-plane instability: a rod of L/R = {sc.L / sc.R:g} under the load "
            f"{sc.load:g} EI/R^2, k_fr = {sc.k_fr:g}, relaxed in the x-z plane, then kicked out of it by "
            f"{sc.kick:g} R (protocol planar_then_3d). (a) end of the planar stage; (b) the first shape of the "
            "second stage whose rms distance from its plane has reached half its final value; (c) the final "
            f"state, defects marked (reversals of handedness between stretches of >= {MIN_DEFECT_LINKS} links). "
            "Side views: z along the pore, x across it (wall at +-R), shaded by depth y. "
            f"(d) Defects of every seed ({seeds}; run '{fig_cfg['shown']}' drawn) in the final state and after "
            f"reducing the load to the fractions {red} of it in turn.")


def count(ds: xr.Dataset, i: int) -> np.ndarray:
    m = ds["in_stretch"].values[i] == 1
    return defects(ds["s_link"].values[m], ds["dphi_ds"].values[i][m], MIN_DEFECT_LINKS)


def build(fig_cfg, sims, context=None) -> xr.Dataset:
    names = list(sims)
    shown = sims[fig_cfg["shown"]]
    oop = shown["snap_out_of_plane"].values
    stage = shown["snap_stage"].values
    second = np.flatnonzero(stage == 1)
    final_oop = oop[second[-1]]
    grow = second[np.flatnonzero(oop[second] >= 0.5 * final_oop)[0]] if second.size else 0
    frames = [int(np.flatnonzero(stage == 0)[-1]), int(grow), int(second[-1]) if second.size else 0]
    data = {f"frame_{c}": variable(("frame", "s_link"), shown[f"snap_{c}"].values[frames], c) for c in "xyz"}
    data["frame_time"] = variable(("frame",), shown["snap_time"].values[frames], "t")
    data["frame_out_of_plane"] = variable(("frame",), oop[frames], "out_of_plane")
    s_def = count(shown, 0)
    # the defects of the drawn run's final state as a flag on the link nearest each (never an
    # empty variable; the positions are s_link where the flag is 1)
    near = np.zeros(shown.sizes["s_link"], dtype=np.int8)
    near[[int(np.argmin(np.abs(shown["s_link"].values - sd))) for sd in s_def]] = 1
    data["defect_at"] = variable(("s_link",), near, "defect_at")
    states = list(shown["state"].values)
    n_def = np.array([[count(sims[n], i).size for i in range(len(states))] for n in names], dtype=np.int32)
    data["n_defects"] = variable(("scene", "state"), n_def, "n_defects")
    data["state_load"] = variable(("state",), shown["state_load"].values, "load")
    data["ensemble_seed"] = variable(("scene",), np.array([int(sims[n].attrs["seed"]) for n in names],
                                                          dtype=np.int64), "seed")
    data["final_converged"] = variable(("scene",), np.array([sims[n]["converged"].values[0] for n in names],
                                                            dtype=np.int8), "converged")
    coords = {"frame": variable(("frame",), np.array(["a", "b", "c"], dtype=object), "frame"),
              "scene": scene_coord("scene", names),
              "state": variable(("state",), np.array(states, dtype=object), "state"),
              "s_link": variable(("s_link",), shown["s_link"].values, "s_link")}
    ds = xr.Dataset(data, coords=coords)
    with_def = int((n_def[:, 0] > 0).sum())
    ds.attrs.update({
        "shown": fig_cfg["shown"], "shown_defects": int(s_def.size),
        "seeds_with_defects": with_def, "seeds": len(names),
        "defects_per_state": [int(v) for v in n_def.sum(axis=0)],
        "seeds_with_defects_per_state": [int(v) for v in (n_def > 0).sum(axis=0)],
        "shown_is": ("typical" if (s_def.size > 0) == (with_def >= len(names) / 2) else "not typical")
        + f" ({with_def} of {len(names)} seeds end with a defect; the shown run has {s_def.size})",
    })
    return ds


def headlines(figure: str, ds: xr.Dataset) -> list[Headline]:
    """The error budget's number: the share k/n of seeds whose helix forms with a defect, with the
    Wilson 95 % score interval of a binomial share (never of zero width, unlike sqrt(p(1-p)/n) at
    k = 0 or n): its larger distance from k/n, over Z95, stands as the standard error."""
    n, k = int(ds.attrs["seeds"]), int(ds.attrs["seeds_with_defects"])
    if not n:
        return []
    lo, hi = wilson_interval(k, n)
    half = max(k / n - lo, hi - k / n)
    return [Headline(f"{figure}.defect_fraction", figure, "share of seeds ending with a defect", k / n,
                     half / Z95, n, "defect_fraction", float(ds.attrs.get("L", 0.0)),
                     float(ds.attrs.get("load", 0.0)), float(ds.attrs.get("k_fr", 0.0)),
                     note=f"binomial over seeds, Wilson 95 % interval [{lo:.3g}, {hi:.3g}]", dof=math.inf)]


def wilson_interval(k: int, n: int, z: float = Z95) -> tuple[float, float]:
    """The Wilson score interval of a binomial share k/n at the normal quantile z:
    (k + z^2/2 -+ z sqrt(k (n - k)/n + z^2/4)) / (n + z^2)."""
    if not 0 <= k <= n or n < 1:
        raise ValueError(f"wilson_interval: need 0 <= k <= n and n >= 1, got k = {k}, n = {n}")
    centre, half = k + z * z / 2.0, z * math.sqrt(k * (n - k) / n + z * z / 4.0)
    return max(0.0, (centre - half) / (n + z * z)), min(1.0, (centre + half) / (n + z * z))


def plot(ds: xr.Dataset):
    from matplotlib.gridspec import GridSpec

    R = float(ds.attrs.get("R", 1.0))
    # printed at its natural size: within the text width and plotting.MAX_HEIGHT_IN
    fig = P.plt.figure(figsize=(P.TEXT_WIDTH_IN, 6.2))
    gs = GridSpec(4, 1, figure=fig, height_ratios=[1, 1, 1, 1.6], hspace=0.75)
    titles = {"a": "planar state (end of the planar stage)", "b": "out-of-plane instability growing",
              "c": "final state"}
    for i, f in enumerate(ds["frame"].values):
        ax = fig.add_subplot(gs[i, 0])
        x, y, z = (ds[f"frame_{c}"].values[i] for c in "xyz")
        side_strip(ax, x, y, z, R, min(z.min(), 0) - R, z.max() + R)
        extra = ""
        if f == "c":
            for zd in z[ds["defect_at"].values == 1]:  # z of the link nearest each defect
                ax.axvline(zd, color="tab:red", lw=1.2, ls="--", zorder=5)
            extra = f", {ds.attrs['shown_defects']} defect(s) (red)"
        ax.set_title(f"({f}) {titles[f]}: $t = {float(ds.frame_time.values[i]):.4g}$, "
                     rf"$\delta_\perp = {float(ds.frame_out_of_plane.values[i]):.2f}\,R${extra}",
                     fontsize=8.5, loc="left")
        if i == 2:
            ax.set_xlabel(r"$z$ [$R$]")
    bx = fig.add_subplot(gs[3, 0])
    n = ds["n_defects"].values
    seeds = ds["ensemble_seed"].values
    states = list(ds["state"].values)
    w = 0.8 / len(states)
    colours = ["tab:red"] + [str(v) for v in np.linspace(0.35, 0.75, max(1, len(states) - 1))]
    for j, s in enumerate(states):
        lab = ("final state" if s == "final" else
               f"load reduced to {float(ds.state_load.values[j]):.3g} $EI/R^2$")
        bx.bar(np.arange(len(seeds)) + (j - (len(states) - 1) / 2) * w, n[:, j], width=w, color=colours[j],
               label=lab)
    shown = list(ds["scene"].values).index(ds.attrs["shown"])
    bx.annotate("drawn", (shown, n[shown].max() + 0.1), ha="center", fontsize=P.SMALL)
    bx.set_xticks(np.arange(len(seeds)), [str(s) for s in seeds])
    bx.set_xlabel("seed")
    bx.set_ylabel("defects")
    bx.set_ylim(0, max(1, n.max()) + 1)
    from matplotlib.ticker import MaxNLocator

    bx.yaxis.set_major_locator(MaxNLocator(integer=True))
    bx.set_title(f"(d) ensemble: the drawn run is {ds.attrs['shown_is']}", fontsize=8.5, loc="left")
    bx.legend(fontsize=P.SMALL, ncol=len(states), loc="upper right")
    return fig
