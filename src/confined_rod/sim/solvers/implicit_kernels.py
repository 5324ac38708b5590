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
    K.cylinder_frames(r, frame)


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
    return phi + step_gradient(r, t, nu, rn, tn, frame, e1, e2, cr, ct, F, M, g)


@njit(cache=True)
def step_gradient(r, t, nu, rn, tn, frame, e1, e2, cr, ct, F, M, g):
    """The drag part of Phi_s, and the gradient of Phi_s in the step coordinates
    from the conservative loads F, M already evaluated at (r, t) (the second
    half of smooth_gradient); returns the drag energy."""
    phi = 0.0
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
def _add_pair(ab, i, j, A, B, w):
    """Add w A^T B to the Hessian block (link i rows, link j columns), i >= j, in
    lower banded storage; A and B (m x NDOF) are the Jacobians of one term's m
    components with respect to link i's and link j's coordinates.  A diagonal
    block (i == j) stores its lower triangle only."""
    for a in range(NDOF):
        row = NDOF * i + a
        for b in range(NDOF):
            col = NDOF * j + b
            if row < col:
                continue
            v = 0.0
            for c in range(A.shape[0]):
                v += A[c, a] * B[c, b]
            ab[row - col, col] += w * v


@njit(cache=True)
def _end_jacobian(i, s, h, frame, e1, e2, A):
    """Jacobian of the end point r_i + s h t_i with respect to link i's step
    coordinates (3 x NDOF): the frame vectors, then s h e1, s h e2."""
    for c in range(3):
        for k in range(3):
            A[c, k] = frame[i, k, c]
        A[c, 3] = s * h * e1[i, c]
        A[c, 4] = s * h * e2[i, c]


@njit(cache=True)
def _add_bond_diagonal(ab, i, A, h, k):
    """Add k A^T A to link i's diagonal block, A = _end_jacobian of one of its
    ends: the frame is orthonormal and e1, e2 are orthonormal, so A^T A is the
    identity on the translations, h^2 on the rotations, and A_k . A_3, A_k . A_4
    (k < 3) between them."""
    q = NDOF * i
    for d in range(3):
        ab[0, q + d] += k
    ab[0, q + 3] += k * h * h
    ab[0, q + 4] += k * h * h
    for d in range(3):
        for a in range(3, NDOF):
            ab[a - d, q + d] += k * (A[0, d] * A[0, a] + A[1, d] * A[1, a] + A[2, d] * A[2, a])


