"""Static friction is truly static; above the friction limit the rod slides at
the velocity Coulomb's law predicts.

Set-up with an analytic answer: a straight rod of length L pressed against the
wall by a body force p per unit length (so N = p l0 on every link), lower end
free and no floor (nothing but friction holds it), pushed axially by T.  The friction capacity of the whole rod is
k_fr p L.  Below it the rod must come to rest and stay there exactly; above it
every link slides at the limit and the rod moves at v = (T - k_fr p L)/(beta_ph L).
"""
import numpy as np
import pytest

from confined_rod import Scene
from confined_rod.sim.solvers import base, explicit, implicit
from confined_rod.sim.solvers.base import RunState

# solver and where a contact's friction acts (Scene.friction_at): at the link centre, or at each
# link end on the wall with its own normal force and anchor (the limit is the same sum, k_fr p L)
SOLVERS = {"explicit-centre": (explicit.relax, "centre"), "implicit-centre": (implicit.relax, "centre"),
           "explicit-ends": (explicit.relax, "ends"), "implicit-ends": (implicit.relax, "ends")}

P, KFR, L = 0.1, 0.5, 4.0  # capacity k_fr p L = 0.2


def scene(T, tol=1e-8, friction_at="centre"):
    return Scene(L=L, l0=0.5, load=T, k_fr=KFR, friction_cap=0.0, body_force=(P, 0.0, 0.0),
                 lower_end="free", floor=False, perturbation=1e-6, k_ph=200.0, tol=tol,
                 friction_at=friction_at, name=f"T={T}")


@pytest.mark.parametrize("solver", sorted(SOLVERS))
def test_below_the_limit_the_rod_sticks_and_never_creeps(solver, monkeypatch):
    relax, at = SOLVERS[solver]
    sc = scene(0.1, friction_at=at)
    st = RunState(*sc.initial_state())
    relax(sc, st, t_end=2000.0, progress=False)
    assert st.converged, "the rod must come to rest below the friction limit"
    t_rest = st.time
    z_rest = st.r[:, 2].copy()
    phi_rest = np.arctan2(st.r[:, 1], st.r[:, 0])
    # run on for 2 x 10x as long with an unreachable tolerance: nothing may creep along the wall.
    # The implicit solver holds a stuck link with a spring (k_t = k_w/10) to its stick anchor; as its
    # Newton residual falls from the step's forcing level to round-off the rod may settle within
    # that spring, by (residual force)/k_t << f_max/k_t = 2.5e-4 R here, once (measured 3.4e-9 R;
    # 3.4e-10 R at k_t = k_w).  Creep would move it by as much again in the second half; 1e-12 R
    # allows for round-off only.
    # (a tiny tol alone would be lifted to the round-off floor, where this rod counts as settled)
    monkeypatch.setattr(base, "equilibrium_tol", lambda scene: 0.0)
    sc_long = scene(0.1, tol=1e-9, friction_at=at)
    span = 10 * max(t_rest, 50.0)
    relax(sc_long, st, t_end=t_rest + span, progress=False)
    assert not st.converged and st.time >= (t_rest + span) * (1 - 1e-12)
    # the explicit scheme holds a stuck link's centre rigidly; its ends' friction, like the implicit
    # solver's, with springs k_t, so it settles within them as the implicit solver does
    settle = {"explicit-centre": 1e-12}.get(solver, 1e-8)
    assert np.abs(st.r[:, 2] - z_rest).max() < settle
    z_mid, phi_mid = st.r[:, 2].copy(), np.arctan2(st.r[:, 1], st.r[:, 0])
    assert np.abs(phi_mid - phi_rest).max() < settle
    relax(sc_long, st, t_end=t_rest + 2 * span, progress=False)
    assert np.abs(st.r[:, 2] - z_mid).max() < 1e-12
    assert np.abs(np.arctan2(st.r[:, 1], st.r[:, 0]) - phi_mid).max() < 1e-12


@pytest.mark.parametrize("solver", sorted(SOLVERS))
def test_above_the_limit_the_rod_slides_at_the_coulomb_velocity(solver):
    relax, at = SOLVERS[solver]
    T = 0.3
    sc = scene(T, friction_at=at)
    st = RunState(*sc.initial_state())
    relax(sc, st, t_end=60.0, progress=False)  # transient: reach the wall (~R/p = 10)
    z0, t0 = st.r[:, 2].mean(), st.time
    relax(sc, st, t_end=120.0, progress=False)
    v = (st.r[:, 2].mean() - z0) / (st.time - t0)
    v_coulomb = -(T - KFR * P * L) / L  # beta_ph = 1
    # steady sliding: the only error is the penalty penetration changing N by O(p/k_w)
    assert v == pytest.approx(v_coulomb, rel=1e-3)


