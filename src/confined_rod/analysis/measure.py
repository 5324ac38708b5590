"""Measurements of finished scene datasets (post-processing: reads datasets, never runs the simulator).

Every function takes one scene dataset as written by ``simulate`` (variables
``F_z(s)``, ``x, y, z, contact(s_link)``, ``phi, dphi_ds(s_helix)``, attributes
``L, l0, R, EI, load``) and returns plain numbers or arrays.
"""
from __future__ import annotations

import numpy as np
import xarray as xr


def n_turns(sim: xr.Dataset) -> float:
    """Turns of the wall-contact stretch about the axis, |phi_end - phi_start|/(2 pi)."""
    phi = sim["phi"].values
    return float(abs(phi[-1] - phi[0]) / (2 * np.pi)) if phi.size >= 2 else 0.0


def bulk_pitch(sim: xr.Dataset) -> float:
    """Axial length of one turn, 2 pi |dz/dphi|, fitted over the middle half of the
    wall-contact stretch; 0 if the stretch winds less than one turn."""
    if n_turns(sim) < 1.0:
        return 0.0
    phi = sim["phi"].values
    z = sim["z"].sel(s_link=sim["s_helix"].values).values
    n = phi.size
    mid = slice(n // 4, n - n // 4)
    slope = np.polyfit(phi[mid], z[mid], 1)[0]
    return float(2 * np.pi * abs(slope))


def contact_range(sim: xr.Dataset) -> tuple[float, float]:
    """Arc lengths of the joints that bound the wall-contact stretch: the upper end of the
    first run of at least HELIX_RUN consecutive links on the wall and the lower end of the
    last such run (wall forces act on link ends), i.e. (detached length at the loaded end,
    L - detached length at the support).  Isolated contacts of a detached tip do not start
    the stretch (the end links of a buckled rod touch the wall, so the first and last contacts
    would make the stretch the whole rod).  Without such a run (a planar rod on a few points):
    the first and the last link on the wall; (L, L) if no link touches it."""
    L = float(sim.attrs["L"])
    contact = np.asarray(sim["contact"].values)
    if not contact.any():
        return L, L
    if helix_runs(contact):
        top, bottom = detached_lengths(sim)
        return top, L - bottom
    s = np.asarray(sim["s_link"].values, dtype=float)[contact == 1]
    half = 0.5 * float(sim.attrs["l0"])
    return float(s.min() - half), float(s.max() + half)


HELIX_RUN = 4  # links: a run of wall contacts at least this long is helix; shorter ones near an end are tips


def helix_runs(contact: np.ndarray, run: int = HELIX_RUN) -> list[np.ndarray]:
    """Link indices of the runs of at least `run` consecutive links on the wall, in order
    from the loaded end (link 0)."""
    idx = np.flatnonzero(np.asarray(contact) > 0)
    if idx.size == 0:
        return []
    runs = np.split(idx, np.flatnonzero(np.diff(idx) > 1) + 1)
    return [r for r in runs if r.size >= run]


def detached_lengths(sim: xr.Dataset, run: int = HELIX_RUN) -> tuple[float, float]:
    """Arc lengths (loaded end, support end) over which the rod is detached from the wall:
    from s = 0 (the loaded end, link 0) to the upper end of the first run of at least `run`
    consecutive links on the wall, and from the lower end of the last such run to s = L.
    Isolated tip contacts (shorter runs) do not count.  (L, L) if there is no such run."""
    L = float(sim.attrs["L"])
    runs = helix_runs(sim["contact"].values, run)
    if not runs:
        return L, L
    s_link = np.asarray(sim["s_link"].values, dtype=float)
    half = 0.5 * float(sim.attrs["l0"])
    return float(s_link[runs[0][0]] - half), float(L - (s_link[runs[-1][-1]] + half))


def euler_ratio(sim: xr.Dataset) -> float:
    """Load over Euler's critical force pi^2 EI/L^2 (the ratio the paper's captions quote)."""
    return float(sim.attrs["load"]) * float(sim.attrs["L"]) ** 2 / (np.pi**2 * float(sim.attrs["EI"]))


def transmitted_fraction(sim: xr.Dataset) -> float:
    """|F_z(L)| / |F_z(0)|."""
    return float(sim["F_transmitted"]) / float(sim.attrs["load"])


def force_at_links(sim: xr.Dataset) -> np.ndarray:
    """|F_z| at the link centres (mean of the two joints of each link), from the loaded end."""
    F = np.abs(sim["F_z"].values)
    return 0.5 * (F[1:] + F[:-1])


def handedness_reversals(dphi_ds: np.ndarray) -> np.ndarray:
    """Indices i where the sign of dphi/ds changes between points i and i+1 of the
    contact stretch (a reversal of handedness, or perversion)."""
    sign = np.sign(dphi_ds)
    return np.flatnonzero(sign[1:] * sign[:-1] < 0)


def defects(s: np.ndarray, dphi_ds: np.ndarray, min_links: int = 3,
            min_rate: float = 0.0) -> np.ndarray:
    """Arc lengths of the defects of a helix: reversals of handedness between two
    stretches of at least ``min_links`` links winding in opposite senses.

    A flicker of the sign of dphi/ds over fewer links (round-off where the rod is
    nearly straight, one link crossing a wall contact) is not a defect: runs of one
    sign shorter than min_links are merged into their neighbours first.  Points with
    |dphi/ds| <= min_rate count as no sense at all.  The position of a defect is the
    midpoint between the last point of one sense and the first of the other."""
    sense = np.where(np.abs(dphi_ds) > min_rate, np.sign(dphi_ds), 0.0)
    keep = sense != 0
    s, sense = np.asarray(s)[keep], sense[keep]
    if sense.size == 0:
        return np.zeros(0)
    # runs of one sense: (start index, length, sign)
    edges = np.flatnonzero(np.diff(sense) != 0) + 1
    starts = np.concatenate([[0], edges])
    lengths = np.diff(np.concatenate([starts, [sense.size]]))
    signs = sense[starts]
    long_runs = [(i, n, sg) for i, n, sg in zip(starts, lengths, signs) if n >= min_links]
    out = []
    for (i0, n0, s0), (i1, _, s1) in zip(long_runs[:-1], long_runs[1:]):
        if s0 != s1:
            out.append(0.5 * (s[i0 + n0 - 1] + s[i1]))
    return np.asarray(out)


def half_reduction_length(L: np.ndarray, fraction: np.ndarray, threshold: float = 0.5) -> tuple[float, str]:
    """The rod length at which the transmitted fraction |F_z(L)|/|F_z(0)| first falls below
    `threshold` (1/2 by default), interpolated linearly in (ln L, ln fraction) between the
    bracketing lengths; with how it was found: 'interpolated', 'upper bound' (already below at
    the shortest length, which is returned) or 'lower bound' (never below; the longest length)."""
    L, fraction = np.asarray(L, dtype=float), np.asarray(fraction, dtype=float)
    below = np.flatnonzero(fraction < threshold)
    if below.size == 0:
        return float(L[-1]), "lower bound"
    i = int(below[0])
    if i == 0:
        return float(L[0]), "upper bound"
    x = np.interp(np.log(threshold), [np.log(fraction[i]), np.log(fraction[i - 1])],
                  [np.log(L[i]), np.log(L[i - 1])])
    return float(np.exp(x)), "interpolated"
