"""The discrete chain's torque-free helix (theory.discrete_helix, docs/model.md "The discrete helix"):
the model's own energy (sim/model/reference.py) on a helix whose joints sit on the wall, with
closed bonds, is the continuum energy per length times l0 in the chord variable u = R w, so the
helix relation and the wall force hold for every l0 and only the azimuth per link carries l0."""
import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from confined_rod import Scene, theory
from confined_rod.sim.model import kernels
from confined_rod.sim.model.reference import total_energy

LOAD = 0.25


def chain(u: float, l0: float, n: int, rho: float = 1.0):
    """Link centres and tangents of n links whose joints lie on the cylinder of radius rho, each link
    at angle asin(u) to the axis, the lowest joint at z = 0 (link 0 at the bottom, as the model)."""
    theta = 2.0 * np.arcsin(u * l0 / (2.0 * rho))
    h = l0 * np.sqrt(1.0 - u * u)
    j = np.arange(n + 1)
    joints = np.stack([rho * np.cos(j * theta), rho * np.sin(j * theta), j * h], axis=1)
    t = (joints[1:] - joints[:-1]) / l0
    return 0.5 * (joints[1:] + joints[:-1]), t


def energy_per_link(u: float, l0: float, rho: float = 1.0, n: int = 12) -> float:
    """E(n + 1 links) - E(n links) of the model's energy without the wall's penalty (the wall force
    is what its derivative in rho gives): one more link of the uniform helix."""
    par = Scene(L=(n + 1) * l0, l0=l0, load=LOAD, R=1.0).params()
    par[kernels.K_WALL] = 0.0

    def energy(m):
        r, t = chain(u, l0, m, rho)
        return total_energy(np.ascontiguousarray(r), np.ascontiguousarray(t), par)

    return energy(n + 1) - energy(n)


@pytest.mark.parametrize("l0", [1.0, 0.5, 0.25])
def test_model_energy_per_link_is_the_continuum_energy_in_the_chord_variable(l0):
    for u in (0.2, 0.37, 0.5):
        # joints on the wall: no wall energy; closed bonds: none; one bend per link, C = EI/l0
        expected = l0 * (u**4 / 2.0 + LOAD * np.sqrt(1.0 - u * u))
        assert energy_per_link(u, l0) == pytest.approx(expected, rel=1e-11)


@pytest.mark.parametrize("l0", [1.0, 0.5, 0.25])
def test_discrete_helix_is_the_stationary_point_of_the_model_energy(l0):
    """The u that minimises the model's energy per link is R w of the continuum torque-free helix
    at every l0 (to the minimiser's 1e-7), and the wall force per length it implies, -de/drho / l0,
    is EI R w^4 (central difference in rho: O(1e-8))."""
    best = minimize_scalar(lambda u: energy_per_link(u, l0), bounds=(0.1, 0.7), method="bounded",
                           options={"xatol": 1e-10})
    exact = theory.discrete_helix(LOAD, l0)
    assert best.x == pytest.approx(exact["w"], rel=1e-6)
    d = 1e-5
    K = -(energy_per_link(best.x, l0, 1 + d) - energy_per_link(best.x, l0, 1 - d)) / (2 * d) / l0
    assert K == pytest.approx(exact["K"], rel=1e-6)


def test_only_the_azimuth_per_link_carries_l0():
    """dphi/ds and the pitch are the continuum's times arcsin(x)/x and its inverse, x = w l0/2: a
    second-order term (w l0)^2/24 that vanishes as l0 -> 0, halving l0 quarters it."""
    w, c = theory.helix_frictionless(LOAD)
    pitch0 = 2 * np.pi * np.sqrt(1 - w * w) / w
    errors = []
    for l0 in (1.0, 0.5, 0.25, 0.125):
        h = theory.discrete_helix(LOAD, l0)
        x = w * l0 / 2
        assert h["K"] == pytest.approx(c, rel=1e-12)
        assert h["dphi_ds"] / w - 1 == pytest.approx(x * x / 6, rel=x * x)
        assert h["rho_centre"] == pytest.approx(1 - x * x / 2, abs=x**4)
        errors.append(h["pitch"] / pitch0 - 1)
    assert errors[0] < 0
    assert np.allclose(np.array(errors[:-1]) / np.array(errors[1:]), 4.0, rtol=0.01)


def test_discrete_helix_refuses_a_link_longer_than_the_helix_allows():
    with pytest.raises(ValueError, match="l0"):
        theory.discrete_helix(LOAD, 8.0)
    with pytest.raises(ValueError, match="l0"):
        theory.discrete_helix(LOAD, 0.0)


def test_a_frictionless_l0_ladder_draws_the_discrete_helix_beside_its_rungs():
    """The convergence kind sets the theory's pitch beside each rung of a frictionless l0 ladder
    only (with friction the helix carries a locked torque and a varying force: no such curve)."""
    import xarray as xr

    from confined_rod.analysis.figures import convergence

    def rung(l0, k_fr=0.0):
        return (f"l0_{l0:g}", xr.Dataset(attrs={"k_fr": k_fr, "load": LOAD, "l0": l0, "R": 1.0, "EI": 1.0}))

    items = [rung(1.0), rung(0.5), rung(0.25)]
    got = convergence._discrete_helix_pitch("l0", items)
    np.testing.assert_allclose(got, [theory.discrete_helix(LOAD, l0)["pitch"] for l0 in (1.0, 0.5, 0.25)], rtol=1e-14)
    assert got[0] < got[1] < got[2]
    assert convergence._discrete_helix_pitch("k_ph", items) is None
    assert convergence._discrete_helix_pitch("l0", [rung(1.0, 0.8), rung(0.5, 0.8)]) is None
