"""Figures from the per-figure datasets (styling only: no physics here).

``plot(ds, pdf, png)`` dispatches on ``ds.attrs['kind']``.  Axis labels come
from :mod:`confined_rod.quantities`, so symbols and units are defined once.
"""
from __future__ import annotations

import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker as ticker  # noqa: E402
import numpy as np  # noqa: E402
import xarray as xr  # noqa: E402

from .io import check_finite  # noqa: E402
from .quantities import QUANTITIES, label  # noqa: E402

STYLE = {
    "font.family": "serif",
    "mathtext.fontset": "dejavuserif",
    "font.size": 10,
    "axes.labelsize": 10,
    "legend.fontsize": 8,
    "legend.frameon": False,
    "xtick.direction": "in",
    "ytick.direction": "in",
    "xtick.top": True,
    "ytick.right": True,
    "savefig.dpi": 200,
    "savefig.bbox": "tight",
}
SIM = dict(color="black")
FIT = dict(color="tab:red", lw=1.2)
MODEL = dict(color="tab:blue", ls="--", lw=1.2)
PAPER = dict(color="0.45", ls=":", lw=1.2)


def plot(ds: xr.Dataset, pdf: str | Path, png: str | Path) -> None:
    kind = ds.attrs["kind"]
    fn = {"transmitted_force": transmitted_force, "force_profile": force_profile,
          "convergence": convergence, "time_vs_error": time_vs_error, "stability_map": stability_map}.get(kind)
    if fn is None:
        raise ValueError(f"no plot for figure kind {kind!r}")
    check_finite(ds, "plot")
    with plt.rc_context(STYLE):
        fig = fn(ds)
        _save(fig, pdf)
        _save(fig, png)
        plt.close(fig)


