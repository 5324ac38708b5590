"""Implicit (backward Euler) integrator of the same overdamped dynamics.

Each step minimises Phi = E + drag + friction (solvers.implicit_kernels) by
Newton's method: the exact block-tridiagonal Hessian (implicit_kernels.
smooth_hessian for the smooth terms, contact_hessian and friction_term for the
one-sided contacts and the friction), a banded Cholesky solve
(implicit_kernels.banded_cholesky_solve), and a line search on the slope of Phi.
Newton starts from the last step's displacement scaled to the new dt (a
predictor: where the rod slides steadily it is nearly the answer, and the
contact and stick/slip pattern it implies is nearly the final one).

Coulomb friction.  The exact dissipation f_max |v| of a link on the wall is not
differentiable where every slip starts (v = 0).  The solver uses its Moreau
envelope about a stick anchor: a stuck link is held by a tangential spring of
stiffness k_t to its anchor, with the force capped at f_max = min(k_fr N,
cap); beyond the cap the link slides with friction exactly f_max against its
slip and drags its anchor along.  Stuck links therefore do not creep (their
anchor does not move while |F_t| < f_max); they sit within f_max/k_t of their
anchor, where the explicit scheme holds them rigidly.  The equilibrium
conditions (|F_t| <= f_max on stuck links) are the same.

Stick stiffness.  k_t (Scene.k_t, default k_ph/l0 with friction at the link ends,
k_w/10 at the centre) sets how far a stuck link
may sit from its anchor, f_max/k_t (~6e-5 R at load 0.25; the equilibrium
condition |F_t| <= f_max is the same for any k_t).  It also sets how far a
Newton step carries a change of axial force into a stuck stretch: through a
chain of bonds k_ph/l0 held by springs k_t, over sqrt(k_ph/(l0 k_t)) links.
Where a slip front runs along the rod, Newton moves it that many links per
iteration; at k_t = k_w (4.5 links at the publication numerics) a front
crossing 100 links of an L/R = 640 rod took ~20 iterations of one step, at
k_w/10 (14 links) ~7.  k_t also sets how the force is shared in a stuck stretch,
so it is converged like k_ph (ladder conv_k_t; docs/model.md, "implicit solver").

Step-size control: a step is accepted only if Newton converged (an indefinite
Hessian is shifted, Levenberg-Marquardt, until it factorises) and no link end
moved more than ``2 dx_max``; the next step is scaled by 0.9 dx_max / (largest
displacement), at most doubled.  A failed step is retried with dt/4.  (An earlier
rule also halved dt after a step of more than 10 Newton iterations; where a slip
front runs along a long rod every step needs that many, and dt shrank until the
rod crept: L/R = 640 took 4x the steps. ``newton_slow`` keeps it for the
benchmark's same-run comparison.)  dx_max is the accuracy knob: it bounds how far the path
may be cut short between two evaluations of the normal forces and the contact
set.  Near equilibrium the displacements vanish and dt grows without bound, so a
run ends in a few steps once the shape has settled.
"""
from __future__ import annotations

import numpy as np

from ...errors import DivergenceError
from ...limits import roundoff_force
from ..model import kernels as K
from ..model.forces import Workspace, end_points, evaluate
from ..scenes import Scene
from . import implicit_kernels as IK
from .base import RunState, run_protocol
from .base import relax as _relax

