"""Evaluate all forces and torques of a state (numpy-side wrapper of the kernels)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import kernels as K


@dataclass
class Workspace:
    """Preallocated force arrays of an N-link rod (see kernels for their meaning)."""

    Fm: np.ndarray
    Fp: np.ndarray
    F: np.ndarray
    M: np.ndarray
    Nw: np.ndarray
    Ff: np.ndarray
    stuck: np.ndarray

    @classmethod
    def for_links(cls, n: int) -> "Workspace":
        def z3():
            return np.zeros((n, 3))

        return cls(z3(), z3(), z3(), z3(), np.zeros(n), z3(), np.zeros(n))


def evaluate(par: np.ndarray, r: np.ndarray, t: np.ndarray, ws: Workspace) -> tuple[float, float]:
    """All forces on the state, wall friction included when k_fr > 0.
    Returns (F_z at the support, z force of the floor on the rod)."""
    _, fz_support, f_floor = K.conservative_loads(r, t, par, ws.Fm, ws.Fp, ws.F, ws.M, ws.Nw)
    if par[K.K_FR] > 0.0:
        K.coulomb_friction(r, par, ws.Nw, ws.F, ws.Ff, ws.stuck)
    else:
        ws.Ff[:] = 0.0
        ws.stuck[:] = 0.0
    return fz_support, f_floor
