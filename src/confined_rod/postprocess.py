"""Per-figure datasets: exactly what a figure plots, built from the scene datasets.

``build(kind, figure_config, sims)`` takes the figure's config entry and a
mapping scene id -> scene dataset (as written by :func:`simulate`), and returns
an xarray Dataset with CF attributes.  Analytic curves use the corrected simple
model of :mod:`confined_rod.theory`; the paper's printed form is stored beside
it so the difference is visible in the data, not only in a comment.
"""
from __future__ import annotations

from typing import Any, Mapping

import numpy as np
import xarray as xr

from . import stability, studies, theory
from .fits import PARAMS, FitError, fit_power_law
from .io import finalize, variable
from .quantities import attrs, error_attrs


def build(figure: str, fig_cfg: Mapping[str, Any], sims: Mapping[str, xr.Dataset],
          publication_value: float | None = None) -> xr.Dataset:
    kind = fig_cfg["kind"]
    builders = {"transmitted_force": transmitted_force, "force_profile": force_profile,
                "time_vs_error": studies.time_vs_error,
                "convergence": lambda c, s: studies.convergence(c, s, publication_value),
                "stability_map": stability.stability_map}
    builder = builders.get(kind)
    if builder is None:
        raise ValueError(f"figures.{figure}.kind: unknown figure kind {kind!r}")
    ds = builder(fig_cfg, sims)
    meta = {"figure": figure, "kind": kind, "paper_figure": fig_cfg.get("paper_figure", "none"),
            "figure_title": fig_cfg.get("title", figure), "scenes": list(sims),
            "scene_git_commits": sorted({str(d.attrs.get("git_commit", "unknown")) for d in sims.values()})}
    first = next(iter(sims.values()))
    if kind == "stability_map":  # the probes vary everything; the figure's defaults are the base point
        meta.update(fig_cfg.get("defaults") or {})
        meta["solvers"] = list(fig_cfg.get("solvers", []))
    else:
        for key in ("R", "EI", "load", "k_fr", "l0", "k_ph", "k_w", "friction_cap", "protocol", "seed", "solver",
                    "tol", "L"):
            meta.setdefault(key, first.attrs[key])
    if kind == "transmitted_force":
        meta.pop("L")
    if kind == "convergence":
        meta.pop(fig_cfg["parameter"], None)
    if kind == "time_vs_error":
        for k in ("solver", "l0", "tol"):
            meta.pop(k, None)
    if fig_cfg.get("panel_parameter"):
        meta.pop(fig_cfg["panel_parameter"], None)
    return finalize(ds, f"{fig_cfg.get('title', figure)} (paper Fig. {meta['paper_figure']})", meta)


# -- helpers over one scene dataset ------------------------------------------------
n_turns = studies.n_turns


def contact_range(sim: xr.Dataset) -> tuple[float, float]:
    """Arc lengths of the joints that bound the wall-contact stretch: the upper end of the
    first link on the wall and the lower end of the last one (wall forces act on link
    ends). (L, L) if no link touches the wall."""
    s = sim["s_link"].values[sim["contact"].values == 1]
    if s.size == 0:
        L = float(sim.attrs["L"])
        return L, L
    half = 0.5 * float(sim.attrs["l0"])
    return float(s.min() - half), float(s.max() + half)


# -- Fig 6: transmitted force against L ---------------------------------------------
def transmitted_force(fig_cfg: Mapping[str, Any], sims: Mapping[str, xr.Dataset]) -> xr.Dataset:
    items = sorted(sims.items(), key=lambda kv: float(kv[1].attrs["L"]))
    L = np.array([float(d.attrs["L"]) for _, d in items])
    first = items[0][1]
    load, k_fr, R, EI = (float(first.attrs[k]) for k in ("load", "k_fr", "R", "EI"))
    L_model = np.geomspace(0.8 * L.min(), 1.25 * L.max(), 200)

    def per_scene(name, fn):
        return variable(("L",), [fn(d) for _, d in items], name)

    data = {
        "F_transmitted": per_scene("F_transmitted", lambda d: float(d["F_transmitted"])),
        "L_z": per_scene("L_z", lambda d: float(d["L_z"])),
        "converged": per_scene("converged", lambda d: np.int8(d["converged"])),
        "escaped": per_scene("escaped", lambda d: np.int8(d["escaped"])),
        "n_contact": per_scene("n_contact", lambda d: int(d["contact"].sum())),
        "n_turns": per_scene("n_turns", n_turns),
        "residual_force": per_scene("residual_force", lambda d: float(d["residual_force"])),
        "wall_time": per_scene("wall_time", lambda d: float(d["wall_time"])),
        "F_simple": variable(("L_model",), theory.force_decay(L_model, load, k_fr, R, EI), "F_simple"),
        "F_simple_paper": variable(("L_model",), theory.force_decay(L_model, load, k_fr, R, EI, paper=True),
                                   "F_simple_paper"),
    }
    coords = {"L": variable(("L",), L, "L"), "L_model": variable(("L_model",), L_model, "L_model"),
              "scene": xr.Variable(("L",), np.array([k for k, _ in items], dtype=object), attrs=attrs("scene"))}
    return xr.Dataset(data, coords=coords)