@njit(cache=True)
def smooth_hessian(r, t, tn, frame, e1, e2, cr, ct, par, ab):
    """Exact Hessian of Phi_s without the contact penalties (bonds, bending, load,
    support and pins, drag), in the step coordinates at (r, t) (nu = 1), written
    into ab (lower banded storage, overwritten).  Every term is quadratic or
    linear in the Cartesian r and t, so its coordinate Hessian is J^T H_cart J,
    plus the curvature of the tangent's parametrisation: d^2 t/da^2 = d^2 t/db^2
    = -t (no cross term), which adds -t . dE/dt to both rotation entries.
      bond (k/2)|g|^2, g = r_{i+1} - r_i - h (t_{i+1} + t_i):  k G_a^T G_b,
          dE/dt_i = dE/dt_{i+1} = -h k g;
      bending C (1 - t_i . t_{i+1}):  -C e_a(i+1) . e_b(i) between the links,
          dE/dt_i = -C t_{i+1};
      load P z(r_{N-1}^+):  dE/dt_{N-1} = P h e_z;
      support (k_s/2) z_b^2 and pins (k_s/2) p^2:  k_s G^T G, dE/dt = k_s p dp/dt;
      drag (cr/2)|r - r_n|^2 + (ct/2)|t - t_n|^2:  cr, ct on the diagonal,
          dE/dt = ct (t - t_n).
    Tested against finite differences of the kernel forces (fd_hessian)."""
    n = r.shape[0]
    h = par[K.HALF]
    k = par[K.K_BOND]
    C = par[K.C_BEND]
    ks = par[K.K_SUP]
    ab[:, :] = 0.0
    curv = np.zeros(n)  # -t . dE/dt per link
    A = np.empty((3, NDOF))
    B = np.empty((3, NDOF))
    P = np.empty((1, NDOF))
    for i in range(n - 1):
        # bond between the top of link i and the bottom of link i+1
        gx = (r[i + 1, 0] - r[i, 0]) - h * (t[i + 1, 0] + t[i, 0])
        gy = (r[i + 1, 1] - r[i, 1]) - h * (t[i + 1, 1] + t[i, 1])
        gz = (r[i + 1, 2] - r[i, 2]) - h * (t[i + 1, 2] + t[i, 2])
        _end_jacobian(i, 1.0, h, frame, e1, e2, A)
        _end_jacobian(i + 1, -1.0, h, frame, e1, e2, B)
        _add_bond_diagonal(ab, i, A, h, k)
        _add_bond_diagonal(ab, i + 1, B, h, k)
        q = NDOF * i
        for a in range(NDOF):  # -k B^T A between the links (row - column = NDOF + a - b >= 1)
            for b in range(NDOF):
                ab[NDOF + a - b, q + b] -= k * (B[0, a] * A[0, b] + B[1, a] * A[1, b] + B[2, a] * A[2, b])
        curv[i] += h * k * (gx * t[i, 0] + gy * t[i, 1] + gz * t[i, 2])
        curv[i + 1] += h * k * (gx * t[i + 1, 0] + gy * t[i + 1, 1] + gz * t[i + 1, 2])
        # bending joint: -C e_a(i+1) . e_b(i), a, b over (e1, e2)
        ab[NDOF, q + 3] -= C * (e1[i + 1, 0] * e1[i, 0] + e1[i + 1, 1] * e1[i, 1] + e1[i + 1, 2] * e1[i, 2])
        ab[NDOF - 1, q + 4] -= C * (e1[i + 1, 0] * e2[i, 0] + e1[i + 1, 1] * e2[i, 1] + e1[i + 1, 2] * e2[i, 2])
        ab[NDOF + 1, q + 3] -= C * (e2[i + 1, 0] * e1[i, 0] + e2[i + 1, 1] * e1[i, 1] + e2[i + 1, 2] * e1[i, 2])
        ab[NDOF, q + 4] -= C * (e2[i + 1, 0] * e2[i, 0] + e2[i + 1, 1] * e2[i, 1] + e2[i + 1, 2] * e2[i, 2])
        tt = t[i, 0] * t[i + 1, 0] + t[i, 1] * t[i + 1, 1] + t[i, 2] * t[i + 1, 2]
        curv[i] += C * tt
        curv[i + 1] += C * tt
    # load on the upper end
    curv[n - 1] -= par[K.LOAD] * h * t[n - 1, 2]
    # z support of the lower end, lateral pins of both ends
    if par[K.LOWER_HELD] > 0.5:
        _end_jacobian(0, -1.0, h, frame, e1, e2, A)
        for b in range(NDOF):
            P[0, b] = A[2, b]
        _add_pair(ab, 0, 0, P, P, ks)
        curv[0] += h * ks * (r[0, 2] - h * t[0, 2]) * t[0, 2]
    if par[K.ENDS_PINNED] > 0.5:
        for end in range(2):
            i = 0 if end == 0 else n - 1
            s = -1.0 if end == 0 else 1.0
            _end_jacobian(i, s, h, frame, e1, e2, A)
            for c in range(2):
                for b in range(NDOF):
                    P[0, b] = A[c, b]
                _add_pair(ab, i, i, P, P, ks)
                curv[i] -= s * h * ks * (r[i, c] + s * h * t[i, c]) * t[i, c]
    # drag, and the curvature of the rotations
    for i in range(n):
        q = NDOF * i
        for d in range(3):
            ab[0, q + d] += cr
        ut = t[i, 0] * (t[i, 0] - tn[i, 0]) + t[i, 1] * (t[i, 1] - tn[i, 1]) + t[i, 2] * (t[i, 2] - tn[i, 2])
        c = ct - ct * ut + curv[i]
        ab[0, q + 3] += c
        ab[0, q + 4] += c


