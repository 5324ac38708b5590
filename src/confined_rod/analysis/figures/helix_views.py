"""Kind ``helix_views`` (paper Fig 1): confined rods drawn as tubes inside the pore.

Each scene is one rod (the paper: L/R = 20 and 640 at the same load). A short rod is shown
in a side view (x-z) and a view down the pore axis (x-y); a long rod is wrapped into
columns of ``column_length`` R (read left to right, the loaded end at the top left), so
the whole length stays legible. The tube is shaded by depth (y: pale at the back, dark in
front, drawn back to front) and the pore wall is drawn at x = +-R. End contacts that are
not part of the helix (the detached tips pushing on the wall) are marked.

The dataset stores each rod's link centres, contacts and wall forces (dimension
``link_<scene>``), and per scene: contacts, turns, the detached lengths at both ends, the
wall force of the tips, and the load / Euler-force ratio beside the paper's printed one.
"""
from __future__ import annotations

import numpy as np
import xarray as xr

from .. import ensembles
from .. import plotting as P
from ..figure_quantities import attrs, variable
from ..measure import euler_ratio, n_turns
from ._common import check_scene_keys, same_except, scene_coord

OPTIONS = {
    "paper_euler_ratio": {"type": "object", "additionalProperties": {"type": "number", "exclusiveMinimum": 0},
                          "description": "scene id -> the load / Euler force ratio printed in the paper's caption"},
    "column_length": {"type": "number", "exclusiveMinimum": 0,
                      "description": "length (R) of one column when a long rod is wrapped (default 40)"},
}
HELIX_RUN = 4  # links: a run of wall contacts at least this long is helix, shorter ones at an end are tips


def varied(fig_cfg) -> tuple[str, ...]:
    return ("L", "pore_length")


def validate(figure, fig_cfg, built) -> None:
    same_except(figure, built, varied(fig_cfg), "the rods of a helix-views figure differ only in L")
    check_scene_keys(figure, "paper_euler_ratio", fig_cfg.get("paper_euler_ratio"), built)


def caption(figure, fig_cfg, built) -> str:
    sc = next(iter(built.values()))
    Ls = " and ".join(f"{s.L:g}" for s in built.values())
    col = float(fig_cfg.get("column_length", 40))
    return (f"Confined rods of L/R = {Ls} under the load |F_z(0)| = {sc.load:g} EI/R^2, no torque at the ends, "
            f"k_fr = {sc.k_fr:g}, drawn as tubes in the pore (wall at x = +-R, {P.words(P.WALL)}), shaded by depth y "
            "(pale: back, dark: front). Short rods: side view (x-z) and view down the axis (x-y); long rods: "
            f"wrapped into columns of {col:g} R, loaded end at the top left. Red: wall contacts of the detached "
            "ends that are not part of the helix (the tips pushing on the wall). Load / Euler force "
            "pi^2 EI/L^2 in each panel, with the paper's printed ratio, and the rod's reversals of handedness "
            "if it has any. Friction: the paper's caption states none; we show frictionless "
            f"equilibria reached from the straight start (seed {sc.seed}). They are not unique: without friction "
            "too the final state depends on the start (Fig 2: frictionless seeds end with or without a reversal of "
            "handedness), so each rod is the equilibrium of its seed, one of several. With k_fr = 0.8 the state "
            "depends on the start further: the L/R = 20 rod started from seed 0 jams in a planar S-shape (Fig 6, "
            "its final-state class; docs/model.md).")


def _tips(contact: np.ndarray) -> np.ndarray:
    """1 for contacts in a run shorter than HELIX_RUN at either end of the rod (before the first or
    after the last long run), i.e. tips pushing on the wall, not helix."""
    tip = np.zeros_like(contact)
    idx = np.flatnonzero(contact)
    if idx.size == 0:
        return tip
    runs = np.split(idx, np.flatnonzero(np.diff(idx) > 1) + 1)
    long = [r for r in runs if r.size >= HELIX_RUN]
    if not long:
        return tip
    for r in runs:
        if r.size < HELIX_RUN and (r[-1] < long[0][0] or r[0] > long[-1][-1]):
            tip[r] = 1
    return tip


