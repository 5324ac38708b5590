"""Kind ``transmitted_force`` (paper Fig 6): |F_z(L)| transmitted to the lower end against L.

Scenes differ only in L (and pore_length), and in the seed where a scene is a seed ensemble
(``seeds:``; confined_rod.analysis.ensembles); the dataset holds the transmitted force, L_z, contacts
and winding per length, and the simple model with the corrected K = R F^2/(4EI) and with
the paper's printed 2EI. With ensembles it also holds every member's force, seed and final
state, and per length the mean, standard deviation, standard error, min and max and the
count of each final state; the per-length variables are then ensemble means (converged:
all members; escaped: any).
"""
from __future__ import annotations

import numpy as np
import xarray as xr

from ... import theory
from .. import ensembles, regions
from .. import plotting as P
from ..error_budget import Headline
from ..figure_quantities import label, variable
from ..measure import n_turns
from ._common import (
    bulk_part,
    loosely_wound,
    need_scenes,
    per_scene,
    rod_parts,
    same_except,
    scene_coord,
    tol_effective,
)

OPTIONS: dict = {}
REGION_KEYS = regions.SUMMARY_KEYS
ENSEMBLES = True
#: the ensemble means this kind reports (F(L)/F0 per length), named as the
#: convergence ladders compare them: a ladder that ``serves`` one of its scenes decides on these
REPORTS = ("F_transmitted",)


def varied(fig_cfg) -> tuple[str, ...]:
    return ("L", "pore_length")


def validate(figure, fig_cfg, built) -> None:
    same_except(figure, built, varied(fig_cfg) + ("seed",), "a transmitted-force figure varies only L (and the seed)")
    lengths = {(s.L, s.pore_length): s for s in built.values()}       # one per length (ensembles count once)
    need_scenes(figure, lengths, 2, "a transmitted-force curve (of distinct lengths)")


def caption(figure, fig_cfg, built) -> str:
    sc = next(iter(built.values()))
    Ls = ", ".join(f"{L:g}" for L in sorted({s.L for s in built.values()}))
    n = len(built) / len({(s.L, s.pore_length) for s in built.values()})
    points = (f"symbols: the mean over a seed ensemble of {n:g} runs per length, error bars one standard deviation, "
              f"{P.words(P.SEEDS)} dots the single seeds" if n > 1 else "symbols: simulations")
    return (f"Force |F_z(L)| transmitted to the lower piston against the rod length L/R = {Ls}, "
            f"k_fr = {sc.k_fr:g}; {points} (open = not converged), lines: the simple model "
            f"|F_z(L)| = (1/|F_z(0)| + k_fr R L/(4EI))^-1 ({P.words(P.MODEL)}, corrected) and the paper's form "
            f"with 2EI ({P.words(P.PAPER)}); {P.words(P.GUIDE)} line: eye guide. (b) The local decay law in the "
            "bulk helix of each length "
            f"({regions.__name__}: the stretch where the wall friction is axial and at its Coulomb limit): the "
            f"slope d(1/|F_z|)/ds fitted there, over the corrected k_fr R/(4EI) ({P.words(P.MODEL)} line at 1); "
            f"the paper's K = R F^2/(2EI) gives 2 ({P.words(P.PAPER)}). Lengths without a bulk helix (the short "
            "rods, which jam at a few "
            "contacts) have no point.")


def build(fig_cfg, sims, context=None) -> xr.Dataset:
    ordered = sorted(sims, key=lambda n: float(sims[n].attrs["L"]))
    groups = ensembles.group(ordered, {n: sims[n].attrs for n in ordered}, ("L", "pore_length"))
    if any(len(g) > 1 for g in groups):
        return _build_ensemble(groups, sims)
    return _build(ordered, sims)


