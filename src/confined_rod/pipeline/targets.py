"""What the rules ask of a config: the files each figure reads, what a stored file must hold,
the markers that rebuild a file that is not the run the config asks for, and every artifact."""
from __future__ import annotations

from pathlib import Path
from typing import Any

from .. import layout
from .configs import ROOT, _resolved, canonical_scene, convergence_figures, expand, figures, kinds, scene_params, scenes


def path_spec(config: dict[str, Any], figure: str, scene: str) -> dict[str, Any]:
    """What the rule load_path runs for one scene of a path figure (the kind decides)."""
    fig = config["figures"][figure]
    return kinds.get(fig["kind"]).path_spec(fig, scene)


def figure_sims(config: dict[str, Any], figure: str) -> list[str]:
    """Scene dataset files of a figure, in its scene order (shared scenes point to one file;
    the points of a stability map are probes, which record failures instead of raising)."""
    source = kinds.source(config["figures"][figure]["kind"])
    if source == "probe":
        return [layout.probe_path(figure, s) for s in scenes(config, figure)]
    if source == "path":
        return [layout.path_file(figure, s) for s in scenes(config, figure)]
    return [layout.sim_path(*canonical_scene(config, figure, s)) for s in scenes(config, figure)]


def wanted_scene(config: dict[str, Any], figure: str, scene: str, shared: bool = True) -> dict[str, Any] | None:
    """What the file of a scene must store (analysis.run_checks.check_file): every Scene parameter, defaults
    filled in, under the name of the run that makes the file (with ``shared``, a shared run's
    first figure; without, the scene is the file's own run). None for a stability-map probe,
    whose file records its raw input and how it ended."""
    source = kinds.source(config["figures"][figure]["kind"])
    if source == "probe":
        return None
    f, s = canonical_scene(config, figure, scene) if source == "simulate" and shared else (figure, scene)
    params = scene_params(config, f, s)
    return {**_resolved(params)[0], "name": params["name"]}


def figure_wanted(config: dict[str, Any], figure: str) -> list[dict[str, Any] | None]:
    """wanted_scene of each of a figure's scene files, in the order of figure_sims."""
    return [wanted_scene(config, figure, s) for s in scenes(config, figure)]


_CHECKED: dict[tuple, str | None] = {}


def stale_inputs(config: dict[str, Any], figure: str, scene: str, path: str) -> list[str]:
    """[marker] if the existing file ``path`` of this scene is unreadable or stores another scene
    than the config's (a file copied over another, or built from another config after
    Snakemake's metadata in .snakemake/ was lost), else []. The marker is touched now, so the
    rule that makes the file sees an input newer than its output and rebuilds it (and so
    everything downstream); a note names the file and the first differing parameter."""
    from ..analysis.run_checks import problem

    marker = layout.rebuild_marker(figure, scene)
    file = Path(path)
    if not file.is_file():
        return []
    wanted = wanted_scene(config, figure, scene, shared=False)
    if wanted is None:
        return []
    st = file.stat()
    key = (str(file), st.st_mtime_ns, st.st_size, repr(sorted(wanted.items())))
    if key not in _CHECKED:
        _CHECKED[key] = problem(file, wanted)
        if _CHECKED[key]:
            import sys

            print(f"note: {_CHECKED[key]}: it will be rebuilt", file=sys.stderr)
    if _CHECKED[key] is None:
        if marker.exists():
            marker.unlink()
        return []
    marker.parent.mkdir(parents=True, exist_ok=True)
    if not marker.exists() or marker.stat().st_mtime_ns <= st.st_mtime_ns:
        marker.touch()
        if marker.stat().st_mtime_ns <= st.st_mtime_ns:  # a file stamped in the future
            import os

            os.utime(marker, ns=(st.st_atime_ns, st.st_mtime_ns + 1_000_000_000))
    return [str(marker)]


def expected_outputs(config: dict[str, Any]) -> dict[str, list[str]]:
    """Every artifact a full run of this config produces, by kind (sweeps and ensembles
    expanded into scenes)."""
    config = expand(config)
    out: dict[str, list[str]] = {"sims": [], "datasets": [], "figures": [], "checks": []}
    for f in figures(config):
        out["sims"] += [p for p in figure_sims(config, f) if p not in out["sims"]]
        out["datasets"].append(layout.dataset_path(f))
        out["figures"] += list(layout.figure_paths(f))
    out["checks"] = [layout.check_path(f) for f in convergence_figures(config)]
    out["budget"] = budget_outputs(config)
    out["paper"] = paper_outputs(config)
    out["views"] = view_outputs(config)
    return out


def view_figures(config: dict[str, Any]) -> list[str]:
    """The figures whose scene files are simulations (not probes or load paths): each gets the 3-D
    views of its simulations (rule views)."""
    return [f for f in figures(config) if kinds.source(config["figures"][f]["kind"]) == "simulate"]


def view_outputs(config: dict[str, Any]) -> list[str]:
    """The folder of the 3-D views of those figures' simulations (rule views), if there is any."""
    return [layout.VIEWS_FOLDER] if view_figures(config) else []


def view_scenes(config: dict[str, Any]) -> list[tuple[str, str, list[tuple[str, str]]]]:
    """What rule views draws: (figure, title, [(scene, scene file), ...]) of each such figure."""
    return [(f, config["figures"][f].get("title", f), list(zip(scenes(config, f), figure_sims(config, f))))
            for f in view_figures(config)]


def view_sims(config: dict[str, Any]) -> list[str]:
    """The scene files rule views reads (a file shared by two figures once)."""
    return sorted({p for _, _, pairs in view_scenes(config) for _, p in pairs})


def view_pages(config: dict[str, Any]) -> list[str]:
    """The files in that folder: its index, the shared plotly.js and one page per simulation."""
    if not view_figures(config):
        return []
    pages = [layout.view_page(f, s) for f in view_figures(config) for s in scenes(expand(config), f)]
    return [layout.VIEWS_INDEX, str(layout.VIEWS / layout.VIEWS_PLOTLY), *pages]


def budget_outputs(config: dict[str, Any]) -> list[str]:
    """The error budget (rule error_budget), if a figure of the config reports headline numbers."""
    if any(kinds.has_headlines(config["figures"][f]["kind"]) for f in figures(config)):
        return [layout.ERROR_BUDGET_NC, layout.ERROR_BUDGET_CSV]
    return []


def paper_outputs(config: dict[str, Any]) -> list[str]:
    """The claims table and the manuscript PDF, if the config has a paper section."""
    paper = config.get("paper")
    if not paper:
        return []
    return [layout.CLAIMS_CSV, layout.CLAIMS_NC, layout.paper_pdf(Path(paper["manuscript"]).stem)]


def claim_sims(config: dict[str, Any]) -> dict[str, str]:
    """'figure/scene' -> simulation file, for the figures whose simulations the claims read."""
    from .. import claims

    paper = config.get("paper")
    if not paper:
        return {}
    listed = claims.load(ROOT / paper["claims"])
    return {f"{f}/{s}": p for f in claims.sim_figures(listed)
            for s, p in zip(scenes(config, f), figure_sims(config, f))}


def claim_wanted(config: dict[str, Any]) -> list[dict[str, Any] | None]:
    """wanted_scene of each file of claim_sims, in its order."""
    return [wanted_scene(config, *key.split("/", 1)) for key in claim_sims(config)]
