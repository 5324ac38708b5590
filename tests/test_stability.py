"""Stability stress probes: every point ends with a status and a message, never an
exception or a NaN."""
import numpy as np

from confined_rod import pipeline
from confined_rod.analysis.figures.stability_map import build as stability_map
from confined_rod.io import check_finite
from confined_rod.sim.probe import STATUS, probe

BASE = {"L": 4.0, "l0": 0.5, "load": 0.5, "k_fr": 0.8, "t_max": 1000.0}  # settled by t ~ 300


def status(ds):
    return STATUS[int(ds.status)]


def test_probe_records_equilibrium_divergence_and_invalid_input():
    ok = probe(BASE | {"name": "ok"})
    assert status(ok) == "converged" and int(ok.has_force) == 1 and float(ok.F_transmitted) > 0
    # 3x the explicit stability limit: forward Euler blows up within a few hundred steps
    blow = probe(BASE | {"name": "blow", "solver": "explicit", "dt_factor": 3.0})
    assert status(blow) == "diverged" and "diverged at step" in blow.attrs["message"]
    assert int(blow.has_force) == 0 and float(blow.F_transmitted) == 0.0
    bad = probe(BASE | {"name": "bad", "l0": 10.0})
    assert status(bad) == "invalid" and "'l0': 10.0" in bad.attrs["message"]
    capped = probe(BASE | {"name": "capped", "t_max": 1.0})
    assert status(capped) == "time_cap" and "time cap" in capped.attrs["message"]
    for ds in (ok, blow, bad, capped):
        check_finite(ds)


def test_sweeps_expand_to_one_scene_per_point_and_solver():
    config = {"figures": {"m": {"kind": "stability_map", "solvers": ["implicit", "explicit"],
                                "defaults": BASE, "sweeps": {"dt_factor": [1.0, 3.0], "dx_max": [0.1],
                                                             "k_ph": [0.3]}}}}
    config = pipeline.expand(config)
    names = set(pipeline.scenes(config, "m"))
    assert names == {"implicit-base", "explicit-base", "explicit-dt_factor-1", "explicit-dt_factor-3",
                     "implicit-dx_max-0p1", "implicit-k_ph-0p3", "explicit-k_ph-0p3"}
    pipeline.validate(config)  # invalid points are allowed: the probes record them
    probes = {n: probe(pipeline.scene_params(config, "m", n)) for n in sorted(names)}
    ds = stability_map(config["figures"]["m"], probes)
    st = dict(zip(ds.point.values, (STATUS[i] for i in ds.status.values)))
    assert st["explicit-dt_factor-3"] == "diverged" and st["explicit-dt_factor-1"] == "converged"
    assert st["implicit-k_ph-0p3"] == "invalid"  # refused: bonds would tear (k_ph too small for the load)
    assert set(ds.parameter.values) == {"base", "dt_factor", "dx_max", "k_ph"}
    assert np.all(np.isfinite(ds.F_transmitted.values))


def _probe(status, F, shape=None, n=40):
    """A constructed probe: its status, |F_z(L)| and (if it gave a force) a final shape: 'helix'
    (two turns on the wall) or 'straight' (on the axis)."""
    import xarray as xr

    s = (np.arange(n) + 0.5) * 0.5
    ds = xr.Dataset({"status": ((), np.int8(STATUS.index(status))), "F_transmitted": ((), F),
                     "has_force": ((), np.int8(shape is not None)), "wall_time": ((), 1.0), "n_steps": ((), 10)},
                    attrs={"message": status})
    ds["status"].attrs["flag_meanings"] = " ".join(STATUS)
    if shape is not None:
        phi = np.linspace(0, 4 * np.pi, n) if shape == "helix" else np.zeros(n)
        rho = 0.9 if shape == "helix" else 0.0
        ds = ds.assign(x=("s_link", rho * np.cos(phi)), y=("s_link", rho * np.sin(phi)), z=("s_link", s[::-1].copy()))
        ds = ds.assign_coords(s_link=("s_link", s))
        ds.attrs["R"] = 1.0
    return ds


def test_the_map_classifies_each_point_by_its_physics_as_well_as_its_status():
    """The tol = 0.1 probe that stops on the unbuckled rod (|F_z(L)| = 0.247 of 0.25) and the
    l0 = 0.125 probe that ends at 0.175 where the base point has 0.09 used to be green
    'converged' cells: now another state; a capped, a refused and a load point are told apart."""
    fig = {"kind": "stability_map", "solvers": ["implicit"], "reference_tolerance": 0.05,
           "scenes": {"implicit-base": {"solver": "implicit"}, "implicit-tol-0p1": {"solver": "implicit", "tol": 0.1},
                      "implicit-l0-0p125": {"solver": "implicit", "l0": 0.125},
                      "implicit-dx_max-0p02": {"solver": "implicit", "dx_max": 0.02},
                      "implicit-t_max-1": {"solver": "implicit", "t_max": 1.0},
                      "implicit-k_w-m1": {"solver": "implicit", "k_w": -1.0},
                      "implicit-load-2p5": {"solver": "implicit", "load": 2.5}}}
    probes = {"implicit-base": _probe("converged", 0.09, "helix"),
              "implicit-tol-0p1": _probe("converged", 0.247, "straight"),
              "implicit-l0-0p125": _probe("converged", 0.175, "helix"),
              "implicit-dx_max-0p02": _probe("converged", 0.0915, "helix"),
              "implicit-t_max-1": _probe("time_cap", 0.2, "helix"),
              "implicit-k_w-m1": _probe("invalid", 0.0),
              "implicit-load-2p5": _probe("converged", 1.2, "helix")}
    ds = stability_map(fig, probes)
    from confined_rod.analysis.figures.stability_map import OUTCOMES

    got = {p: OUTCOMES[int(o)] for p, o in zip(ds.point.values, ds.outcome.values)}
    assert got == {"implicit-base": "reference_state", "implicit-tol-0p1": "other_state",
                   "implicit-l0-0p125": "other_state", "implicit-dx_max-0p02": "reference_state",
                   "implicit-t_max-1": "capped", "implicit-k_w-m1": "refused", "implicit-load-2p5": "converged"}
    assert dict(zip(ds.point.values, ds.state.values))["implicit-tol-0p1"] == "straight"
    assert ds.attrs["outcome_counts"].startswith("reference state: 2, other state: 2, converged: 1, capped: 1")


def test_a_probe_status_is_its_runs_status_or_a_failure_with_stable_flag_values():
    """One source for the status words: a probe records its run's status (quantities.RUN_STATUS)
    or how it failed; the flag values stored so far (0 converged ... 6 step_cap) do not move."""
    from confined_rod.quantities import PROBE_STATUS, RUN_STATUS

    assert set(RUN_STATUS) < set(PROBE_STATUS)
    assert PROBE_STATUS == ("converged", "time_cap", "escaped", "diverged", "invalid", "model_violated", "step_cap")
