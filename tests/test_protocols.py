"""The loading protocols 'ramp' and 'helix', and the protocol comparison's ramp ladder."""
from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from confined_rod import Scene
from confined_rod.analysis.figures import protocol_comparison as pc
from confined_rod.errors import SceneError
from confined_rod.limits import roundoff_tol
from confined_rod.sim.solvers.base import ramp_stage
from confined_rod.theory import helix_pitch_rate


def test_ramp_loads_are_geometric_from_above_euler_to_the_load():
    sc = Scene(L=40, load=0.25, protocol="ramp", ramp_steps=8, ramp_start=2.0)
    loads = sc.ramp_loads()
    assert loads.size == 8 and loads[-1] == pytest.approx(0.25)
    assert loads[0] == pytest.approx(2.0 * np.pi**2 / 40**2)
    ratios = loads[1:] / loads[:-1]
    assert np.allclose(ratios, ratios[0])                       # geometric
    # a load below the first ramp load is applied at once
    assert Scene(L=4, load=0.5, protocol="ramp").ramp_loads().tolist() == [0.5]


@pytest.mark.parametrize("key, value", [("ramp_steps", 0), ("ramp_steps", 2.5), ("ramp_steps", True),
                                        ("ramp_start", 1.0), ("ramp_start", -3.0)])
def test_ramp_parameters_are_checked(key, value):
    with pytest.raises(SceneError, match=key):
        Scene(L=40, protocol="ramp", **{key: value})


def test_ramp_stage_tolerance_is_the_round_off_floor_at_small_loads():
    sc = Scene(L=320, load=0.25, k_ph=1e4, tol=1e-5, protocol="ramp")
    small = ramp_stage(sc, 2e-4)
    # the floor normalised by the load grows as 1/load: the stage is relaxed to it, not refused
    assert small.tol == pytest.approx(roundoff_tol(sc, 2e-4))
    assert small.tol > 100 * sc.tol and small.load == 2e-4
    assert ramp_stage(sc, 0.2).tol == pytest.approx(max(sc.tol, roundoff_tol(sc, 0.2)))


def test_helix_start_is_a_stress_free_right_handed_helix_inside_the_wall():
    sc = Scene(L=40, load=0.25, protocol="helix", seed=3)
    r, t = sc.initial_state()
    h = 0.5 * sc.l0
    gap = (r[1:] - h * t[1:]) - (r[:-1] + h * t[:-1])
    assert np.abs(gap).max() < 1e-12                            # every bond at rest: no prestress
    assert np.allclose(np.linalg.norm(t, axis=1), 1.0)
    ends = np.vstack([r - h * t, r[-1:] + h * t[-1:]])
    assert np.hypot(ends[:, 0], ends[:, 1]).max() < sc.R        # inside the wall
    assert ends[0, 2] == pytest.approx(0.0) and np.all(np.diff(ends[:, 2]) > 0)   # from the support up
    phi = np.unwrap(np.arctan2(r[:, 1], r[:, 0]))
    assert np.all(np.diff(phi) > 0)                             # one handedness
    # the pitch angle of the torque-free helix carrying the load: R dphi/ds at the wall
    w = float(helix_pitch_rate(np.array([0.25]))[0])
    assert (phi[-1] - phi[0]) / (r[-1, 2] - r[0, 2]) == pytest.approx(w / np.sqrt(1 - w**2), rel=0.02)


def test_helix_start_depends_on_the_seed():
    a = Scene(L=20, protocol="helix", seed=0).initial_state()[0]
    b = Scene(L=20, protocol="helix", seed=1).initial_state()[0]
    assert 0 < np.abs(a - b).max() < 2e-3


def _member(seed, F, steps, protocol="ramp", turns=3.0):
    return xr.Dataset({"F_transmitted": ((), F), "phi": (("s_helix",), [0.0, 2 * np.pi * turns])},
                      attrs={"seed": seed, "ramp_steps": steps, "protocol": protocol})


