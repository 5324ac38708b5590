"""Local relations (analysis/local_relations.py) read back from constructed helices whose
decay rate, wall force and pitch rate are prescribed (link 0 and s = 0 at the loaded end)."""
import pytest

from confined_rod.analysis import local_relations as LR

from .shapes import prescribed_helix as constructed_helix


def test_frictional_helix_reads_back_what_it_was_built_with():
    ds = constructed_helix()
    got = LR.measure(ds)
    # the decay rate is exact per link (1/F linear in s); the bulk fit's window edges cost nothing
    assert got["decay_ratio"] == pytest.approx(1.1, rel=1e-6)
    # K/(R F^2/4EI) = c_K with F at the link centre: the mean of the joints, off by (dF/F)^2 ~ 1e-5
    assert got["wall_force_ratio"] == pytest.approx(1.1, rel=1e-4)
    assert got["pitch_ratio"] == pytest.approx(0.95, rel=1e-6)


def test_regular_helix_is_the_bulk_from_the_loaded_end():
    """The detached tip at s < 4 R (link 0 at the loaded end) and a detached stretch at the support
    are not regular helix; the regular links start half a smoothing window into the bulk."""
    ds = constructed_helix(tip=10.0, bottom=20.0)
    idx = LR.regular_links(ds)
    s = ds.s_link.values[idx]
    assert s.min() >= 10.0 and s.max() <= 80.0
    assert s.min() == pytest.approx(10.0 + 2.0, abs=0.5 + 1e-9)


def test_frictionless_middle_half():
    ds = constructed_helix(k_fr=0.0, c_K=0.9, c_w=1.02, tip=10.0, L=90.0)
    got = LR.measure(ds)
    assert got["decay_ratio"] is None
    assert got["wall_force_ratio"] == pytest.approx(0.9, rel=1e-9)
    assert got["pitch_ratio"] == pytest.approx(1.02, rel=1e-9)
    idx = LR.regular_links(ds)
    s = ds.s_link.values[idx]
    assert s.min() == pytest.approx(10 + 80 / 4, abs=0.5) and s.max() == pytest.approx(90 - 80 / 4, abs=0.5)


def test_no_helix_no_relation():
    ds = constructed_helix(tip=97.0)
    assert LR.measure(ds) == {"decay_ratio": None, "wall_force_ratio": None, "pitch_ratio": None}
