"""The implicit (backward-Euler) solver reproduces the explicit scheme's equilibria.

Tolerances.  Both runs stop at eps < tol = 1e-4, which bounds each one's error
of F_z by tol * load (4e-5 relative to |F_z(L)| ~ 0.1-0.25).  Without friction
the equilibrium is unique, so the two must agree to that level (2e-4 allows both
errors and the penalty-level differences).  With friction the equilibrium depends
on the path; the implicit path differs from the explicit one by O(dx_max), and
the issue's requirement is the same contact pattern and |F_z(L)| within 1 %.
"""
import numpy as np
import pytest

from confined_rod import Scene, simulate
from confined_rod.errors import DivergenceError
from confined_rod.sim.model import kernels as K


def pair(**kw):
    out = []
    for solver in ("explicit", "implicit"):
        out.append(simulate(Scene(load=0.25, l0=1.0, tol=1e-4, solver=solver, friction_at="centre", **kw),
                            progress=False))
    return out


def test_frictionless_equilibrium_is_the_same():
    ex, im = pair(L=20.0, k_fr=0.0)
    assert ex.converged and im.converged
    assert float(im.F_transmitted) == pytest.approx(float(ex.F_transmitted), rel=2e-4)
    np.testing.assert_array_equal(im.contact.values, ex.contact.values)
    assert float(im.L_z) == pytest.approx(float(ex.L_z), abs=1e-3)


@pytest.mark.parametrize("L", [10.0, 20.0])
def test_frictional_equilibrium_matches_within_one_percent(L):
    """Friction at the link centres: the explicit scheme's rigid Coulomb rule and the implicit
    stick spring land in the same equilibrium. (With friction at the link ends a stuck link also
    holds a torque, the set of equilibria is wider, and one seed's end state moves by 1-3 % with
    dx_max, non-monotonically; the two schemes are compared on their paths instead, below.)"""
    ex, im = pair(L=L, k_fr=0.8)
    assert ex.converged and im.converged
    np.testing.assert_array_equal(im.contact.values, ex.contact.values)
    assert float(im.F_transmitted) == pytest.approx(float(ex.F_transmitted), rel=0.01)


def test_implicit_is_the_default_and_takes_few_steps():
    sc = Scene(L=20.0, load=0.25, k_fr=0.8, l0=1.0, tol=1e-4)
    assert sc.solver == "implicit"
    ds = simulate(sc, progress=False)
    # the explicit scheme needs ~1e6 steps here (dt ~ 3e-4, t ~ 600)
    assert ds.converged and int(ds.n_steps) < 2000


def test_dx_max_is_the_accuracy_knob():
    """Refining dx_max moves the frictional result towards the explicit one
    (first order in dx_max)."""
    kw = dict(L=10.0, load=0.25, k_fr=0.8, l0=1.0, tol=1e-4, friction_at="centre")
    ex = simulate(Scene(solver="explicit", **kw), progress=False)
    errs = []
    for dx in (0.08, 0.02, 0.005):
        im = simulate(Scene(dx_max=dx, **kw), progress=False)
        errs.append(abs(float(im.F_transmitted) / float(ex.F_transmitted) - 1))
    assert errs[2] < errs[0]
    assert errs[2] < 0.005


@pytest.mark.parametrize("friction_at", ["centre", "ends"])
def test_the_implicit_path_converges_to_the_explicit_one(friction_at):
    """Backward Euler is first order in its step: from the same helix on the wall (no buckling
    instability to amplify differences), the implicit state at t = 20 approaches the explicit
    one (dt ~ 1e-3, converged in dt) as dx_max shrinks. Measured at L/R = 10, k_fr = 0.8, max
    |r_im - r_ex| for dx_max = 0.02, 0.005, 0.00125: centre 4.4e-3, 1.3e-3, 3.8e-4; ends 4.9e-3,
    1.5e-3, 4.1e-4 (3.4x and 3.6x per 4x): a factor 2.5 per 4x is asserted, and 1e-3 R at the
    finest step (a quarter of a link's wall penetration at this load)."""
    import dataclasses

    from confined_rod.sim.solvers import base, explicit, implicit

    sc = Scene(L=10.0, load=0.25, k_fr=0.8, l0=1.0, tol=1e-4, friction_at=friction_at, protocol="helix")
    r0, t0 = sc.initial_state()
    st = base.RunState(r=r0.copy(), t=t0.copy())
    base.relax(sc, st, explicit.ExplicitStepper(dataclasses.replace(sc, solver="explicit")), t_end=20.0,
               progress=False)
    r_ex = st.r.copy()
    diff = []
    for dx in (0.02, 0.005, 0.00125):
        sci = dataclasses.replace(sc, dx_max=dx)
        st = base.RunState(r=r0.copy(), t=t0.copy())
        base.relax(sci, st, implicit.ImplicitStepper(sci), t_end=20.0, progress=False)
        diff.append(float(np.abs(st.r - r_ex).max()))
    assert diff[0] > 2.5 * diff[1] > 6.25 * diff[2]
    assert diff[2] < 1e-3