# -- Fig 4 / 7: force profiles with power-law fits ------------------------------------
def force_profile(fig_cfg: Mapping[str, Any], sims: Mapping[str, xr.Dataset]) -> xr.Dataset:
    p = fig_cfg.get("panel_parameter")
    trim = float(fig_cfg.get("fit_trim", 0.0))
    names = list(sims)
    s = sims[names[0]]["s"].values
    F_abs, F_fit, in_fit, F_simple, F_paper = [], [], [], [], []
    fit = {k: [] for k in ("fit_A", "fit_l0", "fit_c", "fit_cov", "fit_rms", "s_h", "s_end", "n_fit")}
    err = {k: [] for k in ("fit_A", "fit_l0", "fit_c")}
    for name in names:
        d = sims[name]
        if d["s"].size != s.size or not np.allclose(d["s"].values, s):
            raise ValueError(f"scene {name!r}: the panels of a force-profile figure must share the rod discretisation")
        R, EI, k_fr = (float(d.attrs[k]) for k in ("R", "EI", "k_fr"))
        F = np.abs(d["F_z"].values)
        s_h, s_e = contact_range(d)
        tiny = 1e-9 * float(d.attrs["L"])  # s_h, s_e are joints: include them despite rounding
        window = (s >= s_h + trim - tiny) & (s <= s_e - trim + tiny)
        F_h = float(np.interp(s_h, s, F))
        guess_A = 4 * EI / (k_fr * R) if k_fr > 0 else F_h
        guess_l0 = max(4 * EI / (k_fr * R * F_h) - s_h, 1.0) if k_fr > 0 else 1.0
        try:
            f = fit_power_law(s[window], F[window], guess=(guess_A, guess_l0, -1.0))
        except FitError as e:
            raise FitError(f"scene {name!r}: {e}") from e
        F_abs.append(F)
        F_fit.append(f(s))
        in_fit.append(window.astype(np.int8))
        F_simple.append(theory.force_decay(np.maximum(s - s_h, 0.0), F_h, k_fr, R, EI))
        F_paper.append(theory.force_decay(np.maximum(s - s_h, 0.0), F_h, k_fr, R, EI, paper=True))
        for k, v, e in zip(("fit_A", "fit_l0", "fit_c"), (f.A, f.l0_fit, f.c), f.errors):
            fit[k].append(v)
            err[k].append(e)
        fit["fit_cov"].append(f.covariance)
        fit["fit_rms"].append(f.rms_relative_residual)
        fit["s_h"].append(s_h)
        fit["s_end"].append(s_e)
        fit["n_fit"].append(f.n_points)

    PJ = ("panel", "joint")
    data = {
        "F_abs": variable(PJ, F_abs, "F_abs"),
        "F_fit": variable(PJ, F_fit, "F_fit"),
        "in_fit": variable(PJ, in_fit, "in_fit"),
        "F_simple": variable(PJ, F_simple, "F_simple"),
        "F_simple_paper": variable(PJ, F_paper, "F_simple_paper"),
        "fit_cov": variable(("panel", "param", "param_"), fit["fit_cov"], "fit_cov"),
        "fit_rms": variable(("panel",), fit["fit_rms"], "fit_rms"),
        "s_h": variable(("panel",), fit["s_h"], "s_h"),
        "s_end": variable(("panel",), fit["s_end"], "s_end"),
        "n_fit": variable(("panel",), fit["n_fit"], "n_fit"),
        "F_transmitted": variable(("panel",), [float(sims[n]["F_transmitted"]) for n in names], "F_transmitted"),
        "converged": variable(("panel",), [np.int8(sims[n]["converged"]) for n in names], "converged"),
        "n_contact": variable(("panel",), [int(sims[n]["contact"].sum()) for n in names], "n_contact"),
        "n_turns": variable(("panel",), [n_turns(sims[n]) for n in names], "n_turns"),
    }
    for k in ("fit_A", "fit_l0", "fit_c"):
        data[k] = variable(("panel",), fit[k], k)
        data[k + "_err"] = xr.Variable(("panel",), np.array(err[k]), attrs=error_attrs(k))
    coords = {
        "s": variable(("joint",), s, "s"),
        "panel": xr.Variable(("panel",), np.array(names, dtype=object), attrs=attrs("panel")),
        "param": xr.Variable(("param",), np.array(PARAMS, dtype=object), attrs=attrs("param")),
        "param_": xr.Variable(("param_",), np.array(PARAMS, dtype=object), attrs=attrs("param")),
    }
    if p:
        pv = [float(sims[n].attrs[p]) for n in names]
        coords["panel_value"] = xr.Variable(("panel",), np.array(pv), attrs={**attrs("panel_value"),
                                            "long_name": f"value of {p} in the panel", "parameter": p})
    ds = xr.Dataset(data, coords=coords)
    ds.attrs.update({"panel_parameter": p or "none", "fit_trim": trim,
                     "fit_method": "scipy.optimize.curve_fit, relative residuals (sigma = |F_z|), A > 0, l0' > 0",
                     "fit_window": "joints between the first and the last link touching the wall, trimmed by fit_trim"})
    return ds
