"""Local relations (analysis/local_relations.py) read back from constructed helices whose
decay rate, wall force and pitch rate are prescribed (link 0 and s = 0 at the loaded end)."""
import numpy as np
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
    assert LR.measure(ds) == {"decay_ratio": None, "wall_force_ratio": None, "pitch_ratio": None,
                              "helix_balance": None}


def test_a_stretch_shorter_than_a_turn_is_no_helix():
    """The bulk between a long detached tip (s < 70 R from the loaded end) and a detached stretch
    at the support winds less than a turn: an arc, not a helix, so no relation is read on it; the
    same helix with a bulk of several turns gives them."""
    from confined_rod.analysis import regions

    short = constructed_helix(tip=70.0, bottom=15.0)
    r = regions.analyse(short).regions
    bulk = np.flatnonzero((short.s_link.values >= r.s_bulk_start) & (short.s_link.values <= r.s_bulk_end))
    assert 0.2 < LR.winding_turns(short, bulk) < LR.MIN_TURNS      # an arc of the helix
    assert LR.regular_links(short).size == 0
    assert LR.measure(short) == dict.fromkeys(LR.RELATIONS)    # the decay law is a helix's too
    long = constructed_helix(tip=10.0, bottom=20.0)
    assert LR.winding_turns(long, LR.regular_links(long)) >= 2 * LR.MIN_TURNS
    assert LR.measure(long)["helix_balance"] is not None


def _balance(ds, c_K, c_w):
    """The expected K / (rho w^2 (F/c - EI w^2)) of a constructed helix (rho = R = EI = 1) over its
    regular links: K = c_K F^2/4 at the link's F, w = c_w w(F)."""
    from confined_rod import theory
    from confined_rod.analysis.measure import force_at_links

    F = force_at_links(ds)[LR.regular_links(ds)]
    w = c_w * theory.helix_pitch_rate(F, 1.0, 1.0)
    c = np.sqrt(1 - w**2)
    return np.median(c_K * F**2 / 4 / (w**2 * (F / c - w**2)))


def test_helix_balance_is_one_for_a_torque_free_helix_and_reads_back_any_other():
    """A torque-free helix (w = w(F), K = rho w^2 (F/c - EI w^2) = EI rho w^4) balances exactly:
    built with that K it reads 1 to the joint-averaging of F. Built with another K, it reads the
    ratio the construction implies (the relation is a measure, not a constant)."""
    from confined_rod import theory
    from confined_rod.analysis.measure import force_at_links

    ds = constructed_helix(k_fr=0.0, c_w=1.0, tip=10.0, L=90.0)
    idx = LR.regular_links(ds)
    F = force_at_links(ds)
    w = theory.helix_pitch_rate(F, 1.0, 1.0)
    K = np.where(ds.contact.values == 1, w**4, 0.0)               # EI rho w^4, the torque-free wall force
    ds["wall_force_density"] = ("s_link", K)
    assert LR.measure(ds)["helix_balance"] == pytest.approx(1.0, abs=1e-12)
    other = constructed_helix(k_fr=0.8, c_K=1.1, c_w=0.8)
    # K of the frictional construction is the friction per link over k_fr, c_K R F^2/(4EI) at the
    # joints' mean force up to (dF/F)^2 ~ 1e-5 (as for wall_force_ratio above)
    assert LR.measure(other)["helix_balance"] == pytest.approx(_balance(other, 1.1, 0.8), rel=1e-4)
    assert idx.size >= LR.MIN_LINKS


def test_helix_balance_holds_for_a_helix_with_locked_torque():
    """A helix wound tighter than the torque-free one (w = 1.2 w(F)) carries a torque tau; its
    wall force from the Kirchhoff relations, K = (EI rho^2 w^4 - w tau)/rho with tau =
    rho^2 w (2 EI w^2 - F/c) (analysis/torque.py), balances: the ratio is 1, while the ratio to
    the torque-free wall force R F^2/(4EI) is not."""
    from confined_rod import theory
    from confined_rod.analysis import torque
    from confined_rod.analysis.measure import force_at_links

    ds = constructed_helix(k_fr=0.0, c_w=1.2, tip=10.0, L=90.0)
    F = force_at_links(ds)
    w = 1.2 * theory.helix_pitch_rate(F, 1.0, 1.0)
    tau = torque.helix_torque(np.ones_like(F), w, F, 1.0)
    K = np.where(ds.contact.values == 1, torque.helix_wall_force(1.0, w, tau, 1.0), 0.0)
    ds["wall_force_density"] = ("s_link", K)
    got = LR.measure(ds)
    assert got["helix_balance"] == pytest.approx(1.0, abs=1e-9)
    assert abs(got["wall_force_ratio"] - 1.0) > 0.05


def test_a_simulated_frictionless_helix_balances():
    """The simulator's frictionless wall helix (L/R = 40, load 0.25, publication l0 and k_ph): the
    lateral balance holds to the discretisation (measured 1.004; the links' chords cut the helix
    by about (w l0)^2/12 ~ 3e-3 at w = 0.35/R, so 1.5 % is a bound with room), and its pitch is
    the torque-free one (no friction, no torque)."""
    from confined_rod import Scene, simulate

    got = LR.measure(simulate(Scene(L=40, load=0.25, k_fr=0.0, l0=0.5, k_ph=1e4, tol=1e-5), progress=False))
    assert got["helix_balance"] == pytest.approx(1.0, abs=0.015)
    assert got["pitch_ratio"] == pytest.approx(1.0, abs=0.015)


def test_a_loosely_wound_bulk_is_told_from_a_tight_one_by_its_wall_force():
    """A bulk built with a quarter of the torque-free wall force (c_K 0.25: a locked torque) is
    loosely wound; the torque-free helix (c_K 1.1) and one just above the threshold are not; no
    helix, no answer. Link 0 is at the loaded end: the detached tip does not enter the median."""
    assert LR.loosely_wound(LR.measure(constructed_helix(c_K=0.25))) is True
    assert LR.loosely_wound(LR.measure(constructed_helix(c_K=1.1))) is False
    assert LR.loosely_wound(LR.measure(constructed_helix(c_K=LR.LOOSE_WALL_RATIO * 1.02, tip=30.0))) is False
    assert LR.loosely_wound(LR.measure(constructed_helix(c_K=LR.LOOSE_WALL_RATIO * 0.98, tip=30.0))) is True
    assert LR.loosely_wound(LR.measure(constructed_helix(tip=97.0))) is None