def _build(names, sims) -> xr.Dataset:
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
        "tol_effective": col("tol_effective", tol_effective),
        "F_simple": variable(("L_model",), theory.force_decay(L_model, load, k_fr, R, EI), "F_simple"),
        "F_simple_paper": variable(("L_model",), theory.force_decay(L_model, load, k_fr, R, EI, paper=True),
                                   "F_simple_paper"),
    }
    summ = [regions.summary(sims[n]) for n in names]
    for k in REGION_KEYS:
        data[k] = variable(("L",), np.array([x[k] for x in summ], dtype=np.int8 if k == "has_bulk" else float), k)
    data["has_bulk"].attrs.update(flag_values=np.array([0, 1], dtype=np.int8), flag_meanings="false true")
    coords = {"L": variable(("L",), L, "L"), "L_model": variable(("L_model",), L_model, "L_model"),
              "scene": scene_coord("L", names)}
    return xr.Dataset(data, coords=coords)


def _build_ensemble(groups, sims) -> xr.Dataset:
    """One point per length from its members: the per-length variables of _build as ensemble
    means, plus every member and the statistics."""
    first_members = [g[0] for g in groups]
    ds = _build(first_members, sims)
    pad = ensembles.Padded(groups, sims)
    members, has = pad.values, pad.has
    F = members(lambda d: float(d["F_transmitted"]))
    cls = members(lambda d: float(ensembles.CLASSES.index(ensembles.final_class(d))))
    st = [ensembles.stats(F[i, has[i] == 1]) for i in range(len(groups))]

    ds["F_transmitted"] = variable(("L",), [s.mean for s in st], "F_transmitted")
    ds["L_z"] = variable(("L",), pad.mean(lambda d: float(d["L_z"])), "L_z")
    ds["n_contact"] = variable(("L",), pad.mean(lambda d: float(d["contact"].sum())), "n_contact")
    ds["n_turns"] = variable(("L",), pad.mean(n_turns), "n_turns")
    ds["converged"] = variable(("L",), np.int8(members(lambda d: float(d["converged"]), 1.0).min(axis=1)), "converged")
    ds["escaped"] = variable(("L",), np.int8(members(lambda d: float(d["escaped"])).max(axis=1)), "escaped")
    ds["residual_force"] = variable(("L",), members(lambda d: float(d["residual_force"])).max(axis=1),
                                    "residual_force")
    ds["wall_time"] = variable(("L",), members(lambda d: float(d["wall_time"])).sum(axis=1), "wall_time")
    ds["tol_effective"] = variable(("L",), members(tol_effective).max(axis=1), "tol_effective")
    ds["F_member"] = variable(("L", "member"), F, "F_member")
    ds["member_seed"] = variable(("L", "member"), members(lambda d: float(d.attrs["seed"])).astype(np.int64),
                                 "member_seed")
    ds["has_member"] = variable(("L", "member"), has, "has_member")
    ds["member_class"] = variable(("L", "member"), cls.astype(np.int8), "member_class")
    analyses = {n: regions.analyse(sims[n]) for g in groups for n in g}
    rate, tip, low = (np.zeros(has.shape) for _ in range(3))
    has_bulk = np.zeros(has.shape, dtype=np.int8)
    loose = np.zeros(has.shape, dtype=np.int8)
    part = np.zeros(has.shape)
    for i, g in enumerate(groups):
        for j, n in enumerate(g):
            a = analyses[n]
            has_bulk[i, j] = int(a.bulk is not None)
            loose[i, j] = int(a.bulk is not None and loosely_wound(sims[n], a))
            part[i, j] = bulk_part(sims[n], a)
            rate[i, j] = a.bulk.rate if a.bulk else 0.0
            tip[i, j], low[i, j] = a.regions.tip_length, a.regions.lower_length
    ds["bulk_decay_rate_member"] = variable(("L", "member"), rate, "bulk_decay_rate_member")
    ds["has_bulk_member"] = variable(("L", "member"), has_bulk, "has_bulk_member")
    ds["tip_length_member"] = variable(("L", "member"), tip, "tip_length_member")
    ds["lower_length_member"] = variable(("L", "member"), low, "lower_length_member")
    ds["loosely_wound_member"] = variable(("L", "member"), loose, "loosely_wound_member")
    ds["bulk_part_member"] = variable(("L", "member"), part, "bulk_part_member")
    rst = [ensembles.stats(rate[i, has_bulk[i] == 1]) if has_bulk[i].any() else None for i in range(len(groups))]
    ds["bulk_decay_rate_mean"] = variable(("L",), [x.mean if x else 0.0 for x in rst], "bulk_decay_rate_mean")
    ds["bulk_decay_rate_std"] = variable(("L",), [x.std if x else 0.0 for x in rst], "bulk_decay_rate_std")
    ds["member_class"].attrs.update({"flag_values": np.arange(len(ensembles.CLASSES), dtype=np.int8),
                                     "flag_meanings": " ".join(ensembles.CLASSES)})
    for name, field in (("n_seeds", "n"), ("F_mean", "mean"), ("F_std", "std"), ("F_sem", "sem"),
                        ("F_min", "min"), ("F_max", "max")):
        ds[name] = variable(("L",), [getattr(s, field) for s in st], name)
    ds["n_class"] = variable(("L", "state_class_name"),
                             [[int(((cls[i] == k) & (has[i] == 1)).sum()) for k in range(len(ensembles.CLASSES))]
                              for i in range(len(groups))], "n_class")
    ds = ds.assign_coords(member=variable(("member",), np.arange(has.shape[1]), "member"),
                          state_class_name=variable(("state_class_name",), np.array(ensembles.CLASSES, dtype=object),
                                                    "state_class_name"))
    ds.attrs["ensemble"] = "mean, standard deviation (ddof 1), standard error, min, max over the seeds of each length"
    return ds


