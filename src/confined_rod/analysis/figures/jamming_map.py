"""Kind ``jamming_map``: the transmitted fraction |F_z(L)|/|F_z(0)| over rod length, load and
friction, and the length at which it first falls below one half.

The paper says an aspect ratio "of the order of 100 or more" is needed for a significant
reduction of the force (its Discussion). This kind turns that into a measured curve. Its
``grid`` (lists of L, load and k_fr) becomes one scene per point (``L<L>-F<load>-k<k_fr>``),
each optionally a seed ensemble (``seeds:``). The dataset holds the fraction at every point
(the ensemble mean, its standard deviation and the per-seed values where seeds are given),
the final state's winding, and the corrected simple model beside it:
F(L)/F(0) = 1/(1 + k_fr R L F0/(4EI)), which falls to 1/2 at L_half = 4EI/(k_fr R F0). It
also holds the measured L_half(load, k_fr) (measure.half_reduction_length; a bound where the
grid does not bracket it) and the largest load a helix on the wall can carry,
4/(3 sqrt 3) EI/R^2. Where the config names a Fig 8 figure (``thresholds``, kind escape),
it holds that figure's measured loads above which the rod folds (closed entrance) or a loop
escapes (open entrance) instead of forming a helix, against L/R: the map's upper boundary,
drawn in the last panel, the (L/R, load) plane, beside the measured and modelled L_half.
"""
from __future__ import annotations

import numpy as np
import xarray as xr
from matplotlib.lines import Line2D

from ... import layout, theory
from ...errors import ConfigError
from .. import ensembles
from .. import plotting as P
from ..figure_quantities import attrs, label, variable
from ..measure import half_reduction_length, n_turns

ENSEMBLES = True
#: the ensemble means this kind reports (F(L)/F0 per point of the map), named as the
#: convergence ladders compare them: a ladder that ``serves`` one of its scenes decides on these
REPORTS = ("F_transmitted",)
AXES = ("L", "load", "k_fr")
OPTIONS = {
    "grid": {"type": "object", "additionalProperties": False, "required": list(AXES),
             "properties": {k: {"type": "array", "minItems": 1, "items": {"type": "number", "exclusiveMinimum": 0},
                                "uniqueItems": True} for k in AXES},
             "description": "the map's axes: rod lengths L [R], loads |F_z(0)| [EI/R^2] and friction coefficients "
                            "k_fr; one scene per combination"},
    "thresholds": {"type": "string", "description": "a figure of kind escape (Fig 8) whose measured fold/escape "
                   "thresholds draw the map's upper boundary (its dataset is read, not rerun)"},
}
READS = {"thresholds": ("escape",)}
HOW = ("interpolated", "upper bound", "lower bound")


def _tag(v: float) -> str:
    return f"{v:g}".replace(".", "p").replace("-", "m").replace("+", "")


def expand_sweeps(fig_cfg: dict) -> None:
    """The grid becomes scenes, in place (idempotent): one per (L, load, k_fr)."""
    grid = fig_cfg.get("grid")
    if not grid:
        return
    for axis in AXES:
        tags: dict[str, object] = {}
        for v in grid.get(axis) or []:
            other = tags.setdefault(_tag(v), v)
            if other != v:
                raise ConfigError(f"grid.{axis}: {other!r} and {v!r} give the same scene name ({axis} "
                                  f"{_tag(v)!r}: names keep 6 significant digits); make them differ within those")
    scenes = fig_cfg.setdefault("scenes", {}) or {}
    done = {n.rsplit("-s", 1)[0] for n in scenes} | set(scenes)              # already expanded (seeds)
    for L in grid["L"]:
        for load in grid["load"]:
            for k in grid["k_fr"]:
                name = f"L{_tag(L)}-F{_tag(load)}-k{_tag(k)}"
                if name not in done:
                    scenes[name] = {"L": L, "load": load, "k_fr": k}
    fig_cfg["scenes"] = scenes


def varied(fig_cfg) -> tuple[str, ...]:
    return AXES + ("pore_length", "seed")


def validate(figure, fig_cfg, built) -> None:
    from ._common import same_except

    if not fig_cfg.get("grid"):
        raise ConfigError(f"figures.{figure}.grid: a jamming map needs a grid of L, load and k_fr")
    if len(fig_cfg["grid"]["L"]) < 2:
        raise ConfigError(f"figures.{figure}.grid.L: a jamming map needs at least 2 lengths, got "
                          f"{fig_cfg['grid']['L']}")
    same_except(figure, built, varied(fig_cfg), "a jamming map varies only L, the load and k_fr (and the seed)")


