"""The comparison of two ensembles (analysis/distributions.py) on constructed draws: its stated
size, power and decisions hold."""
import math

import numpy as np
import pytest
from scipy.stats import norm

from confined_rod.analysis import distributions as D


def test_constants():
    assert D.Z_ALPHA == pytest.approx(norm.ppf(1 - D.ALPHA / 2), rel=1e-12)
    assert D.Z_POWER == pytest.approx(norm.ppf(D.POWER), rel=1e-12)


def test_same_distribution_passes_at_the_stated_rate():
    """400 pairs of ensembles of 40 draws from one distribution (mean 1, s.d. 5 %): the AD test
    rejects at 5 % in about 5 % of them (binomial s.d. 1.1 %: between 1.5 % and 9.5 % is within
    four s.d.), and the shift of the mean lies beyond its 95 % interval about as often."""
    rng = np.random.default_rng(1)
    rejects, outside = 0, 0
    n_trials = 400
    for _ in range(n_trials):
        a, b = rng.normal(1.0, 0.05, 40), rng.normal(1.0, 0.05, 40)
        c = D.compare(a, b, tolerance=0.03)
        rejects += c.p_ad < D.ALPHA
        outside += abs(c.shift) > D.Z_ALPHA * c.se
    assert 0.015 <= rejects / n_trials <= 0.095
    assert 0.015 <= outside / n_trials <= 0.095


def test_resolution_is_detected_at_the_stated_power():
    """A true shift equal to the stated resolution is detected (|d| > z e) in about 95 % of the
    trials (300 trials: binomial s.d. 1.3 %; at least 89 %), a shift of a third of it rarely."""
    rng = np.random.default_rng(2)
    probe = D.compare(rng.normal(1, 0.05, 50), rng.normal(1, 0.05, 50), 0.05)
    delta = probe.resolution
    hits, weak = 0, 0
    for _ in range(300):
        b = rng.normal(1.0, 0.05, 50)
        hits += abs(D.compare(rng.normal(1.0 + delta, 0.05, 50), b, 0.05).shift) > D.Z_ALPHA * probe.se
        weak += abs(D.compare(rng.normal(1.0 + delta / 3, 0.05, 50), b, 0.05).shift) > D.Z_ALPHA * probe.se
    assert hits / 300 >= 0.89
    assert weak / 300 <= 0.5


def test_decisions():
    rng = np.random.default_rng(3)
    base = rng.normal(1.0, 0.02, 60)
    same = D.compare(base * 1.0, rng.normal(1.0, 0.02, 60), tolerance=0.02)
    assert same.verdict == D.WITHIN and same.resolution <= 0.02
    far = D.compare(base * 1.05, rng.normal(1.0, 0.02, 60), tolerance=0.02)
    assert far.verdict == D.BEYOND and far.p_ad < 0.01
    # a small ensemble cannot resolve the tolerance: undecided, with the seeds that would
    small = D.compare(rng.normal(1.0, 0.05, 5), rng.normal(1.0, 0.05, 5), tolerance=0.02)
    assert small.verdict == D.UNDECIDED and small.seeds_needed > 5
    # the seeds it names do decide when the spread is as measured (with the large-sample factors
    # such an ensemble has): resolution at that n <= tol
    s = small
    assert (D.Z_ALPHA + D.Z_POWER) * s.se * math.sqrt(5 / s.seeds_needed) <= 0.02 * (1 + 1e-9)
    assert "seeds per rung would decide" in s.text()


def test_shape_difference_that_the_mean_misses():
    """Same mean, different shape (a bimodal ensemble against a narrow one): the mean is within
    the tolerance, the AD test sees the difference."""
    rng = np.random.default_rng(4)
    a = np.concatenate([rng.normal(0.9, 0.005, 100), rng.normal(1.1, 0.005, 100)])
    b = rng.normal(1.0, 0.005, 200)
    c = D.compare(a, b, tolerance=0.05)
    assert c.verdict == D.WITHIN and c.p_ad <= 0.001 + 1e-12


def test_refuses_bad_input():
    with pytest.raises(ValueError, match="at least two"):
        D.compare([1.0], [1.0, 2.0], 0.1)
    with pytest.raises(ValueError, match="non-finite"):
        D.compare([1.0, np.nan], [1.0, 2.0], 0.1)


def test_pairing_removes_the_spread_a_seed_carries_on_both_rungs():
    """Eight seeds spread by 10 % between them, each moved by +0.5 % (+- 0.1 %) on the finer rung:
    unpaired the shift cannot be bounded within 2 %; paired it is, and its error is the spread of
    the differences (0.1 %/sqrt(8) about), not of the seeds."""
    rng = np.random.default_rng(3)
    a = 0.27 * (1 + 0.10 * rng.standard_normal(8))
    b = a * (1 + 0.005 + 0.001 * rng.standard_normal(8))
    unpaired = D.compare(a, b, 0.02)
    paired = D.compare(a, b, 0.02, paired=True)
    assert unpaired.verdict == D.UNDECIDED
    assert paired.verdict == D.WITHIN and paired.paired
    assert paired.shift == pytest.approx(unpaired.shift, abs=1e-15)      # pairing never moves the shift
    assert paired.shift == pytest.approx(-0.005, abs=0.002)
    assert paired.se == pytest.approx(0.001 / np.sqrt(8), rel=0.6)
    assert "8 paired seeds" in paired.text()
    # a seed that moves to another equilibrium (its value 30 % off) widens the paired error
    b2 = b.copy()
    b2[0] *= 1.3
    assert D.compare(a, b2, 0.02, paired=True).se > 5 * paired.se
    with pytest.raises(ValueError, match="one value per seed"):
        D.compare(a, b[:7], 0.02, paired=True)


