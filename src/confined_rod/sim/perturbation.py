"""The random lateral perturbation of a start: one continuous function of the arc length.

A seed picks a smooth random rod, not a random value per link. The lateral displacement is

    d(z) = a/3 * f(z) / rms(f),   f(z) = sum_{n=1}^{M} c_n sin(n pi z / L + phi_n),

z the height along the straight rod from the support (0 <= z <= L; the simulator's link 0 is at
the support, while the datasets count s from the loaded end),

with c_n standard normal, phi_n uniform in [0, 2 pi), M = floor(2 L / LAMBDA_MIN) modes (the
shortest wavelength LAMBDA_MIN R, set by R and L, never by l0), rms(f) = sqrt(sum c_n^2 / 2) the
continuum root mean square (cross terms dropped), and |d| clipped at the amplitude a. The links
sample d at their own heights, so the starts of one seed at l0 and at l0/2 agree at the heights
both have (tests/test_perturbation.py): a ladder in l0 starts every rung from the same
continuous rod and its rungs pair by seed.

Why: a value per link (white noise of amplitude a) has a spectrum that depends on l0. Its
power per unit wavenumber at the wavelengths that buckle (~10 R) scales as a^2 l0, so a finer
rod was kicked ~sqrt(l0) more weakly where it matters, and "seed 3" at two link lengths were two
unrelated starts (issue 43: the l0 ladder drifted monotonically). Here the spectrum is a property
of the seed and R: white up to wavenumber 2 pi/LAMBDA_MIN and zero above it.

Streams: each use of a seed draws from its own stream (``default_rng([seed, stream])``), so
that the start, the second-stage kick of planar_then_3d and the nudges of a load path are
independent functions.
"""
from __future__ import annotations

import numpy as np

#: shortest wavelength of the perturbation, in units of R: resolved by four links of the
#: coarsest l0 a ladder uses (1 R), and below the buckling wavelengths of every load the paper
#: uses (the helix's pitch 2 pi sqrt(2 EI/F) is 12.6 R at F = 0.5 EI/R^2)
LAMBDA_MIN = 4.0
#: root mean square of d over its clipping amplitude (clipping then touches about 0.3 % of a
#: Gaussian rod)
RMS_OF_AMPLITUDE = 1.0 / 3.0
#: the streams of one seed (a new use appends its own)
START, KICK, NUDGE, SADDLE = 0, 1, 2, 3


def n_modes(L: float, R: float) -> int:
    """M = floor(2 L / (LAMBDA_MIN R)), at least 1."""
    return max(1, int(2.0 * L / (LAMBDA_MIN * R)))


def modes(seed: int | list[int], L: float, R: float, components: int = 2,
          stream: int = START) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(wavenumbers q_n (M,), amplitudes c_n (M, components), phases phi_n (M, components)) of a
    seed's function; ``seed`` may be a list (a seed and a sub-stream, e.g. the step of a load path)."""
    key = [*seed, stream] if isinstance(seed, (list, tuple)) else [int(seed), stream]
    rng = np.random.default_rng(key)
    M = n_modes(L, R)
    c = rng.standard_normal((M, components))
    phi = rng.uniform(0.0, 2.0 * np.pi, size=(M, components))
    return np.arange(1, M + 1) * np.pi / L, c, phi


def lateral(z: np.ndarray, L: float, R: float, amplitude: float, seed: int | list[int],
            components: int = 2, stream: int = START) -> np.ndarray:
    """d(z) (len(z), components): the seed's lateral displacement at the heights z along the
    straight rod (from the support, 0 <= z <= L), root mean square amplitude/3, clipped at
    +-amplitude."""
    q, c, phi = modes(seed, L, R, components, stream)
    z = np.asarray(z, dtype=float)
    out = np.empty((z.size, components))
    rms = np.sqrt(0.5 * np.sum(c * c, axis=0))
    for j in range(components):
        out[:, j] = np.sin(np.outer(z, q) + phi[:, j]) @ c[:, j]
    out *= amplitude * RMS_OF_AMPLITUDE / rms
    return np.clip(out, -amplitude, amplitude)


def lateral_twin(z: np.ndarray, L: float, R: float, amplitude: float, seed: int,
                 components: int = 2, stream: int = START) -> np.ndarray:
    """Plain-loop twin of :func:`lateral` (one point, one mode at a time), for the tests."""
    q, c, phi = modes(seed, L, R, components, stream)
    out = np.zeros((len(z), components))
    for j in range(components):
        rms = np.sqrt(sum(0.5 * c[n, j] ** 2 for n in range(len(q))))
        for i, zi in enumerate(z):
            v = sum(c[n, j] * np.sin(q[n] * zi + phi[n, j]) for n in range(len(q)))
            out[i, j] = min(max(v * amplitude * RMS_OF_AMPLITUDE / rms, -amplitude), amplitude)
    return out
