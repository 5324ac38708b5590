"""Figure style shared by every figure kind, and ``plot(ds, pdf, png)``.

``plot`` dispatches on ``ds.attrs['kind']`` to the kind's module in
:mod:`confined_rod.analysis.figures`; this module holds only what all of them share
(the rc style, line styles, log ticks, parameter text, atomic saving). Axis
labels and parameter symbols come from :mod:`confined_rod.quantities`.
"""
from __future__ import annotations

import textwrap
from pathlib import Path

import matplotlib.pyplot as plt
import matplotlib.ticker as ticker
import numpy as np
import xarray as xr

from ..io import atomic_write, check_finite
from .figure_quantities import param_text

#: Figures are drawn at the size they are printed at: the manuscript includes each at its natural
#: size (paper.figure_scale: scaled down only if wider than the text width, TEXT_WIDTH_IN, or taller
#: than MAX_HEIGHT_IN), and no text in it may be smaller than MIN_FONT_PT there
#: (tools/check_figure_text.py checks every figure of a config).
TEXT_WIDTH_IN = 7.0
MAX_HEIGHT_IN = 5.7
MIN_FONT_PT = 7.0
#: the size of small print (annotations, cell texts, dense legends): the smallest allowed
SMALL = MIN_FONT_PT
STYLE = {
    "font.family": "serif",
    "mathtext.fontset": "dejavuserif",
    "font.size": 9,
    "axes.labelsize": 9,
    "axes.titlesize": 9,
    "figure.titlesize": 9,
    "xtick.labelsize": 8.5,
    "ytick.labelsize": 8.5,
    "legend.fontsize": 8,
    "legend.frameon": False,
    "xtick.direction": "in",
    "ytick.direction": "in",
    "xtick.top": True,
    "ytick.right": True,
    "savefig.dpi": 200,
    "savefig.bbox": "tight",
}
# What a figure draws, by role: the kinds plot with these styles and their captions name them
# with words(style), so that a caption says what the figure shows.
SIM = dict(color="black")
FIT = dict(color="tab:red", lw=1.2)
MODEL = dict(color="tab:blue", ls="--", lw=1.2)
PAPER = dict(color="0.45", ls=":", lw=1.2)
#: the paper's printed fit, drawn beside ours
PAPER_FIT = dict(color="tab:orange", ls="-.", lw=1.3)
#: the single seeds of an ensemble (dots, thin lines)
SEEDS = dict(color="0.6")
#: eye guides and reference lines
GUIDE = dict(color="0.6", lw=0.7)
#: points singled out (a handedness reversal, a seed that ends in another state)
MARK = dict(color="tab:red")
#: the stretch of the rod on the wall
CONTACT = dict(color="0.93")
#: the pore's wall in a drawing of the rod
WALL = dict(color="0.55", lw=0.9)
#: the loads above which a rod folds instead of coiling (the jamming map's plane)
FOLDED = dict(color="0.88")
#: the range of |F_z(s)| over a panel's seeds
ENSEMBLE_BAND = dict(color="#b9d7ea")
#: the three regions of a loaded rod (analysis.regions), shaded
REGIONS = {"tip": dict(color="#f6d8b8"), "bulk": dict(color="#d5ecd4"), "lower": dict(color="#dcdcef")}
COLOR_WORDS = {"black": "black", "tab:red": "red", "tab:blue": "blue", "tab:orange": "orange", "tab:green": "green",
               "0.45": "grey", "0.55": "grey", "0.6": "grey", "0.88": "light grey", "0.93": "light grey",
               "#b9d7ea": "light blue", "#f6d8b8": "orange", "#d5ecd4": "green", "#dcdcef": "violet"}
LINE_WORDS = {"-": "", "--": "dashed", ":": "dotted", "-.": "dash-dotted"}

__all__ = ["plt", "np", "STYLE", "TEXT_WIDTH_IN", "MAX_HEIGHT_IN", "MIN_FONT_PT", "SMALL", "SIM", "FIT", "MODEL",
           "PAPER", "PAPER_FIT", "SEEDS", "GUIDE", "MARK", "CONTACT", "WALL", "FOLDED", "ENSEMBLE_BAND", "REGIONS",
           "words", "plot", "plain_log_ticks", "params_text", "bottom_legend"]


def words(style: dict) -> str:
    """How a caption names a style: 'black', 'blue dashed', 'grey dotted' (KeyError for a colour
    without words: add it to COLOR_WORDS)."""
    return " ".join(w for w in (COLOR_WORDS[style["color"]], LINE_WORDS[style.get("ls", "-")]) if w)


def plot(ds: xr.Dataset, pdf: str | Path, png: str | Path) -> None:
    from . import figures

    module = figures.get(ds.attrs["kind"])
    check_finite(ds, "plot")
    with plt.rc_context(STYLE):
        fig = module.plot(ds)
        mark_unsettled(fig, ds)
        _save(fig, pdf)
        _save(fig, png)
        plt.close(fig)


