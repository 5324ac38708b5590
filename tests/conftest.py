import os

os.environ.setdefault("MPLBACKEND", "Agg")   # the package forces no backend; the tests draw to files

import numpy as np
import pytest

from confined_rod import Scene


@pytest.fixture
def rng():
    return np.random.default_rng(12345)


def random_state(scene: Scene, rng, lateral=0.95, wiggle=0.15):
    """A bent rod whose ends partly penetrate the wall (so every force term is active)."""
    N = scene.N
    s = (np.arange(N) + 0.5) * scene.l0
    phase = 0.6 * s
    r = np.stack([lateral * scene.R * np.cos(phase), lateral * scene.R * np.sin(phase), 0.97 * s], axis=1)
    r += rng.normal(scale=wiggle * scene.l0, size=r.shape)
    t = np.gradient(r, axis=0)
    t += rng.normal(scale=0.2, size=t.shape)
    t /= np.linalg.norm(t, axis=1)[:, None]
    return np.ascontiguousarray(r), np.ascontiguousarray(t)
