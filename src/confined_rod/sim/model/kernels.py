"""numba kernels of the discrete model, one job each.

Arrays (all C-contiguous float64):
  r, t      (N, 3)  link centres and unit tangents, link 0 at the bottom (z ~ 0),
                    link N-1 at the top where the load acts
  Fm, Fp    (N, 3)  forces on the lower (r_i^-) and upper (r_i^+) end of each link
  F, M      (N, 3)  net force on the link centre, torque about the link centre
  Nw        (N,)    magnitude of the wall normal force on each link (sum over its ends)
  par       (NPAR,) scalar parameters, indexed by the constants below

Conventions: r_i^pm = r_i pm (l0/2) t_i.  The energy functions return the energy
of the term they add, so that forces can be checked against -grad(E).
"""
from __future__ import annotations

import numpy as np
from numba import njit

# indices into the parameter vector ``par``
HALF = 0  # l0/2
K_BOND = 1  # k = k_ph/l0
K_WALL = 2  # k_w
R_WALL = 3  # R
Z_TOP = 4  # z of the open pore entrance (no wall above it)
LOAD = 5  # |F_z(0)|, pushes the upper end towards -z
K_SUP = 6  # stiffness of the z support of the lower end and of lateral pins
C_BEND = 7  # C = EI/l0
K_FR = 8  # Coulomb coefficient
F_CAP = 9  # cap on the friction force per link (friction_cap); <= 0: no cap
FX = 10  # external force per link (body force per length * l0)
FY = 11
FZ = 12
LOWER_HELD = 13  # 1: lower end held in z by a penalty spring at z = 0
ENDS_PINNED = 14  # 1: both ends held on the axis laterally (Euler test); 0: free
GAMMA_T = 15  # translational drag per link
GAMMA_R = 16  # rotational drag per link
FLOOR = 17  # 1: the lower piston at z = 0 is a one-sided wall (stiffness k_w) for every link end
GUIDED = 18  # 1: the loaded end point slides in a guide of radius R: it feels the wall above the entrance too
R_ESCAPE = 19  # limits.ESCAPE_RADIUS * R: a link end above the entrance this far from the axis has left the pore
NPAR = 20


@njit(cache=True)
def bond_forces(r, t, par, Fm, Fp):
    """Bond penalty (k/2)|r_{i+1}^- - r_i^+|^2; adds end forces, returns energy."""
    h = par[HALF]
    k = par[K_BOND]
    e = 0.0
    for i in range(r.shape[0] - 1):
        # centre difference first: it is exact (Sterbenz) or accurate to eps l0,
        # where the end points r +- h t would each be rounded to eps |r| ~ eps L,
        # and k times that error would be a force noise that grows with L
        gx = (r[i + 1, 0] - r[i, 0]) - h * (t[i + 1, 0] + t[i, 0])
        gy = (r[i + 1, 1] - r[i, 1]) - h * (t[i + 1, 1] + t[i, 1])
        gz = (r[i + 1, 2] - r[i, 2]) - h * (t[i + 1, 2] + t[i, 2])
        Fp[i, 0] += k * gx
        Fp[i, 1] += k * gy
        Fp[i, 2] += k * gz
        Fm[i + 1, 0] -= k * gx
        Fm[i + 1, 1] -= k * gy
        Fm[i + 1, 2] -= k * gz
        e += 0.5 * k * (gx * gx + gy * gy + gz * gz)
    return e


@njit(cache=True)
def _wall_point(px, py, pz, par, guided):
    """Radial overlap of one end point with the pore wall: 0 inside the pore, above
    the entrance (unless the point is ``guided``: the loaded end in its guide), and
    where the point is nearer the block's top face than the wall (_face_point)."""
    rho = np.sqrt(px * px + py * py)
    d = rho - par[R_WALL]
    if d <= 0.0 or (not guided and d > par[Z_TOP] - pz):
        return 0.0, 0.0, 0.0
    return d, px / rho, py / rho


