"""Seed ensembles: statistics over runs that differ only in the random seed of their start.

With friction the equilibrium depends on the path, so one run per point is an anecdote. A
scene of the config may ask for ``seeds: N`` (seeds s, s+1, ..., s+N-1 from the scene's own
``seed``) or ``seeds: [list]``; :func:`confined_rod.pipeline.expand` turns it into
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

#: final-state classes (flag_meanings of ``member_class``; new classes are appended so that the
#: codes of the others stay): helix (coiled, one handedness), planar (buckled in a plane along
#: the pore axis), defects (coiled with a reversal of handedness), straight (not buckled),
#: twisted (buckled out of any plane but not coiled: a zig-zag whose plane turns along the rod,
#: crossing the axis between its contacts, as two of Fig 6's five L = 40 R rods jam)
CLASSES = ("helix", "planar", "defects", "straight", "twisted")

# Thresholds of final_class, all on the link centres and in units of the pore radius R.
#: straight: every link centre within this distance of the chord through the first and the last
#: one. An unbuckled rod deviates from its chord by the start perturbation (1e-3 R) and the wall
#: penetration (~1e-3 R); any buckled rod in the pore by a good fraction of R. Same value as
#: confined_rod.sim.load_paths.STRAIGHT_MAX (the classes of Fig 3).
STRAIGHT_MAX = 0.05
#: planar: the rms spread of (x, y) across the pore along its smaller principal axis is below
#: this. A rod buckled in a plane parallel to the axis projects onto a line across the pore,
#: with a spread of the start perturbation (1e-3 R) plus whatever out-of-plane bow friction
#: locked in while the shape grew: 0.02-0.06 R for the planar S-shapes of Fig 6 (L = 20 R,
#: seeds 0 and 4; L = 40 R, seed 4). Any coil spreads in both directions: an arc on the wall of
#: a quarter turn has 0.09 R along its smaller axis, half a turn 0.31 R, whole turns
#: R/sqrt(2) = 0.71 R; the least-spread non-planar rods of Fig 6 have 0.25 R.
PLANAR_RMS = 0.1
#: off-axis: the azimuth phi = atan2(y, x) of a link centre further than this from the axis is
#: defined to ~1e-3 rad against the perturbation and the wall penetration (~1e-3 R); near the
#: axis it is not, and a rod crossing the axis turns phi by ~pi with no handedness.
OFF_AXIS = 0.5
#: a step of phi larger than this between consecutive off-axis centres is an axis crossing, not
#: winding: a helix on the wall turns by omega l0 <= l0/R per link (|t| = 1 gives R omega <= 1),
#: at most 1 rad for l0 <= R.
MAX_STEP = 0.5 * np.pi
#: handedness: |dphi/ds| at or below this (rad/R) has no sense. The slowest helix of the
#: publication configs (Fig 7, 0.0125 EI/R^2) winds at 0.045-0.1 rad/R (5th-95th percentile),
#: the round-off of a converged state (positions to ~1e-5 R) gives ~1e-5 rad/R, and the near
#: straight stretch above the support of Fig 6's L = 640 R rods turns at ~0.001 rad/R (no sense).
MIN_RATE = 0.01
#: handedness runs shorter than this many link increments are flicker, not a helical stretch
#: (as the defects of Fig 2, figures.transition.MIN_DEFECT_LINKS)
MIN_RUN = 3
#: coiled: the off-axis links wind by at least this many turns in all (sum of |dphi|, so that
#: the two senses of a defect do not cancel). A short coil winds little: at 0.25 EI/R^2 one turn
#: takes 2 pi/omega = 17 R of arc, and an L = 20 R rod keeps about 10 R of it between its
#: detached ends, about 0.55 turn (Fig 6, L = 20 R, seeds 1-3: 0.54-0.55). A twisted zig-zag
#: turns its azimuth by crossing the axis, which is not winding, and keeps 0.10-0.16 turn (Fig 6,
#: L = 40 R, seeds 0 and 1). 0.3 lies between them with a factor of ~1.8 on either side.
HELIX_MIN_TURNS = 0.3


@dataclass(frozen=True)
class Shape:
    """The geometry final_class decides on (lengths in R)."""
    deflection: float       # largest distance of a link centre from the chord of the first and last
    spread_min: float       # rms of (x, y) about its mean along the smaller principal axis
    spread_max: float       # ... and along the larger one
    net_turns: float        # |sum of the phi increments| / 2 pi over the off-axis links
    total_turns: float      # sum of |phi increments| / 2 pi
    reversals: np.ndarray   # arc lengths of the reversals of handedness (measure.defects)


def shape(sim: xr.Dataset) -> Shape:
    """The whole rod's geometry from the link centres x, y, z (link 0 at the loaded end,
    ``s_link`` its arc length): straightness, spread across the pore, winding and
    reversals of handedness. Rotation about the pore axis leaves every number unchanged."""
    R = float(sim.attrs.get("R", 1.0))
    r = np.stack([np.asarray(sim[c].values, dtype=float) for c in "xyz"], axis=1) / R
    s = np.asarray(sim["s_link"].values, dtype=float) / R
    chord = r[-1] - r[0]
    rel = r - r[0]
    if np.linalg.norm(chord) > 0:
        rel = rel - np.outer(rel @ chord / (chord @ chord), chord)
    deflection = float(np.linalg.norm(rel, axis=1).max()) if len(r) else 0.0
    xy = r[:, :2] - r[:, :2].mean(axis=0)
    lam = np.linalg.eigvalsh(xy.T @ xy / max(len(r), 1))          # ascending
    spread_min, spread_max = (float(np.sqrt(max(v, 0.0))) for v in lam)
    rho = np.hypot(r[:, 0], r[:, 1])
    phi = np.arctan2(r[:, 1], r[:, 0])
    step = np.angle(np.exp(1j * np.diff(phi)))                  # wrapped to (-pi, pi]
    ok = (rho[1:] > OFF_AXIS) & (rho[:-1] > OFF_AXIS) & (np.abs(step) <= MAX_STEP)
    ds = np.diff(s)[ok]
    rate = step[ok] / np.where(ds > 0, ds, 1.0)
    reversals = measure.defects(0.5 * (s[1:] + s[:-1])[ok], rate, min_links=MIN_RUN, min_rate=MIN_RATE)
    return Shape(deflection, spread_min, spread_max, float(abs(step[ok].sum()) / (2 * np.pi)),
                 float(np.abs(step[ok]).sum() / (2 * np.pi)), reversals)


def final_class(sim: xr.Dataset) -> str:
    """The final state's class (CLASSES) from the geometry of the whole rod (:func:`shape`), in
    this order: straight (every link centre within STRAIGHT_MAX of the chord), planar (spread
    across the pore along the smaller principal axis below PLANAR_RMS), twisted (out of any
    plane but winding less than HELIX_MIN_TURNS turns in all), defects (coiled, with a
    reversal of handedness between stretches of >= MIN_RUN off-axis links), helix (coiled,
    one handedness)."""
    sh = shape(sim)
    if sh.deflection < STRAIGHT_MAX:
        return "straight"
    if sh.spread_min < PLANAR_RMS:
        return "planar"
    if sh.total_turns < HELIX_MIN_TURNS:
        return "twisted"
    return "defects" if sh.reversals.size else "helix"


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


#: a seed whose contact stretch winds differently by at least this many turns in two runs that
#: differ only in the path (a ramp's steps) settled in another final state (measured on the
#: ramp ladders at L/R = 320: same-state pairs differ by <= 0.08 turn, switches by >= 0.5 turn)
STATE_TURNS = 0.25


def paired_changes(seeds: np.ndarray, v: np.ndarray, turns: np.ndarray, has: np.ndarray, i: int,
                   j: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Two ensembles (rows i and j of Padded arrays: seeds, values v, windings turns) compared
    seed by seed: (the seeds both have, the relative changes v_j/v_i - 1, whether the seed
    changed its final state, i.e. its winding by >= STATE_TURNS)."""
    at_i = {int(seeds[i, k]): k for k in range(has.shape[1]) if has[i, k]}
    at_j = {int(seeds[j, k]): k for k in range(has.shape[1]) if has[j, k]}
    common = sorted(set(at_i) & set(at_j))
    rel = np.array([v[j, at_j[s]] / v[i, at_i[s]] - 1.0 for s in common])
    changed = np.array([abs(turns[j, at_j[s]] - turns[i, at_i[s]]) >= STATE_TURNS for s in common], dtype=bool)
    return np.array(common, dtype=int), rel, changed


def group(names: Sequence[str], attrs: Mapping[str, Mapping[str, object]], params: Sequence[str]) -> list[list[str]]:
    """Members grouped by the values of `params` (e.g. ('L', 'pore_length')), groups in the
    order of their first member, members by seed."""
    groups: dict[tuple, list[str]] = {}
    for n in names:
        groups.setdefault(tuple(repr(attrs[n].get(p)) for p in params), []).append(n)
    return [sorted(g, key=lambda n: int(attrs[n].get("seed", 0))) for g in groups.values()]


def member_name(base: str, seed: int) -> str:
    """The scene name of the member of seed ``seed`` of the ensemble ``base``: ``<base>-s<seed>``
    (the pipeline's expansion of ``seeds``; base_name reads it back)."""
    return f"{base}-s{seed}"


def base_name(name: str, seed: int) -> str:
    """The config's scene name of an ensemble member (:func:`member_name`); any other name as it is."""
    suffix = member_name("", seed)
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