def test_an_impossible_state_stops_with_a_message(monkeypatch):
    # a bond stiffness far too small for the load: refused up front (strain load/k_ph = 10) ...
    from confined_rod import limits
    from confined_rod.errors import SceneError

    kw = dict(L=10.0, load=5.0, k_fr=0.0, l0=0.5, k_ph=0.5, tol=1e-4, t_max=1e4)
    with pytest.raises(SceneError, match=r"'k_ph': 0\.5 .*load/k_ph = 10"):
        Scene(**kw)
    # ... and if it got through, the joints come apart during the run
    monkeypatch.setattr(limits, "MAX_STRAIN", float("inf"))
    with pytest.raises(DivergenceError, match="scene"):
        simulate(Scene(**kw), progress=False)


def test_a_frictionless_scene_does_no_friction_work(monkeypatch):
    """k_fr = 0: neither the implicit friction envelope nor the Coulomb law is ever
    evaluated (both are replaced by functions that fail if called)."""
    from confined_rod.sim.model import forces
    from confined_rod.sim.solvers import implicit

    def boom(*a, **k):
        raise AssertionError("friction evaluated in a frictionless scene")

    monkeypatch.setattr(implicit.IK, "friction_term", boom)
    monkeypatch.setattr(forces.K, "coulomb_friction", boom)
    for solver in ("implicit", "explicit"):
        ds = simulate(Scene(L=6.0, load=0.5, k_fr=0.0, l0=1.0, tol=1e-4, solver=solver), progress=False)
        assert ds.converged and float(abs(ds.friction_force).max()) == 0.0


@pytest.mark.parametrize("floor", [False, True, "rim"])
def test_exact_contact_hessian_matches_finite_differences(rng, floor):
    """The Newton Hessian = finite differences of the smooth terms + the exact
    Hessian of the one-sided contacts.  Away from the switch-on of a contact both
    are smooth, so the split must equal finite differences of everything.  Entries
    are up to k_w = 1e3 (the bonds 2e3); one-sided differences with a 1e-7 step
    err by ~ k_w h / R ~ 1e-4 plus round-off k L eps / h ~ 1e-5, so 1e-3 is a
    relative 1e-6 of the largest entries, while a wrong contact term errs by O(k_w)."""
    from confined_rod.sim.solvers import implicit_kernels as IK
    from confined_rod.sim.solvers.base import RunState
    from confined_rod.sim.solvers.implicit import ImplicitStepper

    from .conftest import random_state

    if floor == "rim":  # ends under the block's top face, and the guided loaded end above it
        scene = Scene(L=12.0, load=0.25, k_fr=0.8, ends="guided", pore_length=9.0)
        r, t = random_state(scene, rng, lateral=1.05)
        r[-1, :2] = (1.1, 0.0)
        ends = np.concatenate([r - 0.5 * scene.l0 * t, r + 0.5 * scene.l0 * t])
        par = scene.params()
        assert sum(K._face_point(*p, par, False) > 0 for p in ends) >= 1
    else:
        scene = Scene(L=12.0, load=0.25, k_fr=0.8, lower_end="free" if floor else "held", floor=floor)
        r, t = random_state(scene, rng)
    if floor is True:
        r[:, 2] -= 0.3  # some link ends below the piston
    stepper = ImplicitStepper(scene, dt=10.0)
    stepper._start_step(RunState(r=r, t=t), 10.0)
    S = stepper
    IK.tangent_bases(t, S.e1, S.e2)
    S.fd_step[:] = 1e-7
    ws = S.ws
    hessians = []
    for par in (S.par, S.par_fd):
        g0 = np.zeros_like(S.g0)
        IK.smooth_gradient(r, t, S.nu1, S.rn, S.tn, S.frame, S.e1, S.e2, S.cr, S.ct, par, ws.Fm, ws.Fp, ws.F, ws.M,
                           ws.Nw, g0)
        IK.fd_hessian(r, t, S.rn, S.tn, S.frame, S.e1, S.e2, S.cr, S.ct, par, S.fd_step, g0, ws.Fm, ws.Fp, ws.F,
                      ws.M, ws.Nw, S.rp, S.tp, S.nu, S.gp, S.ab)
        hessians.append(S.ab.copy())
    full, split = hessians
    contact = full - split
    assert np.abs(contact).max() > 100.0  # the contacts are there and matter
    IK.contact_hessian(r, t, S.frame, S.e1, S.e2, S.par, split)
    assert np.abs(split - full).max() < 1e-3


