"""numba kernels of the backward-Euler (implicit) step, one job each.

One implicit step of length dt from the state (r_n, t_n) minimises

    Phi(r, t) = E(r, t) + (beta/2dt) sum |r_i - r_n,i|^2 + (gamma_r/2dt) sum |t_i - t_n,i|^2
                + sum_i f_max,i |P_i (r_i - r_n,i)|,

E the conservative energy of model.kernels, P_i the projection onto the wall's
tangent plane at r_n,i (azimuthal and axial directions) and f_max,i the Coulomb
limit min(k_fr N_i, cap) with the wall force N_i of the step's start state.  The
stationarity condition of Phi is backward Euler for gamma dx/dt = F + friction,
and its last term is Coulomb's law: a link whose tangential force stays below
f_max does not move along the wall (the minimum of |v| sits at v = 0 exactly),
a sliding link feels f_max against its motion (docs/model.md, "implicit solver").

Coordinates of the Newton iteration, 5 per link (array shapes (N, 5)):
  0-2  displacement of the link centre along the local frame at r_n,i:
       radial n_i, azimuthal e_phi,i, axial e_z (frame[i, k, :], (N, 3, 3))
  3-4  rotation of the tangent in its tangent plane: t = (t + a e1 + b e2)/|...|
       with e1, e2 an orthonormal basis perpendicular to the current t.
The Hessian of the smooth part Phi_s = E + drag is built from coloured finite
differences of the kernel forces, except for the one-sided contact penalties
(wall, floor), whose curvature jumps where a contact switches on; they and the
friction term are added exactly (contact_hessian, friction_term).
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ..model import kernels as K

NDOF = 5  # coordinates per link
BAND = 2 * NDOF - 1  # half-bandwidth of the block-tridiagonal Hessian


@njit(cache=True)
def local_frames(r, frame):
    """Radial, azimuthal and axial unit vectors at each link centre (x axis for a
    centre on the cylinder axis)."""
    for i in range(r.shape[0]):
        rho = np.sqrt(r[i, 0] ** 2 + r[i, 1] ** 2)
        if rho > 1e-14:
            nx = r[i, 0] / rho
            ny = r[i, 1] / rho
        else:
            nx = 1.0
            ny = 0.0
        frame[i, 0, 0] = nx
        frame[i, 0, 1] = ny
        frame[i, 0, 2] = 0.0
        frame[i, 1, 0] = -ny
        frame[i, 1, 1] = nx
        frame[i, 1, 2] = 0.0
        frame[i, 2, 0] = 0.0
        frame[i, 2, 1] = 0.0
        frame[i, 2, 2] = 1.0


@njit(cache=True)
def tangent_bases(t, e1, e2):
    """Orthonormal e1, e2 perpendicular to each unit tangent t (e2 = t x e1)."""
    for i in range(t.shape[0]):
        # the coordinate axis least aligned with t, made perpendicular to it
        ax = np.abs(t[i, 0])
        ay = np.abs(t[i, 1])
        az = np.abs(t[i, 2])
        ux = 0.0
        uy = 0.0
        uz = 0.0
        if ax <= ay and ax <= az:
            ux = 1.0
        elif ay <= az:
            uy = 1.0
        else:
            uz = 1.0
        d = ux * t[i, 0] + uy * t[i, 1] + uz * t[i, 2]
        ux -= d * t[i, 0]
        uy -= d * t[i, 1]
        uz -= d * t[i, 2]
        n = np.sqrt(ux * ux + uy * uy + uz * uz)
        e1[i, 0] = ux / n
        e1[i, 1] = uy / n
        e1[i, 2] = uz / n
        e2[i, 0] = t[i, 1] * e1[i, 2] - t[i, 2] * e1[i, 1]
        e2[i, 1] = t[i, 2] * e1[i, 0] - t[i, 0] * e1[i, 2]
        e2[i, 2] = t[i, 0] * e1[i, 1] - t[i, 1] * e1[i, 0]


@njit(cache=True)
def smooth_gradient(r, t, nu, rn, tn, frame, e1, e2, cr, ct, par, Fm, Fp, F, M, Nw, g):
    """Phi_s = E + (cr/2)|r - r_n|^2 + (ct/2)|t - t_n|^2 and its gradient in the
    step coordinates (cr = beta/dt, ct = gamma_r/dt); nu[i] = |t + a e1 + b e2|
    before normalisation (1 at the expansion point).  Returns Phi_s."""
    phi, _, _ = K.conservative_loads(r, t, par, Fm, Fp, F, M, Nw)
    for i in range(r.shape[0]):
        dx = r[i, 0] - rn[i, 0]
        dy = r[i, 1] - rn[i, 1]
        dz = r[i, 2] - rn[i, 2]
        phi += 0.5 * cr * (dx * dx + dy * dy + dz * dz)
        gx = -F[i, 0] + cr * dx
        gy = -F[i, 1] + cr * dy
        gz = -F[i, 2] + cr * dz
        for k in range(3):
            g[i, k] = frame[i, k, 0] * gx + frame[i, k, 1] * gy + frame[i, k, 2] * gz
        ux = t[i, 0] - tn[i, 0]
        uy = t[i, 1] - tn[i, 1]
        uz = t[i, 2] - tn[i, 2]
        phi += 0.5 * ct * (ux * ux + uy * uy + uz * uz)
        # d Phi_s / dt projected on the tangent plane: -(M x t) + ct P_t (t - t_n)
        ut = ux * t[i, 0] + uy * t[i, 1] + uz * t[i, 2]
        wx = -(M[i, 1] * t[i, 2] - M[i, 2] * t[i, 1]) + ct * (ux - ut * t[i, 0])
        wy = -(M[i, 2] * t[i, 0] - M[i, 0] * t[i, 2]) + ct * (uy - ut * t[i, 1])
        wz = -(M[i, 0] * t[i, 1] - M[i, 1] * t[i, 0]) + ct * (uz - ut * t[i, 2])
        g[i, 3] = (wx * e1[i, 0] + wy * e1[i, 1] + wz * e1[i, 2]) / nu[i]
        g[i, 4] = (wx * e2[i, 0] + wy * e2[i, 1] + wz * e2[i, 2]) / nu[i]
    return phi


@njit(cache=True)
def displace(r, t, frame, e1, e2, p, alpha, r_out, t_out, nu):
    """State at coordinates alpha * p about (r, t): r + alpha sum_k p_k frame_k,
    t = (t + alpha (p_3 e1 + p_4 e2)) / nu."""
    for i in range(r.shape[0]):
        for c in range(3):
            r_out[i, c] = r[i, c] + alpha * (p[i, 0] * frame[i, 0, c] + p[i, 1] * frame[i, 1, c]
                                             + p[i, 2] * frame[i, 2, c])
        x = t[i, 0] + alpha * (p[i, 3] * e1[i, 0] + p[i, 4] * e2[i, 0])
        y = t[i, 1] + alpha * (p[i, 3] * e1[i, 1] + p[i, 4] * e2[i, 1])
        z = t[i, 2] + alpha * (p[i, 3] * e1[i, 2] + p[i, 4] * e2[i, 2])
        n = np.sqrt(x * x + y * y + z * z)
        nu[i] = n
        t_out[i, 0] = x / n
        t_out[i, 1] = y / n
        t_out[i, 2] = z / n


@njit(cache=True)
def fd_hessian(r, t, rn, tn, frame, e1, e2, cr, ct, par, h, g0, Fm, Fp, F, M, Nw,
               rp, tp, nu, gp, ab):
    """Hessian of Phi_s in the step coordinates by one-sided finite differences of
    the gradient (step h[d] in coordinate d: a length for 0-2, an angle for 3-4,
    so that the scheme is invariant under a change of units), in LAPACK lower banded storage ab[i - j, j] = H[i, j]
    (half-bandwidth BAND).  The Hessian is block-tridiagonal (each link interacts
    with its neighbours only), so links three apart are perturbed together:
    3 colours x 5 coordinates = 15 gradient evaluations.  The result is
    symmetrised, (H + H^T)/2.  The solver passes par with k_w = 0 (and g0 computed
    with it): the contacts are added exactly by contact_hessian."""
    n = r.shape[0]
    ab[:, :] = 0.0
    p = np.zeros((n, NDOF))
    for colour in range(3):
        for d in range(NDOF):
            p[:, :] = 0.0
            for i in range(colour, n, 3):
                p[i, d] = h[d]
            displace(r, t, frame, e1, e2, p, 1.0, rp, tp, nu)
            smooth_gradient(rp, tp, nu, rn, tn, frame, e1, e2, cr, ct, par, Fm, Fp, F, M, Nw, gp)
            for j in range(colour, n, 3):
                col = NDOF * j + d
                # the step actually taken: r + h is rounded to the spacing of r (up to
                # L eps along the axis), a relative error eps L/h in the step that would
                # put noise k eps L/h into the stiff bond entries; rp - r is exact
                hj = h[d]
                if d < 3:
                    hj = ((rp[j, 0] - r[j, 0]) * frame[j, d, 0] + (rp[j, 1] - r[j, 1]) * frame[j, d, 1]
                          + (rp[j, 2] - r[j, 2]) * frame[j, d, 2])
                lo = j - 1 if j > 0 else 0
                hi = j + 1 if j < n - 1 else n - 1
                for li in range(lo, hi + 1):
                    for dd in range(NDOF):
                        row = NDOF * li + dd
                        v = (gp[li, dd] - g0[li, dd]) / hj
                        if row == col:
                            ab[0, col] += v
                        elif row > col:
                            ab[row - col, col] += 0.5 * v
                        else:
                            ab[col - row, row] += 0.5 * v


@njit(cache=True)
def _add_end_hessian(i, s, h, q, frame, e1, e2, hp, gp, t, ab):
    """Add the Hessian of an end-point energy with point Hessian hp (3x3) and
    point gradient gp to link i's diagonal block (end point r_i + s h t_i):
    J^T hp J with J = [frame_0, frame_1, frame_2, s h e1, s h e2], plus the
    curvature of the tangent's rotation, d^2 p/da^2 = d^2 p/db^2 = -s h t."""
    J = np.empty((NDOF, 3))
    for k in range(3):
        for c in range(3):
            J[k, c] = frame[i, k, c]
    for c in range(3):
        J[3, c] = s * h * e1[i, c]
        J[4, c] = s * h * e2[i, c]
    for a in range(NDOF):
        for b in range(a, NDOF):
            v = 0.0
            for c in range(3):
                for d in range(3):
                    v += J[a, c] * hp[c, d] * J[b, d]
            ab[b - a, q + a] += v
    curv = -s * h * (gp[0] * t[i, 0] + gp[1] * t[i, 1] + gp[2] * t[i, 2])
    ab[0, q + 3] += curv
    ab[0, q + 4] += curv