def test_ramp_ladder_pairs_members_by_seed():
    sims = {f"r8-s{s}": _member(s, F, 8) for s, F in zip(range(3), (0.1, 0.2, 0.3))}
    sims.update({f"r16-s{s}": _member(s, F, 16) for s, F in zip(range(3), (0.11, 0.2, 0.27))})
    groups = {"r8": [f"r8-s{s}" for s in range(3)], "r16": [f"r16-s{s}" for s in range(3)]}
    ds = xr.Dataset()
    pc._ramp_ladder(ds, groups, sims)
    rel = np.array([0.1, 0.0, -0.1])
    assert ds.attrs["ramp_ladder_paired_change"][0] == pytest.approx(rel.mean(), abs=1e-12)
    assert ds.attrs["ramp_ladder_max_change"][0] == pytest.approx(0.1)
    assert ds.attrs["ramp_ladder_mean_change"][0] == pytest.approx(0.58 / 0.6 - 1)
    assert ds.attrs["ramp_ladder_state_changes"][0] == 0
    assert "8 -> 16 steps" in ds.attrs["ramp_ladder"]


def test_ramp_ladder_counts_a_change_of_final_state_apart():
    """Seed 2 ends half a turn apart with the finer ramp (another equilibrium): its +50 % is
    reported as a change of state, not averaged into the refinement of the same state."""
    sims = {f"r8-s{s}": _member(s, F, 8) for s, F in zip(range(3), (0.1, 0.2, 0.2))}
    sims.update({f"r16-s{s}": _member(s, F, 16, turns=t) for s, F, t in
                 zip(range(3), (0.101, 0.199, 0.3), (3.02, 2.98, 3.5))})
    groups = {"r8": [f"r8-s{s}" for s in range(3)], "r16": [f"r16-s{s}" for s in range(3)]}
    ds = xr.Dataset()
    pc._ramp_ladder(ds, groups, sims)
    assert ds.attrs["ramp_ladder_paired_change"][0] == pytest.approx((0.01 - 0.005) / 2, abs=1e-12)
    assert ds.attrs["ramp_ladder_same_state"][0] == 2
    assert ds.attrs["ramp_ladder_state_changes"][0] == 1
    assert ds.attrs["ramp_ladder_max_change"][0] == pytest.approx(0.01)
    assert "seed 2 +50 %" in ds.attrs["ramp_ladder"]


def test_protocol_comparison_stores_the_torque_and_the_formation():
    """Two variants of a short rod, one storing snapshots: per member the torque closure and the
    bulk ratios, along s the force and torque of the variants drawn, the force while forming;
    nothing NaN, and the figure draws."""
    from confined_rod import simulate
    from confined_rod.analysis import plotting as P
    from confined_rod.io import check_finite

    sims = {}
    for seed in (0, 1):
        sims[f"straight-s{seed}"] = simulate(Scene(L=40, load=0.25, seed=seed, snapshot_interval=50.0,
                                                   snapshot_growth=2.0, name=f"straight-s{seed}"), progress=False)
        sims[f"helix-s{seed}"] = simulate(Scene(L=40, load=0.25, seed=seed, protocol="helix",
                                                name=f"helix-s{seed}"), progress=False)
    ds = pc.build({"profiles": ["straight", "helix"]}, sims)
    check_finite(ds, "test")
    assert list(ds.profile.values) == ["straight", "helix"]
    assert ds.attrs["formation_variant"] == "straight" and ds.sizes["t"] >= 5
    np.testing.assert_allclose(ds.formation_F_abs.values[:, 0], 0.25)
    assert np.all(ds.torque_closure_member.values < 1e-3)
    # the profile drawn is the first seed's, from the loaded end
    np.testing.assert_allclose(ds.profile_F_abs.values[0], np.abs(sims["straight-s0"].F_z.values))
    # the manuscript's macros read the formation's time axis t (the last snapshot's time)
    from confined_rod.claims.manuscript import Macros, protocol_macros

    macros = Macros()
    protocol_macros("protocols", ds, macros)
    plain = {k.split("@", 1)[1]: v[2] for k, v in macros.items.items()}
    final = float(plain["protocols.formation_final"].replace("x10", "e"))      # '8.1x103' as typeset
    assert final == pytest.approx(float(ds.t.values[-1]), rel=0.05)
    ds.attrs.update(kind="protocol_comparison", title="test")
    fig = pc.plot(ds)
    assert len(fig.axes) == 8
    P.plt.close(fig)