def build(fig_cfg, sims, context=None) -> xr.Dataset:
    names = sorted(sims, key=lambda n: float(sims[n].attrs["L"]))
    printed = fig_cfg.get("paper_euler_ratio") or {}
    data, coords = {}, {}
    per = {k: [] for k in ("n_contact", "n_turns", "euler_ratio", "detached_top", "detached_bottom",
                           "end_contact_force", "F_transmitted", "converged")}
    for n in names:
        d = sims[n]
        dim = f"link_{n}"
        contact = d["contact"].values.astype(np.int8)
        tip = _tips(contact)
        helix = np.flatnonzero(contact & (1 - tip))
        s_link = d["s_link"].values
        half = 0.5 * float(d.attrs["l0"])
        L = float(d.attrs["L"])
        coords[f"s_{n}"] = variable((dim,), s_link, "s_link")
        for k in ("x", "y", "z", "wall_force"):
            data[f"{k}_{n}"] = variable((dim,), d[k].values, k)
        data[f"contact_{n}"] = variable((dim,), contact, "contact")
        data[f"tip_{n}"] = xr.Variable((dim,), tip, attrs={"long_name": "wall contact of a detached end "
                                                           "(not helix)", "units": "1"})
        per["n_contact"].append(int(contact.sum()))
        per["n_turns"].append(n_turns(d))
        per["euler_ratio"].append(euler_ratio(d))
        per["detached_top"].append(float(s_link[helix[0]] - half) if helix.size else L)
        per["detached_bottom"].append(float(L - s_link[helix[-1]] - half) if helix.size else L)
        per["end_contact_force"].append(float(d["wall_force"].values[tip == 1].sum()))
        per["F_transmitted"].append(float(d["F_transmitted"]))
        per["converged"].append(np.int8(d["converged"]))
    for k, v in per.items():
        data[k] = variable(("scene",), v, k if k != "n_turns" else "n_turns_scene")
    data["end_contact_force"].attrs["long_name"] = "total wall force on the tips of the detached ends"
    # the final state from the whole rod's geometry: a frictionless rod is not necessarily one helix
    data["final_class"] = xr.Variable(
        ("scene",), np.array([ensembles.CLASSES.index(ensembles.final_class(sims[n])) for n in names], dtype=np.int8),
        attrs={"long_name": "final state from the geometry of the rod (ensembles.final_class)", "units": "1",
               "flag_values": np.arange(len(ensembles.CLASSES), dtype=np.int8),
               "flag_meanings": " ".join(ensembles.CLASSES)})
    data["n_reversals"] = xr.Variable(("scene",), np.array([ensembles.shape(sims[n]).reversals.size for n in names]),
                                      attrs={"long_name": "reversals of handedness along the rod (ensembles.shape)",
                                             "units": "1"})
    data["paper_euler_ratio"] = xr.Variable(("scene",), np.array([float(printed.get(n, 0.0)) for n in names]),
                                            attrs={**attrs("euler_ratio"), "long_name": "load / Euler force as "
                                                   "printed in the paper's caption (0: not printed)"})
    coords["scene"] = scene_coord("scene", names)
    coords["L"] = variable(("scene",), [float(sims[n].attrs["L"]) for n in names], "L")
    ds = xr.Dataset(data, coords=coords)
    ds.attrs["column_length"] = float(fig_cfg.get("column_length", 40.0))
    return ds


def _depth_cmap():
    from matplotlib.colors import ListedColormap

    return ListedColormap(P.plt.get_cmap("Blues")(np.linspace(0.18, 1.0, 256)))


_CMAP = _depth_cmap()


def _tube(ax, x, z, y, R, lw=2.4):
    """Rod through the points (x, z), shaded by depth y, drawn back to front with an outline."""
    from matplotlib import patheffects as pe
    from matplotlib.collections import LineCollection

    seg = np.stack([np.column_stack([x[:-1], z[:-1]]), np.column_stack([x[1:], z[1:]])], axis=1)
    depth = 0.5 * (y[:-1] + y[1:]) / R
    order = np.argsort(depth)
    lc = LineCollection(seg[order], array=depth[order], cmap=_CMAP, norm=P.plt.Normalize(-1.0, 1.0),
                        linewidths=lw, capstyle="round", zorder=3)
    lc.set_path_effects([pe.Stroke(linewidth=lw + 1.0, foreground="0.15"), pe.Normal()])
    ax.add_collection(lc)
    return lc


def side_strip(ax, x, y, z, R, z0, z1, lw=2.0, entrance=None) -> None:
    """A rod lying along the pore, drawn as a horizontal strip: z along the pore, x across
    it (wall at +-R), the tube shaded by depth y (Figs 2 and 8).  With ``entrance`` the
    pore ends there: the solid around it is hatched and open space lies beyond."""
    top = z1 if entrance is None else entrance
    half = max(1.35 * R, 1.1 * float(np.abs(x).max()))
    ax.fill_between([z0, top], -R, R, color="0.96", zorder=0, lw=0)
    for xw in (-R, R):
        ax.plot([z0, top], [xw, xw], **P.WALL, zorder=1)
    if entrance is not None:
        for sgn in (-1, 1):
            ax.fill_between([z0, entrance], sgn * R, sgn * half, facecolor="none", edgecolor="0.7", hatch="///",
                            lw=0, zorder=0)
    _tube(ax, z, x, y, R, lw=lw)
    ax.set_xlim(z0, z1)
    ax.set_ylim(-half, half)
    ax.set_yticks([-R, 0, R])
    ax.set_ylabel(r"$x$ [$R$]")


def _pore(ax, x0, z0, z1, R):
    ax.axvspan(x0 - R, x0 + R, ymin=0, ymax=1, color="0.96", zorder=0)
    for xw in (x0 - R, x0 + R):
        ax.plot([xw, xw], [z0, z1], **P.WALL, zorder=1)


