"""The start's perturbation is one continuous random rod per seed (sim/perturbation.py): the
same at every l0 where the links share a height, with the stated amplitude and spectrum."""
import numpy as np
import pytest

from confined_rod.sim import perturbation as P
from confined_rod.sim.scenes import Scene


@pytest.mark.parametrize("protocol", ["straight", "ramp", "planar"])
def test_start_at_l0_and_half_agree_at_shared_heights(protocol):
    """Link centres at l0 sit at z = (i + 1/2) l0, those at l0/2 at z = (i + 1/2) l0/2: the
    midpoint of fine links 2i and 2i + 1 is the coarse centre i. Linear interpolation over the
    spacing h = l0/2 errs by at most h^2/8 max|d''|, and a sum of sines with wavenumbers up to
    q_max has max|d''| <= q_max^2 max|d| (Bernstein's inequality): h^2 q_max^2/8 = 0.019 of the
    largest displacement, which the clipping keeps near the amplitude a; 0.03 a allows for it."""
    a = Scene(L=40, l0=0.5, seed=3, protocol=protocol)
    b = Scene(L=40, l0=0.25, seed=3, protocol=protocol)
    ra, _ = a.initial_state()
    rb, _ = b.initial_state()
    mid = 0.5 * (rb[0::2, :2] + rb[1::2, :2])
    q_max = 2 * np.pi / P.LAMBDA_MIN
    assert (0.25**2 / 8) * q_max**2 < 0.02
    assert np.max(np.abs(mid - ra[:, :2])) <= 0.03 * a.perturbation
    assert np.max(np.abs(ra[:, :2])) > 0.3 * a.perturbation      # not vanishing
    # exactly equal where the heights coincide
    z = np.array([0.75, 10.25, 39.75])
    assert np.array_equal(P.lateral(z, 40, 1, 1e-3, 3), P.lateral(z.copy(), 40, 1, 1e-3, 3))


def test_seed_pairs_across_l0_white_noise_would_not():
    """Two rungs of one seed are nearly the same rod (correlation ~1), two seeds are not."""
    ra, _ = Scene(L=80, l0=1.0, seed=5).initial_state()
    rb, _ = Scene(L=80, l0=0.125, seed=5).initial_state()
    rc, _ = Scene(L=80, l0=1.0, seed=6).initial_state()
    zb = rb[:, 2]
    xb_at_a = np.interp(ra[:, 2], zb, rb[:, 0])
    assert np.corrcoef(ra[:, 0], xb_at_a)[0, 1] > 0.99
    assert abs(np.corrcoef(ra[:, 0], rc[:, 0])[0, 1]) < 0.5


def test_amplitude_spectrum_and_twin():
    z = np.linspace(0, 320, 6401)
    d = P.lateral(z, 320, 1.0, 1e-3, 11)
    assert np.all(np.abs(d) <= 1e-3)
    rms = np.sqrt(np.mean(d**2, axis=0))
    # continuum rms a/3, cross terms of M = 160 random modes average out to ~1/sqrt(M)
    assert np.allclose(rms, 1e-3 / 3, rtol=0.2)
    # no power above the shortest wavelength: the spectrum beyond 2 pi/LAMBDA_MIN is round-off
    spec = np.abs(np.fft.rfft(d[:, 0]))
    k = 2 * np.pi * np.fft.rfftfreq(z.size, z[1] - z[0])
    assert spec[k > 1.2 * 2 * np.pi / P.LAMBDA_MIN].max() < 0.05 * spec.max()
    # the plain-loop twin
    zs = np.array([0.0, 1.3, 77.7, 320.0])
    assert np.allclose(P.lateral(zs, 320, 1.0, 1e-3, 11), P.lateral_twin(zs, 320, 1.0, 1e-3, 11), rtol=1e-12,
                       atol=1e-18)


def test_streams_and_steps_are_independent():
    z = np.linspace(0, 40, 81)
    a = P.lateral(z, 40, 1, 1e-3, 2)
    b = P.lateral(z, 40, 1, 1e-3, 2, stream=P.KICK)
    c = P.lateral(z, 40, 1, 1e-3, [2, 7], stream=P.NUDGE)
    assert abs(np.corrcoef(a[:, 0], b[:, 0])[0, 1]) < 0.6 and abs(np.corrcoef(a[:, 0], c[:, 0])[0, 1]) < 0.6


def test_helix_start_stays_inside_the_wall():
    sc = Scene(L=40, l0=0.5, seed=4, protocol="helix", load=0.25, perturbation=0.01)
    r, t = sc.initial_state()
    ends = np.vstack([r - 0.25 * t, r[-1:] + 0.25 * t[-1:]])
    assert np.hypot(ends[:, 0], ends[:, 1]).max() <= sc.R
    assert np.allclose(np.linalg.norm(t, axis=1), 1.0)