@njit(cache=True)
def _add_end_hessian(i, s, h, q, frame, e1, e2, hp, gp, t, ab, J):
    """Add the Hessian of an end-point energy with point Hessian hp (3x3) and
    point gradient gp to link i's diagonal block (end point r_i + s h t_i):
    J^T hp J with J the end point's Jacobian (_end_jacobian; J is scratch), plus
    the curvature of the tangent's rotation, d^2 p/da^2 = d^2 p/db^2 = -s h t."""
    _end_jacobian(i, s, h, frame, e1, e2, J)
    for b in range(NDOF):  # hp J, then J^T (hp J): 90 products instead of 270
        u0 = hp[0, 0] * J[0, b] + hp[0, 1] * J[1, b] + hp[0, 2] * J[2, b]
        u1 = hp[1, 0] * J[0, b] + hp[1, 1] * J[1, b] + hp[1, 2] * J[2, b]
        u2 = hp[2, 0] * J[0, b] + hp[2, 1] * J[1, b] + hp[2, 2] * J[2, b]
        for a in range(b + 1):
            ab[b - a, q + a] += J[0, a] * u0 + J[1, a] * u1 + J[2, a] * u2
    curv = -s * h * (gp[0] * t[i, 0] + gp[1] * t[i, 1] + gp[2] * t[i, 2])
    ab[0, q + 3] += curv
    ab[0, q + 4] += curv


@njit(cache=True)
def _add_wall_hessian(i, s, h, q, frame, e1, e2, h00, h01, h11, g0, g1, t, ab, J):
    """_add_end_hessian for a point Hessian and gradient in the xy plane only (the wall's:
    [[h00, h01, 0], [h01, h11, 0], [0, 0, 0]] and (g0, g1, 0)): the same sums without their
    zero terms, so the same result (the wall is on most links of a helix, and this kernel
    is a tenth of a Newton iteration's work)."""
    _end_jacobian(i, s, h, frame, e1, e2, J)
    for b in range(NDOF):
        u0 = h00 * J[0, b] + h01 * J[1, b]
        u1 = h01 * J[0, b] + h11 * J[1, b]
        for a in range(b + 1):
            ab[b - a, q + a] += J[0, a] * u0 + J[1, a] * u1
    curv = -s * h * (g0 * t[i, 0] + g1 * t[i, 1])
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
    J = np.empty((3, NDOF))
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
                _add_wall_hessian(i, s, h, q, frame, e1, e2, kw * (nx * nx + c * (1.0 - nx * nx)),
                                  kw * (1.0 - c) * nx * ny, kw * (ny * ny + c * (1.0 - ny * ny)),
                                  kw * d * nx, kw * d * ny, t, ab, J)
            if par[K.FLOOR] > 0.5 and pz < 0.0 and not (i == 0 and s < 0.0 and par[K.LOWER_HELD] > 0.5):
                hp[:, :] = 0.0
                hp[2, 2] = kw
                gp[0] = 0.0
                gp[1] = 0.0
                gp[2] = kw * pz
                _add_end_hessian(i, s, h, q, frame, e1, e2, hp, gp, t, ab, J)
            dz = K._face_point(px, py, pz, par, guided)
            if dz > 0.0:
                hp[:, :] = 0.0
                hp[2, 2] = kw
                gp[0] = 0.0
                gp[1] = 0.0
                gp[2] = -kw * dz
                _add_end_hessian(i, s, h, q, frame, e1, e2, hp, gp, t, ab, J)


