"""Measures that read positions along the rod, on constructed rods whose answer is known.

In every dataset link 0 and s = 0 are the loaded end; these rods are built so that the
loaded end and the support differ (tip and lower regions of different lengths, detached
lengths that differ at the two ends), so a measure that reads the wrong end fails.
"""
from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from confined_rod import measure, regions

L, L0, R, EI, K_FR, LOAD = 100.0, 0.5, 1.0, 1.0, 0.8, 0.25
N = int(L / L0)


def constructed(tip_end=6.0, bulk_end=70.0, q_lower=0.1, tip_contacts=(1, 7), detached_bottom=None):
    """A rod with a tip (0 <= s < tip_end: isolated contacts, friction axial at the limit there),
    a bulk (tip_end <= s <= bulk_end: every link on the wall, sliding axially at the Coulomb
    limit, 1/|F| linear in s with the corrected slope) and a lower region (on the wall, axial
    friction q_lower of the limit, so |F| falls slowly). Friction and F_z are consistent:
    |F_z| falls along s by the axial friction of each link."""
    s = np.arange(N + 1) * L0
    s_link = (np.arange(N) + 0.5) * L0
    contact = np.zeros(N, dtype=np.int8)
    contact[list(tip_contacts)] = 1
    contact[(s_link >= tip_end) & (s_link <= L)] = 1
    if detached_bottom is not None:
        contact[s_link > L - detached_bottom] = 0
    rate = K_FR * R / (4 * EI)
    F_tip = 0.2                                       # after the tip drop
    F = np.empty(N + 1)
    F[0] = LOAD
    fz = np.zeros(N)
    # the tip: the contacts carry the drop from LOAD to F_tip
    tips = [i for i in tip_contacts]
    for i in range(N):
        if s_link[i] < tip_end:
            fz[i] = (LOAD - F_tip) / len(tips) if i in tips else 0.0
        elif s_link[i] <= bulk_end:
            F_here = F[i]
            fz[i] = F_here - 1.0 / (1.0 / F_here + rate * L0)
        else:
            fz[i] = q_lower * 1e-3
        F[i + 1] = F[i] - fz[i]
    # wall force: in the tip and bulk the friction is at its limit (fz = k_fr N);
    # in the lower region N is that of the bulk's end and fz a share q_lower of k_fr N
    N_w = np.where(contact == 1, np.where(s_link <= bulk_end, fz / K_FR, 1e-3 / K_FR), 0.0)
    ds = xr.Dataset(
        {"F_z": (("joint",), -F), "contact": (("link",), contact), "wall_force": (("link",), N_w),
         "friction_z": (("link",), fz * (contact == 1)), "friction_force": (("link",), fz * (contact == 1))},
        coords={"s": (("joint",), s), "s_link": (("link",), s_link)},
        attrs={"L": L, "l0": L0, "R": R, "EI": EI, "k_fr": K_FR, "friction_cap": 0.0, "load": LOAD})
    return ds, rate


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
