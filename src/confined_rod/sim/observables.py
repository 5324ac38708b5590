"""Observables of an equilibrium (or final) state, ordered from the loaded end.

Sign convention: F_z at a joint is the z force exerted by the part of the rod
above the joint on the part below it (negative = compression); F_z(0) = -load,
and F_z(L) is the force the rod exerts on the lower support.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .model import kernels as K
from .model.forces import Workspace, end_friction, evaluate
from .scenes import Scene


@dataclass
class Observables:
    s: np.ndarray  # (N+1,) joints from the loaded end
    F_z: np.ndarray
    s_link: np.ndarray  # (N,) link centres from the loaded end
    r: np.ndarray  # (N, 3)
    t: np.ndarray  # (N, 3)
    wall_force: np.ndarray  # (N,)
    contact: np.ndarray
    friction_force: np.ndarray
    friction_z: np.ndarray
    friction_phi: np.ndarray  # axial torque about the pore axis over rho (the azimuthal component at the centre)
    stuck: np.ndarray
    s_helix: np.ndarray  # contact stretch
    phi: np.ndarray
    dphi_ds: np.ndarray
    L_z: float
    F_transmitted: float  # z force on the lower piston: support + floor contacts
    face_force: np.ndarray  # (N,) z force of the block's top face around the entrance on the link
    body_force_z: float  # z component of the body force on the whole rod


def face_forces(par: np.ndarray, r: np.ndarray, t: np.ndarray) -> np.ndarray:
    """z force (>= 0) of the block's top face z = z_top on each link (rod order, from below): the
    penalty k_w (z_top - z) on a link end below the face where the face is its nearest way out
    of the block (kernels._face_point, the same rule as the wall_forces kernel, in numpy). It is
    the one external force on the rod along z besides the load, the friction, the body force and
    the lower piston, so with them it closes the axial balance."""
    n = r.shape[0]
    h = par[K.HALF]
    out = np.zeros(n)
    for sgn in (-1.0, 1.0):
        p = r + sgn * h * t
        dz = par[K.Z_TOP] - p[:, 2]
        on_face = (dz >= 0.0) & (np.hypot(p[:, 0], p[:, 1]) - par[K.R_WALL] > dz)
        if sgn > 0.0 and par[K.GUIDED] > 0.5:
            on_face[n - 1] = False            # the guided loaded end is in its sleeve, not on the face
        out += np.where(on_face, par[K.K_WALL] * dz, 0.0)
    return out


def axial_forces(scene: Scene, r: np.ndarray, t: np.ndarray, fz_support: float) -> np.ndarray:
    """F_z at the N+1 joints, from the loaded end (s = 0) to the support (s = L)."""
    k = scene.constants().k
    h = 0.5 * scene.l0
    gz = (r[1:, 2] - h * t[1:, 2]) - (r[:-1, 2] + h * t[:-1, 2])  # bond b: links b, b+1
    bonds_from_top = (k * gz)[::-1]
    return np.concatenate([[-scene.load], bonds_from_top, [fz_support]])


def contact_stretch(contact: np.ndarray) -> slice:
    """From the first to the last link touching the wall (empty if < 3 links touch)."""
    idx = np.flatnonzero(contact)
    if idx.size < 3:
        return slice(0, 0)
    return slice(idx[0], idx[-1] + 1)


def compute(scene: Scene, r: np.ndarray, t: np.ndarray, anchors: np.ndarray | None = None) -> Observables:
    """The observables of the state (r, t). With friction at the link ends (Scene.friction_at)
    the friction is the run's own, from its stick anchors ``anchors`` (RunState.anchor); without
    them (a state no friction has acted on yet) it is the rigid rule at the link centres."""
    par = scene.params()
    ws = Workspace.for_links(scene.N)
    ends = anchors if scene.friction_at == "ends" else None
    fz_support, f_floor = evaluate(par, r, t, ws, ends, scene.k_t)
    F_z = axial_forces(scene, r, t, fz_support)
    s = np.arange(scene.N + 1) * scene.l0
    order = np.arange(scene.N)[::-1]  # link index from the loaded end
    s_link = (np.arange(scene.N) + 0.5) * scene.l0
    rr, tt = r[order], t[order]
    Nw = ws.Nw[order]
    Ff = ws.Ff[order]
    contact = (Nw > 0).astype(np.int8)
    sl = contact_stretch(contact)
    phi = np.unwrap(np.arctan2(rr[sl, 1], rr[sl, 0]))
    s_helix = s_link[sl]
    dphi = np.gradient(phi, s_helix) if phi.size >= 2 else np.zeros_like(phi)
    rho = np.hypot(rr[:, 0], rr[:, 1])
    # the friction's axial torque about the pore axis on each link, over rho: its azimuthal
    # component with friction at the centre; at the ends, plus the torque of the end forces
    # about the centre (the lever arm of an end is R, not rho)
    tau_z = rr[:, 0] * Ff[:, 1] - rr[:, 1] * Ff[:, 0]
    if ends is not None and scene.k_fr > 0.0:
        tau_z = tau_z + end_friction(par, r, t, ends, scene.k_t, Workspace.for_links(scene.N))[order, 2]
    f_phi = np.divide(tau_z, rho, out=np.zeros(scene.N), where=rho > 0)
    h = 0.5 * scene.l0
    L_z = float((r[-1, 2] + h * t[-1, 2]) - (r[0, 2] - h * t[0, 2]))
    return Observables(
        s=s, F_z=F_z, s_link=s_link, r=rr, t=tt, wall_force=Nw, contact=contact,
        friction_force=np.linalg.norm(Ff, axis=1), friction_z=Ff[:, 2], friction_phi=f_phi,
        stuck=ws.stuck[order].astype(np.int8), s_helix=s_helix, phi=phi, dphi_ds=dphi,
        L_z=L_z, F_transmitted=float(f_floor - F_z[-1]),
        face_force=face_forces(par, r, t)[order], body_force_z=float(par[K.FZ] * scene.N),
    )


def shape_measures(r: np.ndarray, R: float) -> tuple[float, float]:
    """(deflection, out_of_plane) of a rod's link centres, in units of R.

    deflection: largest distance of a centre from the straight line through the first
    and last centres (0 for a straight rod, also one lying diagonally across the pore);
    out_of_plane: rms distance of the centres from their best-fitting plane (0 for a
    straight or a planar rod, of order R for a helix)."""
    a, b = r[0], r[-1]
    d = b - a
    n = np.linalg.norm(d)
    rel = r - a
    if n > 0:
        rel = rel - np.outer(rel @ d / n**2, d)
    deflection = float(np.linalg.norm(rel, axis=1).max()) / R
    centred = r - r.mean(axis=0)
    sv = np.linalg.svd(centred, compute_uv=False)
    out_of_plane = float(sv[-1] / np.sqrt(r.shape[0])) / R if r.shape[0] >= 3 else 0.0
    return deflection, out_of_plane


#: a final state's known saddles (docs/model.md, "Caveat: saddles"), for the ``saddle`` flag
SADDLES = ("none", "straight_above_euler", "planar_above_second_threshold")
#: a rod is straight when no link centre is this far (R) from the line through its end centres
#: (the start's perturbation is 1e-3 R; a rod on the wall is deflected by about R), and planar
#: when its rms distance from its best plane is below PLANAR_R (a helix: about R)
STRAIGHT_R = 0.05
PLANAR_R = 0.01


def saddle(scene: Scene, r: np.ndarray) -> int:
    """Index in SADDLES of the known unstable equilibrium a state sits on: straight above the
    (discrete, diagonal) Euler load, or planar and frictionless above the second threshold
    4 pi^2 EI/L^2 (with friction a planar state on the wall can be held); 0 otherwise. A residual
    test cannot tell a saddle from a stable state, so a run can stop on one."""
    from .. import theory

    deflection, out_of_plane = shape_measures(r, scene.R)
    if deflection < STRAIGHT_R and scene.load > theory.first_threshold(scene.L, scene.R, scene.l0, scene.EI):
        return 1
    if (scene.k_fr == 0.0 and deflection >= STRAIGHT_R and out_of_plane < PLANAR_R
            and scene.load > theory.second_threshold_estimate(scene.L, scene.EI)):
        return 2
    return 0