@pytest.mark.parametrize("kw", [{}, {"ends": "pinned", "k_fr": 0.0}, {"lower_end": "free"},
                                {"ends": "guided", "pore_length": 9.0}, {"bending_constant": "paper"}])
def test_analytic_smooth_hessian_matches_finite_differences(rng, kw):
    """The exact Hessian of the smooth terms (bonds, bending, load, support and
    pins, drag) against one-sided finite differences of the numba forces, at a
    state moved away from the step's start (so the drag's curvature term
    ct (1 - t.t_n) is not zero).  Entries reach 2 k h^2 + ... ~ 4e3; the
    differences err by ~ k h_fd ~ 1e-4 (curvature times step) plus round-off
    k L eps / h_fd ~ 1e-5, so 1e-3 is a relative 2.5e-7; a missing or wrong
    term errs by at least the smallest physical entry, C = EI/l0 = 2 (or the
    drag cr = beta/dt = 0.05), far above it."""
    from confined_rod.sim.solvers import implicit_kernels as IK
    from confined_rod.sim.solvers.base import RunState
    from confined_rod.sim.solvers.implicit import ImplicitStepper

    from .conftest import random_state

    scene = Scene(L=12.0, load=0.25, **({"k_fr": 0.8} | kw))
    r0, t0 = random_state(scene, rng)
    S = ImplicitStepper(scene, dt=10.0)
    S._start_step(RunState(r=r0, t=t0), 10.0)
    r = np.ascontiguousarray(r0 + rng.normal(scale=0.05, size=r0.shape))
    t = t0 + rng.normal(scale=0.1, size=t0.shape)
    t = np.ascontiguousarray(t / np.linalg.norm(t, axis=1)[:, None])
    IK.tangent_bases(t, S.e1, S.e2)
    S.fd_step[:] = 1e-7
    ws = S.ws
    g0 = np.zeros_like(S.g0)
    IK.smooth_gradient(r, t, S.nu1, S.rn, S.tn, S.frame, S.e1, S.e2, S.cr, S.ct, S.par_fd, ws.Fm, ws.Fp, ws.F, ws.M,
                       ws.Nw, g0)
    IK.fd_hessian(r, t, S.rn, S.tn, S.frame, S.e1, S.e2, S.cr, S.ct, S.par_fd, S.fd_step, g0, ws.Fm, ws.Fp, ws.F,
                  ws.M, ws.Nw, S.rp, S.tp, S.nu, S.gp, S.ab)
    exact = np.zeros_like(S.ab)
    IK.smooth_hessian(r, t, S.tn, S.frame, S.e1, S.e2, S.cr, S.ct, S.par, exact)
    assert np.abs(S.ab).max() > 1e3
    assert np.abs(exact - S.ab).max() < 1e-3


