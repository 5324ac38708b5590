"""Per-figure datasets: exactly what a figure plots, built from the scene datasets.

``build(figure, fig_cfg, sims, context)`` dispatches to the figure kind's module
(:mod:`confined_rod.figures`) and adds what every figure dataset carries: CF global
attributes, the scene parameters common to its scenes, the scenes' git commits and the
provenance. Post-processing reads datasets only; it never imports the simulator.
"""
from __future__ import annotations

from typing import Any, Mapping

import xarray as xr

from . import evidence, figures
from .io import finalize

#: scene attributes copied onto every figure dataset (those the figure varies are left out)
COMMON = ("R", "EI", "load", "k_fr", "l0", "k_ph", "k_w", "friction_cap", "protocol", "seed", "solver", "tol", "L",
          "bending_constant")


def unsettled(figure: str, kind: str, sims: Mapping[str, xr.Dataset]) -> list[str]:
    """The figure's runs that are not at equilibrium (a step or time cap, an escape), named with
    their status and printed as a warning: the figure draws them (marked), and no claim, fit
    verdict or convergence rung is decided on them. Probes and load paths record how each
    point ended in their own variables."""
    if figures.source(kind) != "simulate":
        return []
    runs = [f"{figure}/{r}" for r in evidence.not_at_equilibrium(sims)]
    if runs:
        evidence.warn(f"warning: {figure}: {len(runs)} of {len(sims)} runs are not at a stable equilibrium; "
                      "no claim is decided on this figure's dataset, and a convergence ladder leaves them out: "
                      + "; ".join(runs))
    return runs


def build(figure: str, fig_cfg: Mapping[str, Any], sims: Mapping[str, xr.Dataset],
          context: Mapping[str, Any] | None = None) -> xr.Dataset:
    kind = fig_cfg["kind"]
    module = figures.get(kind)
    ds = module.build(fig_cfg, sims, dict(context or {}))
    meta = {"figure": figure, "kind": kind, "paper_figure": fig_cfg.get("paper_figure", "none"),
            "figure_title": fig_cfg.get("title", figure), "scenes": list(sims),
            "scene_git_commits": sorted({str(d.attrs.get("git_commit", "unknown")) for d in sims.values()}),
            "not_at_equilibrium": evidence.join(unsettled(figure, kind, sims))}
    if hasattr(module, "meta"):
        meta.update(module.meta(fig_cfg, sims))
    else:
        first = next(iter(sims.values()))
        varied = set(figures.varied(kind, fig_cfg))
        meta.update({k: first.attrs[k] for k in COMMON if k in first.attrs and k not in varied})
    return finalize(ds, f"{fig_cfg.get('title', figure)} {figures.origin(fig_cfg)}", meta)
