"""Kind ``bifurcation`` (paper Fig 3): L_z against the load, straight, planar and 3-D
branches, and both thresholds.

Its scenes are run by the rule ``load_path`` (confined_rod.sim.load_paths.run_spec): each
scene is a sweep over the figure's load grid (``up`` or ``down`` by continuation
from the previous equilibrium, or ``fresh`` from the scene's own perturbed start at
each load) or the two thresholds by bisection (``thresholds``: the first, straight to
buckled; the second, planar to 3-D).  Panel (a) draws the sweeps of one rod with
its thresholds; panel (b) the thresholds against L/R with their estimates:
F_1 = Euler's load of the rod lying diagonally across the pore,
(pi^2 EI/L^2) sqrt(1 - 4R^2/L^2) (discrete: pi^2/L^2 -> (4/l0^2) sin^2(pi l0/2L)),
and F_2 ~ the second Euler mode 4 pi^2 EI/L^2 (docs/model.md, "Transitions").
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np
import xarray as xr

from ... import theory
from ...errors import ConfigError, SceneError
from .. import plotting as P
from ..error_budget import Headline, euler_discretisation
from ..figure_quantities import label, variable
from ._common import check_scene_keys, same_except, scene_coord

SOURCE = "path"
RUNS = ("up", "down", "fresh", "thresholds")  # as confined_rod.sim.load_paths.RUNS (simulation side)
CLASSES = ("straight", "planar", "three_d")  # as confined_rod.sim.load_paths.CLASSES
OPTIONS = {
    "loads": {"type": "object", "required": ["min", "max", "n"], "additionalProperties": False,
              "properties": {"min": {"type": "number", "exclusiveMinimum": 0},
                             "max": {"type": "number", "exclusiveMinimum": 0},
                             "n": {"type": "integer", "minimum": 2, "maximum": 400}},
              "description": "load grid of the sweeps, in EI/R^2, evenly spaced in log(load)"},
    "runs": {"type": "object", "minProperties": 2, "additionalProperties": {"enum": list(RUNS)},
             "description": "scene id -> how it is run: up / down (continuation), fresh, or thresholds"},
    "precision": {"type": "number", "exclusiveMinimum": 0, "maximum": 0.1,
                  "description": "relative precision of the threshold bisection (hi - lo <= precision hi)"},
}
SWEEPS = ("up", "down", "fresh")
CLASS_COLOURS = {"straight": "0.35", "planar": "tab:blue", "three_d": "tab:red"}
RUN_MARKERS = {"up": "^", "down": "v", "fresh": "o"}


def load_grid(fig_cfg) -> np.ndarray:
    g = fig_cfg["loads"]
    return np.geomspace(float(g["min"]), float(g["max"]), int(g["n"]))


def path_spec(fig_cfg, scene: str) -> dict:
    return {"run": fig_cfg["runs"][scene], "loads": [float(F) for F in load_grid(fig_cfg)],
            "precision": float(fig_cfg.get("precision", 1e-3))}


def varied(fig_cfg) -> tuple[str, ...]:
    return ("L", "protocol", "k_fr")


def _split(fig_cfg, built):
    runs = fig_cfg.get("runs", {})
    sweeps = {n: sc for n, sc in built.items() if runs.get(n) in SWEEPS}
    thr = {n: sc for n, sc in built.items() if runs.get(n) == "thresholds"}
    return sweeps, thr


def stiff_twins(thr: dict[str, tuple[float, float, float, float]]) -> tuple[list[str], dict[str, str]]:
    """(the thresholds rows of panel (b), {row: its stiff twin}) from ``thr`` = {scene: (L, R, l0,
    k_ph)}: scenes of one rod (L, R, l0) that differ in k_ph are a bond check; the softest is the
    figure's row, the stiffest the twin its threshold is compared with (the bias of a finite k_ph:
    error_budget's k_ph term)."""
    rods: dict[tuple[float, float, float], list[str]] = {}
    for n, (L, R, l0, _) in thr.items():
        rods.setdefault((L, R, l0), []).append(n)
    rows, twins = [], {}
    for names in rods.values():
        names = sorted(names, key=lambda n: thr[n][3])
        rows.append(names[0])
        if len(names) > 1 and thr[names[-1]][3] > thr[names[0]][3]:
            twins[names[0]] = names[-1]
    return [n for n in thr if n in rows], twins