@njit(cache=True)
def contact_hessian(r, t, frame, e1, e2, par, ab):
    """Exact Hessian of the one-sided contact penalties (wall (k_w/2)(rho - R)^2,
    floor (k_w/2) z^2, the block's top face (k_w/2)(z_top - z)^2) in the step
    coordinates, added to ab.

    These penalties switch on where an end touches (their curvature jumps from
    0 to k_w), and a grazing contact sits within ~1e-8 R of that switch; a
    finite-difference step of the same size would straddle it and average the
    two sides.  So fd_hessian leaves them out (k_w = 0) and they are added here
    on the side the end is on.  Point Hessian of the wall term, for overlap
    d = rho - R > 0 and radial unit vector n: k_w [n n^T + (d/rho)(P_xy - n n^T)]."""
    h = par[K.HALF]
    kw = par[K.K_WALL]
    hp = np.zeros((3, 3))
    gp = np.zeros(3)
    n = r.shape[0]
    for i in range(n):
        q = NDOF * i
        for s in (-1.0, 1.0):
            px = r[i, 0] + s * h * t[i, 0]
            py = r[i, 1] + s * h * t[i, 1]
            pz = r[i, 2] + s * h * t[i, 2]
            guided = K.is_guided(i, s, n, par)
            d, nx, ny = K._wall_point(px, py, pz, par, guided)
            if d > 0.0:
                rho = np.sqrt(px * px + py * py)
                c = d / rho
                hp[0, 0] = kw * (nx * nx + c * (1.0 - nx * nx))
                hp[1, 1] = kw * (ny * ny + c * (1.0 - ny * ny))
                hp[0, 1] = kw * (1.0 - c) * nx * ny
                hp[1, 0] = hp[0, 1]
                hp[0, 2] = hp[1, 2] = hp[2, 0] = hp[2, 1] = hp[2, 2] = 0.0
                gp[0] = kw * d * nx
                gp[1] = kw * d * ny
                gp[2] = 0.0
                _add_end_hessian(i, s, h, q, frame, e1, e2, hp, gp, t, ab)
            if par[K.FLOOR] > 0.5 and pz < 0.0 and not (i == 0 and s < 0.0):
                hp[:, :] = 0.0
                hp[2, 2] = kw
                gp[0] = 0.0
                gp[1] = 0.0
                gp[2] = kw * pz
                _add_end_hessian(i, s, h, q, frame, e1, e2, hp, gp, t, ab)
            dz = K._face_point(px, py, pz, par, guided)
            if dz > 0.0:
                hp[:, :] = 0.0
                hp[2, 2] = kw
                gp[0] = 0.0
                gp[1] = 0.0
                gp[2] = -kw * dz
                _add_end_hessian(i, s, h, q, frame, e1, e2, hp, gp, t, ab)


