"""The model at its edges: a free lower end on the floor, nothing holding the rod, and the
axial force balance with a body force and an open entrance (every external force stored)."""
import numpy as np
import pytest

from confined_rod import Scene, simulate
from confined_rod.errors import SceneError


def _lowest_end(ds, l0):
    """z of the lowest link end: the last link in the dataset's order (from the loaded end)."""
    return float(ds.z.values[-1] - 0.5 * l0 * abs(ds.tz.values[-1]))


def test_a_free_lower_end_rests_on_the_floor():
    """lower_end 'free' with the floor: the lowest end is a link end like any other, held by
    the floor's penalty, so it sits at most a few F/k_w below z = 0 (before the fix it was exempt
    and sank 0.44-0.48 R, and the run blamed k_w). The rod then carries the load to the floor:
    F_transmitted = load - sum f_z."""
    sc = Scene(name="free", L=20, load=0.25, k_fr=0.3, lower_end="free", l0=1.0, tol=1e-5)
    ds = simulate(sc, progress=False)
    assert ds.attrs["status"] == "converged", ds.attrs["status_reason"]
    z_end = _lowest_end(ds, sc.l0)
    assert -3 * sc.load / sc.k_w <= z_end <= 1e-3, z_end       # within the penalty's overlap F/k_w
    assert float(ds.F_transmitted) == pytest.approx(sc.load - float(ds.friction_z.sum()), abs=1e-4)


def test_a_free_lower_end_without_a_floor_is_refused_unless_friction_can_hold_it():
    with pytest.raises(SceneError, match=r"'floor': False .*lower_end 'free'.*floor: true or lower_end: held"):
        Scene(name="x", lower_end="free", floor=False)
    with pytest.raises(SceneError, match=r"'floor': False"):     # pressed on the wall, but no friction
        Scene(name="x", lower_end="free", floor=False, k_fr=0.0, body_force=(0.1, 0.0, 0.0))
    Scene(name="x", lower_end="held", floor=False)                # the support holds it
    # pressed on the wall by a sideways body force, friction can hold it (tests/test_friction.py)
    Scene(name="x", lower_end="free", floor=False, k_fr=0.5, body_force=(0.1, 0.0, 0.0))


def test_the_axial_balance_closes_from_the_dataset_with_a_body_force_and_an_open_entrance():
    """A sideways body force bends the part of the rod above an open entrance over the rim onto
    the block's top face: that face carries most of the load (the case where F_transmitted was
    0.198 while load - sum f_z was far larger, the difference in no variable). face_force stores
    it, and load = F_transmitted + sum f_z + sum f_top + F_body,z to the residual."""
    sc = Scene(name="b", L=20, load=0.25, k_fr=0.3, l0=1.0, tol=1e-5, body_force=[0.5, 0.0, 0.0])
    ds = simulate(sc, progress=False)
    face = float(ds.face_force.sum())
    assert face > 0.5 * sc.load                                      # the top face carries a real share
    total = float(ds.F_transmitted) + float(ds.friction_z.sum()) + face + float(ds.body_force_z)
    assert total == pytest.approx(sc.load, abs=1e-4)
    assert abs(float(ds.axial_balance)) < 1e-4
    down = Scene(name="w", L=20, load=0.25, k_fr=0.3, l0=1.0, tol=1e-5, body_force=[0.0, 0.0, -0.01])
    dw = simulate(down, progress=False)
    assert float(dw.body_force_z) == pytest.approx(-0.01 * down.L)  # its weight: 0.2 EI/R^2 down
    assert float(dw.F_transmitted) + float(dw.friction_z.sum()) - 0.2 == pytest.approx(down.load, abs=1e-4)
    assert np.all(dw.face_force.values == 0.0)                      # closed entrance: no face force


@pytest.mark.parametrize("kw, flag", [
    # pinned ends at 1.2 x Euler's load: the residual test stops on the straight rod
    (dict(ends="pinned", load=1.2 * np.pi**2 / 400, k_fr=0.0), 1),
    # planar_then_3d with a kick of 1e-9 R: the planar state above the second threshold
    (dict(protocol="planar_then_3d", kick=1e-9, load=0.25, k_fr=0.0, l0=1.0, tol=1e-5), 2),
    # the paper's start at the paper's load: a helix on the wall, no saddle
    (dict(load=0.25, k_fr=0.8, l0=1.0, tol=1e-5), 0),
])
def test_a_run_that_stops_on_a_known_saddle_says_so(kw, flag):
    """The dataset flags a converged state that is a known saddle, and the evidence check then
    names it (claims and figures need the stable, buckled state: run_checks.status)."""
    from confined_rod.analysis import run_checks
    from confined_rod.sim import observables

    ds = simulate(Scene(name="s", L=20, **kw), progress=False)
    assert ds.attrs["status"] == "converged" and int(ds.saddle) == flag
    assert ds.saddle.attrs["flag_meanings"].split()[flag] == observables.SADDLES[flag]
    assert (run_checks.status(ds) == "converged") == (flag == 0)
    if flag:
        assert run_checks.not_at_equilibrium({"s": ds}) == [f"s ({run_checks.SADDLE_STATUS[flag]})"]


@pytest.mark.parametrize("kw", [
    # the paper's protocol with a start of 1e-9 R: the residual test stops on the straight rod
    dict(perturbation=1e-9, load=0.25, k_fr=0.0),
    # pinned ends at 1.2 x Euler's load
    dict(ends="pinned", load=1.2 * np.pi**2 / 400, k_fr=0.0),
])
def test_a_run_that_stops_on_a_saddle_is_kicked_and_relaxed_again(kw):
    """saddle_kicks: the state a run stopped on is a known saddle, so it is displaced by the kick
    and relaxed again: the run ends buckled, off the saddle, and counts its kicks; without it the
    run ends on the saddle (the test above)."""
    from confined_rod.analysis.measure import n_turns
    from confined_rod.sim.observables import shape_measures

    stuck = simulate(Scene(name="s", L=20, **kw), progress=False)
    ds = simulate(Scene(name="s", L=20, saddle_kicks=3, **kw), progress=False)
    assert int(stuck.saddle) == 1 and int(ds.saddle) == 0
    assert ds.attrs["status"] == "converged"
    assert 1 <= ds.attrs["work_saddle_kicks"] <= 3 and stuck.attrs["work_saddle_kicks"] == 0
    deflection, _ = shape_measures(np.stack([ds.x, ds.y, ds.z], axis=1), 1.0)
    assert deflection > 0.5                              # buckled, at the wall or near it
    if kw.get("ends") != "pinned":                       # free ends at 0.25 EI/R^2: the wall helix
        assert n_turns(ds) > 1.0
        assert float(ds.L_z) < float(stuck.L_z) - 1.0


def test_saddle_kicks_is_a_count():
    with pytest.raises(SceneError, match="'saddle_kicks'"):
        Scene(name="s", L=20, saddle_kicks=-1)
    with pytest.raises(SceneError, match="'saddle_kicks'"):
        Scene(name="s", L=20, saddle_kicks=1.5)
