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

SOLVERS = {"explicit": explicit.relax, "implicit": implicit.relax}

P, KFR, L = 0.1, 0.5, 4.0  # capacity k_fr p L = 0.2


def scene(T, tol=1e-8):
    return Scene(L=L, l0=0.5, load=T, k_fr=KFR, friction_cap=0.0, body_force=(P, 0.0, 0.0),
                 lower_end="free", floor=False, perturbation=1e-6, k_ph=200.0, tol=tol,
                 name=f"T={T}")


@pytest.mark.parametrize("solver", sorted(SOLVERS))
def test_below_the_limit_the_rod_sticks_and_never_creeps(solver, monkeypatch):
    relax = SOLVERS[solver]
    sc = scene(0.1)
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
    sc_long = scene(0.1, tol=1e-9)
    span = 10 * max(t_rest, 50.0)
    relax(sc_long, st, t_end=t_rest + span, progress=False)
    assert not st.converged and st.time >= (t_rest + span) * (1 - 1e-12)
    settle = {"explicit": 1e-12, "implicit": 1e-8}[solver]
    assert np.abs(st.r[:, 2] - z_rest).max() < settle
    z_mid, phi_mid = st.r[:, 2].copy(), np.arctan2(st.r[:, 1], st.r[:, 0])
    assert np.abs(phi_mid - phi_rest).max() < settle
    relax(sc_long, st, t_end=t_rest + 2 * span, progress=False)
    assert np.abs(st.r[:, 2] - z_mid).max() < 1e-12
    assert np.abs(np.arctan2(st.r[:, 1], st.r[:, 0]) - phi_mid).max() < 1e-12


@pytest.mark.parametrize("solver", sorted(SOLVERS))
def test_above_the_limit_the_rod_slides_at_the_coulomb_velocity(solver):
    relax = SOLVERS[solver]
    T = 0.3
    sc = scene(T)
    st = RunState(*sc.initial_state())
    relax(sc, st, t_end=60.0, progress=False)  # transient: reach the wall (~R/p = 10)
    z0, t0 = st.r[:, 2].mean(), st.time
    relax(sc, st, t_end=120.0, progress=False)
    v = (st.r[:, 2].mean() - z0) / (st.time - t0)
    v_coulomb = -(T - KFR * P * L) / L  # beta_ph = 1
    # steady sliding: the only error is the penalty penetration changing N by O(p/k_w)
    assert v == pytest.approx(v_coulomb, rel=1e-3)