def caption(figure, fig_cfg, built) -> str:
    g = fig_cfg["grid"]
    n = len(built) / (len(g["L"]) * len(g["load"]) * len(g["k_fr"]))
    return ("Jamming map: transmitted fraction |F_z(L)|/|F_z(0)| against L/R = " + ", ".join(f"{v:g}" for v in g["L"])
            + " for loads " + ", ".join(f"{v:g}" for v in g["load"]) + " EI/R^2 (colours), one panel per k_fr = "
            + ", ".join(f"{v:g}" for v in g["k_fr"])
            + ("" if n <= 1 else f"; symbols the mean over {n:g} seeds, error bars one standard deviation")
            + f"; dashed: the corrected simple model 1/(1 + k_fr R L F0/(4EI)); {P.words(P.GUIDE)} line: one half. "
            "Last panel: the "
            "length L_half at which the fraction first falls below 1/2 against the load, measured (symbols; open: a "
            "bound, the grid does not bracket it) and from the simple model, 4EI/(k_fr R F0) (lines), in the "
            "(L/R, load) plane: left of the model's curve the rod passes more than half the load, right of it less "
            "(a measured L_half is only where the mean fraction first falls below 1/2 on the grid); dotted: "
            "4/(3 sqrt 3) EI/R^2, the largest load a helix on the wall can carry"
            + ("" if not fig_cfg.get("thresholds") else
               f"; {P.words(P.MARK)}: the loads above which the rod folds instead of coiling (closed entrance, as "
               f"the map's rods), measured in {fig_cfg['thresholds']} (bars: the bisection bracket), "
               f"{P.words(P.FOLDED)} above them; the "
               "open-entrance escape thresholds are in the dataset") + ".")


def build(fig_cfg, sims, context=None) -> xr.Dataset:
    g = {k: np.array(sorted(fig_cfg["grid"][k]), dtype=float) for k in AXES}
    first = next(iter(sims.values()))
    R, EI = float(first.attrs["R"]), float(first.attrs["EI"])
    members: dict[tuple, list[xr.Dataset]] = {}
    for d in sims.values():
        members.setdefault(tuple(float(d.attrs[k]) for k in AXES), []).append(d)
    shape = tuple(len(g[k]) for k in AXES)
    n_max = max(len(m) for m in members.values())
    frac = np.zeros(shape + (n_max,))
    has = np.zeros(shape + (n_max,), dtype=np.int8)
    turns = np.zeros(shape)
    converged = np.ones(shape, dtype=np.int8)
    escaped = np.zeros(shape, dtype=np.int8)
    for i, L in enumerate(g["L"]):
        for j, load in enumerate(g["load"]):
            for k, k_fr in enumerate(g["k_fr"]):
                ms = members.get((L, load, k_fr))
                if not ms:
                    raise ValueError(f"jamming map: no simulation at L = {L:g}, load = {load:g}, k_fr = {k_fr:g}")
                frac[i, j, k, :len(ms)] = [float(d["F_transmitted"]) / load for d in ms]
                has[i, j, k, :len(ms)] = 1
                turns[i, j, k] = np.mean([n_turns(d) for d in ms])
                converged[i, j, k] = min(int(d["converged"]) for d in ms)
                escaped[i, j, k] = max(int(d["escaped"]) for d in ms)
    stats = [[[ensembles.stats(frac[i, j, k, has[i, j, k] == 1]) for k in range(shape[2])]
              for j in range(shape[1])] for i in range(shape[0])]
    mean = np.array([[[s.mean for s in row] for row in plane] for plane in stats])
    std = np.array([[[s.std for s in row] for row in plane] for plane in stats])
    L_model = np.geomspace(0.8 * g["L"].min(), 1.25 * g["L"].max(), 200)
    model = np.array([[theory.force_decay(L_model, load, k, R, EI) / load for k in g["k_fr"]] for load in g["load"]])
    half = np.zeros(shape[1:])
    how = np.zeros(shape[1:], dtype=np.int8)
    for j in range(shape[1]):
        for k in range(shape[2]):
            v, h = half_reduction_length(g["L"], mean[:, j, k])
            half[j, k], how[j, k] = v, HOW.index(h)
    half_model = np.array([[-theory.critical_length(load, k, R, EI) for k in g["k_fr"]] for load in g["load"]])
    dims = AXES
    data = {
        "fraction": xr.Variable(dims, mean, attrs={**attrs("transmitted_fraction"),
                                                   "long_name": "transmitted fraction |F_z(L)|/|F_z(0)| (ensemble "
                                                                "mean where the point has several seeds)"}),
        "fraction_std": variable(dims, std, "fraction_std"),
        "fraction_member": variable(dims + ("member",), frac, "fraction_member"),
        "has_member": variable(dims + ("member",), has, "has_member"),
        "n_turns": variable(dims, turns, "n_turns"),
        "converged": variable(dims, converged, "converged"),
        "escaped": variable(dims, escaped, "escaped"),
        "fraction_model": variable(("load", "k_fr", "L_model"), model, "fraction_model"),
        "L_half": variable(("load", "k_fr"), half, "L_half"),
        "L_half_how": variable(("load", "k_fr"), how, "L_half_how"),
        "L_half_model": variable(("load", "k_fr"), half_model, "L_half_model"),
    }
    data["L_half_how"].attrs.update({"flag_values": np.arange(len(HOW), dtype=np.int8),
                                     "flag_meanings": " ".join(h.replace(" ", "_") for h in HOW)})
    coords = {"L": variable(("L",), g["L"], "L"), "load": variable(("load",), g["load"], "load"),
              "k_fr": variable(("k_fr",), g["k_fr"], "k_fr"), "L_model": variable(("L_model",), L_model, "L_model"),
              "member": variable(("member",), np.arange(n_max), "member")}
    ds = xr.Dataset(data, coords=coords)
    ds.attrs["helix_limit"] = theory.helix_load_limit(R, EI)
    if fig_cfg.get("thresholds"):
        ds = _with_boundary(ds, fig_cfg["thresholds"], (context or {}).get("datasets", {}))
    return ds


