"""The simple model (corrected) and the power-law fit of the force profiles."""
import numpy as np
import pytest

from confined_rod import theory
from confined_rod.analysis.fits import FitError, fit_power_law, power_law


def test_force_decay_obeys_its_ode():
    """d|F|/ds = -k_fr K with K = R F^2/(4 EI): checked by central differences
    (error O(h^2) ~ 1e-8 relative for h = 1e-3), in units with R, EI != 1."""
    R, EI, k_fr, F0 = 2.0, 3.0, 0.8, 0.4
    s = np.linspace(0.0, 50.0, 11)
    h = 1e-3
    F = theory.force_decay(s, F0, k_fr, R, EI)
    dF = (theory.force_decay(s + h, F0, k_fr, R, EI) - theory.force_decay(s - h, F0, k_fr, R, EI)) / (2 * h)
    assert F[0] == pytest.approx(F0, rel=1e-15)
    np.testing.assert_allclose(dF, -k_fr * R * F**2 / (4 * EI), rtol=1e-6)
    # the paper's printed form has twice the friction: K = R F^2/(2 EI)
    Fp = theory.force_decay(s, F0, k_fr, R, EI, paper=True)
    dFp = (theory.force_decay(s + h, F0, k_fr, R, EI, paper=True)
           - theory.force_decay(s - h, F0, k_fr, R, EI, paper=True)) / (2 * h)
    np.testing.assert_allclose(dFp, -k_fr * R * Fp**2 / (2 * EI), rtol=1e-6)


def test_critical_length_is_the_pole():
    F0, k_fr = 0.25, 0.8
    lc = theory.critical_length(F0, k_fr)
    assert lc == pytest.approx(-20.0)  # -4 EI/(k_fr R F0)
    s = np.array([0.0, 10.0, 300.0])
    np.testing.assert_allclose(theory.force_decay(s, F0, k_fr), 4.0 / k_fr / (s - lc), rtol=1e-14)
    assert theory.critical_length(F0, k_fr, paper=True) == pytest.approx(-10.0)


def test_simple_model_matches_the_frictionless_helix_at_small_load():
    """K = R F^2/(4EI) is the small-load limit of the exact K = EI R w^4."""
    for F in (1e-4, 1e-3):
        _, K = theory.helix_frictionless(F)
        assert K == pytest.approx(F**2 / 4, rel=2 * F)  # next order is O(F)


def test_fit_recovers_an_exact_power_law():
    s = np.linspace(3.0, 300.0, 200)
    F = power_law(s, 11.95, 44.9, -0.903)  # the paper's Fig 4(c) values
    f = fit_power_law(s, F, guess=(5.0, 20.0, -1.0))
    assert (f.A, f.l0_fit, f.c) == pytest.approx((11.95, 44.9, -0.903), rel=1e-6)
    assert f.rms_relative_residual < 1e-9
    np.testing.assert_allclose(f(s), F, rtol=1e-8)


@pytest.mark.parametrize("seed", range(5))
def test_fit_errors_cover_the_scatter(seed):
    """1 % relative noise: each parameter within 4 of its standard errors of the truth
    (a 4-sigma band fails with probability ~6e-5 per parameter if the errors are right),
    and the error of c is in the range the noise level implies."""
    rng = np.random.default_rng(seed)
    s = np.linspace(0.0, 300.0, 300)
    truth = (20.0, 80.0, -0.9)
    F = power_law(s, *truth) * (1 + 0.01 * rng.standard_normal(s.size))
    f = fit_power_law(s, F, guess=(4 / 0.8, 20.0, -1.0))
    for v, e, t in zip((f.A, f.l0_fit, f.c), f.errors, truth):
        assert abs(v - t) < 4 * e
    assert 1e-3 < f.errors[2] < 0.1
    assert f.rms_relative_residual == pytest.approx(0.01, rel=0.2)


def test_fit_refuses_bad_input():
    s = np.linspace(0, 10, 20)
    with pytest.raises(FitError, match="at least 5"):
        fit_power_law(s[:4], np.ones(4), guess=(1, 1, -1))
    with pytest.raises(FitError, match="finite and positive"):
        fit_power_law(s, np.where(s > 5, np.nan, 1.0), guess=(1, 1, -1))
    with pytest.raises(FitError, match=">= 0"):
        fit_power_law(s - 1, np.ones_like(s), guess=(1, 1, -1))
    # a flat profile does not determine l0' (scipy would report its error as 0)
    with pytest.raises(FitError, match="degenerate"):
        fit_power_law(s, np.full(s.size, 0.2), guess=(5, 20, -1))