@njit(cache=True)
def _face_point(px, py, pz, par, guided):
    """Depth of one end point below the top face z = z_top of the block around the
    pore, where that face is its nearest way out of the block (rho - R > z_top - z
    >= 0); 0 elsewhere.  With _wall_point this penalises the point's distance to
    the block's surface, continuous across the entrance's rim."""
    if guided or pz > par[Z_TOP]:
        return 0.0
    dz = par[Z_TOP] - pz
    if np.sqrt(px * px + py * py) - par[R_WALL] > dz:
        return dz
    return 0.0


@njit(cache=True)
def is_guided(i, sgn, n, par):
    """True for the upper end point of the top link (the loaded end) when it is guided."""
    return par[GUIDED] > 0.5 and i == n - 1 and sgn > 0.0


@njit(cache=True)
def wall_forces(r, t, par, Fm, Fp, Nw):
    """One-sided wall penalty (k_w/2)(rho - R)^2 on both ends of every link below
    the pore entrance, and (k_w/2)(z_top - z)^2 under the block's frictionless top
    face (see _face_point); adds end forces, fills Nw (the pore wall's normal force,
    which friction acts with), returns energy."""
    h = par[HALF]
    kw = par[K_WALL]
    e = 0.0
    n = r.shape[0]
    for i in range(n):
        Nw[i] = 0.0
        for sgn in (-1.0, 1.0):
            px = r[i, 0] + sgn * h * t[i, 0]
            py = r[i, 1] + sgn * h * t[i, 1]
            pz = r[i, 2] + sgn * h * t[i, 2]
            g = is_guided(i, sgn, n, par)
            d, nx, ny = _wall_point(px, py, pz, par, g)
            if d > 0.0:
                f = kw * d
                if sgn < 0.0:
                    Fm[i, 0] -= f * nx
                    Fm[i, 1] -= f * ny
                else:
                    Fp[i, 0] -= f * nx
                    Fp[i, 1] -= f * ny
                Nw[i] += f
                e += 0.5 * kw * d * d
            dz = _face_point(px, py, pz, par, g)
            if dz > 0.0:
                if sgn < 0.0:
                    Fm[i, 2] += kw * dz
                else:
                    Fp[i, 2] += kw * dz
                e += 0.5 * kw * dz * dz
    return e


@njit(cache=True)
def boundary_forces(r, t, par, Fm, Fp):
    """Load on the upper end, z support of the lower end, optional lateral pins.

    Returns (energy, F_z at the support) where F_z(L) is the z force exerted by
    the rod on the support (negative = compression)."""
    h = par[HALF]
    n = r.shape[0] - 1
    ks = par[K_SUP]
    # load: potential load * z(r_{N-1}^+)
    ztop = r[n, 2] + h * t[n, 2]
    Fp[n, 2] -= par[LOAD]
    e = par[LOAD] * ztop
    fz_support = 0.0
    zb = r[0, 2] - h * t[0, 2]
    if par[LOWER_HELD] > 0.5:
        Fm[0, 2] -= ks * zb
        e += 0.5 * ks * zb * zb
        fz_support = ks * zb
    if par[ENDS_PINNED] > 0.5:
        for c in range(2):
            pb = r[0, c] - h * t[0, c]
            pt = r[n, c] + h * t[n, c]
            Fm[0, c] -= ks * pb
            Fp[n, c] -= ks * pt
            e += 0.5 * ks * (pb * pb + pt * pt)
    return e, fz_support


