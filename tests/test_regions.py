"""Measures that read positions along the rod, on constructed rods whose answer is known.

In every dataset link 0 and s = 0 are the loaded end; these rods are built so that the
loaded end and the support differ (tip and lower regions of different lengths, detached
lengths that differ at the two ends), so a measure that reads the wrong end fails.
"""
from __future__ import annotations

import numpy as np
import pytest

from confined_rod.analysis import measure, regions

from .shapes import PROFILE as _P
from .shapes import profile_rod as constructed

L, L0, R, EI, K_FR, LOAD = (_P[k] for k in ("L", "l0", "R", "EI", "k_fr", "load"))
N = int(L / L0)


def test_regions_are_found_where_they_were_built():
    ds, rate = constructed(tip_end=6.0, bulk_end=70.0)
    a = regions.analyse(ds)
    # boundaries within half a smoothing window (the running mean shifts them by up to that)
    half_window = 0.5 * regions.WINDOW_R * R
    assert a.regions.has_bulk
    assert abs(a.regions.s_bulk_start - 6.0) <= half_window + L0
    assert abs(a.regions.s_bulk_end - 70.0) <= half_window + L0
    assert a.regions.tip_length < a.regions.lower_length     # which end is which
    assert a.regions.lower_length == pytest.approx(30.0, abs=half_window + L0)
    # 1/|F| is exactly linear in the bulk: the fitted rate is the built one to round-off
    assert a.bulk.rate == pytest.approx(rate, rel=1e-6)
    assert a.bulk.err < 1e-6 * rate
    assert a.model == pytest.approx(rate)
    assert a.paper == pytest.approx(2 * rate)
    # over the whole contact stretch the flat lower region pulls the slope down
    assert a.whole.rate < 0.9 * rate


def test_regions_mirror_reads_the_loaded_end():
    """A short bulk near the support: the tip region is now the long one."""
    ds, _ = constructed(tip_end=40.0, bulk_end=90.0, tip_contacts=(3, 20, 50))
    reg = regions.analyse(ds).regions
    assert reg.has_bulk and reg.tip_length > reg.lower_length
    assert reg.s_bulk_start == pytest.approx(40.0, abs=0.5 * regions.WINDOW_R + L0)


def test_no_bulk_when_friction_is_azimuthal_or_stuck():
    ds, _ = constructed()
    ds["friction_z"] = ds["friction_z"] * 0.2         # friction mostly azimuthal: q <= 0.2 everywhere
    a = regions.analyse(ds)
    assert not a.regions.has_bulk and a.bulk is None
    assert a.regions.tip_length == L


def test_decay_rate_window_effect():
    """A profile whose local rate changes within the window: the uncertainty is the
    difference of the halves, not the (small) standard error of the straight line."""
    s = np.linspace(0, 50, 101)
    rate = np.where(s < 25, 0.2, 0.1)
    inv = 4.0 + np.concatenate([[0.0], np.cumsum(rate[:-1] * np.diff(s))])
    d = regions.decay_rate(s, 1.0 / inv, 0.0, 50.0)
    assert d.halves[0] == pytest.approx(0.2, rel=0.02) and d.halves[1] == pytest.approx(0.1, rel=0.02)
    assert d.err == pytest.approx(0.05, rel=0.05)
    assert 0.1 < d.rate < 0.2


def test_contact_range_skips_the_isolated_tip_contacts():
    """The end links of a buckled rod touch the wall: the contact stretch that the fits use
    starts at the first run of links on the wall (s = 6 R), not at the tip contact of link 1
    (s = 0.5 R), and ends 15 R above the support, not at the last link."""
    ds, _ = constructed(tip_end=6.0, detached_bottom=15.0)
    contact = ds["contact"].values.copy()
    contact[-1] = 1                                  # the support end touches the wall too
    ds["contact"] = ("s_link", contact)
    s_h, s_e = measure.contact_range(ds)
    assert s_h == pytest.approx(6.0, abs=L0)
    assert s_e == pytest.approx(L - 15.0, abs=L0)


def test_contact_range_of_a_rod_without_a_run_on_the_wall():
    """A planar rod touching the wall at three isolated links: first to last contact; no
    contact: (L, L)."""
    ds, _ = constructed()
    contact = np.zeros(N, dtype=np.int8)
    contact[[10, 60, 150]] = 1
    ds["contact"] = ("s_link", contact)
    assert measure.contact_range(ds) == pytest.approx((10 * L0, 151 * L0))
    ds["contact"] = ("s_link", np.zeros(N, dtype=np.int8))
    assert measure.contact_range(ds) == (L, L)