@njit(cache=True)
def banded_cholesky_solve(ab, b, work, x):
    """Solve H x = b for the symmetric positive definite block-tridiagonal Newton Hessian
    (NDOF x NDOF blocks, one per link), given in LAPACK lower band storage ab[i - j, j] =
    H[i, j] (half-bandwidth BAND), by block Cholesky H = L L^T and two triangular solves.
    work (n_links, 2 NDOF, NDOF) holds L: rows 0..NDOF-1 of work[I] the lower-triangular
    diagonal block L_II with the reciprocals of its diagonal on the diagonal, rows
    NDOF..2 NDOF-1 the block below it, L_I+1,I.  Returns False if a pivot is not positive
    (H is not positive definite).

    The band storage holds zeros for the entries two blocks apart (within BAND of the
    diagonal but outside the block tridiagonal); no fill-in lands there, so the block
    recursion D_I = chol(H_II - C_I-1 C_I-1^T), C_I = H_I+1,I D_I^-T is exact.  With the block
    size a compile-time constant it is 1.8x faster than the unblocked band algorithm of
    LAPACK's dpbtrf/dpbtrs that it replaced (160 against 225 multiply-adds per link, no
    division in the inner loops; measured side by side on a random matrix of 12 800 unknowns,
    2026-12-02), and 2.9x faster than scipy.linalg.solveh_banded at 1280 links, whose call
    overhead was 40 % of a Newton iteration (benchmarks/results/solvers.json). The forward
    substitution runs in the factorisation's sweep (the same operations in the same order, so
    the same result; with _add_wall_hessian and the bending entries written out in
    smooth_hessian, L/R = 640 ran in 0.93x the time, benchmarks/results/ab_kernels.json)."""
    nb = ab.shape[1] // NDOF
    A = np.empty((NDOF, NDOF))
    for I in range(nb):
        q = NDOF * I
        for a in range(NDOF):
            for c in range(a + 1):
                A[a, c] = ab[a - c, q + c]
        if I > 0:  # H_II - C C^T
            for a in range(NDOF):
                for c in range(a + 1):
                    s = A[a, c]
                    for k in range(NDOF):
                        s -= work[I - 1, NDOF + a, k] * work[I - 1, NDOF + c, k]
                    A[a, c] = s
        for c in range(NDOF):  # D_I, with 1/D_cc on the diagonal
            s = A[c, c]
            for k in range(c):
                s -= work[I, c, k] * work[I, c, k]
            if not s > 0.0:
                return False
            inv = 1.0 / np.sqrt(s)
            work[I, c, c] = inv
            for a in range(c + 1, NDOF):
                s = A[a, c]
                for k in range(c):
                    s -= work[I, a, k] * work[I, c, k]
                work[I, a, c] = s * inv
        for a in range(NDOF):  # L y = b, this block's rows (in the same sweep, while L_I is in cache)
            s = b[q + a]
            if I > 0:
                for k in range(NDOF):
                    s -= work[I - 1, NDOF + a, k] * x[q - NDOF + k]
            for k in range(a):
                s -= work[I, a, k] * x[q + k]
            x[q + a] = s * work[I, a, a]
        if I + 1 < nb:  # C_I = H_I+1,I D_I^-T
            for a in range(NDOF):
                for c in range(NDOF):
                    s = ab[NDOF + a - c, q + c]  # H[q + NDOF + a, q + c], within the band
                    for k in range(c):
                        s -= work[I, NDOF + a, k] * work[I, c, k]
                    work[I, NDOF + a, c] = s * work[I, c, c]
    for I in range(nb - 1, -1, -1):  # L^T x = y
        q = NDOF * I
        for a in range(NDOF - 1, -1, -1):
            s = x[q + a]
            if I + 1 < nb:
                for k in range(NDOF):
                    s -= work[I, NDOF + k, a] * x[q + NDOF + k]
            for k in range(a + 1, NDOF):
                s -= work[I, k, a] * x[q + k]
            x[q + a] = s * work[I, a, a]
    return True


def cholesky_work(n_links: int) -> np.ndarray:
    """The work array of banded_cholesky_solve for n_links links."""
    return np.zeros((n_links, 2 * NDOF, NDOF))


@njit(cache=True)
def dot(a, b):
    """Sum of a * b over two arrays of one shape, in a fixed order.  numpy's dot calls the BLAS,
    whose threaded reduction above ~10 000 elements (OpenBLAS) sums in an order set by the
    number of threads: the slopes of the line search, and with them the path of a long rod
    (N >= 2 000 links), then depended on the machine's core count (L/R = 1280, seed 0: 20 557
    against 18 491 Newton iterations and |F_z(L)| 7 % apart with OPENBLAS_NUM_THREADS = 2 and 1)."""
    x = a.ravel()
    y = b.ravel()
    s = 0.0
    for i in range(x.size):
        s += x[i] * y[i]
    return s