def _with_boundary(ds: xr.Dataset, name: str, datasets) -> xr.Dataset:
    """The fold/escape thresholds of the Fig 8 dataset `name`, in units of EI/R^2 against
    L/R: the loads above which a fresh run folds or escapes instead of forming a helix."""
    if name not in datasets:
        raise ValueError(f"jamming map: thresholds = {name!r}, but its dataset ({layout.dataset_path(name)}) was "
                         "not given to the builder")
    e = datasets[name]
    scale = e["threshold_R2_over_EI"].values
    B = ("boundary",)
    ds["boundary_load_lo"] = variable(B, e["threshold_lo"].values * scale, "boundary_load_lo")
    ds["boundary_load_hi"] = variable(B, e["threshold_hi"].values * scale, "boundary_load_hi")
    ds["boundary_escaped"] = variable(B, e["escaped_above"].values.astype(np.int8), "escaped_above")
    ds["boundary_free_span"] = variable(B, e["free_span"].values / e["aspect_R"].values, "boundary_free_span")
    ds = ds.assign_coords(boundary_aspect=variable(B, e["aspect"].values, "aspect"))
    ds.attrs.update({"boundary_source": f"{layout.dataset_path(name)} (threshold_lo, threshold_hi, escaped_above)",
                     "boundary_git_commit": str(e.attrs.get("git_commit", "unknown"))})
    return ds


