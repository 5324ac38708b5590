"""Seed ensembles: statistics over runs that differ only in the random seed of their start.

With friction the equilibrium depends on the path, so one run per point is an anecdote. A
scene of the config may ask for ``seeds: N`` (seeds s, s+1, ..., s+N-1 from the scene's own
``seed``) or ``seeds: [list]``; :func:`confined_rod.pipeline.expand_ensembles` turns it into
one scene per seed (``<scene>-s<seed>``), each its own cached simulation, and the figure kinds
that support ensembles (``ENSEMBLES = True``) group the members back (runs whose parameters
differ only in the seed) and store what :func:`stats` and :func:`final_class` compute.

Post-processing: reads datasets only.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Iterable, Mapping, Sequence

import numpy as np
import xarray as xr

from . import measure

CLASSES = ("helix", "planar", "defects")


@dataclass(frozen=True)
class Stats:
    n: int
    mean: float
    std: float      # sample standard deviation (ddof = 1); 0 for a single member
    sem: float      # standard error of the mean, std / sqrt(n)
    min: float
    max: float


def stats(values: Iterable[float]) -> Stats:
    v = np.asarray(list(values), dtype=float)
    if v.size == 0:
        raise ValueError("an ensemble needs at least one member")
    if not np.all(np.isfinite(v)):
        raise ValueError(f"ensemble values must be finite, got {v.tolist()}")
    std = float(np.std(v, ddof=1)) if v.size > 1 else 0.0
    return Stats(int(v.size), float(np.mean(v)), std, std / np.sqrt(v.size), float(v.min()), float(v.max()))


def final_class(sim: xr.Dataset) -> str:
    """helix (the wall-contact stretch winds at least one turn, one handedness), defects (a
    helix with a reversal of handedness between stretches of >= 3 links) or planar (less
    than a turn: the rod jammed or buckled without coiling)."""
    if measure.n_turns(sim) < 1.0:
        return "planar"
    found = measure.defects(np.asarray(sim["s_helix"].values), np.asarray(sim["dphi_ds"].values))
    return "defects" if len(found) else "helix"


def member_key(params: Mapping[str, object]) -> tuple:
    """What ensemble members share: every parameter but the seed and the name."""
    return tuple(sorted((k, repr(v)) for k, v in params.items() if k not in ("seed", "name")))


def group(names: Sequence[str], attrs: Mapping[str, Mapping[str, object]], params: Sequence[str]) -> list[list[str]]:
    """Members grouped by the values of `params` (e.g. ('L', 'pore_length')), groups in the
    order of their first member, members by seed."""
    groups: dict[tuple, list[str]] = {}
    for n in names:
        groups.setdefault(tuple(repr(attrs[n].get(p)) for p in params), []).append(n)
    return [sorted(g, key=lambda n: int(attrs[n].get("seed", 0))) for g in groups.values()]


def base_name(name: str, seed: int) -> str:
    """The config's scene name of an ensemble member ``<scene>-s<seed>`` (the names
    :func:`confined_rod.pipeline.expand_ensembles` gives); any other name as it is."""
    suffix = f"-s{seed}"
    return name[:-len(suffix)] if name.endswith(suffix) and len(name) > len(suffix) else name


def by_base(names: Sequence[str], seeds: Mapping[str, int]) -> dict[str, list[str]]:
    """Members grouped by their config scene name (:func:`base_name`), in the order of the
    first member, members by seed: the first of each list is the ensemble's lowest seed."""
    out: dict[str, list[str]] = {}
    for n in names:
        out.setdefault(base_name(n, int(seeds[n])), []).append(n)
    return {b: sorted(m, key=lambda n: int(seeds[n])) for b, m in out.items()}


class Padded:
    """Members of several ensembles (groups of scene ids) as rectangular arrays: row i holds
    group i's members, padded to the largest group; ``has`` is 1 where a member exists."""

    def __init__(self, groups: Sequence[Sequence[str]], sims: Mapping[str, xr.Dataset]):
        self.groups, self.sims = [list(g) for g in groups], sims
        n_max = max(len(g) for g in self.groups)
        self.has = np.zeros((len(self.groups), n_max), dtype=np.int8)
        for i, g in enumerate(self.groups):
            self.has[i, :len(g)] = 1

    def values(self, fn, fill: float = 0.0) -> np.ndarray:
        """fn(member dataset) for every member; `fill` where has is 0."""
        out = np.full(self.has.shape, fill, dtype=float)
        for i, g in enumerate(self.groups):
            out[i, :len(g)] = [fn(self.sims[n]) for n in g]
        return out

    def mean(self, fn) -> np.ndarray:
        """Mean of fn over each group's members."""
        return (self.values(fn) * self.has).sum(axis=1) / self.has.sum(axis=1)


def seeds_of(spec, first: int) -> list[int]:
    """The seeds of a `seeds:` entry: N -> first, ..., first + N - 1; a list as given."""
    if isinstance(spec, bool) or not isinstance(spec, (int, list)):
        raise ValueError(f"seeds must be a count or a list of seeds, got {spec!r}")
    out = list(range(first, first + spec)) if isinstance(spec, int) else list(spec)
    if not out or len(set(out)) != len(out) or any(isinstance(s, bool) or not isinstance(s, int) or s < 0
                                                   for s in out):
        raise ValueError(f"seeds must give at least one distinct non-negative integer seed, got {spec!r}")
    return out
