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


def end_points(r: np.ndarray, t: np.ndarray, h: float) -> np.ndarray:
    """The link end points (2N, 3) in the order of kernels.end_normal_forces: r_i - h t_i at
    2i, r_i + h t_i at 2i + 1 (the stick anchors of friction at the ends, where they start)."""
    return np.ascontiguousarray(np.stack([r - h * t, r + h * t], axis=1).reshape(-1, 3))


def end_friction(par: np.ndarray, r: np.ndarray, t: np.ndarray, anchors: np.ndarray, k_t: float,
                 ws: Workspace) -> np.ndarray:
    """The friction of the link ends on the wall from their stick anchors (kernels.end_friction_loads):
    the net force on each link into ws.Ff, its stick flags into ws.stuck; returns the friction's
    torque about each link centre (N, 3)."""
    n2 = 2 * r.shape[0]
    Ne, fmax, pf = np.zeros(n2), np.zeros(n2), np.zeros((n2, 3, 3))
    K.end_friction_bounds(r, t, par, Ne, fmax)
    K.point_frames(r, t, par[K.HALF], pf)
    F, M = np.zeros_like(r), np.zeros_like(r)
    K.end_friction_loads(r, t, anchors, pf, par[K.HALF], fmax, k_t, F, M, ws.Ff, ws.stuck)
    return M


def evaluate(par: np.ndarray, r: np.ndarray, t: np.ndarray, ws: Workspace,
             end_anchors: np.ndarray | None = None, k_t: float = 0.0) -> tuple[float, float]:
    """All forces on the state, wall friction included when k_fr > 0: at the link centres by
    the rigid rule (kernels.coulomb_friction), or, given the stick anchors of the link ends
    (Scene.friction_at = "ends", shape (2N, 3)), at the link ends by their stick springs k_t
    capped at Coulomb's bound (kernels.end_friction_loads, the implicit solver's friction).
    Returns (F_z at the support, z force of the floor on the rod)."""
    _, fz_support, f_floor = K.conservative_loads(r, t, par, ws.Fm, ws.Fp, ws.F, ws.M, ws.Nw)
    if par[K.K_FR] > 0.0 and end_anchors is not None:
        ws.M += end_friction(par, r, t, end_anchors, k_t, ws)
        ws.F += ws.Ff
    elif par[K.K_FR] > 0.0:
        K.coulomb_friction(r, par, ws.Nw, ws.F, ws.Ff, ws.stuck)
    else:
        ws.Ff[:] = 0.0
        ws.stuck[:] = 0.0
    return fz_support, f_floor