@njit(cache=True)
def newton_residuals(g, r, rn, t, tn):
    """Largest force and moment residual of a Newton iterate (max |g| over the translations and
    over the rotations) and the largest change of a centre and of a tangent coordinate since
    the step's start: the four numbers of the Newton stopping test, in one pass."""
    gf = 0.0
    gm = 0.0
    dr = 0.0
    dt = 0.0
    for i in range(g.shape[0]):
        for c in range(3):
            gf = max(gf, abs(g[i, c]))
            dr = max(dr, abs(r[i, c] - rn[i, c]))
            dt = max(dt, abs(t[i, c] - tn[i, c]))
        gm = max(gm, abs(g[i, 3]), abs(g[i, 4]))
    return gf, gm, dr, dt


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
    so Newton converges on it without an active set (stick_model's guess only
    shortens the way).  Adds the gradient to g and (if
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
    kt |d| = fmax; a link off the wall has its anchor at its centre; a link on the wall keeps
    its anchor in the tangent plane of its centre (kernels.drop_normal_offset)."""
    for i in range(r.shape[0]):
        if fmax[i] <= 0.0:
            anchor[i, 0] = r[i, 0]
            anchor[i, 1] = r[i, 1]
            anchor[i, 2] = r[i, 2]
            continue
        d1, d2 = tangential_offset(r, anchor, frame, i)
        K.drag_anchor(anchor, i, d1, d2, frame[i], fmax[i] / kt)
        K.drop_normal_offset(anchor, i, r[i, 0], r[i, 1], r[i, 2])


@njit(cache=True)
def stick_model(r, anchor, frame, fmax, kt, p, g, ab):
    """Active-set guess for the Newton model: links in slip whose step p would carry them back
    into the stick zone (new offset along the old slip direction u below f_max/k_t) are
    modelled on the stick branch of the friction potential, (k_t/2)|d|^2, instead of the
    slip branch, whose only curvature along u is the drag's: in g (a copy of the gradient)
    f_max u becomes k_t d, in ab the slip Hessian (f_max/|d|)(1 - u u^T) becomes k_t 1.
    Returns how many links."""
    count = 0
    for i in range(r.shape[0]):
        if fmax[i] <= 0.0:
            continue
        d1, d2 = tangential_offset(r, anchor, frame, i)
        nd = np.sqrt(d1 * d1 + d2 * d2)
        lim = fmax[i] / kt
        if nd <= lim:
            continue
        j = NDOF * i + 1
        u1 = d1 / nd
        u2 = d2 / nd
        if (d1 + p[j]) * u1 + (d2 + p[j + 1]) * u2 < lim:
            c = fmax[i] / nd
            ab[0, j] += kt - c * (1.0 - u1 * u1)
            ab[1, j] += c * u1 * u2
            ab[0, j + 1] += kt - c * (1.0 - u2 * u2)
            g[i, 1] += kt * d1 - fmax[i] * u1
            g[i, 2] += kt * d2 - fmax[i] * u2
            count += 1
    return count


@njit(cache=True)
def contact_model(r, t, frame, e1, e2, par, p, g, ab):
    """Active-set guess for the Newton model, for the wall: a link end off the wall (or above
    the entrance) that the step p carries into the wall is modelled in contact, with the
    penalty (k_w/2)(rho - R)^2 continued to its current point (gradient k_w d n with d < 0,
    Hessian k_w n n^T), added to g (a copy of the gradient) and ab. Off the wall the model has
    no wall at all, and the step sent the front of a helix forming along a long rod hundreds
    of link ends deep into the wall at once (L/R = 1280: 310 ends; line search alpha 0.006).
    Returns how many ends."""
    h = par[K.HALF]
    kw = par[K.K_WALL]
    hp = np.zeros((3, 3))
    gp = np.zeros(3)
    J = np.empty((3, NDOF))
    n = r.shape[0]
    count = 0
    for i in range(n):
        q = NDOF * i
        # the most an end of link i can move in the step (|J p| <= |translation| + h |rotation|)
        reach = (np.sqrt(p[q] ** 2 + p[q + 1] ** 2 + p[q + 2] ** 2)
                 + h * np.sqrt(p[q + 3] ** 2 + p[q + 4] ** 2))
        for s in (-1.0, 1.0):
            px = r[i, 0] + s * h * t[i, 0]
            py = r[i, 1] + s * h * t[i, 1]
            pz = r[i, 2] + s * h * t[i, 2]
            if np.sqrt(px * px + py * py) + reach <= par[K.R_WALL]:
                continue
            guided = K.is_guided(i, s, n, par)
            d, _, _ = K._wall_point(px, py, pz, par, guided)
            if d > 0.0:
                continue
            _end_jacobian(i, s, h, frame, e1, e2, J)
            dx = 0.0
            dy = 0.0
            dz = 0.0
            for b in range(NDOF):
                dx += J[0, b] * p[q + b]
                dy += J[1, b] * p[q + b]
                dz += J[2, b] * p[q + b]
            d2, _, _ = K._wall_point(px + dx, py + dy, pz + dz, par, guided)
            if d2 <= 0.0:
                continue
            rho = np.sqrt(px * px + py * py)
            if rho < 1e-12:
                continue
            nx = px / rho
            ny = py / rho
            dd = rho - par[K.R_WALL]
            hp[:, :] = 0.0
            hp[0, 0] = kw * nx * nx
            hp[0, 1] = hp[1, 0] = kw * nx * ny
            hp[1, 1] = kw * ny * ny
            gp[0] = kw * dd * nx
            gp[1] = kw * dd * ny
            gp[2] = 0.0
            _add_end_hessian(i, s, h, q, frame, e1, e2, hp, gp, t, ab, J)
            for b in range(NDOF):
                g[i, b] += J[0, b] * gp[0] + J[1, b] * gp[1]
            count += 1
    return count


@njit(cache=True)
def end_friction_hessian(r, t, anchor, pf, frame, e1, e2, h, fmax, kt, ab):
    """Hessian of K.end_friction_loads' envelope in the step coordinates, added to ab: per end
    on the wall J^T hp J (_add_end_hessian) with hp = kt P (stick) or (fmax/|d|)(P - w w^T)
    (slip), P the projector on the end's tangent plane (pf[m] rows 1, 2), w the slip
    direction, and the curvature of the end point's rotation."""
    J = np.empty((3, NDOF))
    hp = np.zeros((3, 3))
    gp = np.zeros(3)
    for m in range(2 * r.shape[0]):
        if fmax[m] <= 0.0:
            continue
        i = m // 2
        s = 2.0 * (m % 2) - 1.0
        d1, d2 = K.end_offset(r, t, anchor, pf, h, m)
        nd = np.sqrt(d1 * d1 + d2 * d2)
        stick = kt * nd <= fmax[m]
        c = kt if stick else fmax[m] / nd
        for a in range(3):
            gp[a] = c * (d1 * pf[m, 1, a] + d2 * pf[m, 2, a])
            for b in range(3):
                hp[a, b] = c * (pf[m, 1, a] * pf[m, 1, b] + pf[m, 2, a] * pf[m, 2, b])
        if not stick:
            u1 = d1 / nd
            u2 = d2 / nd
            for a in range(3):
                wa = u1 * pf[m, 1, a] + u2 * pf[m, 2, a]
                for b in range(3):
                    hp[a, b] -= c * wa * (u1 * pf[m, 1, b] + u2 * pf[m, 2, b])
        _add_end_hessian(i, s, h, NDOF * i, frame, e1, e2, hp, gp, t, ab, J)


@njit(cache=True)
def end_stick_model(r, t, anchor, pf, frame, e1, e2, h, fmax, kt, p, g, ab):
    """stick_model for friction at the link ends: an end in slip that the step p carries back
    into its stick zone (new offset along the old slip direction u below f_max/k_t) is modelled
    on the stick branch, kt |d|^2/2, instead of the slip branch: the difference of the two
    branches' point gradients and Hessians goes through the end's Jacobian into g (a copy of
    the gradient) and ab. Returns how many ends."""
    J = np.empty((3, NDOF))
    hp = np.zeros((3, 3))
    gp = np.zeros(3)
    count = 0
    for m in range(2 * r.shape[0]):
        if fmax[m] <= 0.0:
            continue
        d1, d2 = K.end_offset(r, t, anchor, pf, h, m)
        nd = np.sqrt(d1 * d1 + d2 * d2)
        lim = fmax[m] / kt
        if nd <= lim:
            continue
        i = m // 2
        s = 2.0 * (m % 2) - 1.0
        q = NDOF * i
        _end_jacobian(i, s, h, frame, e1, e2, J)
        u1 = d1 / nd
        u2 = d2 / nd
        step = 0.0  # the end's move along the slip direction in the step
        for a in range(3):
            ua = u1 * pf[m, 1, a] + u2 * pf[m, 2, a]
            for b in range(NDOF):
                step += ua * J[a, b] * p[q + b]
        if nd + step >= lim:
            continue
        c = fmax[m] / nd
        for a in range(3):
            wa = u1 * pf[m, 1, a] + u2 * pf[m, 2, a]
            gp[a] = (kt - c) * (d1 * pf[m, 1, a] + d2 * pf[m, 2, a])
            for b in range(3):
                wb = u1 * pf[m, 1, b] + u2 * pf[m, 2, b]
                hp[a, b] = (kt - c) * (pf[m, 1, a] * pf[m, 1, b] + pf[m, 2, a] * pf[m, 2, b]) + c * wa * wb
        _add_end_hessian(i, s, h, q, frame, e1, e2, hp, gp, t, ab, J)
        for b in range(NDOF):
            g[i, b] += J[0, b] * gp[0] + J[1, b] * gp[1] + J[2, b] * gp[2]
        count += 1
    return count


def slip_branch_point_model(d, dp, fmax, kt):
    """Plain-numpy twin of end_slip_model's point terms, in an end's tangent plane (2-vectors):
    the slip branch of the friction envelope, f(d) = fmax |d| - fmax^2/(2 kt), modelled about the
    point the step predicts, d' = d + dp, as a quadratic in the displacement from d: gradient at
    d, fmax u' + c (d - u' (u'.d)), and Hessian c (1 - u' u'^T), with u' = d'/|d'| and
    c = fmax/|d'|. At d' it has the envelope's exact gradient fmax u' and Hessian: along the
    slip the force is fmax whatever the step, across it the direction turns with curvature c.
    Returned minus the stick branch's (kt d, kt 1), as the kernel adds them."""
    d, dp = np.asarray(d, dtype=float), np.asarray(dp, dtype=float)
    new = d + dp
    u = new / np.linalg.norm(new)
    c = fmax / np.linalg.norm(new)
    grad = fmax * u + c * (d - u * (u @ d))
    hess = c * (np.eye(2) - np.outer(u, u))
    return grad - kt * d, hess - kt * np.eye(2)


@njit(cache=True)
def end_slip_model(r, t, anchor, pf, frame, e1, e2, h, fmax, kt, p, g, ab):
    """The reverse of end_stick_model: an end in its stick zone (|d| <= f_max/k_t) that the step p
    carries beyond it (|d + J p| > f_max/k_t along the tangent plane) is modelled on the slip
    branch about the point the step predicts (slip_branch_point_model: exact gradient f_max u'
    and Hessian there) instead of the stick spring k_t, whose force the step would otherwise
    take as k_t |d'|, far above f_max. With k_t = k_ph/l0 a stuck stretch passes a change of
    axial force on over about one link per Newton iteration (implicit.py, stick stiffness), so
    a slip front crossing m links took about m iterations; modelled on its slip branch, an end
    the step carries past its bound passes the force on within the same linear solve. The
    difference of the branches' point gradients and Hessians goes through the end's Jacobian
    into g (a copy of the gradient) and ab. Returns how many ends."""
    J = np.empty((3, NDOF))
    hp = np.zeros((3, 3))
    gp = np.zeros(3)
    count = 0
    for m in range(2 * r.shape[0]):
        if fmax[m] <= 0.0:
            continue
        d1, d2 = K.end_offset(r, t, anchor, pf, h, m)
        lim = fmax[m] / kt
        if d1 * d1 + d2 * d2 > lim * lim:
            continue  # in slip already: end_friction_hessian models it so
        i = m // 2
        s = 2.0 * (m % 2) - 1.0
        q = NDOF * i
        _end_jacobian(i, s, h, frame, e1, e2, J)
        s1 = 0.0
        s2 = 0.0
        for a in range(3):
            jp = 0.0
            for b in range(NDOF):
                jp += J[a, b] * p[q + b]
            s1 += pf[m, 1, a] * jp
            s2 += pf[m, 2, a] * jp
        n1 = d1 + s1
        n2 = d2 + s2
        nn = np.sqrt(n1 * n1 + n2 * n2)
        if nn <= lim:
            continue
        u1 = n1 / nn
        u2 = n2 / nn
        c = fmax[m] / nn
        ud = u1 * d1 + u2 * d2
        for a in range(3):
            wa = u1 * pf[m, 1, a] + u2 * pf[m, 2, a]
            da = d1 * pf[m, 1, a] + d2 * pf[m, 2, a]
            gp[a] = fmax[m] * wa + c * (da - wa * ud) - kt * da
            for b in range(3):
                wb = u1 * pf[m, 1, b] + u2 * pf[m, 2, b]
                hp[a, b] = (c - kt) * (pf[m, 1, a] * pf[m, 1, b] + pf[m, 2, a] * pf[m, 2, b]) - c * wa * wb
        _add_end_hessian(i, s, h, q, frame, e1, e2, hp, gp, t, ab, J)
        for b in range(NDOF):
            g[i, b] += J[0, b] * gp[0] + J[1, b] * gp[1] + J[2, b] * gp[2]
        count += 1
    return count
