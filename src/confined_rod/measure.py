"""Measurements of finished scene datasets (post-processing: reads datasets, never runs the simulator).

Every function takes one scene dataset as written by ``simulate`` (variables
``F_z(joint)``, ``x, y, z, contact(link)``, ``phi, dphi_ds(helix)``, attributes
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
    first link on the wall and the lower end of the last one (wall forces act on link
    ends). (L, L) if no link touches the wall."""
    s = sim["s_link"].values[sim["contact"].values == 1]
    if s.size == 0:
        L = float(sim.attrs["L"])
        return L, L
    half = 0.5 * float(sim.attrs["l0"])
    return float(s.min() - half), float(s.max() + half)


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
