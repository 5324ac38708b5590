"""Batches: the small scenes of a figure run in one process (rule batch; confined_rod.sim.runs),
each written to its own dataset in the batch's folder, then moved into place by its own job."""
from __future__ import annotations

from typing import Any

from .. import layout
from ..errors import ConfigError
from .configs import _config_stamp, build_scene, canonical_scene, figures, kinds, scene_params, scenes

#: estimated solver seconds (limits.estimated_solver_time) a batch holds at most: a job's start-up
#: (limits.JOB_STARTUP_S, ~2 s) is then at most a tenth of its work, while a long build still
#: spreads over its cores (a scene estimated above this runs alone)
BATCH_S = 20.0


_BATCHES: dict[int, tuple[dict[str, Any], tuple, dict[str, Any]]] = {}


def run_kind(config: dict[str, Any], figure: str) -> str | None:
    """The rule that runs a figure's scenes, 'simulate' or 'probe' (None for load paths)."""
    source = kinds.source(config["figures"][figure]["kind"])
    return source if source in ("simulate", "probe") else None


def solver_estimate(config: dict[str, Any], figure: str, scene: str) -> float:
    """limits.estimated_solver_time of a scene of the config (0 for input that builds no Scene)."""
    from ..limits import estimated_solver_time

    try:
        return estimated_solver_time(build_scene(config, figure, scene))
    except ConfigError:  # a probe of deliberately invalid input stops at once
        return 0.0


def job_estimate_s(config: dict[str, Any], figure: str, scene: str, runs: int = 1) -> float:
    """A job's estimated wall time (s) for a scene run alone (runs = 1) or a load path (runs = 10:
    tens of loads in one process): one start-up (limits.JOB_STARTUP_S) and ``runs`` times the
    scene's solver estimate. The rules' priorities and est_s, and tools/progress_error.py's replay."""
    from ..limits import JOB_STARTUP_S

    return JOB_STARTUP_S + runs * solver_estimate(config, figure, scene)


def batch_estimate_s(config: dict[str, Any], figure: str, members: list[str]) -> float:
    """A batch's estimated wall time (s): one start-up and its members' solver estimates."""
    from ..limits import JOB_STARTUP_S

    return JOB_STARTUP_S + sum(solver_estimate(config, figure, m) for m in members)


def plan_batches(names: list[str], cost: list[float], budget: float = BATCH_S) -> list[list[str]]:
    """Consecutive scenes (declaration order: a seed ensemble's members are neighbours) packed
    into batches of at most ``budget`` estimated seconds; a scene above it is a batch of its own."""
    out: list[list[str]] = []
    total = 0.0
    for name, c in zip(names, cost):
        if out and total + c <= budget:
            out[-1].append(name)
            total += c
        else:
            out.append([name])
            total = c
    return out


def batch_name(members: list[str]) -> str:
    """A batch is named by its first and last member (stable while they stay neighbours)."""
    return members[0] if len(members) == 1 else f"{members[0]}-to-{members[-1]}"


def _batch_index(config: dict[str, Any]) -> dict[str, Any]:
    """{'batches': {figure: {batch: [scenes]}}, 'of': {(figure, scene): batch}} for the scenes each
    figure runs itself (a shared scene runs in its first figure); single-scene batches are left
    out (such a scene runs in its own job). Built once per config, as the canonical index."""
    stamp = _config_stamp(config)
    cached = _BATCHES.get(id(config))
    if cached is None or cached[0] is not config or cached[1] != stamp:
        index: dict[str, Any] = {"batches": {}, "of": {}}
        for f in figures(config):
            kind = run_kind(config, f)
            if kind is None:
                continue
            own = [s for s in scenes(config, f) if kind == "probe" or canonical_scene(config, f, s) == (f, s)]
            for members in plan_batches(own, [solver_estimate(config, f, s) for s in own]):
                if len(members) > 1:
                    name = batch_name(members)
                    index["batches"].setdefault(f, {})[name] = members
                    index["of"].update({(f, s): name for s in members})
        _BATCHES[id(config)] = cached = (config, stamp, index)
    return cached[2]


def batches(config: dict[str, Any], figure: str) -> dict[str, list[str]]:
    """The batches of a figure: name -> its scenes (scenes that run alone are in none)."""
    return _batch_index(config)["batches"].get(figure, {})


def batch_of(config: dict[str, Any], figure: str, scene: str) -> str | None:
    return _batch_index(config)["of"].get((figure, scene))


def _kind_batch(config: dict[str, Any], kind: str, figure: str, scene: str) -> str | None:
    """The batch of ``kind`` that runs this scene, or None if it runs alone."""
    batch = batch_of(config, figure, scene)
    return batch if batch and run_kind(config, figure) == kind else None


def member_batch(config: dict[str, Any], kind: str, figure: str, scene: str) -> list[str]:
    """[the manifest of the batch that runs this scene], or [] if it runs alone."""
    batch = _kind_batch(config, kind, figure, scene)
    return [layout.batch_manifest(kind, figure, batch)] if batch else []


def member_cache(config: dict[str, Any], kind: str, figure: str, scene: str) -> str:
    """The batch's copy of this scene's dataset ('' if it runs alone)."""
    batch = _kind_batch(config, kind, figure, scene)
    return layout.batch_member(kind, figure, batch, scene) if batch else ""


def batch_job(config: dict[str, Any], kind: str, figure: str, batch: str) -> dict[str, Any]:
    """What rule batch runs: the members' parameters and where each dataset goes."""
    members = batches(config, figure).get(batch)
    if not members or run_kind(config, figure) != kind:
        raise ConfigError(f"figures.{figure}: no {kind} batch named {batch!r}")
    return {"members": [scene_params(config, figure, s) for s in members],
            "outputs": [layout.batch_member(kind, figure, batch, s) for s in members],
            "folder": layout.batch_folder(kind, figure, batch)}


def batch_outputs(config: dict[str, Any]) -> list[str]:
    """Every batch manifest of the config."""
    return [layout.batch_manifest(run_kind(config, f), f, b) for f in figures(config) for b in batches(config, f)]