def validate(figure, fig_cfg, built) -> None:
    check_scene_keys(figure, "runs", fig_cfg.get("runs"), built)
    missing = [n for n in built if n not in fig_cfg.get("runs", {})]
    if missing:
        raise ConfigError(f"figures.{figure}.runs: no run given for the scene(s) {', '.join(missing)}")
    if "loads" not in fig_cfg:
        raise ConfigError(f"figures.{figure}.loads: a bifurcation diagram needs a load grid {{min, max, n}}")
    if not fig_cfg["loads"]["min"] < fig_cfg["loads"]["max"]:
        raise ConfigError(f"figures.{figure}.loads: min {fig_cfg['loads']['min']} must be below max "
                          f"{fig_cfg['loads']['max']}")
    sweeps, thr = _split(fig_cfg, built)
    if not sweeps or not thr:
        raise ConfigError(f"figures.{figure}.runs: needs at least one sweep (up, down, fresh) and one "
                          f"thresholds scene, got {dict(fig_cfg['runs'])}")
    same_except(figure, sweeps, ("protocol", "k_fr"), "the sweeps of a bifurcation diagram are one rod "
                                                      "(they may differ in protocol and friction)")
    for n, sc in thr.items():
        if sc.k_fr != 0.0:
            raise ConfigError(f"figures.{figure}.scenes.{n}: k_fr = {sc.k_fr:g}; thresholds are defined "
                              "frictionless (static friction holds states that are unstable without it)")
    # every load a job will run must make a valid scene (e.g. the round-off floor grows as 1/load)
    checks = [(n, sc, F) for n, sc in sweeps.items() for F in load_grid(fig_cfg)]
    checks += [(n, sc, F) for n, sc in thr.items()
               for br in theory.threshold_brackets(sc.L, sc.C_l0()).values() for F in br]
    for n, sc, F in checks:
        try:
            dataclasses.replace(sc, load=float(F))
        except SceneError as exc:
            raise ConfigError(f"figures.{figure}.scenes.{n} at load {F:.4g} (a load its run visits): {exc}") from None
    rod = next(iter(sweeps.values()))
    if not any(sc.L == rod.L and sc.R == rod.R for sc in thr.values()):
        raise ConfigError(f"figures.{figure}.runs: no thresholds scene for the sweeps' rod (L = {rod.L:g}, "
                          f"R = {rod.R:g})")


def caption(figure, fig_cfg, built) -> str:
    sweeps, thr = _split(fig_cfg, built)
    rod = next(iter(sweeps.values()))
    runs = fig_cfg["runs"]
    desc = "; ".join(f"{n}: {runs[n]}, protocol {sc.protocol}, k_fr = {sc.k_fr:g}" for n, sc in sweeps.items())
    rows, twins = stiff_twins({n: (sc.L, sc.R, sc.l0, sc.k_ph) for n, sc in thr.items()})
    aspects = ", ".join(f"{thr[n].L / thr[n].R:g}" for n in rows)
    bond = ("" if not twins else
            " The same rods at a stiffer bond (k_ph = "
            + ", ".join(sorted({f"{thr[t].k_ph:g}" for t in twins.values()}))
            + f" at L/R = {', '.join(f'{thr[n].L / thr[n].R:g}' for n in twins)}) give each threshold's bias of a "
            "finite k_ph (error budget).")
    g = fig_cfg["loads"]
    return (f"(a) Projection L_z of a rod of L/R = {rod.L / rod.R:g} on the pore axis against the load "
            f"({g['n']} loads from {g['min']:g} to {g['max']:g} EI/R^2): {desc}. Colours give the class of "
            "each equilibrium (straight, planar, 3-D). With both ends free sideways the straight rod lies "
            f"diagonally across the pore, L_z = sqrt(L^2 - 4R^2) (less F L/k_ph; {P.words(P.MODEL)} line), not L. "
            "Vertical bands: both thresholds by bisection with fresh runs (frictionless); lines: Euler's load "
            "pi^2 EI/L^2, the tilted rod's (pi^2 EI/L^2) sqrt(1 - 4R^2/L^2) and the second mode "
            f"4 pi^2 EI/L^2. (b) Both thresholds times L^2/EI against L/R = {aspects} with those estimates "
            f"(relative precision {fig_cfg.get('precision', 1e-3):g}). Frictionless is the reference because "
            "static friction can hold buckled states that are unstable without it; a frictional sweep, where "
            "given, shows how the picture changes." + bond)