def test_banded_cholesky_matches_lapack(rng):
    """The solver's block Cholesky against LAPACK (scipy.linalg.solveh_banded) on a random
    positive definite block-tridiagonal matrix (the Newton Hessian's pattern: 5 x 5 blocks,
    the band entries two blocks apart zero): equal to round-off (cond ~ 10 here, so 1e-12
    relative is ample); and an indefinite matrix is reported, not solved."""
    from scipy.linalg import solveh_banded

    from confined_rod.sim.solvers import implicit_kernels as IK

    links = 30
    n = IK.NDOF * links
    ab = rng.normal(scale=0.3, size=(IK.BAND + 1, n))
    ab[0] = 5.0 + rng.random(n)
    row, col = np.arange(IK.BAND + 1)[:, None] + np.arange(n)[None, :], np.arange(n)[None, :]
    ab[row // IK.NDOF - col // IK.NDOF > 1] = 0.0  # two blocks apart: not in the pattern
    b = rng.normal(size=n)
    work, x = IK.cholesky_work(links), np.zeros(n)
    assert IK.banded_cholesky_solve(ab, b, work, x)
    ref = solveh_banded(ab, b, lower=True)
    assert np.abs(x - ref).max() < 1e-12 * np.abs(ref).max()
    ab[0, n // 2] = -1.0
    assert not IK.banded_cholesky_solve(ab, b, work, x)


def test_exact_and_finite_difference_hessians_give_the_same_equilibrium():
    """The Newton Hessian changes the iteration, not the step's solution: without
    friction (unique equilibrium) both end at the same F_z(L) within the stopping
    tolerance, tol * load = 1e-5 (plus the penalty-level difference)."""
    from confined_rod.sim import observables as obs
    from confined_rod.sim.solvers.base import run_protocol
    from confined_rod.sim.solvers.implicit import ImplicitStepper

    sc = Scene(L=20.0, load=0.25, k_fr=0.0, tol=1e-4)
    F = []
    for hessian in ("analytic", "fd"):
        st = run_protocol(sc, lambda s, h=hessian: ImplicitStepper(s, hessian=h), progress=False)
        assert st.converged
        F.append(obs.compute(sc, st.r, st.t).F_transmitted)
    assert abs(F[0] - F[1]) < 2e-5


def _frames(r):
    from confined_rod.sim.solvers import implicit_kernels as IK

    frame = np.zeros((len(r), 3, 3))
    IK.local_frames(r, frame)
    return frame


def test_stick_model_switches_only_links_the_step_carries_back_into_the_stick_zone():
    """Constructed: two links on the wall at x = 1 (frame: radial x, azimuthal y, axial z),
    both in slip along +z (offset 0.01 R from the anchor, f_max/k_t = 1e-3 R). The step moves
    link 0 back by 0.0095 R (into the stick zone) and link 1 on by 0.005 R (still slipping)."""
    from confined_rod.sim.solvers import implicit_kernels as IK

    NDOF = IK.NDOF
    r = np.array([[1.0, 0.0, 0.51], [1.0, 0.0, 1.01]])
    anchor = r - np.array([0.0, 0.0, 0.01])
    fmax, kt = np.array([0.1, 0.1]), 100.0
    p = np.zeros(2 * NDOF)
    p[2], p[NDOF + 2] = -0.0095, 0.005
    g = np.zeros((2, NDOF))
    ab = np.zeros((IK.BAND + 1, 2 * NDOF))
    assert IK.stick_model(r, anchor, _frames(r), fmax, kt, p, g, ab) == 1
    # link 0 on the stick branch: gradient k_t d = 1.0 along z instead of f_max = 0.1, curvature
    # k_t along z and, the slip Hessian's (f_max/|d|)(1 - u u^T) = 10 along phi removed, k_t - 10
    assert g[0, 2] == pytest.approx(kt * 0.01 - 0.1) and g[0, 1] == 0.0
    assert ab[0, 2] == pytest.approx(kt) and ab[0, 1] == pytest.approx(kt - 0.1 / 0.01)
    assert not g[1].any() and not ab[:, NDOF:].any()


def test_contact_model_puts_ends_the_step_carries_into_the_wall_in_contact():
    """Constructed: a link parallel to the axis at radius 0.99 R (ends 0.01 R off the wall) and
    one on the axis; the step moves both 0.02 R outwards: only the first link's ends reach the
    wall, and each gets the penalty continued to its point, gradient k_w (rho - R) = -10 radially."""
    from confined_rod.sim.solvers import implicit_kernels as IK

    sc = Scene(L=4.0, l0=1.0, k_w=1000.0, name="cm")
    NDOF = IK.NDOF
    r = np.array([[0.99, 0.0, 1.5], [0.0, 0.0, 2.5]])
    t = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 1.0]])
    frame = _frames(r)
    e1, e2 = np.zeros((2, 3)), np.zeros((2, 3))
    IK.tangent_bases(t, e1, e2)
    p = np.zeros(2 * NDOF)
    p[0], p[NDOF] = 0.02, 0.02
    g = np.zeros((2, NDOF))
    ab = np.zeros((IK.BAND + 1, 2 * NDOF))
    assert IK.contact_model(r, t, frame, e1, e2, sc.params(), p, g, ab) == 2
    assert g[0, 0] == pytest.approx(2 * 1000.0 * (0.99 - 1.0))
    assert ab[0, 0] == pytest.approx(2 * 1000.0)
    assert not g[1].any() and not ab[:, NDOF:].any()