@njit(cache=True)
def tangential_offset(r, anchor, frame, i):
    """Offset of link i's centre from its stick anchor along the azimuthal and
    axial directions of its step frame."""
    dx = r[i, 0] - anchor[i, 0]
    dy = r[i, 1] - anchor[i, 1]
    dz = r[i, 2] - anchor[i, 2]
    return (frame[i, 1, 0] * dx + frame[i, 1, 1] * dy + frame[i, 1, 2] * dz,
            frame[i, 2, 0] * dx + frame[i, 2, 1] * dy + frame[i, 2, 2] * dz)


@njit(cache=True)
def friction_term(r, anchor, frame, fmax, kt, g, ab, hessian):
    """Coulomb friction of the links on the wall (fmax > 0) as the convex
    potential H(d) of the tangential offset d of the link centre from its stick
    anchor (d along the azimuthal and axial directions of the step frame):

        H = (kt/2)|d|^2                      if kt |d| <= fmax   (stick)
        H = fmax |d| - fmax^2/(2 kt)         otherwise           (slip)

    Its force is -kt d in stick, bounded by fmax, and exactly fmax against the slip
    in slip.  H is the Moreau envelope of fmax |d|, continuously differentiable,
    so Newton converges without an active set.  Adds the gradient to g and (if
    hessian) the Hessian to ab; returns the sum of H."""
    e = 0.0
    for i in range(r.shape[0]):
        if fmax[i] <= 0.0:
            continue
        d1, d2 = tangential_offset(r, anchor, frame, i)
        nd = np.sqrt(d1 * d1 + d2 * d2)
        j = NDOF * i + 1
        if kt * nd <= fmax[i]:
            e += 0.5 * kt * nd * nd
            g[i, 1] += kt * d1
            g[i, 2] += kt * d2
            if hessian:
                ab[0, j] += kt
                ab[0, j + 1] += kt
        else:
            e += fmax[i] * nd - 0.5 * fmax[i] * fmax[i] / kt
            u1 = d1 / nd
            u2 = d2 / nd
            g[i, 1] += fmax[i] * u1
            g[i, 2] += fmax[i] * u2
            if hessian:
                c = fmax[i] / nd
                ab[0, j] += c * (1.0 - u1 * u1)
                ab[1, j] += -c * u1 * u2
                ab[0, j + 1] += c * (1.0 - u2 * u2)
    return e


@njit(cache=True)
def update_anchors(r, anchor, frame, fmax, kt):
    """After an accepted step: a link in slip drags its anchor along so that
    kt |d| = fmax; a link off the wall has its anchor at its centre."""
    for i in range(r.shape[0]):
        if fmax[i] <= 0.0:
            anchor[i, 0] = r[i, 0]
            anchor[i, 1] = r[i, 1]
            anchor[i, 2] = r[i, 2]
            continue
        d1, d2 = tangential_offset(r, anchor, frame, i)
        nd = np.sqrt(d1 * d1 + d2 * d2)
        lim = fmax[i] / kt
        if nd > lim:
            s = 1.0 - lim / nd
            for c in range(3):
                anchor[i, c] += s * (d1 * frame[i, 1, c] + d2 * frame[i, 2, c])