def headlines(figure: str, ds: xr.Dataset) -> list[Headline]:
    """The error budget's numbers: F(L)/F0 at each length, with the standard error of the
    ensemble mean (analysis.error_budget)."""
    load, k_fr = float(ds.attrs["load"]), float(ds.attrs["k_fr"])
    protocol = str(ds.attrs.get("protocol", "straight"))
    out = []
    for i, L in enumerate(ds["L"].values):
        ensemble = "F_sem" in ds
        out.append(Headline(
            f"{figure}.fraction.L{L:g}", figure, f"F(L)/F0, L/R = {L:g}", float(ds["F_transmitted"].values[i]) / load,
            float(ds["F_sem"].values[i]) / load if ensemble and int(ds["n_seeds"].values[i]) > 1 else None,
            int(ds["n_seeds"].values[i]) if ensemble else 1, "F_transmitted", float(L), load, k_fr, protocol,
            note="ensemble mean over seeds; statistical error sd/sqrt(n)",
            numerics={"tol": float(ds["tol_effective"].values[i])} if "tol_effective" in ds else {},
            force_parts=rod_parts(ds["F_member"].values[i], ds["bulk_part_member"].values[i],
                                  ds["has_bulk_member"].values[i]) if "bulk_part_member" in ds else None))
    return out


def _plot_local_law(bx, ds: xr.Dataset) -> None:
    """(b): the bulk decay rate of each length over the corrected local law k_fr R/(4EI), with
    the paper's 2 (its K = R F^2/(2EI)) beside it."""
    L = ds["L"].values
    model = ds["decay_rate_model"].values
    ok = ds["has_bulk"].values == 1
    if "bulk_decay_rate_member" in ds:
        has = ds["has_bulk_member"].values == 1
        Lm = np.broadcast_to(L[:, None], has.shape)
        ratio_m = ds["bulk_decay_rate_member"].values / model[:, None]
        bx.plot(Lm[has], ratio_m[has], ".", ms=3, **P.SEEDS, label="single seeds")
        mean = ds["bulk_decay_rate_mean"].values / model
        sd = ds["bulk_decay_rate_std"].values / model
        ok = ok | has.any(axis=1)
        bx.errorbar(L[ok], mean[ok], yerr=sd[ok], fmt="o", ms=4.5, color="black", capsize=2.5,
                    label=_seeds_label(ds))
    else:
        mean = ds["bulk_decay_rate"].values / model
        bx.errorbar(L[ok], mean[ok], yerr=(ds["bulk_decay_rate_err"].values / model)[ok], fmt="o", ms=4.5,
                    color="black", capsize=2.5, label="simulation")
    # the same line styles as (a)'s model curves, under the same legend entries
    bx.axhline(1.0, **P.MODEL, label=MODEL_LABEL)
    bx.axhline(2.0, **P.PAPER, label=PAPER_LABEL)
    bx.set_xscale("log")
    P.plain_log_ticks(bx.xaxis)
    bx.set_ylim(0, 2.4)
    bx.set_xlabel(label("L"))
    bx.set_ylabel(r"bulk $d(1/|F_z|)/ds$ over $k_{fr}R/(4EI)$")
    bx.set_title("(b) local decay law in the bulk helix", fontsize=9, loc="left")


