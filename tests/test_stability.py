"""Stability stress probes: every point ends with a status and a message, never an
exception or a NaN."""
import numpy as np

from confined_rod import pipeline
from confined_rod.figures.stability_map import build as stability_map
from confined_rod.io import check_finite
from confined_rod.stability import STATUS, probe

BASE = {"L": 4.0, "l0": 0.5, "load": 0.5, "k_fr": 0.8, "t_max": 200.0}


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
    assert status(capped) == "not_converged" and "time cap" in capped.attrs["message"]
    for ds in (ok, blow, bad, capped):
        check_finite(ds)


def test_sweeps_expand_to_one_scene_per_point_and_solver():
    config = {"figures": {"m": {"kind": "stability_map", "solvers": ["implicit", "explicit"],
                                "defaults": BASE, "sweeps": {"dt_factor": [1.0, 3.0], "dx_max": [0.1],
                                                             "k_ph": [0.3]}}}}
    pipeline.expand_sweeps(config)
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
