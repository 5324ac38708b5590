"""Kind ``transmitted_force`` (paper Fig 6): |F_z(L)| transmitted to the lower end against L.

Scenes differ only in L (and pore_length); the dataset holds the transmitted force,
L_z, contacts and winding per length, and the simple model with the corrected
K = R F^2/(4EI) and with the paper's printed 2EI.
"""
from __future__ import annotations

import numpy as np
import xarray as xr

from .. import plotting as P
from .. import theory
from ..io import variable
from ..measure import n_turns
from ..quantities import label
from ._common import need_scenes, per_scene, same_except, scene_coord

OPTIONS: dict = {}


def varied(fig_cfg) -> tuple[str, ...]:
    return ("L", "pore_length")


def validate(figure, fig_cfg, built) -> None:
    same_except(figure, built, varied(fig_cfg), "a transmitted-force figure varies only L")
    need_scenes(figure, built, 2, "a transmitted-force curve")


def caption(figure, fig_cfg, built) -> str:
    sc = next(iter(built.values()))
    Ls = ", ".join(f"{s.L:g}" for s in built.values())
    return (f"Force |F_z(L)| transmitted to the lower piston against the rod length L/R = {Ls}, "
            f"k_fr = {sc.k_fr:g}; symbols: simulations (open = not converged), lines: the simple model "
            f"|F_z(L)| = (1/|F_z(0)| + k_fr R L/(4EI))^-1 (dashed, corrected) and the paper's form with "
            f"2EI (dotted); grey line: eye guide.")


def build(fig_cfg, sims, context=None) -> xr.Dataset:
    names = sorted(sims, key=lambda n: float(sims[n].attrs["L"]))
    L = np.array([float(sims[n].attrs["L"]) for n in names])
    first = sims[names[0]]
    load, k_fr, R, EI = (float(first.attrs[k]) for k in ("load", "k_fr", "R", "EI"))
    L_model = np.geomspace(0.8 * L.min(), 1.25 * L.max(), 200)

    def col(name, fn):
        return per_scene("L", sims, names, name, fn)

    data = {
        "F_transmitted": col("F_transmitted", lambda d: float(d["F_transmitted"])),
        "L_z": col("L_z", lambda d: float(d["L_z"])),
        "converged": col("converged", lambda d: np.int8(d["converged"])),
        "escaped": col("escaped", lambda d: np.int8(d["escaped"])),
        "n_contact": col("n_contact", lambda d: int(d["contact"].sum())),
        "n_turns": col("n_turns", n_turns),
        "residual_force": col("residual_force", lambda d: float(d["residual_force"])),
        "wall_time": col("wall_time", lambda d: float(d["wall_time"])),
        "F_simple": variable(("L_model",), theory.force_decay(L_model, load, k_fr, R, EI), "F_simple"),
        "F_simple_paper": variable(("L_model",), theory.force_decay(L_model, load, k_fr, R, EI, paper=True),
                                   "F_simple_paper"),
    }
    coords = {"L": variable(("L",), L, "L"), "L_model": variable(("L_model",), L_model, "L_model"),
              "scene": scene_coord("L", names)}
    return xr.Dataset(data, coords=coords)


def plot(ds: xr.Dataset):
    fig, ax = P.plt.subplots(figsize=(4.6, 3.4), label=ds.attrs["title"])
    L = ds["L"].values
    F = ds["F_transmitted"].values
    ok = ds["converged"].values == 1
    ax.plot(ds["L_model"], ds["F_simple"], **P.MODEL, label=r"simple model, $K = RF^2/(4EI)$")
    ax.plot(ds["L_model"], ds["F_simple_paper"], **P.PAPER, label=r"paper's Eq. (Fz-simple), $K = RF^2/(2EI)$")
    ax.plot(L, F, "-", color="0.6", lw=0.7, label="eye guide")
    ax.plot(L[ok], F[ok], "o", ms=5, **P.SIM, label="simulation")
    if (~ok).any():
        ax.plot(L[~ok], F[~ok], "o", ms=5, mfc="white", mec="black", label="simulation, not converged")
    ax.axhline(float(ds.attrs["load"]), color="0.7", lw=0.8)
    ax.annotate("load $|F_z(0)|$", (ds["L_model"].values[0], float(ds.attrs["load"])), xytext=(2, -10),
                textcoords="offset points", fontsize=8, color="0.4")
    ax.set_xscale("log")
    ax.set_yscale("log")
    P.plain_log_ticks(ax.xaxis)
    P.plain_log_ticks(ax.yaxis)
    ax.set_xlabel(label("L"))
    ax.set_ylabel(label("F_transmitted"))
    ax.set_title(P.params_text(ds, ("load", "k_fr", "l0")), fontsize=9)
    # lower left is empty (every curve falls with L); "best" put the legend's
    # marker among the data, where it read as an extra point
    ax.legend(loc="lower left", fontsize=7.5)
    return fig