def _bend_stiffness(d: xr.Dataset) -> float:
    """EI the joints represent: EI (corrected C = EI/l0) or EI R/l0 (the paper's C)."""
    EI, R, l0 = (float(d.attrs[k]) for k in ("EI", "R", "l0"))
    return EI if d.attrs.get("bending_constant", "corrected") == "corrected" else EI * R / l0


def build(fig_cfg, sims, context=None) -> xr.Dataset:
    runs = fig_cfg["runs"]
    sweeps = [n for n in sims if runs[n] in SWEEPS]
    thr, twins = stiff_twins({n: tuple(float(sims[n].attrs[k]) for k in ("L", "R", "l0", "k_ph"))
                              for n in sims if runs[n] == "thresholds"})
    loads = load_grid(fig_cfg)
    data: dict[str, xr.Variable] = {}

    def on_grid(name: str, key: str) -> np.ndarray:
        d = sims[name].sortby("load")
        return d[key].values

    for key in ("L_z", "deflection", "out_of_plane"):
        data[key] = variable(("branch", "load"), [on_grid(n, key) for n in sweeps], key)
    for key in ("state_class", "converged", "escaped"):
        data[key] = variable(("branch", "load"), np.array([on_grid(n, key) for n in sweeps], dtype=np.int8), key)
        for a in ("flag_values", "flag_meanings"):
            data[key].attrs[a] = sims[sweeps[0]][key].attrs[a]
    data["n_contact"] = variable(("branch", "load"), np.array([on_grid(n, "n_contact") for n in sweeps],
                                                              dtype=np.int32), "n_contact")
    data["run"] = variable(("branch",), np.array([runs[n] for n in sweeps], dtype=object), "run")
    data["branch_k_fr"] = variable(("branch",), [float(sims[n].attrs["k_fr"]) for n in sweeps], "branch_k_fr")
    data["branch_protocol"] = variable(("branch",), np.array([sims[n].attrs["protocol"] for n in sweeps],
                                                             dtype=object), "branch_protocol")
    rod = sims[sweeps[0]]
    L, R, k_ph = (float(rod.attrs[k]) for k in ("L", "R", "k_ph"))
    data["L_z_straight"] = variable(("load",), np.sqrt(L**2 - 4 * R**2) * (1.0 - loads / k_ph), "L_z_straight")

    # thresholds against L/R
    lo = np.array([sims[n]["threshold_lo"].sel(threshold=["first", "second"]).values for n in thr])
    hi = np.array([sims[n]["threshold_hi"].sel(threshold=["first", "second"]).values for n in thr])
    aspect = np.array([float(sims[n].attrs["L"]) / float(sims[n].attrs["R"]) for n in thr])
    estimate = np.array([[theory.first_threshold(float(d.attrs["L"]), float(d.attrs["R"]), float(d.attrs["l0"]),
                                                 _bend_stiffness(d)),
                          theory.second_threshold_estimate(float(d.attrs["L"]), _bend_stiffness(d))]
                         for d in (sims[n] for n in thr)])
    euler = np.array([np.pi**2 * _bend_stiffness(sims[n]) / float(sims[n].attrs["L"]) ** 2 for n in thr])
    scale = np.array([float(sims[n].attrs["L"]) ** 2 / _bend_stiffness(sims[n]) for n in thr])  # L^2/EI
    data["threshold_lo"] = variable(("aspect", "threshold"), lo, "threshold_lo")
    data["threshold_hi"] = variable(("aspect", "threshold"), hi, "threshold_hi")
    data["threshold_estimate"] = variable(("aspect", "threshold"), estimate, "threshold_estimate")
    data["F_euler"] = variable(("aspect",), euler, "F_euler")
    data["L2_over_EI"] = variable(("aspect",), scale, "L2_over_EI")
    data["aspect_scene"] = scene_coord("aspect", thr)
    data["aspect_l0"] = variable(("aspect",), [float(sims[n].attrs["l0"]) / float(sims[n].attrs["R"]) for n in thr],
                                 "l0_over_R")
    # the same rod at a stiffer bond (a bond check): its thresholds, 0 where there is none
    stiff = [sims[twins[n]] if n in twins else None for n in thr]
    data["has_stiff_twin"] = variable(("aspect",), np.array([d is not None for d in stiff], dtype=np.int8),
                                      "has_stiff_twin")
    data["stiff_k_ph"] = variable(("aspect",), [float(d.attrs["k_ph"]) if d is not None else 0.0 for d in stiff],
                                  "stiff_k_ph")
    data["aspect_k_ph"] = variable(("aspect",), [float(sims[n].attrs["k_ph"]) for n in thr], "aspect_k_ph")
    for side in ("lo", "hi"):
        data[f"threshold_{side}_stiff"] = variable(
            ("aspect", "threshold"), [d[f"threshold_{side}"].sel(threshold=["first", "second"]).values
                                      if d is not None else np.zeros(2) for d in stiff], f"threshold_{side}_stiff")
    coords = {"load": variable(("load",), loads, "load"), "branch": scene_coord("branch", sweeps),
              "aspect": variable(("aspect",), aspect, "aspect"),
              "threshold": variable(("threshold",), np.array(["first", "second"], dtype=object), "threshold")}
    ds = xr.Dataset(data, coords=coords)
    main = [i for i, n in enumerate(thr) if float(sims[n].attrs["L"]) == L and float(sims[n].attrs["R"]) == R][0]
    ds.attrs.update({"main_aspect": L / R, "main_index": main,
                     "first_threshold": [float(lo[main, 0]), float(hi[main, 0])],
                     "second_threshold": [float(lo[main, 1]), float(hi[main, 1])]})
    if {"up", "down"} <= {runs[n] for n in sweeps}:
        iu = [i for i, n in enumerate(sweeps) if runs[n] == "up"][0]
        idn = [i for i, n in enumerate(sweeps) if runs[n] == "down"][0]
        differ = ds.state_class.values[iu] != ds.state_class.values[idn]
        ds.attrs["hysteresis_loads"] = int(differ.sum())
        ds.attrs["hysteresis_max_dL_z"] = float(np.abs(ds.L_z.values[iu] - ds.L_z.values[idn]).max())
    return ds