@pytest.mark.parametrize("L", [40.0, 80.0])
def test_active_set_model_changes_the_work_not_the_path(L, monkeypatch):
    """The re-solved Newton direction changes how Newton gets to each step's solution, not the
    solution: |F_z(L)| of a frictional helix the same to 1e-4, fewer gradients. With friction the
    equilibrium is a set (stuck links may sit anywhere their friction holds), and a path changed
    at the Newton tolerance lands elsewhere in it: measured 2.7e-5 at L/R = 40 with the continuous
    start of seed 1 (2e-8 with the old per-link start), while another equilibrium (half a turn
    more or less) would move |F_z(L)| by per cent. Friction at the link centres: at the link ends
    the set is wider (a stuck link holds a torque too) and the same change moved |F_z(L)| by
    1.3e-4 and 1.3e-3 (seeds 1, 2 at L/R = 40), with 12 % fewer and 3 % more gradients."""
    from confined_rod.sim import observables
    from confined_rod.sim.solvers import implicit

    out = []
    for flag in (False, True):
        monkeypatch.setattr(implicit, "ACTIVE_SET_MODEL", flag)
        sc = Scene(L=L, load=0.25, k_fr=0.8, k_ph=1e4, seed=1, name="asm", friction_at="centre")
        st = implicit.run(sc, progress=False)
        assert st.converged
        F = observables.compute(sc, st.r, st.t).F_transmitted
        out.append((F, st.work["gradients"], st.work.get("active_set_models", 0)))
    (F0, g0, m0), (F1, g1, m1) = out
    assert m0 == 0 and m1 > 0
    assert F1 == pytest.approx(F0, rel=1e-4)
    assert g1 < g0


def test_a_run_whose_friction_bound_lags_settles_instead_of_reaching_t_max():
    """Near rest the friction bound is taken from the step's end state by a few re-solves; where
    they do not close the gap (a link whose normal force moves with its own friction), dt must not
    keep doubling. Found at the publication numerics, L/R = 320, seed 4: the run reached t_max =
    1e9 at eps_F = 4e-4 (40 tol) in 708 steps; now it settles at t ~ 3e5."""
    from confined_rod.sim.solvers import implicit

    sc = Scene(L=320.0, load=0.25, k_fr=0.8, l0=0.5, k_ph=1e4, k_w=1e3, tol=1e-5, seed=4, name="lag")
    st = implicit.run(sc, progress=False)
    assert st.converged and st.time < 1e7


def test_a_light_sliding_contact_whose_bound_cycles_settles():
    """The re-solves near rest solve bound(r(f_max)) = f_max link by link; plain substitution went
    round a cycle of five values at every step for a link sliding lightly along the wall (its
    normal force moving with its own sliding): protocols_L640/ramp32-s0 (publication numerics,
    L/R = 640, ramp of 32 loads, seed 0) stayed at eps_F = 3.8e-3 (10x its tolerance) for 70 000
    steps of ramp stage 28 (load 0.083), 30 min. The passes' Anderson acceleration (or, before it,
    bisection within the bracket the bound has been seen on both sides of) settles that stage in
    tens of steps (this test: the 28 stages, ~10 s)."""
    import dataclasses

    from confined_rod.sim.solvers import base, implicit

    sc = Scene(L=640.0, load=0.25, k_fr=0.8, l0=0.5, k_ph=1e4, k_w=1e3, tol=1e-5, seed=0, protocol="ramp",
               ramp_steps=32, name="cycle")
    r, t = sc.initial_state()
    st = base.RunState(r=r, t=t)
    loads = sc.ramp_loads()
    for F in loads[:28]:
        stage = dataclasses.replace(base.ramp_stage(sc, float(F)), max_steps=st.steps + 3000)  # a cycle fails fast
        steps = st.steps
        base.relax(stage, st, implicit.ImplicitStepper(stage), progress=False)
        assert st.converged, f"ramp stage at load {F:.3g}"
    assert st.steps - steps < 500


@pytest.mark.parametrize("friction_at", ["centre", "ends"])
def test_a_step_never_holds_a_link_beyond_the_bound_at_its_solution(friction_at):
    """When the re-solves near rest do not close, the last one's extrapolated bound could lie above
    the bound at the step's solution, and the step was accepted with a link held there: stuck beyond
    Coulomb's limit (its tangential load 0.3 % above k_fr N), step after step, while the equilibrium
    test at the end state's bound never passed. Found at the publication numerics: protocols/ramp-s2
    (L/R = 320, ramp of 128 loads, seed 2) spent 65 000 steps and 1 000 s in ramp stage 114 and
    ended at t_max = 1e9 with eps_F = 345. Now that stage settles in a few thousand steps (this
    test: the 114 stages, ~5 s), and no accepted step holds a link above its end state's bound."""
    import dataclasses

    from confined_rod.sim.solvers import base, implicit
    from confined_rod.sim.solvers import implicit_kernels as IK

    sc = Scene(L=320.0, load=0.25, k_fr=0.8, l0=0.5, k_ph=1e4, k_w=1e3, tol=1e-5, seed=2, protocol="ramp",
               ramp_steps=128, name="held", friction_at=friction_at)
    r, t = sc.initial_state()
    st = base.RunState(r=r, t=t)
    for F in sc.ramp_loads()[:114]:
        stage = dataclasses.replace(base.ramp_stage(sc, float(F)), max_steps=st.steps + 6000)  # a stall fails fast
        stepper = implicit.ImplicitStepper(stage)
        base.relax(stage, st, stepper, progress=False)
        assert st.converged, f"ramp stage at load {F:.3g}"
    bound = stepper._bound(st.r, st.t)
    if stepper.ends:  # per link end, at the end's own bound
        held = np.array([stepper.kt * np.hypot(*K.end_offset(st.r, st.t, st.anchor, stepper.pf, stepper.h, m))
                         for m in range(2 * sc.N)])
    else:
        held = np.array([stepper.kt * np.hypot(*IK.tangential_offset(st.r, st.anchor, stepper.frame, i))
                         for i in range(sc.N)])
    on = bound > 0
    assert np.all(np.minimum(held[on], stepper.fmax[on]) <= bound[on] + stepper.gtol_F)