def _seeds_label(ds: xr.Dataset) -> str:
    n = ds["n_seeds"].values
    return f"mean $\\pm$ s.d. of {int(n.min())}" + (f"-{int(n.max())}" if n.max() > n.min() else "") + " seeds"


MODEL_LABEL = r"simple model, $K = RF^2/(4EI)$; (b): $k_{fr}R/(4EI)$"
PAPER_LABEL = r"paper's Eq. (Fz-simple), $K = RF^2/(2EI)$; (b): $k_{fr}R/(2EI)$"


def plot(ds: xr.Dataset):
    local = "bulk_decay_rate" in ds and bool((ds["has_bulk"].values == 1).any())
    if local:
        fig, (ax, bx) = P.plt.subplots(1, 2, figsize=(7.0, 3.9), label=ds.attrs["title"])
        _plot_local_law(bx, ds)
    else:
        fig, ax = P.plt.subplots(figsize=(4.6, 3.4), label=ds.attrs["title"])
    L = ds["L"].values
    F = ds["F_transmitted"].values
    ok = ds["converged"].values == 1
    ax.plot(ds["L_model"], ds["F_simple"], **P.MODEL, label=MODEL_LABEL if local else MODEL_LABEL.split(";")[0])
    ax.plot(ds["L_model"], ds["F_simple_paper"], **P.PAPER, label=PAPER_LABEL if local else PAPER_LABEL.split(";")[0])
    ax.plot(L, F, "-", **P.GUIDE, label="eye guide")
    if "F_member" in ds:
        has = ds["has_member"].values == 1
        Lm = np.broadcast_to(L[:, None], has.shape)
        ax.plot(Lm[has], ds["F_member"].values[has], ".", ms=3, **P.SEEDS, label="single seeds")
        ax.errorbar(L[ok], F[ok], yerr=ds["F_std"].values[ok], fmt="none", ecolor="black", elinewidth=0.9, capsize=2.5)
        label_sim = _seeds_label(ds)
    else:
        label_sim = "simulation"
    ax.plot(L[ok], F[ok], "o", ms=5, **P.SIM, label=label_sim)
    if (~ok).any():
        ax.plot(L[~ok], F[~ok], "o", ms=5, mfc="white", mec="black", label="simulation, not converged")
    ax.axhline(float(ds.attrs["load"]), color="0.7", lw=0.8)
    ax.annotate("load $|F_z(0)|$", (ds["L_model"].values[0], float(ds.attrs["load"])), xytext=(2, -10),
                textcoords="offset points", fontsize=8, color="0.4")
    P.log_axes(ax)
    ax.set_xlabel(label("L"))
    ax.set_ylabel(label("F_transmitted"))
    ax.set_title(("(a) " if local else "") + P.params_text(ds, ("load", "k_fr", "l0")), fontsize=9,
                 loc="left" if local else "center")
    if not local:
        # lower left is empty (every curve falls with L); "best" put the legend's
        # marker among the data, where it read as an extra point
        ax.legend(loc="lower left", fontsize=7.5)
        return fig
    bx.set_xlim(ax.get_xlim())       # the same lengths as (a): the short rods without a bulk have no point
    P.plain_log_ticks(bx.xaxis)
    # one legend for both panels, below them: inside (a) it covered the model curves
    handles, labels = P.legend_entries((ax, bx))
    fig.legend(handles, labels, loc="lower center", ncol=2, fontsize=7.5, bbox_to_anchor=(0.5, 0.0))
    rows = -(-len(labels) // 2)
    fig.tight_layout(rect=(0, (0.16 * rows + 0.08) / fig.get_figheight(), 1, 1))
    return fig