#: the half-wave a threshold's Euler mode buckles in, as a fraction of L
HALF_WAVE = {"first": 1.0, "second": 0.5}


def headlines(figure: str, ds: xr.Dataset) -> list[Headline]:
    """The error budget's numbers: each threshold at each aspect ratio in units of pi^2 EI/L^2,
    with the bisection's bracket and the discretisation of the discrete chain's Euler load as its
    bias; a frictionless threshold of the straight or planar rod has no seed spread. A rod
    repeated in other units (R = 2, the same L/R and l0/R) is counted once."""
    out, seen = [], set()
    for i, aspect in enumerate(ds["aspect"].values):
        rod = (float(aspect), float(ds["aspect_l0"].values[i]))
        if rod in seen:         # the same rod in other units (R = 2): a units check, counted once
            continue
        seen.add(rod)
        for j, which in enumerate(ds["threshold"].values):
            lo, hi = float(ds["threshold_lo"].values[i, j]), float(ds["threshold_hi"].values[i, j])
            unit = float(ds["L2_over_EI"].values[i]) / np.pi**2
            l0_over_L = float(ds["aspect_l0"].values[i]) / float(aspect)
            scene = str(ds["aspect_scene"].values[i])
            terms = {"bracket": ((hi - lo) / (hi + lo), "half the bisection's bracket"),
                     "discretisation": (euler_discretisation(l0_over_L, HALF_WAVE[str(which)]),
                                        "Euler load of the discrete chain (theory)")}
            if "has_stiff_twin" in ds and int(ds["has_stiff_twin"].values[i]):
                terms["k_ph"] = _bond_term(ds, i, j)
            out.append(Headline(
                f"{figure}.{which}_threshold.{scene}", figure,
                f"{which} threshold [pi^2 EI/L^2], L/R = {aspect:g} ({scene})", 0.5 * (lo + hi) * unit, 0.0, 1,
                "threshold", float(aspect), 0.5 * (lo + hi), float(ds.attrs.get("k_fr", 0.0)),
                terms=terms,
                note="bisection of one frictionless run per load: no seed spread", dof=math.inf))
    return out