FD_STEP = 1e-8  # finite-difference step of the Hessian (in R for the translations, rad for the rotations)
MAX_NEWTON = 100
DT_START_FACTOR = 10.0  # first step = this x the explicit stability limit
DT_MIN_FACTOR = 1e-2  # give up below this x the explicit stability limit
GROW_MAX = 2.0
LS_C2 = 0.1  # line search: accept when the slope has fallen to C2 |initial slope|
NEWTON_TOL = 0.3  # Newton stops at a step residual of NEWTON_TOL * tol (normalised as eps_F) ...
NEWTON_ETA = 1e-2  # ... or, during the approach, at NEWTON_ETA x the largest drag force of the step
SHIFT_START = 1e-8  # indefinite Hessian: first diagonal shift, relative to each diagonal entry
SHIFT_GROW = 100.0
ACTIVE_SET_MODEL = True  # re-solve the Newton direction with the branches the step predicts (_active_set_model)
SLIP_MODEL = True  # ... switching stuck ends the step carries past their bound to the slip branch too
ACTIVE_SET_PASSES = 6  # ... predicting the branches again from each re-solved direction, at most this many solves
NORMAL_PASSES = 8  # at most this many re-solves of a step with the friction bound from its end state
ANDERSON_DEPTH = 5  # ... accelerated by Anderson mixing over this many previous passes
PASSES_BELOW = 0.1  # ... and only in a step that moved no link end by more than this x dx_max
SLOW_FACTOR = 0.5  # newton_slow (benchmark only): a step of more Newton iterations caps the next at this x its dt
HESSIANS = ("analytic", "fd")  # smooth part of the Newton Hessian: exact (default), or finite differences (the
# previous method, 15 gradient evaluations per iteration; kept for the benchmark's same-run comparison and the tests)


class AndersonHistory:
    """Anderson acceleration (type II, mixing 1) of a fixed-point iteration x = G(x), from the
    gaps g = G(x) - x of the last ``depth`` iterates: the next iterate is x + g - (dX + dG) c,
    c minimising |g - dG c| (least squares), where dX, dG hold the differences of successive
    iterates and gaps (Walker and Ni, SIAM J. Numer. Anal. 49, 1715 (2011)). Without history it
    is plain substitution x + g. Where G is linear with Jacobian J, depth k solves the fixed
    point exactly once the differences span a Krylov space of I - J on which it closes (as
    GMRES would); a nonsmooth G (a contact switching) is handled as well as its secants allow."""

    def __init__(self, n: int, depth: int):
        self.depth = depth
        self.dX, self.dG = np.zeros((depth, n)), np.zeros((depth, n))  # one difference per row
        self.k = 0  # differences stored
        self.last: tuple[np.ndarray, np.ndarray] | None = None

    def update(self, x: np.ndarray, g: np.ndarray) -> np.ndarray:
        """The next iterate after x with gap g (new array). The sums run in a fixed order
        (implicit_kernels.dot; the BLAS's threaded sums would make the path depend on the core
        count) and the m x m least-squares problem is solved by its normal equations."""
        if self.last is not None:
            j = self.k % self.depth
            np.subtract(x, self.last[0], out=self.dX[j])
            np.subtract(g, self.last[1], out=self.dG[j])
            self.k += 1
        self.last = (x.copy(), g.copy())
        m = min(self.k, self.depth)
        out = x + g
        if m == 0:
            return out
        dX, dG = self.dX[:m], self.dG[:m]
        A = np.array([[IK.dot(dG[i], dG[j]) for j in range(m)] for i in range(m)])
        b = np.array([IK.dot(dG[i], g) for i in range(m)])
        c = np.linalg.lstsq(A, b, rcond=1e-12)[0]
        for i in range(m):
            out -= c[i] * (dX[i] + dG[i])
        return out


class StepFailed(Exception):
    """An implicit step did not converge (retried with a smaller dt)."""


