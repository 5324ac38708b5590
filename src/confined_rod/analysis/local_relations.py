"""Local relations of the helix on the wall: what holds in whichever equilibrium a seed reached.

With friction a rod has many neighbouring equilibria, and a change of any numerical parameter
moves a seed from one to another; its final state is no per-seed question. The relations below
hold at every point of the regular helix whatever the state, so they are properties of the
discretisation and converge seed by seed (issue 43):

* ``decay_ratio``: the bulk decay rate d(1/|F_z|)/ds over the simple model's k_fr R/(4EI)
  (regions.analyse; friction only);
* ``wall_force_ratio``: the wall force per length K over its lowest order R F_z^2/(4EI), the
  median over the regular helix (exact constant pitch: 1/(1 - R^2 w^2), 1.14 at F = 0.25);
* ``pitch_ratio``: |dphi/ds| over the pitch rate w(F) of a torque-free helix on the wall at the
  local force, 2 EI w^2 sqrt(1 - R^2 w^2) = |F_z| (theory.helix_pitch_rate), the median over
  the regular helix;
* ``helix_balance``: K over rho w^2 (|F_z|/c - EI w^2), c = sqrt(1 - rho^2 w^2), the median over
  the regular helix (rho the link centre's distance from the axis, w = |dphi/ds|).

The first three compare the helix with the *torque-free* one, and a frictional helix is not
torque-free: the friction locks an axial torque into it (analysis/torque.py), which moves its
pitch and wall force off the torque-free values and with them the decay rate. That torque is a
property of the state the path selected (a ramp locks in more than a sudden load), so these
ratios move with the state: they are compared as distributions over the ensemble, like the final
states. ``helix_balance`` holds whatever the torque: eliminating the torque tau from the
Kirchhoff relations of a helix on the wall, F = c (2 EI w^2 - tau/(rho^2 w)) and
K = (EI rho^2 w^4 - w tau)/rho (analysis/torque.py, derived in docs/model.md), gives
K = rho w^2 (F/c - EI w^2), the lateral force balance of the helix: 1 in every equilibrium up
to the discretisation (and the helix's non-uniformity), so it is the relation that must converge
seed by seed. Dimensions: K in EI/R^3; rho w^2 F in R R^-2 EI R^-2 = EI/R^3; rho EI w^4 likewise.
Limit: tau = 0 gives F = 2 EI w^2 c, so K = rho w^2 (2 EI w^2 - EI w^2) = EI rho w^4, and to lowest
order in R w, R F^2/(4EI): the simple model's wall force.

Where the helix is regular: with friction the bulk of regions.detect less half a smoothing
window at each end (where the friction is at its Coulomb limit and mostly axial); without
friction the middle half of the longest stretch of links on the wall; in both, only if the
whole stretch (the bulk's links on the wall, or that longest stretch) winds at least MIN_TURNS
full turns about the axis. The relations are those of a helix
whose wall force is the same all around a turn; a stretch on the wall shorter than a turn is an
arc held between its detachment points (a handedness reversal or a detached stretch beside it),
whose wall force is set by those ends, not by the balance (seen in the l0 ladder: a 15 R arc of
0.5 turn between a reversal and the detached lower region balances at 0.70). Dimensions: every ratio
is a number (K in EI/R^3 over R F^2/EI; w in 1/R). Test twin: tests/test_local_relations.py
builds a helix with a prescribed F(s) and reads back the rate, K and w it was built with.

Post-processing only: reads datasets, never imports the simulator.
"""
from __future__ import annotations

import numpy as np
import xarray as xr

from .. import theory
from . import regions
from .measure import force_at_links, helix_runs

RELATIONS = ("decay_ratio", "wall_force_ratio", "pitch_ratio", "helix_balance")
#: the relation that holds in every equilibrium whatever its locked torque (module docstring); the
#: others compare with the torque-free helix and move with the state
UNIVERSAL = ("helix_balance",)
#: the ratios to the torque-free helix: their premise (no locked torque) is what a loosely wound
#: bulk breaks (:func:`loosely_wound`); compared as distributions of the state
TORQUE_FREE = tuple(k for k in RELATIONS if k not in UNIVERSAL)
#: a bulk whose wall force per length is below this share of the torque-free helix's R F_z^2/(4EI)
#: is loosely wound (:func:`loosely_wound`)
LOOSE_WALL_RATIO = 0.5
#: the least links of regular helix a median needs
MIN_LINKS = 8
#: the least azimuthal winding, in turns, of the stretch a relation is read on (module docstring)
MIN_TURNS = 1.0


def winding_turns(sim: xr.Dataset, idx: np.ndarray) -> float:
    """|phi(s_last) - phi(s_first)| / 2 pi over the links idx (phi unwrapped along s_helix); 0
    for fewer than two links."""
    if idx.size < 2 or sim["s_helix"].size < 2:
        return 0.0
    s = np.asarray(sim["s_link"].values, dtype=float)[[idx[0], idx[-1]]]
    phi = np.interp(s, np.asarray(sim["s_helix"].values, dtype=float), np.asarray(sim["phi"].values, dtype=float))
    return float(abs(phi[1] - phi[0]) / (2.0 * np.pi))


