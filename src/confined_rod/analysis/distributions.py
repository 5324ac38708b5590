"""Two ensembles of one quantity compared: is the shift of the mean within a tolerance, and
what would the ensembles have seen (issue 43).

A rung of a convergence ladder is an ensemble of seeds, and with friction each seed's final
state is one draw from a distribution of neighbouring equilibria. What is well posed is whether
two rungs draw from the same distribution, not whether a seed keeps its state. For ensembles a
(the publication rung) and b (a finer rung) of one quantity x:

* shift   d = mean(a)/mean(b) - 1, relative to the finer rung;
* its standard error e, to first order in the errors, either unpaired (Welch)
  e = sqrt(s_a^2/n_a + (mean(a)/mean(b))^2 s_b^2/n_b) / |mean(b)|, or **paired** when the two
  ensembles hold the same seeds and every seed starts from the same rod on both rungs (a
  convergence ladder: sim/perturbation.py draws the start as one continuous rod per seed):
  e = sd(a_i - (mean(a)/mean(b)) b_i) / sqrt(n) / |mean(b)| over the seeds i. Pairing never biases
  the shift (the mean of the differences is the difference of the means); it removes the part of
  the spread that a seed carries on both rungs (its equilibrium, where it keeps it), and a seed that
  moves to another equilibrium simply adds its large difference to the spread;
* the 95 % bound |d| +- t e with t Student's quantile (two-sided 5 %) for the degrees of freedom
  of e (n - 1 paired, Welch-Satterthwaite unpaired): 2.26 for 10 seeds, 4.30 for 3, the normal
  1.959964 for many; an ensemble of a few seeds estimates its own spread poorly;
* the **resolution** r = (t + t_pow) e, t_pow the 95 % quantile (1.644854 for many seeds): the
  smallest shift of the mean that a two-sided 5 % test would have detected with probability
  about 95 % (the power of the ensembles);
* the **Anderson-Darling k-sample test** of scipy (scipy.stats.anderson_ksamp, its p-value
  floored at 0.001 and capped at 0.25 by scipy): a difference of shape that the means miss.

Decided against a tolerance tol (relative):

* ``within``: |d| + t e <= tol (the shift is bounded inside the tolerance at 95 %) and r <= tol
  (a shift of the size of the tolerance would have been seen);
* ``beyond``: |d| - t e > tol (the shift exceeds the tolerance at 95 %);
* ``undecided`` otherwise, with the seeds per ensemble that would decide, with the large-sample
  factors z: n max((z e / (tol - |d|))^2, ((z + z_pow) e / tol)^2) below the tolerance,
  n (z e / (|d| - tol))^2 above (errors shrink as 1/sqrt(n)); infinite at |d| = tol, and
  unstable near it: the estimate assumes the observed shift is the true one.

The tolerance a figure's numbers set (:func:`budget_tolerance`). A ladder that vouches for the
ensemble means a figure reports over n seeds holds their numerical bias to a share of the
figure's own statistical error: tol = BUDGET_SHARE t_{n-1} s_lo/(sqrt(n) |mean|), mean the mean of
the ladder's publication rung (the same rod) and s_lo the one-sided 95 % lower confidence bound
of its spread, s sqrt((m - 1)/chi2_{0.95}(m - 1)) over its m seeds (0.58 s at m = 3, 0.73 s at
10): a few seeds that happen to spread widely do not widen the tolerance. At share 1/2 a bias at
the tolerance is half the 95 % half-width of the figure's mean: an interval that ignores it
still covers the true value with probability Phi(z/2) - Phi(-3z/2) = 0.83 (z = 1.96, normal
errors) instead of 0.95, and one widened by it (1.5 times) covers it at least as often as
stated. It is not random, so it does not add in quadrature; the error budget states it beside
the figure's statistical error (analysis/error_budget.py).

Tests on constructed ensembles (tests/test_distributions.py): two draws of one distribution
are ``within`` and pass the AD test at the stated rate; a shift of the resolution is detected
at the stated power; a shift of twice the tolerance is ``beyond``.
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

ALPHA = 0.05        # two-sided size of the tests
POWER = 0.95        # the power at which the resolution is stated
Z_ALPHA = 1.959963984540054     # norm.ppf(1 - ALPHA/2): the large-sample limit of t_alpha
Z_POWER = 1.6448536269514722    # norm.ppf(POWER)


def t_quantiles(dof: float) -> tuple[float, float]:
    """Student's t quantiles (1 - ALPHA/2, POWER) for ``dof`` degrees of freedom: the factors of a
    standard error estimated from a few seeds (12.7 and 6.3 at dof 1, 2.26 and 1.83 at 9, the
    normal Z_ALPHA and Z_POWER as dof -> inf)."""
    if not dof > 0:
        raise ValueError(f"t_quantiles needs positive degrees of freedom, got {dof!r}")
    if math.isinf(dof):
        return Z_ALPHA, Z_POWER
    from scipy.stats import t

    return float(t.ppf(1.0 - ALPHA / 2.0, dof)), float(t.ppf(POWER, dof))


WITHIN, BEYOND, UNDECIDED = "within", "beyond", "undecided"
#: the share of a figure's 95 % statistical error its numerical bias may take (module docstring)
BUDGET_SHARE = 0.5


def spread_lower_bound(values) -> float:
    """The one-sided 95 % lower confidence bound of the standard deviation of the distribution the
    ``values`` were drawn from, s sqrt((m - 1)/chi2_{0.95}(m - 1)) (normal sampling theory)."""
    from scipy.stats import chi2

    x = np.asarray(values, dtype=float)
    m = x.size
    return float(x.std(ddof=1)) * math.sqrt((m - 1) / float(chi2.ppf(POWER, m - 1)))


def budget_tolerance(values, n: int, share: float = BUDGET_SHARE) -> float:
    """share t_{n-1} s_lo/(sqrt(n) |mean|) of the ensemble ``values`` (module docstring; s_lo its
    spread_lower_bound): the relative tolerance that keeps a numerical bias within ``share`` of the
    95 % error of a mean over ``n`` seeds drawn from the same distribution. Needs two values, a
    nonzero mean and n >= 2."""
    x = np.asarray(values, dtype=float)
    if x.size < 2 or not np.all(np.isfinite(x)):
        raise ValueError(f"budget_tolerance needs at least two finite values, got {x.size}")
    if int(n) < 2:
        raise ValueError(f"budget_tolerance: a figure's mean over n = {n} seeds has no statistical error")
    mean = float(x.mean())
    if mean == 0.0:
        raise ValueError("budget_tolerance: the ensemble's mean is 0; a relative tolerance is not defined")
    return share * t_quantiles(float(n - 1))[0] * spread_lower_bound(x) / math.sqrt(n) / abs(mean)
#: the range scipy.stats.anderson_ksamp clips its p-value to
AD_P_MIN, AD_P_MAX = 0.001, 0.25


@dataclass(frozen=True)
class Comparison:
    n_a: int
    n_b: int
    mean_a: float
    mean_b: float
    shift: float         # mean_a/mean_b - 1
    se: float            # its standard error
    resolution: float    # shift detected with POWER at ALPHA
    p_ad: float          # Anderson-Darling k-sample p-value (scipy's range 0.001-0.25); 1 if both constant
    verdict: str         # WITHIN, BEYOND or UNDECIDED against the tolerance
    tolerance: float
    seeds_needed: float  # per ensemble to decide (0 when decided; inf when |shift| = tolerance)
    paired: bool = False  # se from the differences seed by seed (module docstring)
    dof: float = math.inf  # degrees of freedom of se: n - 1 paired, Welch-Satterthwaite unpaired
    jumps: int = 0        # paired seeds whose difference is an outlier (jumps): another equilibrium
    largest_jump: float = 0.0  # the largest such difference, relative to the finer rung's mean

    @property
    def bound(self) -> float:
        """|shift| + t se: the largest shift compatible with the ensembles at 95 %."""
        return abs(self.shift) + t_quantiles(self.dof)[0] * self.se

    def text(self, unit: str = "%", tolerance_note: str = "") -> str:
        """One line: shift, bound, resolution, AD p, seeds, the verdict against the tolerance (with
        ``tolerance_note`` after it: where the tolerance comes from) and the seeds that would decide."""
        scale = 100.0 if unit == "%" else 1.0
        need = ("" if self.verdict != UNDECIDED else
                "; no finite number of seeds decides (the shift equals the tolerance)" if math.isinf(self.seeds_needed)
                else f"; about {math.ceil(self.seeds_needed)} seeds per rung would decide")
        n = f"{self.n_a} paired seeds" if self.paired else f"n = {self.n_a}/{self.n_b}"
        if self.jumps:
            n += (f" ({self.jumps} of them {'jumps' if self.jumps == 1 else 'jump'} to another state, largest "
                  f"{scale * self.largest_jump:+.2g} {unit})")
        return (f"shift {scale * self.shift:+.2g} +- {scale * self.se:.2g} {unit} (95 % bound {scale * self.bound:.3g} "
                f"{unit}), resolution {scale * self.resolution:.3g} {unit}, {ad_text(self.p_ad)}, {n}: "
                f"{self.verdict} {scale * self.tolerance:.3g} {unit}{tolerance_note}{need}")


def ad_text(p: float) -> str:
    """'AD p = 0.013', or 'AD p >= 0.25' / 'AD p <= 0.001' at the ends scipy clips the p-value to."""
    if p >= AD_P_MAX and p < 1.0:
        return f"AD p >= {AD_P_MAX:g}"
    if p <= AD_P_MIN:
        return f"AD p <= {AD_P_MIN:g}"
    return f"AD p = {p:.3g}"


def anderson_p(a: np.ndarray, b: np.ndarray) -> float:
    """The AD k-sample p-value of two samples (1 where both are one constant value)."""
    from scipy.stats import anderson_ksamp

    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if np.ptp(np.concatenate([a, b])) == 0.0:
        return 1.0
    with warnings.catch_warnings():     # scipy warns when it floors or caps the p-value
        warnings.simplefilter("ignore")
        return float(anderson_ksamp([a, b]).pvalue)


def decide(shift: float, se: float, dof: float, tolerance: float) -> str:
    """WITHIN, BEYOND or UNDECIDED of a relative shift with standard error ``se`` (``dof`` degrees
    of freedom) against ``tolerance`` (module docstring)."""
    t_alpha, t_power = t_quantiles(dof)
    if abs(shift) - t_alpha * se > tolerance:
        return BEYOND
    if abs(shift) + t_alpha * se <= tolerance and (t_alpha + t_power) * se <= tolerance:
        return WITHIN
    return UNDECIDED


def compare(a, b, tolerance: float, paired: bool = False) -> Comparison:
    """Ensemble a (publication rung) against b (finer rung), relative to b (module docstring).
    Needs at least two values in each; ``paired``: a[i] and b[i] are one seed (equal sizes)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if a.size < 2 or b.size < 2:
        raise ValueError(f"compare needs at least two values per ensemble, got {a.size} and {b.size}")
    if paired and a.size != b.size:
        raise ValueError(f"compare: paired ensembles need one value per seed in each, got {a.size} and {b.size}")
    if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
        raise ValueError("compare: non-finite values in an ensemble")
    ma, mb = float(a.mean()), float(b.mean())
    if mb == 0.0:
        raise ValueError("compare: the finer ensemble's mean is 0; a relative shift is not defined")
    ratio = ma / mb
    jumps, largest = 0, 0.0
    if paired:
        se = float(np.std(a - ratio * b, ddof=1)) / math.sqrt(a.size) / abs(mb)
        dof = float(a.size - 1)
        jumps, largest = seed_jumps((a - b) / abs(mb))
    else:
        va, vb = a.var(ddof=1) / a.size, ratio**2 * b.var(ddof=1) / b.size
        se = math.sqrt(va + vb) / abs(mb)
        # Welch-Satterthwaite; two constant ensembles have no spread to estimate: the normal limit
        dof = (va + vb) ** 2 / (va**2 / (a.size - 1) + vb**2 / (b.size - 1)) if va + vb > 0 else math.inf
    t_alpha, t_power = t_quantiles(dof)
    shift = ratio - 1.0
    resolution = (t_alpha + t_power) * se
    n = max(a.size, b.size)
    verdict, need = decide(shift, se, dof, tolerance), 0.0
    if verdict == UNDECIDED:
        # seeds that would decide, with the large-sample factors (a larger ensemble has them)
        margin = tolerance - abs(shift)
        if margin > 0:
            need = n * max((Z_ALPHA * se / margin) ** 2, ((Z_ALPHA + Z_POWER) * se / tolerance) ** 2)
        elif margin < 0:
            need = n * (Z_ALPHA * se / margin) ** 2
        else:
            need = math.inf
    return Comparison(int(a.size), int(b.size), ma, mb, shift, se, resolution, anderson_p(a, b), verdict,
                      float(tolerance), need, bool(paired), float(dof), jumps, largest)


#: a paired difference this many robust standard deviations (1.4826 MAD) from the median is a jump
JUMP_SIGMAS = 5.0
#: ... and at least this far from it, relative to the mean: neighbouring equilibria of a frictional
#: rod differ by per cents, while rungs of a converged ladder (tol, k_ph) differ seed by seed by
#: 1e-5 of the mean or less, whose outliers are the equilibrium test's resolution, not a new state
JUMP_FLOOR = 1e-3


def seed_jumps(d: np.ndarray) -> tuple[int, float]:
    """(count, largest) of the paired differences d (relative to the mean) that are outliers:
    further than JUMP_SIGMAS robust standard deviations and than JUMP_FLOOR from their median, the
    seeds that moved to another equilibrium rather than shifted with the rest. The largest is the
    outlier furthest from the median, with its sign."""
    d = np.asarray(d, dtype=float)
    dev = d - np.median(d)
    mad = 1.4826 * float(np.median(np.abs(dev)))
    out = (np.abs(dev) > JUMP_SIGMAS * mad) & (np.abs(dev) > JUMP_FLOOR)
    if not out.any():
        return 0, 0.0
    i = int(np.argmax(np.where(out, np.abs(dev), -1.0)))
    return int(out.sum()), float(d[i])
