"""Implicit (backward Euler) integrator of the same overdamped dynamics.

Each step minimises Phi = E + drag + Coulomb dissipation (solvers.implicit_kernels)
by Newton's method: a finite-difference block-tridiagonal Hessian, a banded
Cholesky solve (LAPACK via scipy), a backtracking line search on Phi, and an
active set for Coulomb friction:

* links touching the wall at the step's start are *stuck* (their tangential
  displacement is held at exactly zero) or *sliding* (friction f_max against the
  slip direction), starting from the explicit law's decision;
* a stuck link whose tangential reaction exceeds f_max at the solution starts
  to slide; a sliding link whose slip reverses sticks; the step is solved again
  until the set no longer changes.

Step-size control: a step is accepted only if Newton converged, the Hessian was
positive definite and no link end moved more than ``2 dx_max``; the next step is
scaled by 0.9 dx_max / (largest displacement), at most doubled.  A failed step
is retried with dt/4.  dx_max is the accuracy knob: it bounds how far the path
may be cut short between two evaluations of the friction law and the contact
set.  Near equilibrium the displacements vanish and dt grows without bound, so a
run ends in a few steps once the shape has settled.
"""
from __future__ import annotations

import numpy as np
from scipy.linalg import LinAlgError, solveh_banded

from ..errors import DivergenceError
from ..model import kernels as K
from ..model.forces import Workspace, evaluate
from ..scenes import Scene
from . import implicit_kernels as IK
from .base import RunState, run_protocol
from .base import relax as _relax

FD_STEP = 1e-7  # finite-difference step of the Hessian (R, rad)
MAX_NEWTON = 25
MAX_ACTIVE_SET = 6
DT_START_FACTOR = 10.0  # first step = this x the explicit stability limit
DT_MIN_FACTOR = 1e-2  # give up below this x the explicit stability limit
GROW_MAX = 2.0
LS_C2 = 0.5  # line search: accept when the slope has fallen to C2 |initial slope|
V_SLIP = 1e-9  # below this slip (R) a sliding link slips along its net tangential force
NEWTON_TOL = 0.3  # Newton stops at a step residual of NEWTON_TOL * tol (normalised as eps_F)


class StepFailed(Exception):
    """An implicit step did not converge (retried with a smaller dt)."""


