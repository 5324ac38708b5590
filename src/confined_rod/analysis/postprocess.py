"""Per-figure datasets: exactly what a figure plots, built from the scene datasets.

``build(figure, fig_cfg, sims, context)`` dispatches to the figure kind's module
(:mod:`confined_rod.analysis.figures`) and adds what every figure dataset carries: CF global
attributes, the scene parameters common to its scenes, the scenes' git commits and the
provenance. Post-processing reads datasets only; it never imports the simulator.
"""
from __future__ import annotations

from typing import Any, Mapping

import xarray as xr

from ..io import finalize
from . import ensembles, figures, run_checks
from .figure_quantities import STATED_PARAMETERS

#: scene attributes copied onto every figure dataset (those the figure varies are left out)
COMMON = STATED_PARAMETERS


def settle(kind: str, sims: Mapping[str, xr.Dataset]) -> tuple[dict[str, xr.Dataset], list[str]]:
    """(the runs a figure's statistics use, the runs left out of them): a run not at a stable
    equilibrium (a step or time cap, an escape, a known saddle: run_checks.status) is left out of
    its seed ensemble when other members of it are at one. A run alone, or an ensemble with no
    member at equilibrium, stays in (the figure draws it, marked; no claim is decided on it). A
    kind that sorts its runs itself (HANDLES_UNSETTLED: the convergence ladders, which leave a
    paired seed out at every rung) gets them all. Probes and load paths record how each point
    ended in their own variables."""
    module = figures.get(kind)
    if figures.source(kind) != "simulate" or getattr(module, "HANDLES_UNSETTLED", False):
        return dict(sims), []
    seeds = {n: int(d.attrs.get("seed", 0)) for n, d in sims.items()}
    bad = run_checks.unsettled(sims)
    out = []
    for members in ensembles.by_base(list(sims), seeds).values():
        if any(m not in bad for m in members):
            out += [m for m in members if m in bad]
    return {n: d for n, d in sims.items() if n not in out}, out


def build(figure: str, fig_cfg: Mapping[str, Any], sims: Mapping[str, xr.Dataset],
          context: Mapping[str, Any] | None = None) -> xr.Dataset:
    """The figure's dataset from its scene datasets, with the attributes every figure dataset
    carries; ``not_at_equilibrium`` names the runs in it that are not at a stable equilibrium
    (no claim is decided on it then) and ``left_out`` those left out of its statistics."""
    kind = fig_cfg["kind"]
    module = figures.get(kind)
    used, dropped = settle(kind, sims)
    ds = module.build(fig_cfg, used, dict(context or {}))
    named = ({n: f"{figure}/{n} ({st})" for n, st in run_checks.unsettled(sims).items()}
             if figures.source(kind) == "simulate" else {})
    left_out = [named[n] for n in dropped] + [f"{figure}/{r}"
                                              for r in run_checks.flagged(ds.attrs.pop("left_out", None))]
    inside = [r for r in named.values() if r not in left_out]
    if named:
        run_checks.warn(f"warning: {figure}: {len(named)} of {len(sims)} runs are not at a stable equilibrium"
                      + (f"; left out of its statistics: {'; '.join(left_out)}" if left_out else "")
                      + (f"; in its dataset, so no claim is decided on it: {'; '.join(inside)}" if inside else ""))
    meta = {"figure": figure, "kind": kind, "paper_figure": fig_cfg.get("paper_figure", "none"),
            "figure_title": fig_cfg.get("title", figure), "scenes": list(used),
            "scene_git_commits": sorted({str(d.attrs.get("git_commit", "unknown")) for d in sims.values()}),
            "not_at_equilibrium": run_checks.join(inside), "left_out": run_checks.join(left_out),
            # the loading protocols of its runs (the claims table says which protocol decided a claim)
            "protocols": ", ".join(sorted({str(d.attrs["protocol"]) for d in sims.values() if "protocol" in d.attrs}))
            or "none"}
    systems = sorted({str(d.attrs.get("unit_system", "reduced")) for d in sims.values()})
    if len(systems) > 1:
        raise ValueError(f"figure {figure!r} mixes scenes of unit systems {', '.join(systems)}: its dataset can "
                         "state one (set unit_system in the figure's defaults)")
    meta["unit_system"] = systems[0] if systems else "reduced"
    if hasattr(module, "meta"):
        meta.update(module.meta(fig_cfg, used))
    else:
        first = next(iter(used.values()))
        varied = set(figures.varied(kind, fig_cfg))
        meta.update({k: first.attrs[k] for k in COMMON if k in first.attrs and k not in varied})
    return finalize(ds, f"{fig_cfg.get('title', figure)} {figures.origin(fig_cfg)}", meta)
