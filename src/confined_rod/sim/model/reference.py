"""Plain-numpy twin of the total energy of the discrete model (for tests).

Written independently of the kernels, vectorised, with no shared code, so a
finite-difference gradient of :func:`total_energy` checks the forces and torques
of :mod:`confined_rod.sim.model.kernels`.
"""
from __future__ import annotations

import numpy as np

from . import kernels as K


def total_energy(r: np.ndarray, t: np.ndarray, par: np.ndarray) -> float:
    h = par[K.HALF]
    rm = r - h * t
    rp = r + h * t
    gap = rm[1:] - rp[:-1]
    e = 0.5 * par[K.K_BOND] * np.sum(gap**2)
    ends = np.concatenate([rm, rp])
    rho = np.hypot(ends[:, 0], ends[:, 1])
    # the solid around the pore: depth below its surface, the nearer of the wall rho = R
    # and the top face z = z_top; the guided loaded end r_{N-1}^+ meets the wall at any z
    radial = rho - par[K.R_WALL]
    below_face = par[K.Z_TOP] - ends[:, 2]
    depth = np.where((radial > 0) & (below_face >= 0), np.minimum(radial, below_face), 0.0)
    if par[K.GUIDED] > 0.5:
        depth[-1] = max(radial[-1], 0.0)
    e += 0.5 * par[K.K_WALL] * np.sum(depth**2)
    if par[K.FLOOR] > 0.5:
        # the lower end is exempt only when the support holds it (its spring sets its z)
        zs = np.concatenate([rm[1:, 2] if par[K.LOWER_HELD] > 0.5 else rm[:, 2], rp[:, 2]])
        e += 0.5 * par[K.K_WALL] * np.sum(np.minimum(zs, 0.0) ** 2)
    e += par[K.LOAD] * rp[-1, 2]
    ks = par[K.K_SUP]
    if par[K.LOWER_HELD] > 0.5:
        e += 0.5 * ks * rm[0, 2] ** 2
    if par[K.ENDS_PINNED] > 0.5:
        e += 0.5 * ks * (np.sum(rm[0, :2] ** 2) + np.sum(rp[-1, :2] ** 2))
    e += par[K.C_BEND] * np.sum(1.0 - np.einsum("ij,ij->i", t[:-1], t[1:]))
    e -= np.sum(r @ par[[K.FX, K.FY, K.FZ]])
    return float(e)