def _bond_term(ds: xr.Dataset, i: int, j: int) -> tuple[float, str, float, float]:
    """The k_ph bias term of threshold j of row i, (value, why, standard error, limit factor): its
    shift from the same rod at the stiffer bond, mid/mid_stiff - 1, times f = 1/(1 - k_ph/k_ph_stiff),
    the first-order distance to the rigid-bond limit in h = 1/k_ph (error_budget.bias_limit_factor).
    Each bisection places its threshold anywhere in its bracket, so the shift comes in steps of a
    bracket: its standard error is that of the difference of two uniform errors of the brackets'
    half-widths b, f sqrt(b^2 + b_stiff^2)/sqrt(3) (relative)."""
    lo, hi = float(ds["threshold_lo"].values[i, j]), float(ds["threshold_hi"].values[i, j])
    lo_s, hi_s = float(ds["threshold_lo_stiff"].values[i, j]), float(ds["threshold_hi_stiff"].values[i, j])
    k, k_stiff = float(ds["aspect_k_ph"].values[i]), float(ds["stiff_k_ph"].values[i])
    f = 1.0 / (1.0 - k / k_stiff)
    b, b_s = (hi - lo) / (hi + lo), (hi_s - lo_s) / (hi_s + lo_s)
    return (((lo + hi) / (lo_s + hi_s) - 1.0) * f,
            f"the same rod at k_ph = {k_stiff:g} (bisection), to first order in 1/k_ph",
            f * math.hypot(b, b_s) / math.sqrt(3.0), f)