def plot(ds: xr.Dataset):
    """One panel per k_fr and the map in the (L/R, load) plane, up to three panels a row at the text
    width (printed at its natural size); the legends below the panels (the map's in a free panel slot
    where the grid has one)."""
    k_frs = ds["k_fr"].values
    loads = ds["load"].values
    n = len(k_frs) + 1
    ncol = min(3, n)
    nrow = -(-n // ncol)
    fig, axes = P.plt.subplots(nrow, ncol, figsize=(P.TEXT_WIDTH_IN, 2.45 * nrow), squeeze=False,
                               label=ds.attrs["title"])
    flat = list(axes.ravel())
    colors = P.plt.get_cmap("viridis")(np.linspace(0.0, 0.85, len(loads)))
    L = ds["L"].values
    for ax, k in zip(flat, range(len(k_frs))):
        for j, c in enumerate(colors):
            f = ds["fraction"].values[:, j, k]
            ok = ds["converged"].values[:, j, k] == 1
            ax.errorbar(L, f, yerr=ds["fraction_std"].values[:, j, k], fmt="-", color=c, lw=0.8, capsize=2,
                        label=rf"$|F_z(0)| = {loads[j]:g}\,EI/R^2$")
            ax.plot(L[ok], f[ok], "o", ms=4, color=c)
            if (~ok).any():
                ax.plot(L[~ok], f[~ok], "o", ms=4, mfc="white", mec=c)
            ax.plot(ds["L_model"], ds["fraction_model"].values[j, k], "--", color=c, lw=1.0)
        ax.axhline(0.5, **P.GUIDE)
        P.log_axes(ax)
        ax.set_xlabel(label("L"))
        ax.set_ylabel(r"$|F_z(L)|/|F_z(0)|$")
        ax.set_title(rf"$k_{{fr}} = {k_frs[k]:g}$")
    plane = flat[n - 1]
    plane_handles, plane_labels = _plane(plane, ds)
    for ax in flat[n:]:
        ax.axis("off")
    handles, labels = flat[0].get_legend_handles_labels()
    handles += [Line2D([], [], ls="--", color="black", lw=1.0), Line2D([], [], **P.GUIDE)]
    labels += ["corrected simple model (dashed)", "one half"]
    if (ds["converged"].values != 1).any():
        handles.append(Line2D([], [], ls="", marker="o", ms=4, mfc="white", mec="black"))
        labels.append("open: not converged")
    fig.tight_layout()
    # below the panels (the saved figure's tight bounding box takes them in)
    left = flat[0].get_position().x0
    fig.legend(handles, labels, loc="upper left", bbox_to_anchor=(left, 0.0), ncol=2 if n > 2 else 1,
               fontsize=P.SMALL)
    if n < len(flat):
        flat[n].legend(plane_handles, plane_labels, loc="center right", bbox_to_anchor=(1.0, 0.5), fontsize=P.SMALL,
                       borderaxespad=0.0)
    else:
        fig.legend(plane_handles, plane_labels, loc="upper right", bbox_to_anchor=(plane.get_position().x1, 0.0),
                   fontsize=P.SMALL)
    return fig


def _plane(ax, ds: xr.Dataset) -> tuple[list, list]:
    """The map in the (L/R, load) plane: L_half(load) measured and modelled per k_fr, the
    helix limit, and (where the dataset has them) the measured fold/escape thresholds. Returns its
    legend's handles and labels."""
    loads = ds["load"].values
    markers = "osD^v"
    for k, k_fr in enumerate(ds["k_fr"].values):
        m = markers[k % len(markers)]
        half, how = ds["L_half"].values[:, k], ds["L_half_how"].values[:, k]
        exact = how == 0
        ax.plot(half[exact], loads[exact], m, color="black", ms=5,
                label=rf"$L_{{1/2}}$ measured, $k_{{fr}} = {k_fr:g}$")
        if (~exact).any():
            ax.plot(half[~exact], loads[~exact], m, mfc="white", mec="black", ms=5)
        for x, y, h in zip(half[~exact], loads[~exact], how[~exact]):   # arrow: where L_1/2 lies
            ax.annotate("", xy=(x * (0.75 if HOW[h] == "upper bound" else 1.33), y), xytext=(x, y),
                        arrowprops={"arrowstyle": "->", "lw": 0.8, "shrinkA": 4, "shrinkB": 0})
        F = np.geomspace(loads.min() / 2, loads.max() * 4, 50)
        L_half = -theory.critical_length(F, k_fr, float(ds.attrs.get("R", 1.0)), float(ds.attrs.get("EI", 1.0)))
        ax.plot(L_half, F, "--", color="tab:blue", lw=0.8 + 0.5 * k,
                label=rf"$L_{{1/2}} = 4EI/(k_{{fr}} R F_0)$, $k_{{fr}} = {k_fr:g}$")
    top = float(ds.attrs["helix_limit"])
    ax.axhline(top, color="0.3", lw=0.8, ls=":", label=r"helix limit $4/(3\sqrt{3})\,EI/R^2$")
    if "boundary_load_lo" in ds:
        a = ds["boundary_aspect"].values
        lo, hi = ds["boundary_load_lo"].values, ds["boundary_load_hi"].values
        closed = ds["boundary_free_span"].values == 0    # the map's rods: closed entrance, they can only fold
        if closed.any():
            ax.errorbar(a[closed], 0.5 * (lo + hi)[closed], yerr=0.5 * (hi - lo)[closed], fmt="v", **P.MARK,
                        ms=5, capsize=2, label="rod folds above (Fig 8)")
            order = np.argsort(a[closed])
            ax.fill_between(a[closed][order], lo[closed][order], 10 * top, **P.FOLDED, lw=0, zorder=0)
    P.log_axes(ax)
    ax.set_xlim(0.7 * float(ds["L"].min()), 1.6 * float(ds["L"].max()))
    ax.set_ylim(0.5 * loads.min(), 1.6 * top)
    ax.set_xlabel(label("L"))
    ax.set_ylabel(label("load"))
    ax.set_title(r"map: $L_{1/2}$ and the fold boundary")
    handles, labels = ax.get_legend_handles_labels()
    if (ds["L_half_how"].values != 0).any():
        handles.append(Line2D([], [], ls="", marker="o", ms=5, mfc="white", mec="black"))
        labels.append("open: a bound, the grid does not\nbracket $L_{1/2}$ (arrow: where it lies)")
    return handles, labels