@pytest.mark.parametrize("eigenvalues", [(-0.5, 0.3, 0.9), (-1.0, -1.0, 0.5), (-3.0, 0.5, 2.0)])
def test_anderson_passes_solve_a_linear_fixed_point_that_substitution_cannot(eigenvalues, rng):
    """The normal-force passes solve f = G(f). For a linear G(x) = J x + b of n distinct
    eigenvalues, Anderson mixing with depth >= n is GMRES on (I - J) x = b: exact after n + 1
    passes up to round-off, where plain substitution cycles (eigenvalue -1: a two-cycle, the
    cycles the passes met on the wall) or diverges (|eigenvalue| > 1)."""
    from confined_rod.sim.solvers.implicit import AndersonHistory

    n = len(eigenvalues)
    Q = np.linalg.qr(rng.normal(size=(n, n)))[0]
    J = Q @ np.diag(eigenvalues) @ Q.T
    b = rng.normal(size=n)
    x_star = np.linalg.solve(np.eye(n) - J, b)
    hist, x = AndersonHistory(n, depth=5), np.zeros(n)
    for _ in range(n + 1):
        x = hist.update(x, J @ x + b - x)
    assert np.abs(x - x_star).max() < 1e-9 * max(1.0, np.abs(x_star).max())
    y = np.zeros(n)  # plain substitution from the same start is nowhere near after as many passes
    for _ in range(n + 1):
        y = J @ y + b
    assert np.abs(y - x_star).max() > 1e-3


def test_a_long_rod_runs_bitwise_the_same_with_any_number_of_blas_threads():
    """The path of a rod must not depend on the machine's core count. numpy's dot calls the BLAS,
    whose threaded reduction (OpenBLAS, above ~10 000 elements, i.e. rods of more than 2 000
    links) sums in an order set by the number of threads; with it in the line search, 40 steps of
    this L/R = 1100 rod already ended bitwise apart with OPENBLAS_NUM_THREADS = 1 and 2. Each run
    in its own process (the BLAS reads its thread count at start-up)."""
    import os
    import subprocess
    import sys

    code = ("import hashlib; from confined_rod import Scene; from confined_rod.sim.solvers.base import run_protocol;"
            "from confined_rod.sim.solvers.implicit import ImplicitStepper;"
            "sc = Scene(L=1100.0, seed=0, load=0.25, k_fr=0.8, k_ph=1e4, max_steps=40, name='blas');"
            "st = run_protocol(sc, ImplicitStepper, progress=False);"
            "print(st.steps, hashlib.sha1(st.r.tobytes() + st.t.tobytes()).hexdigest())")
    out = [subprocess.run([sys.executable, "-c", code], env=dict(os.environ, OPENBLAS_NUM_THREADS=str(n)),
                          check=True, capture_output=True, text=True).stdout.split() for n in (1, 2)]
    assert out[0][0] == "40" and out[0] == out[1]