@njit(cache=True)
def floor_forces(r, t, par, Fm, Fp):
    """Lower piston: one-sided penalty (k_w/2) z^2 for link ends below z = 0, except
    the lower end itself when the support holds it (lower_end 'held': its spring sets
    its z); a free lower end rests on the floor like every other link end. Returns
    (energy, total z force of the floor on the rod)."""
    if par[FLOOR] < 0.5:
        return 0.0, 0.0
    h = par[HALF]
    kw = par[K_WALL]
    first = 1 if par[LOWER_HELD] > 0.5 else 0
    e = 0.0
    ftot = 0.0
    for i in range(r.shape[0]):
        zm = r[i, 2] - h * t[i, 2]
        zp = r[i, 2] + h * t[i, 2]
        if zm < 0.0 and i >= first:
            Fm[i, 2] -= kw * zm
            ftot -= kw * zm
            e += 0.5 * kw * zm * zm
        if zp < 0.0:
            Fp[i, 2] -= kw * zp
            ftot -= kw * zp
            e += 0.5 * kw * zp * zp
    return e, ftot


@njit(cache=True)
def bending_torques(t, par, M):
    """Couples C t_i x (t_{i-1} + t_{i+1}) from E_b = C sum (1 - t_i.t_{i+1});
    adds to M, returns energy."""
    C = par[C_BEND]
    n = t.shape[0]
    e = 0.0
    for i in range(n):
        sx = 0.0
        sy = 0.0
        sz = 0.0
        if i > 0:
            sx += t[i - 1, 0]
            sy += t[i - 1, 1]
            sz += t[i - 1, 2]
        if i < n - 1:
            sx += t[i + 1, 0]
            sy += t[i + 1, 1]
            sz += t[i + 1, 2]
            e += C * (1.0 - (t[i, 0] * t[i + 1, 0] + t[i, 1] * t[i + 1, 1] + t[i, 2] * t[i + 1, 2]))
        M[i, 0] += C * (t[i, 1] * sz - t[i, 2] * sy)
        M[i, 1] += C * (t[i, 2] * sx - t[i, 0] * sz)
        M[i, 2] += C * (t[i, 0] * sy - t[i, 1] * sx)
    return e


@njit(cache=True)
def collect_link_loads(r, t, par, Fm, Fp, F, M):
    """Net force on each link centre (end forces + body force) and the torque of
    the end forces, (l0/2) t x (F^+ - F^-); returns the body-force energy."""
    h = par[HALF]
    e = 0.0
    for i in range(r.shape[0]):
        for c in range(3):
            F[i, c] = Fm[i, c] + Fp[i, c]
        F[i, 0] += par[FX]
        F[i, 1] += par[FY]
        F[i, 2] += par[FZ]
        e -= par[FX] * r[i, 0] + par[FY] * r[i, 1] + par[FZ] * r[i, 2]
        dx = Fp[i, 0] - Fm[i, 0]
        dy = Fp[i, 1] - Fm[i, 1]
        dz = Fp[i, 2] - Fm[i, 2]
        M[i, 0] += h * (t[i, 1] * dz - t[i, 2] * dy)
        M[i, 1] += h * (t[i, 2] * dx - t[i, 0] * dz)
        M[i, 2] += h * (t[i, 0] * dy - t[i, 1] * dx)
    return e


@njit(cache=True)
def coulomb_friction(r, par, Nw, F, Ff, stuck):
    """Overdamped Coulomb friction at the link centre (docs/model.md, "friction").

    For a link touching the wall, with F_t the part of its net conservative force
    tangent to the wall (normal = radial direction at the centre) and
    f_max = min(k_fr N, cap):  |F_t| <= f_max  ->  friction = -F_t   (stick: the
    centre does not move along the wall, exactly);  otherwise friction =
    -f_max F_t/|F_t| (slip at the limit).  Adds friction to F, writes Ff, stuck."""
    kfr = par[K_FR]
    cap = par[F_CAP]
    for i in range(r.shape[0]):
        Ff[i, 0] = 0.0
        Ff[i, 1] = 0.0
        Ff[i, 2] = 0.0
        stuck[i] = 0.0
        if Nw[i] <= 0.0 or kfr <= 0.0:
            continue
        rho = np.sqrt(r[i, 0] ** 2 + r[i, 1] ** 2)
        if rho == 0.0:
            continue
        nx = r[i, 0] / rho
        ny = r[i, 1] / rho
        fn = F[i, 0] * nx + F[i, 1] * ny
        tx = F[i, 0] - fn * nx
        ty = F[i, 1] - fn * ny
        tz = F[i, 2]
        ft = np.sqrt(tx * tx + ty * ty + tz * tz)
        fmax = kfr * Nw[i]
        if cap > 0.0 and fmax > cap:
            fmax = cap
        if ft <= fmax:
            s = 1.0
            stuck[i] = 1.0
        else:
            s = fmax / ft
        Ff[i, 0] = -s * tx
        Ff[i, 1] = -s * ty
        Ff[i, 2] = -s * tz
        F[i, 0] += Ff[i, 0]
        F[i, 1] += Ff[i, 1]
        F[i, 2] += Ff[i, 2]