def test_a_one_end_contact_resists_a_pivot_only_with_friction_at_the_ends():
    """Why the centre law's stuck states drift with l0 (docs/model.md, "Friction"): a link that
    touches the wall with one end, stuck, turned about its centre by delta about the radial axis.
    Its wall end slides along the wall by arm * delta (arm = h t_z); with friction at the ends
    that end's stick spring resists with a torque -k_t arm^2 delta about the radial axis, while
    friction at the centre sees a centre that did not move and resists nothing: there the pivot
    is held by bending alone, whose stiffness per contact depends on l0."""
    from confined_rod.sim.model import kernels as K
    from confined_rod.sim.model.forces import end_points
    from confined_rod.sim.solvers import implicit_kernels as IK

    sc = Scene(L=3.0, l0=1.0, load=0.1, k_fr=KFR, friction_cap=0.0, name="pivot")
    par, h, kt = sc.params(), 0.5 * sc.l0, sc.k_t
    u = 0.42  # sin of the link's tilt: the upper end at rho = 1.01 R, the lower one at 0.59 R
    r = np.array([[0.8, 0.0, 0.6], [0.0, 0.0, 1.5], [0.0, 0.0, 2.5]])
    t = np.array([[u, 0.0, np.sqrt(1 - u * u)], [0.0, 0.0, 1.0], [0.0, 0.0, 1.0]])
    Ne, fmax, pf = np.zeros(6), np.zeros(6), np.zeros((6, 3, 3))
    K.end_friction_bounds(r, t, par, Ne, fmax)
    assert Ne[0] == 0.0 and Ne[1] == pytest.approx(sc.k_w * 0.01) and not Ne[2:].any()
    anchor = end_points(r, t, h)              # stuck where it stands
    K.point_frames(r, t, h, pf)
    delta, arm = 1e-4, h * t[0, 2]
    t1 = t.copy()
    t1[0] = [t[0, 0], -t[0, 2] * np.sin(delta), t[0, 2] * np.cos(delta)]
    F, M, Ff, stuck = np.zeros((3, 3)), np.zeros((3, 3)), np.zeros((3, 3)), np.zeros(3)
    K.end_friction_loads(r, t1, anchor, pf, h, fmax, kt, F, M, Ff, stuck)
    assert stuck[0] == 1.0 and kt * arm * delta < fmax[1]
    assert M[0, 0] == pytest.approx(-kt * arm**2 * delta, rel=1e-3)
    assert np.abs(F[0]).max() == pytest.approx(kt * arm * delta, rel=1e-3)
    # the centre law: the link's stick spring at its centre, anchored where the centre is
    frame = np.zeros((3, 3, 3))
    IK.local_frames(r, frame)
    g = np.zeros((3, IK.NDOF))
    e = IK.friction_term(r, r.copy(), frame, np.array([KFR * Ne[:2].sum(), 0.0, 0.0]), kt, g, np.zeros((1, 1)),
                         False)
    assert e == 0.0 and not g.any()


@pytest.mark.parametrize("stuck", [True, False])
def test_a_stick_anchor_keeps_no_offset_along_the_wall_normal(stuck):
    """kernels.drop_normal_offset: an end that touched down with its anchor 1e-3 R off the wall's
    tangent plane (the offset of its approach). The stick spring reads only the tangential offset,
    in the frame of the point at the start of a step; an anchor off the tangent plane by d_n turns
    a rotation dtheta of that frame into a force k_t d_n dtheta that no displacement caused (the
    ramp stage that ran to the time cap, kernels.drop_normal_offset). After the anchor update the
    offset is tangential, a stuck end keeps its tangential offset, a sliding one is dragged to
    k_t |d| = f_max, and a frame rotation changes the force by at most f_max dtheta, the
    rotation of the force itself (before: k_t d_n dtheta = 20 dtheta, 4e4 times larger)."""
    from confined_rod.sim.model import kernels as K
    from confined_rod.sim.model.forces import end_points
    from confined_rod.sim.solvers import implicit_kernels as IK

    kt, fm, h, dn = 2e4, 1e-3, 0.25, 1e-3
    r, t = np.array([[1.0001, 0.0, 5.0]]), np.array([[0.0, 0.0, 1.0]])
    p = end_points(r, t, h)                          # both ends at rho = 1.0001: the wall
    tangential = np.array([0.0, 2e-8, 1e-8]) * (1.0 if stuck else 1e3)   # k_t |d_t| = 4.5e-4 or 0.45
    anchor = p - tangential - np.array([dn, 0.0, 0.0])
    fmax, pf = np.array([fm, fm]), np.zeros((2, 3, 3))
    K.point_frames(r, t, h, pf)
    K.update_end_anchors(r, t, anchor, pf, h, fmax, kt)
    off = p - anchor
    ulp = 4.0 * np.finfo(float).eps * np.abs(p).max()   # the round-off of a difference of positions ~5 R
    assert np.abs(off[:, 0]).max() <= ulp            # radial (the wall normal at these points): none
    if stuck:
        np.testing.assert_allclose(off[:, 1:], np.tile(tangential[1:], (2, 1)), rtol=0.0, atol=ulp)
    else:
        np.testing.assert_allclose(np.linalg.norm(off, axis=1), fm / kt, rtol=0.0, atol=ulp)
    # the force under a frame rotated by dtheta about the axis (the point moved along the wall)
    dth = 1e-6
    rot = np.array([[np.cos(dth), -np.sin(dth), 0.0], [np.sin(dth), np.cos(dth), 0.0], [0.0, 0.0, 1.0]])
    pf_rot = np.zeros_like(pf)
    K.cylinder_frames(p @ rot.T, pf_rot)
    forces = []
    for frames in (pf, pf_rot):
        F, M, Ff, s = np.zeros((1, 3)), np.zeros((1, 3)), np.zeros((1, 3)), np.zeros(1)
        K.end_friction_loads(r, t, anchor, frames, h, fmax, kt, F, M, Ff, s)
        forces.append(F[0])
        assert s[0] == 1.0 or not stuck    # a dragged anchor sits on the edge of the stick zone
    assert np.abs(forces[1] - forces[0]).max() <= 2.0 * (2 * fm) * dth
    # the centre law's anchors follow the same rule
    anchor_c = r - np.array([[dn, 1e-8, 0.0]])
    frame = np.zeros((1, 3, 3))
    IK.local_frames(r, frame)
    IK.update_anchors(r, anchor_c, frame, np.array([fm]), kt)
    assert abs((r - anchor_c)[0, 0]) <= ulp and (r - anchor_c)[0, 1] == pytest.approx(1e-8, abs=ulp)