def test_the_bound_passes_wait_until_the_step_has_nearly_stopped_moving():
    """The end-state passes run only in a step that moved no link end by more than dx_max/10:
    a step of a creeping helix at dt ~ 1e4 passes the drag test (its drag is tiny) while it still
    slides by ~dx_max, and there the passes cannot close (the slip itself moves the bound). On a
    rod on the wall at a large dt: a step that moved it outwards by dx_max/2 runs no pass, one that
    moved it by dx_max/100 does (both change the normal forces by far more than the tolerance)."""
    from confined_rod.sim.solvers import base, implicit

    sc = Scene(L=20.0, load=0.25, k_fr=0.8, seed=0, name="gate")
    st = implicit.run(sc, progress=False)
    assert st.converged
    counts = []
    for move in (0.5, 0.01):
        stp = implicit.ImplicitStepper(sc)
        stp._start_step(st, 1e12)  # drag ~ 0: only the displacement gate can stop the passes
        assert stp.fmax.any()
        r, t = st.r.copy(), st.t.copy()
        r[:, :2] *= 1.0 + move * sc.dx_max / sc.R  # outwards: the wall's normal forces change
        probe = base.RunState(r=st.r.copy(), t=st.t.copy())
        stp._implicit_normal_forces(r, t, probe)
        counts.append(probe.work.get("normal_force_passes", 0))
    assert counts[0] == 0 and counts[1] > 0


def _ends_on_the_wall(rng):
    """A random rod of 12 R with friction at the link ends and no cap, an implicit step begun on
    it (dt = 10): (scene, stepper, r, t, the ends on the wall), at least six of them."""
    from confined_rod.sim.solvers.base import RunState
    from confined_rod.sim.solvers.implicit import ImplicitStepper

    from .conftest import random_state

    scene = Scene(L=12.0, load=0.25, k_fr=0.8, friction_at="ends", friction_cap=0.0)
    r, t = random_state(scene, rng, lateral=1.0)
    S = ImplicitStepper(scene, dt=10.0)
    st = RunState(r=r, t=t)
    S._start_step(st, 10.0)
    on = np.flatnonzero(S.fmax > 0.0)
    assert on.size >= 6
    return scene, S, r, t, on


def test_friction_at_the_ends_is_the_gradient_and_hessian_of_its_envelope(rng):
    """Friction at the link ends (friction_at 'ends') enters each Newton step as the stick
    envelope of every end on the wall, its force and torque added to the loads (_loads) and its
    Hessian added exactly (end_friction_hessian). Along a random direction p of the step
    coordinates, dPhi/dalpha must equal g.p and the change of g must equal H p, with ends on
    both branches (anchors within and beyond f_max/k_t). Central differences with alpha = 1e-6
    err by ~ alpha^2 |third derivative| ~ 1e-9 of the largest entries (k_w ~ 1e3, the bonds
    2e3); a term missing from the Hessian (the rotation's lever s h, the slip projector) errs
    by ~ k_t = 100 on the entries it touches, so 1e-4 relative to |H p| separates them."""
    from confined_rod.sim.solvers import implicit_kernels as IK
    scene, S, r, t, on = _ends_on_the_wall(rng)
    # anchors displaced tangentially: half of the ends inside their stick zone, half beyond it
    reach = S.fmax / S.kt
    scale = np.where(np.arange(S.fmax.size) % 2 == 0, 0.3, 3.0) * reach
    S.anchor += (S.pf[:, 1] * rng.normal(size=(S.fmax.size, 1)) + S.pf[:, 2] * rng.normal(size=(S.fmax.size, 1))) \
        * scale[:, None] / np.sqrt(2.0)
    IK.tangent_bases(t, S.e1, S.e2)
    p = rng.normal(size=IK.NDOF * scene.N)
    p[IK.NDOF - 2::IK.NDOF] *= 0.3
    p[IK.NDOF - 1::IK.NDOF] *= 0.3

    def phi_g(alpha):
        g = np.zeros_like(S.g)
        IK.displace(r, t, S.frame, S.e1, S.e2, p.reshape(scene.N, IK.NDOF), alpha, S.r2, S.t2, S.nu)
        return S._phi(S.r2.copy(), S.t2.copy(), S.nu.copy(), g), g.ravel().copy()

    a = 1e-6
    (pp, gp), (pm, gm), (_, g0) = phi_g(a), phi_g(-a), phi_g(0.0)
    assert (pp - pm) / (2 * a) == pytest.approx(g0 @ p, rel=1e-6)
    S._hessian(r, t)
    ab = S.ab
    n = ab.shape[1]
    Hp = ab[0] * p
    for d in range(1, ab.shape[0]):
        Hp[d:] += ab[d, :n - d] * p[:n - d]
        Hp[:n - d] += ab[d, :n - d] * p[d:]
    fd = (gp - gm) / (2 * a)
    assert np.abs(Hp - fd).max() < 1e-4 * np.abs(fd).max()
    # and the ends' friction is in it: without its Hessian the same comparison fails
    S.use_friction = False
    S._hessian(r, t)
    Hq = S.ab[0] * p
    for d in range(1, ab.shape[0]):
        Hq[d:] += S.ab[d, :n - d] * p[:n - d]
        Hq[:n - d] += S.ab[d, :n - d] * p[d:]
    assert np.abs(Hq - fd).max() > 1e-2 * np.abs(fd).max()


