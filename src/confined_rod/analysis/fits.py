"""Least-squares fits of force profiles: f(s) = A (l0' + s)^c (the paper's Figs 4 and 7).

The fit minimises the *relative* residual (f - F)/F: the profile spans up to a
decade, and a relative criterion weighs the weak far end as much as the loaded
end.  The uncertainties are the standard errors from the covariance of the
Gauss-Newton fit, scaled by the residual variance (scipy's ``curve_fit`` with
``absolute_sigma=False``).  The residuals of a simulated profile are not random
noise but systematic model misfit, so these errors say how well determined the
parameters are by the data, not a statistical confidence level; the correlation
between A, l0' and c is large, so the covariance is stored as well.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import curve_fit

PARAMS = ("A", "l0_fit", "c")


C_BOUND = 10.0          # the fit keeps |c| <= C_BOUND; a fit at the bound has not found an exponent
DEGENERATE_FALL = 2.0   # a 3-parameter power law fitted where F falls by less than this is not determined


def undetermined(c: float, fall: float, fall_min: float = DEGENERATE_FALL) -> str:
    """Why a fit of exponent c over a window where the profile falls by the factor `fall` does
    not determine c ('' if it does): over a fall of less than fall_min any smooth decreasing
    curve fits with some (A, l0', c) (the three are degenerate), and a fit stopped at the bound
    of c has found no exponent. The formal errors do not show either: they are small along the
    degenerate valley."""
    if fall < fall_min:
        return f"|F_z| falls only {fall:.3g}x"
    if abs(c) >= C_BOUND * (1 - 1e-6):
        return f"c at the fit's bound {-C_BOUND:g}" if c < 0 else f"c at the fit's bound {C_BOUND:g}"
    return ""


def determined(c: np.ndarray, fall: np.ndarray, has: np.ndarray, fall_min: float = DEGENERATE_FALL) -> np.ndarray:
    """Where a fit exists (has == 1) and determines its exponent c (undetermined), elementwise:
    the members of a seed ensemble whose exponents its statistics may use."""
    return np.vectorize(lambda ci, fi, hi: bool(hi) and not undetermined(ci, fi, fall_min), otypes=[bool])(c, fall, has)


class FitError(RuntimeError):
    """A fit that cannot be done (too few points, no convergence)."""


@dataclass(frozen=True)
class PowerLawFit:
    A: float
    l0_fit: float  # the paper's l0' (not the link length)
    c: float
    errors: tuple[float, float, float]
    covariance: np.ndarray  # (3, 3) in the order A, l0_fit, c
    rms_relative_residual: float
    n_points: int

    def __call__(self, s):
        return power_law(np.asarray(s, dtype=float), self.A, self.l0_fit, self.c)


def power_law(s, A, l0p, c):
    return A * (l0p + s) ** c


def fit_power_law(s: np.ndarray, F: np.ndarray, *, guess: tuple[float, float, float]) -> PowerLawFit:
    """Fit F(s) = A (l0' + s)^c with A > 0, l0' > 0 (so f is defined for every s >= 0).

    ``guess`` = (A, l0', c), e.g. from the simple model: (4EI/(k_fr R), -l_c, -1)."""
    s = np.asarray(s, dtype=float)
    F = np.asarray(F, dtype=float)
    if s.shape != F.shape or s.ndim != 1:
        raise FitError(f"s and F must be 1-D arrays of equal length, got shapes {s.shape} and {F.shape}")
    if s.size < 5:
        raise FitError(f"a 3-parameter fit needs at least 5 points, got {s.size}")
    if not (np.all(np.isfinite(s)) and np.all(np.isfinite(F)) and np.all(F > 0)):
        raise FitError("the profile to fit must be finite and positive")
    if np.min(s) < 0:
        raise FitError(f"s must be >= 0, got min {np.min(s)!r}")
    A0, l00, c0 = guess
    try:
        popt, pcov = curve_fit(power_law, s, F, p0=(A0, max(l00, 1e-3), c0), sigma=F, absolute_sigma=False,
                               bounds=([0.0, 0.0, -C_BOUND], [np.inf, np.inf, C_BOUND]), max_nfev=20000)
    except (RuntimeError, ValueError) as e:
        raise FitError(f"power-law fit did not converge: {e}") from e
    if not (np.all(np.isfinite(pcov)) and np.all(np.diag(pcov) > 0)):
        # a parameter not determined by the data (e.g. a profile that does not decay)
        raise FitError(f"power-law fit is degenerate (parameters {popt}); the profile does not determine A, l0', c")
    rel = (power_law(s, *popt) - F) / F
    return PowerLawFit(A=float(popt[0]), l0_fit=float(popt[1]), c=float(popt[2]),
                       errors=tuple(float(e) for e in np.sqrt(np.diag(pcov))), covariance=pcov,
                       rms_relative_residual=float(np.sqrt(np.mean(rel**2))), n_points=int(s.size))
