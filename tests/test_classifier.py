"""The final-state classifier (ensembles.final_class) on constructed shapes: it reads the
geometry of the whole rod (spread across the pore along both principal axes, winding of the
off-axis links, reversals of handedness), not the turns of the wall-contact stretch."""
from __future__ import annotations

import numpy as np
import pytest

from confined_rod.analysis import ensembles

from . import shapes


def test_a_planar_zigzag_touching_both_walls_is_planar():
    ds = shapes.planar_zigzag(L=20.0, half_waves=4)
    assert ds["contact"].values.sum() >= 8 and ds["x"].values.min() < -0.9 < 0.9 < ds["x"].values.max()
    sh = ensembles.shape(ds)
    assert sh.spread_min < 1e-12 and sh.spread_max > 0.6 and sh.deflection > 0.9
    assert ensembles.final_class(ds) == "planar"


def test_a_planar_shape_stays_planar_with_the_bow_friction_locks_in():
    # an out-of-plane bow of 0.03 R (docs/model.md: the frictional S of L = 20 R, seed 0)
    ds = shapes.planar_zigzag(L=20.0, bow=0.03)
    assert 0.0 < ensembles.shape(ds).spread_min < ensembles.PLANAR_RMS
    assert ensembles.final_class(ds) == "planar"


@pytest.mark.parametrize("angle", [0.3, 0.7, np.pi / 4, 2.1, -1.0])
def test_the_principal_axes_make_the_classes_rotation_invariant(angle):
    """A planar shape tilted about the axis (its plane no longer x-z) is still planar, and
    every measure of every shape is unchanged by the rotation."""
    for make in (lambda a: shapes.planar_zigzag(angle=a, bow=0.03), lambda a: shapes.helix(angle=a),
                 lambda a: shapes.helix(reverse_at=20.0, angle=a), lambda a: shapes.straight(angle=a)):
        ref, rot = ensembles.shape(make(0.0)), ensembles.shape(make(angle))
        for f in ("deflection", "spread_min", "spread_max", "net_turns", "total_turns"):
            assert getattr(rot, f) == pytest.approx(getattr(ref, f), rel=1e-9, abs=1e-12), f
        np.testing.assert_allclose(rot.reversals, ref.reversals)
        assert ensembles.final_class(make(angle)) == ensembles.final_class(make(0.0))
    assert ensembles.final_class(shapes.planar_zigzag(angle=angle)) == "planar"
    # the tilted plane is not x-z: both x and y vary across the pore, only the principal axes see it flat
    ds = shapes.planar_zigzag(angle=angle)
    assert min(np.ptp(ds["x"].values), np.ptp(ds["y"].values)) > 0.3


@pytest.mark.parametrize("omega", [0.4, -0.4])
def test_a_one_handed_helix_of_several_turns_is_a_helix(omega):
    ds = shapes.helix(L=40.0, omega=omega, tips=2.0)      # detached tips run in towards the axis
    sh = ensembles.shape(ds)
    assert sh.spread_min > 0.6 and sh.reversals.size == 0
    assert sh.net_turns == pytest.approx(sh.total_turns) and 2.0 < sh.net_turns < 2.6
    assert ensembles.final_class(ds) == "helix"


def test_a_short_helix_of_about_one_turn_is_a_helix():
    """L = 20 R at the paper's load: one turn takes 17 R of arc."""
    ds = shapes.helix(L=20.0, omega=0.37, tips=1.0)
    assert 0.9 < ensembles.shape(ds).net_turns < 1.2
    assert ensembles.final_class(ds) == "helix"


def test_a_helix_with_one_reversal_in_the_middle_has_a_defect():
    ds = shapes.helix(L=40.0, omega=0.4, reverse_at=20.0)
    sh = ensembles.shape(ds)
    assert sh.reversals.tolist() == pytest.approx([20.0], abs=0.5)     # s from the loaded end
    assert sh.net_turns < 0.1 < 2.0 < sh.total_turns                     # the two senses cancel
    assert ensembles.final_class(ds) == "defects"
    # a reversal off the middle is found where it is, s measured from the loaded end (link 0)
    flipped = shapes.helix(L=40.0, omega=0.4, reverse_at=12.0)
    assert ensembles.shape(flipped).reversals.tolist() == pytest.approx([12.0], abs=0.5)


def test_a_flicker_of_the_sense_over_fewer_than_three_links_is_no_defect():
    ds = shapes.helix(L=40.0, omega=0.4, tips=0.0)
    phi = np.arctan2(ds["y"].values, ds["x"].values)
    # two links turned back by twice their step: the sense flips over two increments only
    i = 40
    phi[i:i + 2] -= 2 * 0.4 * shapes.L0
    ds["x"].values[:], ds["y"].values[:] = np.cos(phi), np.sin(phi)
    assert ensembles.shape(ds).reversals.size == 0 and ensembles.final_class(ds) == "helix"


@pytest.mark.parametrize("angle", [0.0, 1.1])
def test_a_straight_rod_across_the_pore_is_straight(angle):
    ds = shapes.straight(L=20.0, tilt=0.9, angle=angle)
    sh = ensembles.shape(ds)
    assert sh.deflection < 1e-3 and sh.spread_max > 0.4          # diagonal across the pore, yet unbuckled
    assert ensembles.final_class(ds) == "straight"
    assert ensembles.final_class(shapes.straight(L=20.0, tilt=0.0)) == "straight"


def test_a_short_coil_of_about_half_a_turn_between_detached_ends_is_a_helix():
    """An L = 20 R rod at the paper's load coils over ~10 R between ends that run in through the
    axis: about half a turn of one handedness (Fig 6, L = 20 R, seeds 1-3)."""
    ds = shapes.helix(L=20.0, omega=0.3, tips=5.0)
    sh = ensembles.shape(ds)
    assert 0.4 < sh.total_turns < 0.75 and sh.spread_min > ensembles.PLANAR_RMS
    assert np.hypot(ds["x"], ds["y"]).values.min() < ensembles.OFF_AXIS      # the tips reach the axis
    assert ensembles.final_class(ds) == "helix"


@pytest.mark.parametrize("angle", [0.0, 0.8])
def test_a_zigzag_whose_plane_turns_along_the_rod_is_twisted_not_a_helix(angle):
    """Three half-waves across the pore, each in a plane turned by 60 degrees from the last:
    spread in both directions, but the azimuth turns by crossing the axis, not by winding."""
    L = 30.0
    s = shapes.arc(L)
    u = np.clip(1.3 * np.sin(3 * np.pi * s / L), -1.0, 1.0)
    plane = np.pi / 3 * np.floor(3 * s / L)
    x, y = shapes.rotated(u * np.cos(plane), u * np.sin(plane), angle)
    ds = shapes.rod(x, y, 0.97 * (L - s), L=L)
    sh = ensembles.shape(ds)
    assert sh.spread_min > 0.3 and sh.total_turns < 0.1
    assert ensembles.final_class(ds) == "twisted"


def test_the_classes_are_the_member_class_flags():
    assert ensembles.CLASSES[:3] == ("helix", "planar", "defects")     # the codes of earlier datasets
    assert set(ensembles.CLASSES) == {"helix", "planar", "defects", "straight", "twisted"}
    for make in (shapes.planar_zigzag, shapes.helix, shapes.straight,
                 lambda: shapes.helix(reverse_at=20.0)):
        assert ensembles.final_class(make()) in ensembles.CLASSES