class ImplicitStepper:
    def __init__(self, scene: Scene, dt: float | None = None):
        self.scene = scene
        self.par = scene.params()
        c = scene.constants()
        self.beta, self.gamma_r = c.beta, c.gamma_r
        n = self.n = scene.N
        self.dt_explicit = scene.dt_factor * c.dt_stable
        self.dt = dt if dt is not None else DT_START_FACTOR * self.dt_explicit
        self.dt_min = DT_MIN_FACTOR * c.dt_stable
        self.dx_max = scene.dx_max
        self.use_friction = scene.k_fr > 0.0
        self.cap = scene.friction_cap * scene.l0
        self.h = 0.5 * scene.l0
        scale = scene.l0 * scene.load / scene.L
        self.gtol_F = NEWTON_TOL * scene.tol * scale
        self.gtol_M = self.gtol_F * scene.R
        self.v_slip = V_SLIP * scene.R
        self.step_hint = f"reduce dx_max (now {scene.dx_max})"
        self.ws = Workspace.for_links(n)
        z3 = lambda: np.zeros((n, 3))  # noqa: E731
        self.rn, self.tn, self.e1, self.e2, self.rp, self.tp, self.r2, self.t2 = (z3() for _ in range(8))
        self.frame = np.zeros((n, 3, 3))
        self.g, self.g0, self.gp = (np.zeros((n, IK.NDOF)) for _ in range(3))
        self.ab = np.zeros((IK.BAND + 1, IK.NDOF * n))
        self.nu, self.nu1 = np.ones(n), np.ones(n)
        self.v = np.zeros((n, 2))
        self.u = np.zeros((n, 2))
        self.fmax = np.zeros(n)
        self.mode = np.zeros(n, dtype=np.int64)  # 0 free, 1 stuck, 2 sliding

    # -- one backward-Euler step ------------------------------------------------
    def _smooth(self, r, t, nu, g):
        ws = self.ws
        return IK.smooth_gradient(r, t, nu, self.rn, self.tn, self.frame, self.e1, self.e2, self.cr, self.ct,
                                  self.par, ws.Fm, ws.Fp, ws.F, ws.M, ws.Nw, g)

    def _start_step(self, st: RunState, dt: float) -> None:
        self.cr, self.ct = self.beta / dt, self.gamma_r / dt
        self.rn[:] = st.r
        self.tn[:] = st.t
        IK.local_frames(self.rn, self.frame)
        self.mode[:] = 0
        if not self.use_friction:
            return
        ws = self.ws
        evaluate(self.par, self.rn, self.tn, ws)
        touching = ws.Nw > 0.0
        self.fmax[:] = self.scene.k_fr * ws.Nw
        if self.cap > 0.0:
            np.minimum(self.fmax, self.cap, out=self.fmax)
        self.mode[touching] = np.where(ws.stuck[touching] > 0.5, 1, 2)
        # slip direction of a sliding link: its net tangential force
        ft = np.einsum("ikc,ic->ik", self.frame[:, 1:, :], ws.F)
        nf = np.linalg.norm(ft, axis=1)
        ok = nf > 0
        self.u[:] = 0.0
        self.u[ok] = ft[ok] / nf[ok, None]

    def _stick(self, r: np.ndarray, links: np.ndarray) -> None:
        """Put links back at their start position along the wall (keep the radial part)."""
        n = self.frame[links, 0, :]
        d = r[links] - self.rn[links]
        r[links] = self.rn[links] + np.einsum("ic,ic->i", d, n)[:, None] * n

    def _newton(self, r: np.ndarray, t: np.ndarray, st: RunState) -> None:
        g, ab, v = self.g, self.ab, self.v
        for it in range(MAX_NEWTON):
            st.count("newton_iterations")
            IK.tangent_bases(t, self.e1, self.e2)
            phi = self._smooth(r, t, self.nu1, self.g0)
            ws = self.ws
            IK.fd_hessian(r, t, self.rn, self.tn, self.frame, self.e1, self.e2, self.cr, self.ct, self.par,
                          FD_STEP, self.g0, ws.Fm, ws.Fp, ws.F, ws.M, ws.Nw, self.rp, self.tp, self.nu, self.gp,
                          ab)
            g[:] = self.g0
            IK.tangential_displacement(r, self.rn, self.frame, v)
            phi += IK.add_friction(v, self.fmax, self.mode, self.u, self.v_slip, g, ab)
            IK.pin_stuck(self.mode, g, ab)
            if (np.abs(g[:, :3]).max() <= self.gtol_F and np.abs(g[:, 3:]).max() <= self.gtol_M):
                return
            try:
                p = solveh_banded(ab, -g.ravel(), lower=True, check_finite=False).reshape(self.n, IK.NDOF)
            except (LinAlgError, ValueError):
                st.count("indefinite_hessians")
                raise StepFailed("Hessian not positive definite") from None
            alpha = self._line_search(r, t, p, phi, float(np.dot(g.ravel(), p.ravel())))
            r[:] = self.r2
            t[:] = self.t2
            if self.use_friction:
                # a sliding link whose slip has reversed sticks
                IK.tangential_displacement(r, self.rn, self.frame, v)
                sliding = np.flatnonzero(self.mode == 2)
                rev = sliding[np.einsum("ik,ik->i", v[sliding], self.u[sliding]) < 0.0]
                if rev.size:
                    self.mode[rev] = 1
                    self._stick(r, rev)
        raise StepFailed(f"Newton did not converge in {MAX_NEWTON} iterations")

    def _line_search(self, r, t, p, phi0: float, slope0: float) -> float:
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
            phi = self._smooth(self.r2, self.t2, self.nu, self.gp)
            IK.tangential_displacement(self.r2, self.rn, self.frame, self.v)
            phi += IK.friction_value(self.v, self.fmax, self.mode)
            slope = float(np.dot(self.gp.ravel(), p.ravel())) + IK.friction_slope(self.v, self.fmax, self.mode, p)
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
        for _ in range(MAX_ACTIVE_SET):
            self._newton(r, t, st)
            if not self.use_friction:
                return r, t
            # stuck links whose reaction exceeds the Coulomb limit start to slide
            IK.tangent_bases(t, self.e1, self.e2)
            self._smooth(r, t, self.nu1, self.g0)
            stuck = np.flatnonzero(self.mode == 1)
            react = self.g0[stuck, 1:3]
            nr = np.linalg.norm(react, axis=1)
            over = nr > self.fmax[stuck] * (1.0 + 1e-9) + self.gtol_F
            if not over.any():
                return r, t
            idx = stuck[over]
            self.mode[idx] = 2
            self.u[idx] = -react[over] / nr[over, None]
            st.count("active_set_changes")
        raise StepFailed("friction active set did not settle")

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
            d = float(np.max(np.linalg.norm(r - st.r, axis=1) + self.h * np.linalg.norm(t - st.t, axis=1)))
            if d > 2.0 * self.dx_max:
                self._shrink(st, max(0.1, 0.9 * self.dx_max / d), "displacement above 2 dx_max")
                continue
            st.r[:] = r
            st.t[:] = t
            st.time += dt
            st.steps += 1
            if dt == self.dt:
                self.dt *= min(GROW_MAX, 0.9 * self.dx_max / d) if d > 0 else GROW_MAX
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