@njit(cache=True)
def conservative_loads(r, t, par, Fm, Fp, F, M, Nw):
    """All conservative forces and torques; returns (energy, F_z at the support,
    z force of the floor on the rod)."""
    Fm[:, :] = 0.0
    Fp[:, :] = 0.0
    M[:, :] = 0.0
    e = bond_forces(r, t, par, Fm, Fp)
    e += wall_forces(r, t, par, Fm, Fp, Nw)
    ef, f_floor = floor_forces(r, t, par, Fm, Fp)
    eb, fz_support = boundary_forces(r, t, par, Fm, Fp)
    e += ef + eb
    e += bending_torques(t, par, M)
    e += collect_link_loads(r, t, par, Fm, Fp, F, M)
    return e, fz_support, f_floor


@njit(cache=True)
def residuals(t, F, M):
    """max_i |F_i| and max_i |M_i x t_i| (the torque that turns the link)."""
    fmax = 0.0
    mmax = 0.0
    for i in range(t.shape[0]):
        f = np.sqrt(F[i, 0] ** 2 + F[i, 1] ** 2 + F[i, 2] ** 2)
        mx = M[i, 1] * t[i, 2] - M[i, 2] * t[i, 1]
        my = M[i, 2] * t[i, 0] - M[i, 0] * t[i, 2]
        mz = M[i, 0] * t[i, 1] - M[i, 1] * t[i, 0]
        m = np.sqrt(mx * mx + my * my + mz * mz)
        if f > fmax:
            fmax = f
        if m > mmax:
            mmax = m
    return fmax, mmax


@njit(cache=True)
def euler_update(r, t, F, M, dt, par):
    """One explicit (forward) Euler step of the overdamped dynamics:
    gamma_t dr/dt = F,  gamma_r dt/dt = M x t, then |t| = 1."""
    at = dt / par[GAMMA_T]
    ar = dt / par[GAMMA_R]
    for i in range(r.shape[0]):
        r[i, 0] += at * F[i, 0]
        r[i, 1] += at * F[i, 1]
        r[i, 2] += at * F[i, 2]
        wx = M[i, 1] * t[i, 2] - M[i, 2] * t[i, 1]
        wy = M[i, 2] * t[i, 0] - M[i, 0] * t[i, 2]
        wz = M[i, 0] * t[i, 1] - M[i, 1] * t[i, 0]
        t0 = t[i, 0] + ar * wx
        t1 = t[i, 1] + ar * wy
        t2 = t[i, 2] + ar * wz
        nrm = np.sqrt(t0 * t0 + t1 * t1 + t2 * t2)
        t[i, 0] = t0 / nrm
        t[i, 1] = t1 / nrm
        t[i, 2] = t2 / nrm