def mark_unsettled(fig, ds: xr.Dataset) -> None:
    """A figure says in red below its axes which of its runs are not at a stable equilibrium:
    those drawn (no verdict on them) and those left out of its statistics."""
    from .run_checks import flagged

    def listed(runs):
        return "; ".join(runs[:3]) + (f"; and {len(runs) - 3} more" if len(runs) > 3 else "")

    inside, out = flagged(ds.attrs.get("not_at_equilibrium")), flagged(ds.attrs.get("left_out"))
    parts = ([f"not at a stable equilibrium, drawn, no verdict on them: {listed(inside)}"] if inside else []) + (
        [f"not at a stable equilibrium, left out: {listed(out)}"] if out else [])
    if parts:
        # below everything else (the saved figure's tight bounding box takes it in)
        renderer, to_fig = fig.canvas.get_renderer(), fig.transFigure.inverted()
        lowest = min([ax.get_tightbbox(renderer).transformed(to_fig).y0 for ax in fig.axes]
                     + [text.get_window_extent(renderer).transformed(to_fig).y0 for text in fig.texts]
                     + [leg.get_window_extent(renderer).transformed(to_fig).y0 for leg in fig.legends] + [0.0])
        fig.text(0.01, lowest - 0.01, "\n".join(line for part in parts for line in textwrap.wrap(part, 110)),
                 color="red", fontsize=7, ha="left", va="top")


def _save(fig, path) -> None:
    """Atomic (io.atomic_write), so a failed job leaves nothing behind."""
    path = Path(path)
    fmt = path.suffix[1:]
    atomic_write(path, lambda tmp: fig.savefig(tmp, format=fmt, metadata={"Title": fig.get_label()}
                                               if fmt == "pdf" else None))


def plain_log_ticks(axis) -> None:
    """Log axis with ticks written as plain numbers (0.05, 20, ...): at 1, 2, 5 x 10^n,
    or at 1, 2, 3, 5 x 10^n when the axis spans less than a decade. Over several decades, or
    over more than one on an x axis whose plain labels are long (0.0002, 50000: six
    characters or more), only the decades are labelled, as powers of ten: side by side such
    labels overlap."""
    lo, hi = axis.get_view_interval()
    long_x = axis.axis_name == "x" and (lo < 1e-3 or hi > 1e4)
    if hi / lo > 300 or (long_x and hi / lo > 30):  # label the decades only, as powers of ten
        axis.set_major_locator(ticker.LogLocator(base=10))
        axis.set_major_formatter(ticker.LogFormatterSciNotation())
        axis.set_minor_locator(ticker.LogLocator(base=10, subs=np.arange(2, 10) * 1.0))
        axis.set_minor_formatter(ticker.NullFormatter())
        return
    subs = (1.0, 2.0, 5.0) if hi / lo > 10 else (1.0, 2.0, 3.0, 5.0)
    axis.set_major_locator(ticker.LogLocator(base=10, subs=subs))
    axis.set_major_formatter(ticker.FuncFormatter(lambda v, _: f"{v:g}"))
    axis.set_minor_locator(ticker.LogLocator(base=10, subs=np.arange(1, 10) * 1.0))
    axis.set_minor_formatter(ticker.NullFormatter())


def log_axes(ax) -> None:
    """Both axes logarithmic, with plain tick labels (plain_log_ticks)."""
    ax.set_xscale("log")
    ax.set_yscale("log")
    plain_log_ticks(ax.xaxis)
    plain_log_ticks(ax.yaxis)


def sci(x: float) -> str:
    """x as mathtext, a x 10^b (1.6 x 10^5; plain below 1000)."""
    if x == 0 or 1e-2 <= abs(x) < 1e3:
        return f"{x:.3g}"
    e = int(np.floor(np.log10(abs(x))))
    m = x / 10**e
    return (f"{m:.2g}" + r"\times" if abs(m - 1) > 0.05 else "") + f"10^{{{e}}}"


def params_text(ds: xr.Dataset, keys) -> str:
    """'$L = 320\\,R$, $|F_z(0)| = 0.25\\,EI/R^2$, ...' for the scene parameters among ``keys``
    that the dataset records (symbols and units from quantities.py)."""
    return ", ".join(param_text(k, float(ds.attrs[k])) for k in keys if k in ds.attrs)


def legend_entries(axes) -> tuple[list, list[str]]:
    """(handles, labels) of every axis, each label once, in the order first drawn: one legend
    for panels that share some curves (a curve may be in some panels only)."""
    handles, labels = [], []
    for ax in axes:
        for h, lab in zip(*ax.get_legend_handles_labels()):
            if lab not in labels:
                handles.append(h)
                labels.append(lab)
    return handles, labels


def bottom_legend(fig, ax, bottom: float = 0.07, ncol: int | None = None) -> None:
    """One legend for all panels, below them: the entries of ``ax`` and then those only another
    panel has (each label once)."""
    handles, labels = ax.get_legend_handles_labels()
    for other in fig.axes:
        for h, lab in zip(*other.get_legend_handles_labels()):
            if lab not in labels:
                handles.append(h)
                labels.append(lab)
    fig.legend(handles, labels, loc="lower center", ncol=ncol or len(labels), bbox_to_anchor=(0.5, -0.01))
    fig.tight_layout(rect=(0, bottom, 1, 1))