def test_the_slip_branch_model_has_the_envelopes_gradient_and_hessian_at_the_predicted_point():
    """slip_branch_point_model (the numpy twin of end_slip_model's point terms): added to the
    stick branch's model (k_t d, k_t 1), the quadratic's gradient at the predicted offset d' is
    the envelope's there, f_max d'/|d'| (along the slip the force is f_max, not k_t |d'|), and its
    Hessian is the slip branch's, (f_max/|d'|)(1 - u'u'^T). Values: k_t = 2e4 (k_ph/l0 at the
    publication numerics), f_max = 0.02, d inside the stick zone (|d| = 0.3 f_max/k_t), a step
    to 5 f_max/k_t."""
    from confined_rod.sim.solvers import implicit_kernels as IK

    kt, fmax = 2e4, 0.02
    lim = fmax / kt
    d, dp = np.array([0.3 * lim, 0.0]), np.array([2.0 * lim, 4.5 * lim])
    dg, dh = IK.slip_branch_point_model(d, dp, fmax, kt)
    grad0, hess = kt * d + dg, kt * np.eye(2) + dh
    new = d + dp
    u = new / np.linalg.norm(new)
    assert grad0 + hess @ dp == pytest.approx(fmax * u, rel=1e-12, abs=1e-15)
    assert hess == pytest.approx(fmax / np.linalg.norm(new) * (np.eye(2) - np.outer(u, u)), rel=1e-12)
    # the stick branch alone would have taken k_t |d'| = 5 f_max
    assert np.linalg.norm(kt * new) == pytest.approx(5 * fmax * np.hypot(2.3, 4.5) / 5, rel=1e-12)


def test_end_slip_model_gives_the_step_the_envelopes_gradient_where_stuck_ends_start_to_slip(rng):
    """Friction at the link ends, every end on the wall inside its stick zone (anchors within 0.3
    f_max/k_t, f_max = 0.01), a step p that carries the ends 20 f_max/k_t on: the step's quadratic model with
    the ends the step carries past their bound switched to the slip branch (end_slip_model)
    predicts the gradient of Phi at the displaced state to the model's second-order error
    (|p| ~ 1e-5 R: measured 1e-10 of f_max, held to 1e-4), while the stick-branch model misses
    it by about k_t |d'| - f_max per end, tens of f_max (measured 39 f_max, held to above 5). The
    kernel's terms are its numpy twin's (slip_branch_point_model) through the end Jacobians."""
    from confined_rod.sim.solvers import implicit_kernels as IK
    scene, S, r, t, on = _ends_on_the_wall(rng)
    S.fmax[on] = 0.01  # a bound of the publication rods' size (the random state presses far harder)
    reach = S.fmax / S.kt
    sideways = S.pf[:, 1] * rng.normal(size=(S.fmax.size, 1)) + S.pf[:, 2] * rng.normal(size=(S.fmax.size, 1))
    S.anchor += sideways * 0.3 * reach[:, None] / np.sqrt(2.0)
    IK.tangent_bases(t, S.e1, S.e2)
    p = np.zeros((scene.N, IK.NDOF))
    p[:, 2] = 20.0 * reach[on].max()  # every link moved along the axis (the frame's third vector), no turn
    p = p.ravel()

    def gradient(alpha):
        g = np.zeros_like(S.g)
        IK.displace(r, t, S.frame, S.e1, S.e2, p.reshape(scene.N, IK.NDOF), alpha, S.r2, S.t2, S.nu)
        S._phi(S.r2.copy(), S.t2.copy(), S.nu.copy(), g)
        return g.ravel().copy()

    def banded_times(ab, v):
        n = ab.shape[1]
        out = ab[0] * v
        for d in range(1, ab.shape[0]):
            out[d:] += ab[d, :n - d] * v[:n - d]
            out[:n - d] += ab[d, :n - d] * v[d:]
        return out

    g0, g1 = gradient(0.0), gradient(1.0)
    S._hessian(r, t)
    stick_only = g0 + banded_times(S.ab, p)
    gm = g0.reshape(scene.N, IK.NDOF).copy()
    switched = IK.end_slip_model(r, t, S.anchor, S.pf, S.frame, S.e1, S.e2, S.h, S.fmax, S.kt, p, gm, S.ab)
    assert switched == on.size
    model = gm.ravel() + banded_times(S.ab, p)
    scale = S.fmax[on].max()
    assert np.abs(model - g1).max() < 1e-4 * scale
    assert np.abs(stick_only - g1).max() > 5 * scale