class ImplicitStepper:
    def __init__(self, scene: Scene, dt: float | None = None, hessian: str = "analytic",
                 newton_slow: int | None = None, active_set: bool | None = None, slip_model: bool | None = None,
                 active_set_passes: int | None = None):
        if hessian not in HESSIANS:
            raise ValueError(f"hessian must be one of {HESSIANS}, got {hessian!r}")
        self.scene = scene
        self.hessian = hessian
        self.newton_slow = newton_slow  # None: no cut of dt after slow Newton steps (the default)
        self.active_set = ACTIVE_SET_MODEL if active_set is None else active_set  # False: the plain Newton step
        self.slip_model = SLIP_MODEL if slip_model is None else slip_model
        self.passes = ACTIVE_SET_PASSES if active_set_passes is None else int(active_set_passes)
        if self.passes < 1:
            raise ValueError(f"active_set_passes must be >= 1, got {active_set_passes!r}")
        self.par = scene.params()
        # the finite-difference Hessian leaves out the one-sided contact penalties
        # (added exactly by contact_hessian)
        self.par_fd = self.par.copy()
        self.par_fd[K.K_WALL] = 0.0
        c = scene.constants()
        self.beta, self.gamma_r = c.beta, c.gamma_r
        n = self.n = scene.N
        self.dt_explicit = scene.dt_factor * c.dt_stable
        self.dt = dt if dt is not None else DT_START_FACTOR * self.dt_explicit
        self.dt_min = DT_MIN_FACTOR * c.dt_stable
        self.dx_max = scene.dx_max
        self.use_friction = scene.k_fr > 0.0
        self.cap = scene.friction_cap
        self.h = 0.5 * scene.l0
        scale = scene.l0 * scene.load / scene.L
        self.gtol_F = max(NEWTON_TOL * scene.tol * scale, roundoff_force(scene))
        self.gtol_M = self.gtol_F * scene.R
        self.step_hint = f"reduce dx_max (now {scene.dx_max})"
        self.ws = Workspace.for_links(n)
        z3 = lambda: np.zeros((n, 3))  # noqa: E731
        self.rn, self.tn, self.e1, self.e2, self.rp, self.tp, self.r2, self.t2 = (z3() for _ in range(8))
        self.frame = np.zeros((n, 3, 3))
        self.g, self.g0, self.g_fd, self.gp = (np.zeros((n, IK.NDOF)) for _ in range(4))
        self.ab = np.zeros((IK.BAND + 1, IK.NDOF * n))
        self.ab_base = np.zeros_like(self.ab)  # the Hessian before the active-set model's switches
        self.chol = IK.cholesky_work(n)  # its Cholesky factor, by blocks
        self.p = np.zeros(IK.NDOF * n)  # Newton direction
        self.p_keep, self.rhs = np.zeros(IK.NDOF * n), np.zeros(IK.NDOF * n)
        self.gm = np.zeros((n, IK.NDOF))  # the gradient of the active-set model
        self.nu, self.nu1 = np.ones(n), np.ones(n)
        # friction at the link centres (one bound, anchor and frame per link) or at the link ends
        # (Scene.friction_at = "ends": per end, 2n, ordered as kernels.end_normal_forces)
        self.ends = scene.friction_at == "ends"
        self.fmax = np.zeros(2 * n if self.ends else n)
        self.Ne = np.zeros(2 * n)
        self.pf = np.zeros((2 * n, 3, 3))
        self.fd_step = np.array([FD_STEP * scene.R] * 3 + [FD_STEP] * 2)
        self.kt = scene.k_t  # stiffness of the stick spring (EI/R^3 per link)
        self.prev_dr, self.prev_dt_vec = z3(), z3()  # the last accepted step (predictor)
        self.prev_dt = 0.0
        self.last_iterations = 0
        self.bound_lags = False  # the last step ended with the friction bound still apart from k_fr N
        self.anchor = None  # stick anchors: the run state's, set at the first step

    # -- one backward-Euler step ------------------------------------------------
    def _loads(self, r, t) -> None:
        """Conservative loads at (r, t) into ws, their energy into self.E; with friction at the
        link ends, the ends' stick-spring friction (force and torque) and its envelope too."""
        ws = self.ws
        self.E = K.conservative_loads(r, t, self.par, ws.Fm, ws.Fp, ws.F, ws.M, ws.Nw)[0]
        if self.ends and self.use_friction:
            self.E += K.end_friction_loads(r, t, self.anchor, self.pf, self.h, self.fmax, self.kt, ws.F, ws.M,
                                           ws.Ff, ws.stuck)

    def _centre_friction(self, r, g, hessian: bool) -> float:
        """The centre friction's envelope (friction_term) into g (or its Hessian into ab); 0
        with friction at the ends, which _loads carries."""
        if not self.use_friction or self.ends:
            return 0.0
        return IK.friction_term(r, self.anchor, self.frame, self.fmax, self.kt, g, self.ab, hessian)

    def _smooth(self, r, t, nu, g):
        """Phi_s and its gradient at (r, t); leaves the loads at (r, t) in ws and E in self.E."""
        ws = self.ws
        self._loads(r, t)
        return self.E + IK.step_gradient(r, t, nu, self.rn, self.tn, self.frame, self.e1, self.e2, self.cr, self.ct,
                                         ws.F, ws.M, g)

    def _start_step(self, st: RunState, dt: float) -> None:
        self.cr, self.ct = self.beta / dt, self.gamma_r / dt
        self.rn[:] = st.r
        self.tn[:] = st.t
        IK.local_frames(self.rn, self.frame)
        self.fmax[:] = 0.0
        if st.anchor is None:
            st.anchor = end_points(st.r, st.t, self.h) if self.ends else st.r.copy()
        self.anchor = st.anchor
        if self.ends:
            K.point_frames(self.rn, self.tn, self.h, self.pf)
        # the mirror symmetry y -> -y of a planar state is kept exactly, as in the
        # explicit scheme (its forces have no y component); finite-difference
        # noise in the Hessian would otherwise leak out of the plane
        self.planar = not (np.any(st.r[:, 1]) or np.any(st.t[:, 1]))
        if self.use_friction:
            self.fmax[:] = self._bound(self.rn, self.tn)

    def _bound(self, r: np.ndarray, t: np.ndarray) -> np.ndarray:
        """Coulomb's bound f_max = min(k_fr N, cap) of every link (or link end) at (r, t) (new array)."""
        if self.ends:
            out = np.zeros(2 * self.n)
            K.end_friction_bounds(r, t, self.par, self.Ne, out)
            return out
        evaluate(self.par, r, t, self.ws)
        f = self.scene.k_fr * self.ws.Nw
        return np.minimum(f, self.cap) if self.cap > 0.0 else f

    def _phi(self, r, t, nu, g) -> float:
        """Phi and its gradient (into g) at (r, t)."""
        return self._smooth(r, t, nu, g) + self._centre_friction(r, g, False)

    def _newton(self, r: np.ndarray, t: np.ndarray, st: RunState) -> None:
        """Solve the step to a residual below the run's tolerance or, while the
        rod is still moving, below NEWTON_ETA x its drag forces (an inexact
        Newton forcing term: the leftover residual acts as a force NEWTON_ETA
        times smaller than the one moving the rod, well inside the first-order
        error of the step; near equilibrium the drag vanishes and the run's
        tolerance takes over).

        Work per iteration: the line search's last gradient evaluation is the
        next iteration's (its loads F, M are re-projected on the new tangent
        bases), so an iteration costs one gradient per line-search trial (one
        when the full Newton step is taken), one Hessian assembly and one banded
        factorisation; the Hessian is built only once the residual is known to
        be above the tolerance."""
        g, ab, ws = self.g, self.ab, self.ws
        fresh = False  # ws holds the loads at (r, t), self.E their energy
        for it in range(MAX_NEWTON):
            st.count("newton_iterations")
            IK.tangent_bases(t, self.e1, self.e2)
            if not fresh:
                st.count("gradients")
                self._loads(r, t)
            phi = self.E + IK.step_gradient(r, t, self.nu1, self.rn, self.tn, self.frame, self.e1, self.e2, self.cr,
                                            self.ct, ws.F, ws.M, g)
            phi += self._centre_friction(r, g, False)
            gF, gM, dr, dtv = IK.newton_residuals(g, r, self.rn, t, self.tn)
            if gF <= max(self.gtol_F, NEWTON_ETA * self.cr * dr) and gM <= max(self.gtol_M, NEWTON_ETA * self.ct * dtv):
                return
            self._hessian(r, t)
            p = self._solve(ab, g, st)
            if self.active_set:
                p = self._active_set_model(r, t, g, p, st)
            self._line_search(r, t, p, phi, IK.dot(g, p), st)
            r[:] = self.r2
            t[:] = self.t2
            fresh = not self.planar
            if self.planar:
                r[:, 1] = 0.0
                t[:, 1] = 0.0
                t /= np.linalg.norm(t, axis=1)[:, None]
        raise StepFailed(f"Newton did not converge in {MAX_NEWTON} iterations")

    def _active_set_model(self, r: np.ndarray, t: np.ndarray, g: np.ndarray, p: np.ndarray,
                          st: RunState) -> np.ndarray:
        """The Newton direction solved again with the model switched, for the links the plain
        step p carries across a kink of Phi, to the branch the step predicts (an active-set
        guess, as in primal-dual active-set methods): links in slip carried back into the
        stick zone are modelled as stuck (implicit_kernels.stick_model), link ends carried
        into the wall as in contact (contact_model). Off those branches the model has only
        the drag's curvature, beta/dt, so late in a long run (dt ~ 1e3) the plain step sent
        hundreds of links far past their anchors or deep into the wall, and the line search
        spent 3-6 gradients per iteration finding the kink (L/R = 640, seed 0: 20 500
        gradients in 8 300 iterations; with the models 8 600 in 6 700. L/R = 1280: 87 000
        in 21 800; 37 000 in 17 400). The true gradient is kept for the line search, and the
        new direction only if it descends.

        With friction at the ends, stuck ends that the step carries past their bound are switched
        to the slip branch as well (implicit_kernels.end_slip_model, ``slip_model``), and the
        branches are predicted again from each re-solved direction, until they repeat or after
        ``active_set_passes`` solves (a primal-dual active-set iteration on the step's quadratic
        model: each pass costs a factorisation, not a gradient and a line search). A stuck
        stretch passes a change of axial force on over about sqrt(k_ph/(l0 k_t)) links per solve,
        one at k_t = k_ph/l0, so a slip front moves about one link per pass instead of per Newton
        iteration (L/R = 1280, seed 0: 191 900 Newton iterations with one pass and no slip
        switch, 19 000 with six; benchmarks/results/profile_long_rods_a62bb36.json and
        profile_long_rods.json)."""
        if self.passes > 1:
            np.copyto(self.ab_base, self.ab)
        gm = self.gm
        last = None
        for k in range(self.passes):
            if k > 0:
                np.copyto(self.ab, self.ab_base)
            gm[:] = g
            n_stick = n_slip = 0
            if self.use_friction and self.ends:
                n_stick = IK.end_stick_model(r, t, self.anchor, self.pf, self.frame, self.e1, self.e2, self.h,
                                             self.fmax, self.kt, self.p, gm, self.ab)
                if self.slip_model:
                    n_slip = IK.end_slip_model(r, t, self.anchor, self.pf, self.frame, self.e1, self.e2, self.h,
                                               self.fmax, self.kt, self.p, gm, self.ab)
            elif self.use_friction:
                n_stick = IK.stick_model(r, self.anchor, self.frame, self.fmax, self.kt, self.p, gm, self.ab)
            n_contact = IK.contact_model(r, t, self.frame, self.e1, self.e2, self.par, self.p, gm, self.ab)
            switched = (n_stick, n_slip, n_contact)
            if switched == (0, 0, 0) or switched == last:
                break
            last = switched
            keep = self.p_keep
            keep[:] = self.p  # the kernels read p and change only gm and ab
            st.count("active_set_models")
            q = self._solve(self.ab, gm, st)
            if not IK.dot(g, q) < 0.0:
                self.p[:] = keep
                break
            p = q
        return p

    def _hessian(self, r: np.ndarray, t: np.ndarray) -> None:
        """Newton Hessian of Phi at (r, t) into ab: the smooth part (exact, or by
        finite differences with hessian='fd'), the one-sided contacts and the
        friction (both exact)."""
        ab, ws = self.ab, self.ws
        if self.hessian == "fd":  # clobbers ws, whose loads are no longer needed in this iteration
            IK.smooth_gradient(r, t, self.nu1, self.rn, self.tn, self.frame, self.e1, self.e2, self.cr, self.ct,
                               self.par_fd, ws.Fm, ws.Fp, ws.F, ws.M, ws.Nw, self.g_fd)
            IK.fd_hessian(r, t, self.rn, self.tn, self.frame, self.e1, self.e2, self.cr, self.ct, self.par_fd,
                          self.fd_step, self.g_fd, ws.Fm, ws.Fp, ws.F, ws.M, ws.Nw, self.rp, self.tp, self.nu,
                          self.gp, ab)
        else:
            IK.smooth_hessian(r, t, self.tn, self.frame, self.e1, self.e2, self.cr, self.ct, self.par, ab)
        IK.contact_hessian(r, t, self.frame, self.e1, self.e2, self.par, ab)
        if self.use_friction and self.ends:
            IK.end_friction_hessian(r, t, self.anchor, self.pf, self.frame, self.e1, self.e2, self.h, self.fmax,
                                    self.kt, ab)
        elif self.use_friction:
            IK.friction_term(r, self.anchor, self.frame, self.fmax, self.kt, self.g_fd, ab, True)

    def _solve(self, ab: np.ndarray, g: np.ndarray, st: RunState) -> np.ndarray:
        """Newton direction -H^-1 g by banded Cholesky.  Where Phi is not convex
        (a buckling mode unstable on the scale of dt) the diagonal is shifted
        until H + mu diag|H| is positive definite (Levenberg-Marquardt): a descent direction that the line
        search and the displacement limit then keep short."""
        mu = 0.0
        rhs = self.rhs
        np.negative(g.ravel(), out=rhs)
        for _ in range(8):
            st.count("factorisations")
            if IK.banded_cholesky_solve(ab, rhs, self.chol, self.p):
                return self.p.reshape(self.n, IK.NDOF)
            st.count("shifted_hessians")
            if mu == 0.0:
                diag = np.abs(ab[0])
            new = SHIFT_START if mu == 0.0 else mu * SHIFT_GROW
            ab[0] += (new - mu) * diag
            mu = new
        raise StepFailed("Hessian not positive definite even after a diagonal shift")

    def _line_search(self, r, t, p, phi0: float, slope0: float, st: RunState) -> float:
        """Step length along the Newton direction p.

        Works on the slope d Phi/d alpha, computed from gradients, which keep their
        precision where differences of Phi drown in round-off.  The full step is
        taken if the slope there is still negative or has fallen below C2 |slope0|
        (the usual case).  Otherwise the root of the slope is bracketed and found
        by regula falsi (Illinois variant) to |slope| <= C2 |slope0|: this is what
        an overshoot across the kink of the one-sided wall penalty needs, where the
        slope jumps and bisection-like cuts would crawl.  Phi must not rise
        beyond round-off."""
        if not slope0 < 0.0:
            raise StepFailed("Newton direction is not a descent direction")
        slack = 1e-12 * max(1.0, abs(phi0))
        lim = LS_C2 * -slope0
        lo, s_lo, hi, s_hi = 0.0, slope0, None, 0.0
        alpha, side = 1.0, 0
        for _ in range(30):
            IK.displace(r, t, self.frame, self.e1, self.e2, p, alpha, self.r2, self.t2, self.nu)
            st.count("gradients")
            phi = self._phi(self.r2, self.t2, self.nu, self.gp)
            slope = IK.dot(self.gp, p)
            if not (np.isfinite(phi) and np.isfinite(slope)):
                hi, s_hi = alpha, np.inf
            elif phi <= phi0 + slack and (abs(slope) <= lim or (slope < 0.0 and hi is None)):
                return alpha
            elif slope < 0.0:
                lo, s_lo = alpha, slope
                if side == -1:
                    s_hi *= 0.5
                side = -1
            else:
                hi, s_hi = alpha, slope
                if side == 1:
                    s_lo *= 0.5
                side = 1
            if hi is None:
                raise StepFailed("line search: Phi rose along a descent direction")
            if np.isfinite(s_hi):
                alpha = lo - s_lo * (hi - lo) / (s_hi - s_lo)
                alpha = min(max(alpha, lo + 0.01 * (hi - lo)), hi - 0.01 * (hi - lo))
            else:
                alpha = 0.5 * (lo + hi)
        raise StepFailed("line search failed")

    def _step(self, st: RunState, dt: float) -> tuple[np.ndarray, np.ndarray]:
        self._start_step(st, dt)
        r, t = st.r.copy(), st.t.copy()
        n0 = st.work.get("newton_iterations", 0)
        if self.prev_dt > 0.0:  # predictor: the last step's displacement, scaled to dt
            a = min(dt / self.prev_dt, GROW_MAX)
            r += a * self.prev_dr
            t += a * self.prev_dt_vec
            t /= np.linalg.norm(t, axis=1)[:, None]
        self._newton(r, t, st)
        if self.use_friction:
            self._implicit_normal_forces(r, t, st)
        self.last_iterations = st.work["newton_iterations"] - n0
        return r, t

    def _implicit_normal_forces(self, r: np.ndarray, t: np.ndarray, st: RunState) -> None:
        """Coulomb's bound from the normal forces at the end of the step, not its start: while the
        limits k_fr N of the links that started the step on the wall differ from those at its
        solution by more than Newton's tolerance, they are updated and the step solved again
        (a few passes, each from the last solution). With the bound lagged one step, a link
        sliding off the wall relaxes by one fixed-point iteration per step; near equilibrium dt
        doubles per step, so the run reached t_max first (L/R = 400, k_ph = 1e3: 1.5 tol).
        Only once the rod is nearly at rest: the step's drag below the run's force tolerance,
        and no link end moved by more than PASSES_BELOW x dx_max. While it moves, the lag is
        part of the path's first-order error, which dx_max bounds, and re-solving every step
        tripled the cost of L/R = 640. The drag alone is not enough: at dt ~ 1e4 a long helix
        still creeps by ~dx_max per step under a drag far below the tolerance, and there the
        end state's bound moves with the slip itself (the sliding distance is set by the
        excess of the force over f_max, times dt), so the passes did not close, froze dt, and
        the creep went on over tens of steps of 40-100 Newton iterations each (L/R = 640, seed
        1: 49 such steps, 32 % of its iterations; the gate: 8 336 -> 6 059 iterations, the same
        final state).

        The passes solve the fixed point f_max = G(f_max), G = bound(r(f_max)), on the links
        on the wall, by Anderson acceleration (AndersonHistory; the first pass is plain
        substitution). Plain substitution can cycle: a link sliding lightly along the wall,
        whose normal force moves with its own sliding, went round a cycle of five values at
        every step for 70 000 steps (protocols_L640/ramp32-s0, ramp stage 28: 30 min at 10x the
        tolerance). Per-link bisection within brackets (the previous method) ended that cycle
        but contracts by at most 2 per pass and ignores that neighbouring links share their
        normal forces: the passes rarely closed within a step, the next step started them
        anew at a frozen dt (publication numerics, L/R = 640, seed 1: 4 071 passes in 18 558
        Newton iterations; with Anderson 348 in 8 272. The last stage of a ramp of 128 loads at
        L/R = 320: 121 of its 195 iterations in 6 steps at a frozen dt. Same-run comparisons:
        benchmarks/results/ab_normal_passes.json and ab_normal_passes_ramp.json)."""
        self.bound_lags = False
        if NEWTON_ETA * self.cr * np.abs(r - self.rn).max() > self.gtol_F:
            return
        if self._largest_move(r, t) > PASSES_BELOW * self.dx_max:
            return
        on = np.flatnonzero(self.fmax > 0.0)
        if on.size == 0:
            return
        hist = AndersonHistory(on.size, ANDERSON_DEPTH)
        for _ in range(NORMAL_PASSES):
            x = self.fmax[on]
            gap = self._bound(r, t)[on] - x
            if np.abs(gap).max() <= self.gtol_F:
                return
            x = hist.update(x, gap)
            np.maximum(x, 0.0, out=x)
            if self.cap > 0.0:
                np.minimum(x, self.cap, out=x)
            self.fmax[on] = x
            st.count("normal_force_passes")
            self._newton(r, t, st)
        # still apart (a link whose normal force moves with its own friction: the passes contract
        # slowly). The step is never accepted with a link held by more friction than the bound at
        # its solution: the last pass's extrapolated bound can lie above it, and a link held there
        # stays stuck beyond Coulomb's limit, step after step, while the equilibrium test (at the
        # end state's bound) never passes (protocols/ramp-s2, ramp stage 114 of 128: 65 000
        # steps to t_max, the next stage never relaxed). Such links get the end state's bound and
        # the step is solved once more: they slip by their excess, as Coulomb's law says.
        b = self._bound(r, t)[on]
        if np.any(self.fmax[on] > b + self.gtol_F):
            self.fmax[on] = np.minimum(self.fmax[on], b)
            st.count("normal_force_passes")
            self._newton(r, t, st)
        # the next step is not longer than this one, so that the run settles over more steps
        # instead of doubling dt to t_max (L/R = 320 seed 4: t_max at 40 tol)
        self.bound_lags = True

    def _largest_move(self, r: np.ndarray, t: np.ndarray) -> float:
        """The largest displacement of a link end in the step to (r, t) (bounded by |dr| + h |dt|)."""
        return float(np.max(np.linalg.norm(r - self.rn, axis=1) + self.h * np.linalg.norm(t - self.tn, axis=1)))

    # -- adaptive stepping ---------------------------------------------------------
    def advance(self, st: RunState, t_stop: float) -> int:
        while True:
            dt = min(self.dt, t_stop - st.time)
            if dt <= 0.0:
                return K.STEPS_DONE
            try:
                r, t = self._step(st, dt)
            except StepFailed as exc:
                self._shrink(st, 0.25, str(exc))
                continue
            d = self._largest_move(r, t)
            if d > 2.0 * self.dx_max:
                self._shrink(st, max(0.1, 0.9 * self.dx_max / d), "displacement above 2 dx_max")
                continue
            np.subtract(r, st.r, out=self.prev_dr)
            np.subtract(t, st.t, out=self.prev_dt_vec)
            self.prev_dt = dt
            st.r[:] = r
            st.t[:] = t
            if self.ends:
                K.update_end_anchors(st.r, st.t, self.anchor, self.pf, self.h, self.fmax, self.kt)
            else:
                IK.update_anchors(st.r, self.anchor, self.frame, self.fmax, self.kt)
            st.time += dt
            st.steps += 1
            if dt == self.dt:
                self.dt *= min(GROW_MAX, 0.9 * self.dx_max / d) if d > 0 else GROW_MAX
                if self.bound_lags:
                    self.dt = min(self.dt, dt)
                if self.newton_slow is not None and self.last_iterations > self.newton_slow:
                    self.dt = min(self.dt, SLOW_FACTOR * dt)
            if K.escaped(st.r, st.t, self.par):
                return K.STOP_ESCAPED
            return K.STEPS_DONE

    def _shrink(self, st: RunState, factor: float, why: str) -> None:
        st.count("rejected_steps")
        st.count(f"rejected: {why}")
        self.dt *= factor
        if self.dt < self.dt_min:
            raise DivergenceError(
                f"scene {self.scene.name!r}: implicit step size fell below {self.dt_min:.3g} at t = {st.time:.6g} "
                f"(last failure: {why}); the state is ill-posed for the solver, check k_ph = {self.scene.k_ph}, "
                f"k_w = {self.scene.k_w}, load = {self.scene.load}")


def relax(scene: Scene, st: RunState, *, t_end: float | None = None, progress: bool = True,
          label: str = "") -> RunState:
    """Integrate until equilibrium, escape, or the time cap (t_end or scene.t_max)."""
    return _relax(scene, st, ImplicitStepper(scene), t_end=t_end, progress=progress, label=label)


def run(scene: Scene, *, progress: bool = True) -> RunState:
    """Run the scene's protocol from its initial state."""
    return run_protocol(scene, ImplicitStepper, progress=progress)