def _save(fig, path) -> None:
    """Atomic: write a temporary file, then rename, so a failed job leaves nothing behind."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.stem}.{os.getpid()}.tmp{path.suffix}")
    try:
        fig.savefig(tmp, metadata={"Title": fig.get_label()} if path.suffix == ".pdf" else None)
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()


def _plain_log_ticks(axis) -> None:
    """Log axis with ticks written as plain numbers (0.05, 20, ...): at 1, 2, 5 x 10^n,
    or at 1, 2, 3, 5 x 10^n when the axis spans less than a decade."""
    lo, hi = axis.get_view_interval()
    if hi / lo > 300:  # several decades: label the decades only, as powers of ten
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


# symbols and units of the scene parameters named in titles
_SYM = {"load": r"|F_z(0)|", "k_fr": r"k_{fr}", "L": "L", "l0": "l_0", "seed": r"\mathrm{seed}",
        "friction_cap": r"f_{cap}", "k_ph": r"k_{ph}", "k_w": "k_w", "tol": r"\mathrm{tol}"}
_UNIT = {"load": r"\,EI/R^2", "L": r"\,R", "l0": r"\,R", "friction_cap": r"\,EI/R^3"}


def _params_text(ds: xr.Dataset, keys) -> str:
    return ", ".join(f"${_SYM[k]} = {float(ds.attrs[k]):g}{_UNIT.get(k, '')}$" for k in keys if k in ds.attrs)


def transmitted_force(ds: xr.Dataset):
    fig, ax = plt.subplots(figsize=(4.6, 3.4), label=ds.attrs["title"])
    L = ds["L"].values
    F = ds["F_transmitted"].values
    ok = ds["converged"].values == 1
    ax.plot(ds["L_model"], ds["F_simple"], **MODEL, label=r"simple model, $K = RF^2/(4EI)$")
    ax.plot(ds["L_model"], ds["F_simple_paper"], **PAPER, label=r"paper's Eq. (Fz-simple), $K = RF^2/(2EI)$")
    ax.plot(L, F, "-", color="0.6", lw=0.7, label="eye guide")
    ax.plot(L[ok], F[ok], "o", ms=5, **SIM, label="simulation")
    if (~ok).any():
        ax.plot(L[~ok], F[~ok], "o", ms=5, mfc="white", mec="black", label="simulation, not converged")
    ax.axhline(float(ds.attrs["load"]), color="0.7", lw=0.8)
    ax.annotate("load $|F_z(0)|$", (ds["L_model"].values[0], float(ds.attrs["load"])), xytext=(2, -10),
                textcoords="offset points", fontsize=8, color="0.4")
    ax.set_xscale("log")
    ax.set_yscale("log")
    _plain_log_ticks(ax.xaxis)
    _plain_log_ticks(ax.yaxis)
    ax.set_xlabel(label("L"))
    ax.set_ylabel(label("F_transmitted"))
    ax.set_title(_params_text(ds, ("load", "k_fr", "l0")), fontsize=9)
    # lower left is empty (every curve falls with L); "best" put the legend's
    # marker among the data, where it read as an extra point
    ax.legend(loc="lower left", fontsize=7.5)
    return fig


def force_profile(ds: xr.Dataset):
    n = ds.sizes["panel"]
    fig, axes = plt.subplots(1, n, figsize=(2.6 * n + 0.6, 3.3), sharey=True, squeeze=False,
                             label=ds.attrs["title"])
    s = ds["s"].values
    p = ds.attrs.get("panel_parameter", "none")
    for i, ax in enumerate(axes[0]):
        d = ds.isel(panel=i)
        w = d["in_fit"].values == 1
        ax.axvspan(float(d.s_h), float(d.s_end), color="0.95", zorder=0, lw=0, label="wall contact")
        ax.plot(s, d["F_abs"], lw=2.2, **SIM, label="simulation")
        ax.plot(s[w], d["F_fit"].values[w], **FIT, label=r"fit $A\,(l_0'+s)^c$")
        ax.plot(s, d["F_simple"], **MODEL, label=r"simple model, $K = RF^2/(4EI)$")
        ax.plot(s, d["F_simple_paper"], **PAPER, label=r"paper's form, $K = RF^2/(2EI)$")
        ax.text(0.04, 0.04,
                f"$A = {float(d.fit_A):.3g} \\pm {float(d.fit_A_err):.2g}$\n"
                f"$l_0' = {float(d.fit_l0):.3g} \\pm {float(d.fit_l0_err):.2g}\\,R$\n"
                f"$c = {float(d.fit_c):.3f} \\pm {float(d.fit_c_err):.3f}$",
                transform=ax.transAxes, ha="left", va="bottom", fontsize=7.5, color=FIT["color"])
        ax.set_yscale("log")
        _plain_log_ticks(ax.yaxis)
        ax.set_xlabel(label("s"))
        title = f"({chr(97 + i)})"
        if p != "none":
            title += f" ${_SYM.get(p, p)} = {float(d.panel_value):g}$"
        ax.set_title(title, fontsize=9, loc="left")
        ax.set_xlim(0, s[-1])
    axes[0][0].set_ylabel(label("F_abs"))
    fig.suptitle(_params_text(ds, ("L", "load", "k_fr", "l0")), fontsize=9)
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=len(labels), bbox_to_anchor=(0.5, -0.01))
    fig.tight_layout(rect=(0, 0.07, 1, 1))
    return fig



_H_LABEL = {"l0": r"$h = l_0$ [$R$]", "k_ph": r"$h = 1/k_{ph}$ [$R^2/EI$]", "k_w": r"$h = 1/k_w$ [$R^3/EI$]",
            "tol": r"$h = \mathrm{tol}$"}


def convergence(ds: xr.Dataset):
    """One panel per observable against the refinement variable h (log axis): the
    rungs, the Richardson limit, the tolerance band about it and the publication rung."""
    obs = [k for k in ("F_transmitted", "L_z", "pitch") if k in ds]
    fig, axes = plt.subplots(1, len(obs), figsize=(2.7 * len(obs) + 0.4, 3.0), squeeze=False,
                             label=ds.attrs["title"])
    h = ds["h"].values
    param = ds.attrs["parameter"]
    pub = np.isclose(ds["value"].values, float(ds.attrs["publication_value"]), rtol=1e-9)
    tol = float(ds.attrs["tolerance"])
    checked = list(ds["observable"].values)
    for ax, k in zip(axes[0], obs):
        f = ds[k].values
        ax.plot(h, f, "-", color="0.6", lw=0.7)
        ax.plot(h, f, "o", ms=4.5, **SIM, label="rungs")
        ax.plot(h[pub], f[pub], "s", ms=9, mfc="none", mec="tab:green", mew=1.4, label="publication setting")
        if k in checked:
            i = checked.index(k)
            lim = float(ds[f"{k}_limit"])
            ax.axhline(lim, **MODEL, label="Richardson limit")
            ax.axhspan(lim * (1 - tol), lim * (1 + tol), color="tab:blue", alpha=0.12, lw=0,
                       label=rf"limit $\pm$ {100 * tol:g} %")
            order = float(ds.observed_order[i])
            ax.text(0.04, 0.96, (f"$p = {order:.2f}$" if order > 0 else "$p$ not measurable") + "\n"
                    f"pub.: {100 * float(ds.publication_distance[i]):.2g} % off",
                    transform=ax.transAxes, va="top", fontsize=7.5)
        else:
            ax.text(0.04, 0.96, "not checked\n(not every rung is a helix)", transform=ax.transAxes,
                    va="top", fontsize=7.5)
        ax.set_xscale("log")
        _plain_log_ticks(ax.xaxis)
        ax.set_xlabel(_H_LABEL[param])
        ax.set_ylabel(label(k))
    status = ds.attrs["status"]
    short = status if len(status) < 70 else status[:67] + "..."
    fig.suptitle(f"convergence in ${_SYM.get(param, param)}$: {short}\n"
                 + _params_text(ds, ("L", "load", "k_fr")), fontsize=9)
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=len(labels), bbox_to_anchor=(0.5, -0.01))
    fig.tight_layout(rect=(0, 0.08, 1, 1))
    return fig


def time_vs_error(ds: xr.Dataset):
    """Wall time against error, log-log, one line per solver and link length."""
    fig, ax = plt.subplots(figsize=(4.8, 3.6), label=ds.attrs["title"])
    err = ds["error"].values
    wall = ds["wall_time"].values
    solver = ds["solver"].values
    l0 = ds["run_l0"].values
    knob = ds["run_knob"].values
    marker = {"implicit": "o", "explicit": "s"}
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    groups = sorted({(str(a), float(b)) for a, b in zip(solver, l0)})
    for j, (sv, lk) in enumerate(groups):
        m = (solver == sv) & np.isclose(l0, lk)
        order = np.argsort(knob[m])
        ax.plot(err[m][order], wall[m][order], marker=marker[sv], ms=5, color=colours[j % len(colours)],
                label=rf"{sv}, $l_0 = {lk:g}\,R$")
        # neighbouring rungs can nearly coincide: labels alternate above and below
        for n, (e, w, kv) in enumerate(zip(err[m][order], wall[m][order], knob[m][order])):
            ax.annotate(f"{kv:g}", (e, w), xytext=(4, 3 if n % 2 == 0 else -9), textcoords="offset points",
                        fontsize=6.5, color=colours[j % len(colours)])
    ax.set_xscale("log")
    ax.set_yscale("log")
    _plain_log_ticks(ax.yaxis)
    ax.set_xlabel(label("error"))
    ax.set_ylabel(label("wall_time", "s"))
    ax.set_title(_params_text(ds, ("L", "load", "k_fr")), fontsize=9)
    fig.text(0.02, -0.02, "error $\\epsilon = |F_z(L) - F_{ref}|/F_{ref}$; reference: "
             f"{ds.attrs['reference_solver']}, $l_0 = {float(ds.attrs['reference_l0']):g}\\,R$, "
             f"{ds.attrs['reference_knob']} ({float(ds.attrs['reference_wall_time']):.3g} s).\n"
             "Point labels: $dx_{max}$ [R] (implicit), tol (explicit). Wall time of one simulate job.",
             ha="left", va="top", fontsize=7)
    ax.legend(loc="best")
    return fig


STATUS_COLOURS = {"converged": "#4daf4a", "not_converged": "#ffd92f", "escaped": "#80b1d3",
                  "diverged": "#e41a1c", "invalid": "0.75"}


def stability_map(ds: xr.Dataset):
    """One panel per solver: a row per swept parameter, a cell per value, coloured by how
    the run ended; the cell text is the value (and |F_z(L)| where the run gave one)."""
    from matplotlib.patches import Patch, Rectangle

    meanings = ds["status"].attrs["flag_meanings"].split()
    solvers = [s for s in ("implicit", "explicit") if s in set(ds["solver"].values)]
    params = list(dict.fromkeys(ds["parameter"].values))
    ncol = max(int(np.sum((ds["solver"].values == sv) & (ds["parameter"].values == p)))
               for sv in solvers for p in params)
    fig, axes = plt.subplots(len(solvers), 1, figsize=(1.25 * ncol + 1.6, 0.42 * len(params) * len(solvers) + 1.6),
                             squeeze=False, label=ds.attrs["title"])
    row_label = {"base": "defaults", "dx_max": r"$dx_{max}$ [$R$]", "dt_factor": r"$\Delta t/\Delta t_{stab}$",
                 "tol": r"tol ($\epsilon_F$, $\epsilon_M$)"}
    for ax, sv in zip(axes[:, 0], solvers):
        params = [p for p in dict.fromkeys(ds["parameter"].values)
                  if np.any((ds["solver"].values == sv) & (ds["parameter"].values == p))]
        for row, p in enumerate(params):
            m = np.flatnonzero((ds["solver"].values == sv) & (ds["parameter"].values == p))
            m = m[np.argsort(ds["value"].values[m])]
            for col, i in enumerate(m):
                st = meanings[int(ds["status"].values[i])]
                ax.add_patch(Rectangle((col, row), 0.95, 0.9, color=STATUS_COLOURS[st]))
                txt = "defaults" if p == "base" else f"{float(ds['value'].values[i]):g}"
                if int(ds["has_force"].values[i]):
                    txt += f"\n{float(ds['F_transmitted'].values[i]):.3g}"
                ax.text(col + 0.475, row + 0.45, txt, ha="center", va="center", fontsize=6.5)
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
    handles = [Patch(color=STATUS_COLOURS[k], label=k.replace("_", " ")) for k in meanings]
    fig.legend(handles=handles, loc="lower center", ncol=len(handles), bbox_to_anchor=(0.5, -0.01))
    base = ", ".join(f"{k} = {ds.attrs[k]}" for k in ("L", "load", "k_fr", "l0", "t_max") if k in ds.attrs)
    fig.suptitle(f"stability stress map, one parameter at a time about {base}", fontsize=9)
    fig.tight_layout(rect=(0, 0.06, 1, 1))
    return fig
