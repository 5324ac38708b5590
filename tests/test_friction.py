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