def test_smooth_is_a_running_mean():
    x = np.zeros(20)
    x[10] = 1.0
    y = regions.smooth(x, 5)
    assert y.sum() == pytest.approx(1.0, abs=0.41)     # shrinking window at the ends: interior exact
    assert y[8:13].tolist() == pytest.approx([0.2] * 5)
    assert np.all(y[:8] == 0) and np.all(y[13:] == 0)


def test_detached_lengths_read_each_end():
    """First long run of contacts starts at s = 6 R (isolated tip contacts at links 1 and 7 do
    not count); the last ends 15 R above the support."""
    ds, _ = constructed(tip_end=6.0, detached_bottom=15.0)
    top, bottom = measure.detached_lengths(ds)
    assert top == pytest.approx(6.0, abs=L0)
    assert bottom == pytest.approx(15.0, abs=L0)
    assert top != pytest.approx(bottom, abs=1.0)


def test_force_parts_split_the_inverse_force_by_region_from_the_loaded_end():
    """A constructed helix detached over its first 10 R (|F_z| = load, link 0 at the loaded end), on
    the wall with d(1/|F_z|)/ds = rate exactly, detached again over its last 20 R: the parts sum to
    1/|F(L)| - 1/|F(0)|, and each is the rate times the stretch of helix inside its region (the bulk
    boundaries may sit a little inside or outside the helix; a stretch of helix outside the bulk counts
    to its region at the same rate)."""
    from .shapes import prescribed_helix

    ds = prescribed_helix(L=100.0, tip=10.0, bottom=20.0, c_K=1.1, k_fr=0.8)
    a = regions.analyse(ds)
    parts = regions.force_parts(ds, a)
    F = np.abs(ds["F_z"].values)
    rate = 1.1 * 0.8 / 4.0
    assert sum(parts.values()) == pytest.approx(1 / F[-1] - 1 / F[0], rel=1e-12)
    on_start, on_end = 10.0, 80.0
    sb, se = a.regions.s_bulk_start, a.regions.s_bulk_end
    # 1/|F_z| is linear in s on the helix and flat off it, so interpolation between joints is exact
    assert parts["tip"] == pytest.approx(rate * max(0.0, sb - on_start), abs=1e-9)
    assert parts["bulk"] == pytest.approx(rate * (min(se, on_end) - max(sb, on_start)), rel=1e-9)
    assert parts["lower"] == pytest.approx(rate * max(0.0, on_end - se), abs=1e-9)
    assert parts["bulk"] > 10 * (parts["tip"] + parts["lower"])
    assert regions.force_parts(prescribed_helix(tip=97.0)) is None


def test_friction_use_is_the_force_weighted_share_of_the_coulomb_limit():
    """The constructed rod slides axially at the Coulomb limit in its tip and bulk (use 1) and
    carries q_lower of the limit in its lower region; link ends that touch the wall lightly with
    no axial friction (a contact resolved by more link ends) barely move the force-weighted share
    while the per-link mean q halves."""
    ds, _ = constructed(tip_end=6.0, bulk_end=70.0, q_lower=0.3)
    a = regions.analyse(ds)
    # the detected bulk ends within half a window of the built one, so it may hold a few lower links
    # (q 0.3 at a small normal force): 1 to within 2 %
    assert regions.friction_use(ds, "bulk", a) == pytest.approx(1.0, abs=0.02)
    assert regions.friction_use(ds, "lower", a) == pytest.approx(0.3, rel=1e-9)
    lower = np.flatnonzero(a.regions.of_links(ds["s_link"].values) == 2)
    light = ds.copy(deep=True)
    light["wall_force"].values[lower[1::2]] *= 1e-3        # every other link end barely touches ...
    light["friction_z"].values[lower[1::2]] = 0.0          # ... and carries no axial friction
    assert regions.friction_use(light, "lower", a) == pytest.approx(0.3, rel=2e-3)
    q = regions.axial_utilisation(light["contact"].values, light["wall_force"].values, light["friction_z"].values,
                                  K_FR, 0.0)
    assert q[lower].mean() == pytest.approx(0.15, rel=0.05)
    ds["friction_z"] = ds["friction_z"] * 0.2              # no bulk: nothing to split
    assert regions.friction_use(ds, "lower") is None