def plot(ds: xr.Dataset):
    # printed at its natural size, the text width (plotting.TEXT_WIDTH_IN); the legend of (a) below both panels
    fig, (ax, bx) = P.plt.subplots(1, 2, figsize=(P.TEXT_WIDTH_IN, 3.3), gridspec_kw={"width_ratios": [1.5, 1]})
    loads = ds["load"].values
    classes = ds.state_class.attrs["flag_meanings"].split()
    for i, b in enumerate(ds.branch.values):
        run = str(ds.run.values[i])
        Lz = ds.L_z.values[i]
        ls = (":" if float(ds.branch_k_fr.values[i]) > 0 else
              "--" if str(ds.branch_protocol.values[i]) == "planar" else "-")
        ax.plot(loads, Lz, ls=ls, color="0.6", lw=0.8, zorder=1)
        for c, name in enumerate(classes):
            m = ds.state_class.values[i] == c
            if m.any():
                fresh = run == "fresh"  # open and larger, so coinciding sweeps stay visible
                ax.plot(loads[m], Lz[m], RUN_MARKERS[run], ms=7 if fresh else 4, mfc="none" if fresh else
                        CLASS_COLOURS[name], mec=CLASS_COLOURS[name], ls="none", zorder=2 if fresh else 3)
    ax.plot(loads, ds.L_z_straight.values, **P.MODEL, label=r"straight, diagonal: $\sqrt{L^2-4R^2}\,(1-F/k_{ph})$")
    m = int(ds.attrs["main_index"])
    lo, hi = ds.threshold_lo.values[m], ds.threshold_hi.values[m]
    for j, (name, col) in enumerate((("1", "0.35"), ("2", "tab:red"))):
        ax.axvspan(lo[j], hi[j], color=col, alpha=0.35, lw=0)
        ax.axvline(0.5 * (lo[j] + hi[j]), color=col, lw=0.8, alpha=0.6,
                   label=rf"$F_{name}$ (bisection): {0.5 * (lo[j] + hi[j]):.4g} $EI/R^2$")
    FE = float(ds.F_euler.values[m])
    ax.axvline(FE, **P.PAPER, label=r"Euler $\pi^2EI/L^2$")
    ax.axvline(float(ds.threshold_estimate.values[m, 0]), color="0.35", ls="--", lw=0.9,
               label=r"tilted rod $(\pi^2EI/L^2)\sqrt{1-4R^2/L^2}$")
    ax.axvline(float(ds.threshold_estimate.values[m, 1]), color="tab:red", ls="--", lw=0.9,
               label=r"second mode $4\pi^2EI/L^2$")
    ax.set_xscale("log")
    P.plain_log_ticks(ax.xaxis)
    ax.set_xlabel(label("load"))
    ax.set_ylabel(label("L_z"))
    ax.set_title(f"(a) $L/R = {ds.attrs['main_aspect']:g}$", loc="left")
    from matplotlib.lines import Line2D

    handles, _ = ax.get_legend_handles_labels()
    handles += [Line2D([], [], marker=RUN_MARKERS[r], ls="none", color="k", mfc="k" if r != "fresh" else "none",
                       label={"up": "sweep up (continuation)", "down": "sweep down (continuation)",
                              "fresh": "fresh start at each load"}[r])
                for r in RUN_MARKERS if r in set(map(str, ds.run.values))]
    handles += [Line2D([], [], marker="s", ls="none", color=CLASS_COLOURS[c], label=c.replace("_", "-"))
                for c in classes]
    if "planar" in set(map(str, ds.branch_protocol.values)):
        handles.append(Line2D([], [], ls="--", color="0.6", label="planar-only sweep (protocol planar)"))
    if np.any(ds.branch_k_fr.values > 0):
        handles.append(Line2D([], [], ls=":", color="0.6", label=r"with friction ($k_{fr}$ = "
                              + ", ".join(f"{v:g}" for v in sorted(set(ds.branch_k_fr.values)) if v > 0) + ")"))
    # (b) thresholds against L/R
    a = ds["aspect"].values
    order = np.argsort(a)
    s = ds.L2_over_EI.values
    for j, (name, col, mk) in enumerate((("1", "0.2", "o"), ("2", "tab:red", "s"))):
        mid = 0.5 * (ds.threshold_lo.values[:, j] + ds.threshold_hi.values[:, j]) * s
        err = 0.5 * (ds.threshold_hi.values[:, j] - ds.threshold_lo.values[:, j]) * s
        bx.errorbar(a[order], mid[order], yerr=err[order], fmt=mk, color=col, ms=5, capsize=2,
                    label=rf"$F_{name} L^2/EI$ (bisection)")
        bx.plot(a[order], (ds.threshold_estimate.values[:, j] * s)[order], "--", color=col, lw=1,
                label=(r"$\pi^2\,$(discrete)$\,\sqrt{1-4R^2/L^2}$" if j == 0 else r"$4\pi^2$ (second mode)"))
    bx.axhline(np.pi**2, **P.PAPER, label=r"$\pi^2$ (Euler)")
    bx.set_xscale("log")
    P.plain_log_ticks(bx.xaxis)
    bx.set_xlabel(label("aspect"))
    bx.set_ylabel(r"threshold load $\times\ L^2/EI$")
    bx.set_title("(b) thresholds against $L/R$", loc="left")
    bx.legend(fontsize=P.SMALL)
    fig.tight_layout()
    # below the panels (the saved figure's tight bounding box takes it in)
    fig.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, 0.0), ncol=3, fontsize=P.SMALL)
    return fig