@njit(cache=True)
def escaped(r, t, par):
    """True if a link end is above the open pore entrance and farther than par[R_ESCAPE]
    from the axis: it has left the pore (the block around the pore would stop it from
    coming back below the entrance). The radius comes in the parameter vector, not as a
    global: a cached kernel would keep a global's old value."""
    h = par[HALF]
    lim = par[R_ESCAPE]
    for i in range(r.shape[0]):
        for sgn in (-1.0, 1.0):
            z = r[i, 2] + sgn * h * t[i, 2]
            if z > par[Z_TOP]:
                x = r[i, 0] + sgn * h * t[i, 0]
                y = r[i, 1] + sgn * h * t[i, 1]
                if x * x + y * y > lim * lim:
                    return True
    return False


STEPS_DONE = 0  # explicit_steps stops early with one of these codes
STOP_NONFINITE = 1
STOP_ESCAPED = 2
ESCAPE_CHECK_EVERY = 32


@njit(cache=True)
def explicit_steps(r, t, par, dt, nsteps, Fm, Fp, F, M, Nw, Ff, stuck):
    """Up to ``nsteps`` explicit Euler steps; friction only when k_fr > 0.
    Returns (steps done, code): STEPS_DONE, or STOP_NONFINITE / STOP_ESCAPED
    when a value became non-finite / the rod left the pore (checked every
    ESCAPE_CHECK_EVERY steps, so the escape is caught within a few dt)."""
    use_friction = par[K_FR] > 0.0
    n_last = r.shape[0] - 1
    for n in range(nsteps):
        conservative_loads(r, t, par, Fm, Fp, F, M, Nw)
        if use_friction:
            coulomb_friction(r, par, Nw, F, Ff, stuck)
        euler_update(r, t, F, M, dt, par)
        if not np.isfinite(r[0, 0] + r[n_last, 2] + t[n_last // 2, 0] + F[n_last // 2, 1]):
            return n + 1, STOP_NONFINITE
        if n % ESCAPE_CHECK_EVERY == 0 and escaped(r, t, par):
            return n + 1, STOP_ESCAPED
    return nsteps, STEPS_DONE


# -- friction at the link ends (Scene.friction_at = "ends"): a contact's friction acts at the
#    contact point, the link end that presses on the wall, with its own normal force --------

@njit(cache=True)
def end_normal_forces(r, t, par, Ne):
    """Ne (2N,): the pore wall's normal force on each link end, Ne[2i] on r_i^-, Ne[2i+1] on
    r_i^+ (the terms of wall_forces' Nw, end by end)."""
    h = par[HALF]
    kw = par[K_WALL]
    n = r.shape[0]
    for i in range(n):
        for e in range(2):
            sgn = 2.0 * e - 1.0
            px = r[i, 0] + sgn * h * t[i, 0]
            py = r[i, 1] + sgn * h * t[i, 1]
            pz = r[i, 2] + sgn * h * t[i, 2]
            d, _, _ = _wall_point(px, py, pz, par, is_guided(i, sgn, n, par))
            Ne[2 * i + e] = kw * d if d > 0.0 else 0.0


@njit(cache=True)
def cylinder_frames(p, frame):
    """Radial, azimuthal and axial unit vectors (rows of frame[i], shape (n, 3, 3)) at the points
    p (n, 3) (x axis as radial direction for a point on the cylinder axis)."""
    for i in range(p.shape[0]):
        rho = np.sqrt(p[i, 0] ** 2 + p[i, 1] ** 2)
        if rho > 1e-14:
            nx = p[i, 0] / rho
            ny = p[i, 1] / rho
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
def point_frames(r, t, h, pf):
    """cylinder_frames at every link end point (2N, 3, 3), the ends ordered as in
    end_normal_forces."""
    p = np.empty((2 * r.shape[0], 3))
    for i in range(r.shape[0]):
        for e in range(2):
            sgn = 2.0 * e - 1.0
            for c in range(3):
                p[2 * i + e, c] = r[i, c] + sgn * h * t[i, c]
    cylinder_frames(p, pf)


@njit(cache=True)
def end_offset(r, t, anchor, pf, h, m):
    """Offset of link end m (link m // 2, lower end if m is even) from its stick anchor,
    along the azimuthal and axial directions of pf[m]."""
    i = m // 2
    sgn = 2.0 * (m % 2) - 1.0
    dx = r[i, 0] + sgn * h * t[i, 0] - anchor[m, 0]
    dy = r[i, 1] + sgn * h * t[i, 1] - anchor[m, 1]
    dz = r[i, 2] + sgn * h * t[i, 2] - anchor[m, 2]
    return (pf[m, 1, 0] * dx + pf[m, 1, 1] * dy + pf[m, 1, 2] * dz,
            pf[m, 2, 0] * dx + pf[m, 2, 1] * dy + pf[m, 2, 2] * dz)


@njit(cache=True)
def end_friction_loads(r, t, anchor, pf, h, fmax, kt, F, M, Ff, stuck):
    """Friction of the link ends on the wall (fmax[m] > 0) from their stick springs: the end's
    tangential offset d from its anchor gives -kt d, capped at fmax[m] (the Moreau envelope
    of fmax |d|, as friction_term at the centre). The force acts at the end point: it is
    added to F[i], its torque s h t_i x f about the centre to M[i], the net friction of the
    link to Ff[i] (overwritten); stuck[i] = 1 if every end of the link on the wall is within
    its stick zone. Returns the envelope's energy."""
    n = r.shape[0]
    e = 0.0
    for i in range(n):
        Ff[i, 0] = 0.0
        Ff[i, 1] = 0.0
        Ff[i, 2] = 0.0
        stuck[i] = 0.0
    for m in range(2 * n):
        if fmax[m] <= 0.0:
            continue
        i = m // 2
        sgn = 2.0 * (m % 2) - 1.0
        d1, d2 = end_offset(r, t, anchor, pf, h, m)
        nd = np.sqrt(d1 * d1 + d2 * d2)
        if kt * nd <= fmax[m]:
            c = kt
            e += 0.5 * kt * nd * nd
            if stuck[i] >= 0.0:
                stuck[i] = 1.0
        else:
            c = fmax[m] / nd
            e += fmax[m] * nd - 0.5 * fmax[m] * fmax[m] / kt
            stuck[i] = -1.0
        fx = -c * (d1 * pf[m, 1, 0] + d2 * pf[m, 2, 0])
        fy = -c * (d1 * pf[m, 1, 1] + d2 * pf[m, 2, 1])
        fz = -c * (d1 * pf[m, 1, 2] + d2 * pf[m, 2, 2])
        F[i, 0] += fx
        F[i, 1] += fy
        F[i, 2] += fz
        Ff[i, 0] += fx
        Ff[i, 1] += fy
        Ff[i, 2] += fz
        a = sgn * h
        M[i, 0] += a * (t[i, 1] * fz - t[i, 2] * fy)
        M[i, 1] += a * (t[i, 2] * fx - t[i, 0] * fz)
        M[i, 2] += a * (t[i, 0] * fy - t[i, 1] * fx)
    for i in range(n):
        if stuck[i] < 0.0:
            stuck[i] = 0.0
    return e


@njit(cache=True)
def end_friction_bounds(r, t, par, Ne, fmax):
    """Coulomb's bound min(k_fr N, cap) of every link end (2N,), N its own wall force."""
    end_normal_forces(r, t, par, Ne)
    kfr = par[K_FR]
    cap = par[F_CAP]
    for m in range(Ne.shape[0]):
        f = kfr * Ne[m]
        fmax[m] = cap if (cap > 0.0 and f > cap) else f


@njit(cache=True)
def drag_anchor(anchor, k, d1, d2, fr, lim):
    """A stick anchor k whose point is offset (d1, d2) from it along the azimuthal and axial rows
    of the frame fr (3, 3): in slip (|d| > lim = f_max/k_t) it is dragged along d so that |d| =
    lim; in the stick zone it stays."""
    nd = np.sqrt(d1 * d1 + d2 * d2)
    if nd > lim:
        f = 1.0 - lim / nd
        for c in range(3):
            anchor[k, c] += f * (d1 * fr[1, c] + d2 * fr[2, c])


@njit(cache=True)
def drop_normal_offset(anchor, k, px, py, pz):
    """Stick anchor k moved along the wall normal at the point p (the cylinder's radial direction
    there) into p's tangent plane: its offset from p becomes purely tangential.

    The stick spring acts only on the tangential offset, read in the frame of the point at the
    start of each step. An anchor left off that plane by d_n (an end that touched down keeps the
    offset of its approach; a drag along a straight tangent leaves a curved wall by the chord's
    sag) turns every rotation dtheta of the frame into a spurious force k_t d_n dtheta. At
    k_t = k_ph/l0 = 2e4 and d_n up to 3e-3 R, a frame rotation of 3e-9 rad per step made a force
    of 1.7e-7 against a tolerance of 1e-8: the equilibrium the solver had just reached moved by
    that much after every step, the residual fell by only a quarter per step while dt doubled,
    and the ramp stage ran to the time cap (conv_ramp_steps_b n128-s6, stage 94 of 128). The
    radial coordinate of an anchor means nothing physically (friction is tangential), so it is
    kept at the point's."""
    rho = np.sqrt(px * px + py * py)
    if rho > 1e-14:
        nx = px / rho
        ny = py / rho
        dn = nx * (anchor[k, 0] - px) + ny * (anchor[k, 1] - py)
        anchor[k, 0] -= dn * nx
        anchor[k, 1] -= dn * ny


@njit(cache=True)
def update_end_anchors(r, t, anchor, pf, h, fmax, kt):
    """update_anchors for friction at the link ends: an end in slip drags its anchor along so
    that kt |d| = fmax; an end off the wall has its anchor at the end point; an end on the wall
    keeps its anchor in the tangent plane of its point (drop_normal_offset)."""
    for m in range(anchor.shape[0]):
        i = m // 2
        s = 2.0 * (m % 2) - 1.0
        if fmax[m] <= 0.0:
            for c in range(3):
                anchor[m, c] = r[i, c] + s * h * t[i, c]
            continue
        d1, d2 = end_offset(r, t, anchor, pf, h, m)
        drag_anchor(anchor, m, d1, d2, pf[m], fmax[m] / kt)
        drop_normal_offset(anchor, m, r[i, 0] + s * h * t[i, 0], r[i, 1] + s * h * t[i, 1],
                           r[i, 2] + s * h * t[i, 2])


@njit(cache=True)
def explicit_steps_ends(r, t, par, dt, nsteps, kt, anchor, Ne, fmax, pf, Fm, Fp, F, M, Nw, Ff, stuck):
    """explicit_steps with the friction at the link ends (Scene.friction_at = "ends"): each end
    on the wall is held by its stick spring k_t, capped at its own Coulomb bound, as in the
    implicit solver (end_friction_loads), and its anchor follows a slip after every step."""
    h = par[HALF]
    n_last = r.shape[0] - 1
    for n in range(nsteps):
        conservative_loads(r, t, par, Fm, Fp, F, M, Nw)
        end_friction_bounds(r, t, par, Ne, fmax)
        point_frames(r, t, h, pf)
        end_friction_loads(r, t, anchor, pf, h, fmax, kt, F, M, Ff, stuck)
        euler_update(r, t, F, M, dt, par)
        update_end_anchors(r, t, anchor, pf, h, fmax, kt)
        if not np.isfinite(r[0, 0] + r[n_last, 2] + t[n_last // 2, 0] + F[n_last // 2, 1]):
            return n + 1, STOP_NONFINITE
        if n % ESCAPE_CHECK_EVERY == 0 and escaped(r, t, par):
            return n + 1, STOP_ESCAPED
    return nsteps, STEPS_DONE