def plot(ds: xr.Dataset):
    from matplotlib.gridspec import GridSpec

    names = list(ds["scene"].values)
    R = float(ds.attrs.get("R", 1.0))
    short = [n for n in names if float(ds["L"].sel(scene=n)) <= 3 * ds.attrs["column_length"]]
    long = [n for n in names if n not in short]
    fig = P.plt.figure(figsize=(7.0, 5.4), label=ds.attrs["title"])
    gs = GridSpec(2, 1 + len(long), figure=fig, width_ratios=[1] + [5] * len(long), height_ratios=[4, 1.3],
                  wspace=0.45)
    panel = iter("abcdefgh")
    lc = None

    def info(ax, n, loc):
        d = ds.sel(scene=n)
        r = float(d.euler_ratio)
        ratio = f"{r:,.{1 if r < 100 else 0}f}".replace(",", "{,}")  # thousands separator in mathtext
        k = int(d.n_reversals) if "n_reversals" in d else 0
        txt = (f"({next(panel)}) $L/R = {float(d.L):g}$\n$|F_z(0)|/F_{{crit}} = {ratio}$"
               + (f"\n(paper: {float(d.paper_euler_ratio):,g})" if float(d.paper_euler_ratio) else "")
               + (f"\n{k} reversal{'s' if k > 1 else ''} of handedness" if k else ""))
        ax.set_title(txt, fontsize=8, loc=loc)

    for n in short:  # side view and view down the axis
        ax = fig.add_subplot(gs[0, 0])
        x, y, z = (ds[f"{k}_{n}"].values for k in ("x", "y", "z"))
        _pore(ax, 0.0, z.min() - R, z.max() + R, R)
        lc = _tube(ax, x, z, y, R)
        tip = ds[f"tip_{n}"].values == 1
        ax.plot(x[tip], z[tip], "o", color="tab:red", ms=3.5, zorder=4)
        ax.set_aspect("equal")
        ax.set_xlim(-1.6 * R, 1.6 * R)
        ax.set_xticks([-R, R])
        ax.set_ylim(z.min() - R, z.max() + R)
        ax.set_xlabel("$x$ [$R$]")
        ax.set_ylabel("$z$ [$R$]")
        info(ax, n, "left")
        top = fig.add_subplot(gs[1, 0])
        th = np.linspace(0, 2 * np.pi, 200)
        top.fill(R * np.cos(th), R * np.sin(th), color="0.96", zorder=0)
        top.plot(R * np.cos(th), R * np.sin(th), **P.WALL)
        _tube(top, x, y, z / max(z.max(), 1e-12) * 2 - 1, R, lw=1.6)  # shade by height in the top view
        top.plot(x[tip], y[tip], "o", color="tab:red", ms=3, zorder=4)
        top.set_aspect("equal")
        top.set_xlim(-1.3 * R, 1.3 * R)
        top.set_xticks([-R, R])
        top.set_ylim(-1.3 * R, 1.3 * R)
        top.set_xlabel("$x$ [$R$]")
        top.set_ylabel("$y$ [$R$]")
        top.set_title("down the axis", fontsize=7, loc="left")

    for j, n in enumerate(long):  # wrapped side view
        ax = fig.add_subplot(gs[:, 1 + j])
        x, y, z = (ds[f"{k}_{n}"].values for k in ("x", "y", "z"))
        col = float(ds.attrs["column_length"])
        z_top = z.max() + 0.5
        ncol = int(np.ceil((z_top - z.min()) / col))
        step = 3.2 * R
        tip = ds[f"tip_{n}"].values == 1
        for k in range(ncol):
            hi, lo = z_top - k * col, z_top - (k + 1) * col
            m = (z <= hi + 0.6) & (z >= lo - 0.6)  # a little overlap so the columns join
            _pore(ax, k * step, -col, 0.0, R)
            if m.sum() >= 2:
                lc = _tube(ax, x[m] + k * step, z[m] - hi, y[m], R, lw=1.5)
            mt = m & tip
            ax.plot(x[mt] + k * step, z[mt] - hi, "o", color="tab:red", ms=3, zorder=4)
            ax.text(k * step, 1.0, f"{hi:.0f}", ha="center", va="bottom", fontsize=P.SMALL, color="0.3")
        ax.axvspan(-step, ncol * step, color="white", zorder=-1)
        ax.set_aspect("equal")
        ax.set_xlim(-0.6 * step, (ncol - 0.4) * step)
        ax.set_ylim(-col - 1, 4)
        ax.set_xticks([])
        ax.set_ylabel(r"$z - z_{top}$ [$R$]", labelpad=1)
        ax.set_xlabel(f"columns of {col:g} R, left to right (numbers: $z$ [$R$] at the column top)", fontsize=8)
        info(ax, n, "left")
    if lc is not None:
        cb = fig.colorbar(lc, ax=fig.axes, shrink=0.5, pad=0.02)
        cb.set_label("depth $y/R$ (side views)", fontsize=8)
    fig.suptitle(P.params_text(ds, ("load", "k_fr", "l0")) + ", no end torque", fontsize=9)
    return fig
