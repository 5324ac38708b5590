"""Frictionless helix in the middle of a long rod against the derivation in
docs/model.md: with free ends the axial torque invariant gives K = EI R w^4 and
2 EI w^2 sqrt(1 - R^2 w^2) = |F_z| (w = dphi/ds).

Tolerance 1 %: the discretisation error of a helix drawn with chords of length
l0 is O((w l0)^2/12) = 0.6 % at w = 0.55, l0 = 0.5, and the bond strain
|F_z|/k_ph = 0.17 % changes the arc length; measured: +0.29 % (w), +0.04 % (K).
The paper's K = R F^2/(2EI) is 29 % off at this load (and 2x at small loads), so
the test separates the two."""
import numpy as np
import pytest

from confined_rod import Scene, simulate
from confined_rod.theory import helix_frictionless

L, LOAD = 30.0, 0.5


@pytest.fixture(scope="module")
def helix():
    # k_ph = k_w = 300 instead of 1000 allows a 3x larger explicit step; both
    # compliances stay below 0.2 % here
    sc = Scene(L=L, load=LOAD, k_fr=0.0, k_ph=300.0, k_w=300.0, tol=1e-4, dt_factor=0.9)
    return simulate(sc, progress=False)


def bulk(ds, coord):
    return (ds[coord] > 0.35 * L) & (ds[coord] < 0.65 * L)


def test_bulk_is_a_helix_on_the_wall(helix):
    assert int(helix.converged) == 1
    assert int(helix.contact.where(bulk(helix, "s_link"), 1).min()) == 1
    rho = np.hypot(helix.x, helix.y).where(bulk(helix, "s_link"), drop=True)
    assert np.allclose(rho, 1.0, atol=0.01)
    # frictionless: the axial force is the load everywhere
    np.testing.assert_allclose(helix.F_z.values, -LOAD, rtol=1e-3)


def test_pitch_and_wall_force_match_the_derivation(helix):
    w_th, K_th = helix_frictionless(LOAD)
    w = float(np.abs(helix.dphi_ds.where(bulk(helix, "s_helix"), drop=True)).mean())
    K = float(helix.wall_force_density.where(bulk(helix, "s_link"), drop=True).mean())
    assert w == pytest.approx(w_th, rel=0.01)
    assert K == pytest.approx(K_th, rel=0.01)
    # lowest order of the same relations, and the paper's Eq. (K-simple)
    assert K_th == pytest.approx(LOAD**2 / 4, rel=0.5)
    assert abs(K / (LOAD**2 / 2) - 1) > 0.25


def test_helix_relation_limits():
    # small loads: w^2 -> F/(2EI), K -> R F^2/(4EI)
    w, K = helix_frictionless(1e-4)
    assert w**2 == pytest.approx(1e-4 / 2, rel=1e-4)
    assert K == pytest.approx(1e-8 / 4, rel=1e-4)
    # R and EI enter as the scaling law says
    w2, K2 = helix_frictionless(0.5 * 3.0 / 4.0, R=2.0, EI=3.0)
    w1, K1 = helix_frictionless(0.5)
    assert w2 * 2.0 == pytest.approx(w1, rel=1e-12)
    assert K2 / (3.0 / 8.0) == pytest.approx(K1, rel=1e-12)


def test_equilibrium_does_not_depend_on_the_rotational_drag():
    """The drags set the path, not the equilibrium (frictionless, so the path
    cannot select among jammed states). With tol = 1e-5 the force profile is
    within tol*load = 5e-6 of the exact equilibrium for each run, hence 1e-5 between
    them; measured: 4e-7 (F_z), 3e-7 (wall force), 2e-6 R (L_z)."""
    runs = [simulate(Scene(L=10.0, load=0.5, k_fr=0.0, tol=1e-5, rotational_drag=d), progress=False)
            for d in ("paper", "rigid_link")]
    a, b = runs
    assert int(a.converged) and int(b.converged)
    assert a.attrs["gamma_r"] != b.attrs["gamma_r"]
    assert int(a.contact.sum()) == int(b.contact.sum()) > 0
    np.testing.assert_allclose(a.F_z.values, b.F_z.values, atol=1e-5)
    np.testing.assert_allclose(a.wall_force.values, b.wall_force.values, atol=1e-5)
    assert float(a.L_z) == pytest.approx(float(b.L_z), rel=1e-5)