def test_a_few_seeds_get_students_factor_not_the_normal_one():
    """Three paired seeds estimate their spread with 2 degrees of freedom: the 95 % bound uses
    t = 4.303 (scipy), not 1.96, and 40 seeds come close to the normal factor."""
    from scipy.stats import t

    a, b = np.array([1.00, 1.02, 0.99]), np.array([1.0, 1.0, 1.0])
    c = D.compare(a, b, tolerance=0.5, paired=True)
    assert c.dof == 2
    assert c.bound == pytest.approx(abs(c.shift) + t.ppf(0.975, 2) * c.se, rel=1e-12)
    assert c.resolution == pytest.approx((t.ppf(0.975, 2) + t.ppf(0.95, 2)) * c.se, rel=1e-12)
    rng = np.random.default_rng(3)
    big = D.compare(rng.normal(1, 0.05, 40), rng.normal(1, 0.05, 40), 0.05)
    assert 70 < big.dof <= 78          # Welch-Satterthwaite for two equal spreads: about 2 n - 2
    assert D.t_quantiles(big.dof)[0] == pytest.approx(D.Z_ALPHA, rel=0.03)
    with pytest.raises(ValueError, match="degrees of freedom"):
        D.t_quantiles(0)


def test_the_clipped_ends_of_the_ad_p_value_are_written_as_bounds():
    assert D.ad_text(0.25) == "AD p >= 0.25" and D.ad_text(0.001) == "AD p <= 0.001"
    assert D.ad_text(0.0134) == "AD p = 0.0134" and D.ad_text(1.0) == "AD p = 1"


def test_a_seed_that_jumps_to_another_equilibrium_is_counted_not_averaged_away():
    """Nine seeds shift by 1 % +- 0.1 %, one jumps by +25 %: one jump, its difference named; with
    no outlier none. The jump is what makes the standard error large."""
    rng = np.random.default_rng(5)
    b = rng.normal(1.0, 0.1, 10)
    a = b * (1.01 + rng.normal(0, 0.001, 10))
    assert D.seed_jumps((a - b) / b.mean()) == (0, 0.0)
    a[3] = b[3] + 0.25 * b.mean()
    c = D.compare(a, b, tolerance=0.03, paired=True)
    assert c.jumps == 1 and c.largest_jump == pytest.approx(0.25, rel=1e-12)
    assert "(1 of them jumps to another state, largest +25 %)" in c.text()
    assert D.compare(a, b, tolerance=0.03).jumps == 0           # unpaired: no seed to follow
    # a converged ladder's seeds agree to round-off: an outlier of 1e-5 is not another state
    d = rng.normal(0.0, 1e-7, 32)
    d[[2, 9]] = 1e-5
    assert D.seed_jumps(d) == (0, 0.0)
    d[4] = 0.02
    assert D.seed_jumps(d) == (1, pytest.approx(0.02))


def test_the_budget_tolerance_is_half_the_figures_error_from_a_spread_bounded_below():
    """budget_tolerance = 1/2 t_{n-1} s_lo/(sqrt(n) |mean|), and s_lo, the one-sided 95 % lower
    bound of the spread from m draws, lies below the true spread in about 95 % of ensembles (2000
    ensembles of m = 5 from N(1, 0.1): binomial s.d. 0.5 %, so 93-97 % is four s.d.)."""
    rng = np.random.default_rng(11)
    x = rng.normal(2.0, 0.2, 8)
    s_lo = D.spread_lower_bound(x)
    from scipy.stats import chi2, t
    assert s_lo == pytest.approx(x.std(ddof=1) * math.sqrt(7 / chi2.ppf(0.95, 7)), rel=1e-12)
    assert D.budget_tolerance(x, 3) == pytest.approx(0.5 * t.ppf(0.975, 2) * s_lo / math.sqrt(3) / x.mean(), rel=1e-12)
    # a larger figure has a smaller error, so a tighter tolerance; a bias at it leaves the figure's
    # 95 % interval a coverage of Phi(z - b) - Phi(-z - b), b = share z: 0.83 for normal errors
    assert D.budget_tolerance(x, 10) < D.budget_tolerance(x, 3)
    z, b = D.Z_ALPHA, D.BUDGET_SHARE * D.Z_ALPHA
    assert norm.cdf(z - b) - norm.cdf(-z - b) == pytest.approx(0.835, abs=2e-3)
    below = sum(D.spread_lower_bound(rng.normal(1.0, 0.1, 5)) <= 0.1 for _ in range(2000))
    assert 0.93 <= below / 2000 <= 0.97


@pytest.mark.parametrize("values, n", [([1.0], 3), ([1.0, np.nan], 3), ([1.0, -1.0], 3), ([1.0, 1.2], 1)])
def test_the_budget_tolerance_refuses_what_has_no_error(values, n):
    with pytest.raises(ValueError):
        D.budget_tolerance(values, n)