def regular_links(sim: xr.Dataset, analysis: regions.Analysis | None = None) -> np.ndarray:
    """Indices of the links (from the loaded end) where the helix is regular (module docstring)."""
    a = sim.attrs
    contact = np.asarray(sim["contact"].values) > 0
    s_link = np.asarray(sim["s_link"].values, dtype=float)
    if float(a["k_fr"]) > 0.0:
        an = analysis or regions.analyse(sim)
        if not an.regions.has_bulk:
            return np.zeros(0, dtype=int)
        r = an.regions
        stretch = np.flatnonzero((s_link >= r.s_bulk_start) & (s_link <= r.s_bulk_end) & contact)
        edge = 0.5 * regions.WINDOW_R * float(a["R"])
        idx = np.flatnonzero((s_link >= r.s_bulk_start + edge) & (s_link <= r.s_bulk_end - edge) & contact)
    else:
        runs = helix_runs(contact)
        if not runs:
            return np.zeros(0, dtype=int)
        stretch = max(runs, key=len)
        q = stretch.size // 4
        idx = stretch[q:stretch.size - q]
    return idx if winding_turns(sim, stretch) >= MIN_TURNS else np.zeros(0, dtype=int)


def measure(sim: xr.Dataset, analysis: regions.Analysis | None = None) -> dict[str, float | None]:
    """The relations of one scene dataset; None where one is not defined (no regular helix of
    MIN_LINKS links, no friction for the decay ratio, a bulk that winds less than MIN_TURNS).
    ``analysis``: the dataset's regions.analyse, if the caller has it already."""
    a = sim.attrs
    R, EI = float(a["R"]), float(a["EI"])
    an = (analysis or regions.analyse(sim)) if float(a["k_fr"]) > 0.0 else None
    out: dict[str, float | None] = {k: None for k in RELATIONS}
    idx = regular_links(sim, an)
    if an is not None and an.bulk is not None and an.model > 0 and idx.size:    # the bulk is a helix
        out["decay_ratio"] = an.bulk.rate / an.model
    if idx.size < MIN_LINKS:
        return out
    F = force_at_links(sim)[idx]
    K = np.asarray(sim["wall_force_density"].values, dtype=float)[idx]
    out["wall_force_ratio"] = float(np.median(K * 4.0 * EI / (R * F**2)))
    s_link = np.asarray(sim["s_link"].values, dtype=float)[idx]
    s_h = np.asarray(sim["s_helix"].values, dtype=float)
    carried = F * R**2 / EI < theory.HELIX_F_MAX        # a helix on the wall carries at most this force
    if s_h.size >= 2 and carried.sum() >= MIN_LINKS:
        w = np.interp(s_link[carried], s_h, np.abs(np.asarray(sim["dphi_ds"].values, dtype=float)))
        out["pitch_ratio"] = float(np.median(w / theory.helix_pitch_rate(F[carried], R, EI)))
    if s_h.size >= 2:
        out["helix_balance"] = helix_balance(sim, idx, F, K)
    return out


def helix_balance(sim: xr.Dataset, idx: np.ndarray, F: np.ndarray, K: np.ndarray) -> float | None:
    """The median over the links idx of K / (rho w^2 (F/c - EI w^2)) (module docstring), over the
    links where the balance's force term is positive (w^2 < F/(EI c): a helix that presses on the
    wall); None with fewer than MIN_LINKS of them."""
    a = sim.attrs
    EI = float(a["EI"])
    rho = np.hypot(np.asarray(sim["x"].values, dtype=float), np.asarray(sim["y"].values, dtype=float))[idx]
    s_link = np.asarray(sim["s_link"].values, dtype=float)[idx]
    w = np.interp(s_link, np.asarray(sim["s_helix"].values, dtype=float),
                  np.abs(np.asarray(sim["dphi_ds"].values, dtype=float)))
    c2 = 1.0 - (rho * w) ** 2
    c = np.sqrt(np.where(c2 > 0, c2, 1.0))
    law = rho * w**2 * (F / c - EI * w**2)
    ok = (c2 > 0) & (law > 0)
    if ok.sum() < MIN_LINKS:
        return None
    return float(np.median(K[ok] / law[ok]))


def loosely_wound(measured: dict[str, float | None]) -> bool | None:
    """Whether the relations ``measured`` (:func:`measure`) are those of a loosely wound bulk: a
    helix whose wall force per length is below LOOSE_WALL_RATIO of the torque-free helix's, None
    where no wall force ratio was read.

    The friction can lock an axial torque tau into the helix (analysis/torque.py), and
    K = (EI rho^2 w^4 - w tau)/rho: a torque that unwinds the helix lowers its pitch rate and its
    wall force together. The decay law d(1/|F_z|)/ds = k_fr R/(4EI) follows from the torque-free
    K = R F_z^2/(4EI) at the Coulomb limit (docs/model.md); with K at a quarter of it the bulk
    still slides at the Coulomb limit, so its decay rate is a quarter of the law's: another
    equilibrium, whose share of an ensemble the loading path sets. A description, not a filter:
    at the publication build's ramps (load 0.25, L = 320 R) two seeds of Fig 4(b)'s rod (k_fr 0.3,
    512 steps) read 0.21 and 0.24 against 0.89-1.09 for all others, a gap; every seed of Fig 4(c)'s
    rod (k_fr 0.8) reads 0.08-0.29, and Fig 4(a)'s (k_fr 0.1) spread over 0.45-0.95, across the
    threshold. Test twin: tests/test_local_relations.py builds helices with a prescribed K."""
    r = measured.get("wall_force_ratio")
    return None if r is None else bool(r < LOOSE_WALL_RATIO)
