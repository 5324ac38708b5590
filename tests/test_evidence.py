"""No stale, swapped, corrupted or unconverged evidence reaches a figure, a verdict or the paper
(confined_rod.analysis.run_checks, pipeline.stale_inputs, the claims and the convergence kind)."""
import copy
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml

from confined_rod import claims, layout, pipeline
from confined_rod.analysis import postprocess, run_checks
from confined_rod.io import netcdf_attr

from . import shapes
from .test_convergence import ladder
from .test_pipeline import fake_sim

ROOT = Path(__file__).resolve().parents[1]
CI = ROOT / "config" / "ci.yaml"


def _sim_file(path: Path, wanted: dict, status: str = "converged") -> Path:
    """A minimal scene file storing the scene ``wanted`` (what the checks read)."""
    ds = xr.Dataset({"F_transmitted": ((), 0.1)})
    ds.attrs.update({k: netcdf_attr(v) for k, v in wanted.items()})
    ds.attrs["status"] = status
    path.parent.mkdir(parents=True, exist_ok=True)
    ds.to_netcdf(path)
    return path


def _ci_config():
    return pipeline.expand(yaml.safe_load(CI.read_text()))


# -- a file is the run the config asks for --------------------------------------------------------
def test_a_file_of_another_scene_is_named_with_the_differing_parameter(tmp_path):
    config = _ci_config()
    f = "fig6_FonL"
    s20, s40 = [s for s in pipeline.scenes(config, f) if s.endswith("-s0")][:2]
    wanted = pipeline.wanted_scene(config, f, s20)
    path = _sim_file(tmp_path / "a.nc", pipeline.wanted_scene(config, f, s40))   # L = 40's file in L = 20's place
    with pytest.raises(run_checks.EvidenceError) as e:
        run_checks.check_file(path, wanted)
    msg = str(e.value)
    assert "\n" not in msg and str(path) in msg and "name" in msg and s40 in msg
    renamed = {**pipeline.wanted_scene(config, f, s40), "name": wanted["name"]}   # same name, other L
    _sim_file(path, renamed)
    with pytest.raises(run_checks.EvidenceError, match=r"holds L = \d+ but the config asks for L = \d+"):
        run_checks.check_file(path, wanted)
    _sim_file(path, wanted)
    run_checks.check_file(path, wanted)                                              # the right file passes


@pytest.mark.parametrize("damage", ["truncated", "random bytes", "empty", "attribute removed"])
def test_a_corrupted_file_gets_one_line_saying_how_to_rebuild_it(tmp_path, damage):
    config = _ci_config()
    wanted = pipeline.wanted_scene(config, "fig6_FonL", pipeline.scenes(config, "fig6_FonL")[0])
    path = _sim_file(tmp_path / "a.nc", wanted)
    data = path.read_bytes()
    if damage == "truncated":
        path.write_bytes(data[: len(data) // 2])
    elif damage == "random bytes":
        path.write_bytes(np.random.default_rng(0).bytes(len(data)))
    elif damage == "empty":
        path.write_bytes(b"")
    else:
        _sim_file(path, {k: v for k, v in wanted.items() if k != "load"})
    with pytest.raises(run_checks.EvidenceError) as e:
        run_checks.load(path, wanted)
    msg = str(e.value)
    assert "\n" not in msg and str(path) in msg and "--forcerun" in msg
    if damage == "attribute removed":
        assert "no attribute 'load'" in msg


def test_a_stale_file_gets_a_fresh_marker_and_a_matching_one_none(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    config = _ci_config()
    f = "fig6_FonL"
    s20, s40 = [s for s in pipeline.scenes(config, f) if s.endswith("-s0")][:2]
    path = Path(layout.sim_path(f, s20))
    assert pipeline.stale_inputs(config, f, s20, str(path)) == []                 # no file: nothing to say
    _sim_file(path, pipeline.wanted_scene(config, f, s40))
    marker = pipeline.stale_inputs(config, f, s20, str(path))
    assert marker == [str(layout.rebuild_marker(f, s20))]
    assert Path(marker[0]).stat().st_mtime_ns > path.stat().st_mtime_ns          # newer: the rule reruns
    _sim_file(path, pipeline.wanted_scene(config, f, s20))                        # the rebuilt file
    assert pipeline.stale_inputs(config, f, s20, str(path)) == [] and not Path(marker[0]).exists()


def _snakemake():
    exe = Path(sys.executable).with_name("snakemake")
    if not exe.exists():
        pytest.skip("snakemake not installed (pip install -e .[workflow])")
    return exe


def _planned(tmp_path, *extra):
    out = subprocess.run([str(_snakemake()), "-n", "--snakefile", str(ROOT / "Snakefile"), "--directory",
                          str(tmp_path), *extra, "--configfile", str(CI), "--cores", "1", "--quiet", "rules"],
                         cwd=ROOT, capture_output=True, text=True, timeout=300, env={**os.environ})
    msg = out.stdout + out.stderr
    assert out.returncode == 0, msg[-2000:]
    return msg, {line.split()[0]: int(line.split()[1]) for line in msg.splitlines()
                 if len(line.split()) == 2 and line.split()[1].isdigit()}


def test_swapped_and_stale_files_are_rebuilt_without_snakemakes_metadata(tmp_path):
    """A tree whose every product exists and is newer than the code, without .snakemake/: nothing
    to do; then one simulation file copied over another (the case that used to put an L = 30
    member into the L = 20 statistics) and one built with another load: exactly those two are
    rebuilt (and what reads them), each named with the differing parameter."""
    config = yaml.safe_load(CI.read_text())
    outs = pipeline.expected_outputs(copy.deepcopy(config))
    expanded = _ci_config()
    (tmp_path / "paper").symlink_to(ROOT / "paper")                               # the manuscript's sources
    for f in pipeline.figures(expanded):
        for s, path, wanted in zip(pipeline.scenes(expanded, f), pipeline.figure_sims(expanded, f),
                                   pipeline.figure_wanted(expanded, f)):
            if wanted is not None and not (tmp_path / path).exists():
                _sim_file(tmp_path / path, wanted)
    sources = [layout.paper_source(n) for n in layout.PAPER_SOURCES]
    outs["batches"] = pipeline.batch_outputs(expanded)                            # a built tree has them
    for kind in ("sims", "batches", "datasets", "figures", "checks", "paper", "sources"):
        for p in outs.get(kind, sources):
            (tmp_path / p).parent.mkdir(parents=True, exist_ok=True)
            if not (tmp_path / p).exists():
                (tmp_path / p).write_text("")
    now = time.time_ns()
    for p in (tmp_path / layout.RESULTS).rglob("*"):                                   # one time: no order
        os.utime(p, ns=(now, now))
    _, planned = _planned(tmp_path)
    assert planned.get("simulate", 0) == 0 and planned.get("postprocess", 0) == 0, planned
    f = "fig6_FonL"
    s20, s40 = [s for s in pipeline.scenes(expanded, f) if s.endswith("-s0")][:2]
    (tmp_path / layout.sim_path(f, s20)).write_bytes((tmp_path / layout.sim_path(f, s40)).read_bytes())
    os.utime(tmp_path / layout.sim_path(f, s20), ns=(1, 1))                     # old: mtime alone misses it
    fig4 = "fig4_Fonl"
    s4 = pipeline.scenes(expanded, fig4)[0]
    path4 = tmp_path / layout.sim_path(*pipeline.canonical_scene(expanded, fig4, s4))
    _sim_file(path4, {**pipeline.wanted_scene(expanded, fig4, s4), "load": 0.2})
    os.utime(path4, ns=(1, 1))
    msg, planned = _planned(tmp_path)
    assert planned.get("simulate") == 2 and planned.get("batch", 0) == 0, msg[-3000:]  # each alone
    assert f"{layout.sim_path(f, s20)} holds name = '{f}/{s40}'" in msg
    assert "holds load = 0.2 but the config asks for load = 0.25" in msg
    assert planned.get("postprocess", 0) >= 2, msg[-3000:]
    assert planned.get("claims") == 1 and planned.get("paper") == 1, msg[-3000:]


# -- runs that are not at equilibrium decide nothing ---------------------------------------------
def _unsettled(ds: xr.Dataset, status: str = "step_cap") -> xr.Dataset:
    ds = ds.copy()
    ds.attrs["status"] = status
    ds["converged"] = ((), np.int8(0))
    return ds


def test_a_figure_dataset_names_its_runs_that_are_not_at_equilibrium(capsys):
    sims = {f"L{L}": fake_sim(L, 0.8) for L in (20, 40, 80)}
    fig_cfg = {"kind": "transmitted_force", "scenes": {k: {} for k in sims}}
    ds = postprocess.build("f6", fig_cfg, sims)
    assert ds.attrs["not_at_equilibrium"] == "none"
    sims["L40"] = _unsettled(sims["L40"])
    ds = postprocess.build("f6", fig_cfg, sims)
    assert run_checks.flagged(ds.attrs["not_at_equilibrium"]) == ["f6/L40 (step_cap)"]
    assert "f6/L40 (step_cap)" in capsys.readouterr().err


def test_a_claim_on_a_run_not_at_equilibrium_is_not_testable():
    ds = xr.Dataset({"fit_c": ("panel", [-0.92])}, attrs={"not_at_equilibrium": "none"})
    c = {"id": "x", "where": "Fig. 0", "claim": "a claim", "paper": -0.9,
         "test": {"method": "value", "figure": "f", "var": "fit_c", "isel": {"panel": 0}},
         "tolerance": {"abs": 0.05}}
    assert claims.evaluate_one(c, claims.Evidence({"f": ds})).verdict == "reproduced"
    ds.attrs["not_at_equilibrium"] = "f/L20-s0 (step_cap); f/L20-s1 (time_cap)"
    v = claims.evaluate_one(c, claims.Evidence({"f": ds}))
    assert v.verdict == "not testable" and v.ours == "-"
    assert v.note == "evidence not at equilibrium (f/L20-s0 (step_cap); f/L20-s1 (time_cap))"
    # a measure on the simulations themselves: one member capped makes it not testable
    small = {f"f7/s-s{i}": shapes.profile_rod(tip_end=20.0, seed=i)[0] for i in range(2)}
    large = {f"f4/c-s{i}": shapes.profile_rod(tip_end=5.0, seed=i)[0] for i in range(2)}
    cm = {**c, "test": {"method": "measure", "name": "boundary_wider", "figures": ["f7", "f4"]}, "tolerance": None,
          "paper": "wider"}
    assert claims.evaluate_one(cm, claims.Evidence({}, {**small, **large})).verdict != "not testable"
    large["f4/c-s1"] = _unsettled(large["f4/c-s1"], "time_cap")
    v = claims.evaluate_one(cm, claims.Evidence({}, {**small, **large}))
    assert v.verdict == "not testable" and v.note == "evidence not at equilibrium (f4/c-s1 (time_cap))"


def test_a_convergence_rung_not_at_equilibrium_makes_the_ladder_inconclusive():
    assert ladder(lambda h: 0.1 * (1 + 0.02 * h)).attrs["status"] == "pass"
    ds = ladder(lambda h: 0.1 * (1 + 0.02 * h), unsettled="r1")
    assert ds.attrs["status"] == "inconclusive: evidence not at equilibrium (r1 (step_cap))"


def test_the_figure_says_which_runs_are_not_at_equilibrium():
    import matplotlib.pyplot as plt

    from confined_rod.analysis import figures, plotting

    sims = {f"L{L}": fake_sim(L, 0.8) for L in (20, 40, 80)}
    sims["L80"] = _unsettled(sims["L80"])
    ds = postprocess.build("f6", {"kind": "transmitted_force", "scenes": {k: {} for k in sims}}, sims)
    fig = figures.get("transmitted_force").plot(ds)
    plotting.mark_unsettled(fig, ds)
    texts = [t.get_text() for t in fig.texts]
    plt.close(fig)
    assert any("not at a stable equilibrium, drawn" in t and "f6/L80 (step_cap)" in t for t in texts)


def test_the_unsettled_runs_are_listed_below_a_figure_legend_not_over_it():
    """The jamming map's legend hangs below its axes (fig.legend at y < 0); the red list of
    unsettled runs went on top of it (2026-12-03 map) because only axes and texts were measured."""
    import matplotlib.pyplot as plt
    import xarray as xr

    from confined_rod.analysis import plotting

    fig, ax = plt.subplots(figsize=(4, 3))
    for i in range(6):
        ax.plot([0, 1], [0, i], label=f"line {i}")
    handles, labels = ax.get_legend_handles_labels()
    legend = fig.legend(handles, labels, loc="upper left", bbox_to_anchor=(0.1, 0.0), ncol=2)
    ds = xr.Dataset(attrs={"left_out": "m/L640-s2 (converged on a saddle); m/L640-s7 (converged on a saddle)"})
    plotting.mark_unsettled(fig, ds)
    renderer, to_fig = fig.canvas.get_renderer(), fig.transFigure.inverted()
    red = [t for t in fig.texts if "left out" in t.get_text()]
    legend_bottom = legend.get_window_extent(renderer).transformed(to_fig).y0
    red_top = red[0].get_window_extent(renderer).transformed(to_fig).y1
    plt.close(fig)
    assert len(red) == 1 and red_top <= legend_bottom


def _ensemble_cases():
    """(figure config, members) of every kind built from seed ensembles of simulations, from the
    constructed members of tests/test_ensembles.py."""
    from .test_ensembles import _profile, _sim

    cases = {"transmitted_force": ({"kind": "transmitted_force"},
                                   {f"L{L}-s{s}": _sim(float(L), s, 0.2 / (1 + L / 40) * (1 + 0.05 * s))
                                    for L in (20, 40, 80) for s in range(3)}),
             "force_profile": ({"kind": "force_profile"}, {f"c-s{s}": _profile(s, 1 + 0.1 * s) for s in range(3)})}
    grid = {"kind": "jamming_map", "grid": {"L": [10, 40], "load": [0.25], "k_fr": [0.8]}, "defaults": {"seeds": 2}}
    grid = pipeline.expand({"figures": {"map": grid}})["figures"]["map"]
    cases["jamming_map"] = (grid, {n: _sim(float(n[1:3]), int(n[-1]), 0.2 if n.startswith("L10") else 0.05)
                                   for n in grid["scenes"]})
    ladder_sims = {}                                # as test_ensemble_ladder_dataset_from_constructed_rungs
    for l0, mean in ((1.0, 0.075), (0.5, 0.070), (0.25, 0.0702)):
        for s in range(4):
            d = _sim(80.0, s, mean * (1 + 0.01 * s), turns=0.9 if (l0, s) == (1.0, 0) else 3.2)
            d.attrs["l0"] = l0
            ladder_sims[f"l0_{l0}-s{s}"] = d
    cases["convergence"] = ({"kind": "convergence", "parameter": "l0", "tolerance": 0.05}, ladder_sims)
    return cases


@pytest.mark.parametrize("kind", ["transmitted_force", "force_profile", "jamming_map", "convergence"])
def test_a_member_not_at_equilibrium_through_every_ensemble_kind(kind, capsys):
    """One member of a seed ensemble ended at its step cap: every ensemble kind leaves it out of
    its statistics (a ladder out of its verdict) and names it; with every member capped the
    dataset is built from them, flagged, so that no claim is decided on it."""
    fig_cfg, sims = _ensemble_cases()[kind]
    sims = {k: d.copy() for k, d in sims.items()}
    for d in sims.values():
        d.attrs["status"] = "converged"
    victim = sorted(sims)[1]
    sims[victim] = _unsettled(sims[victim])
    context = {"publication_value": 0.5} if kind == "convergence" else {}
    ds = postprocess.build("f", fig_cfg, sims, context)
    # its ensemble has members at equilibrium: it is left out of the statistics, and named
    assert run_checks.flagged(ds.attrs["left_out"]) == [f"f/{victim} (step_cap)"]
    assert ds.attrs["not_at_equilibrium"] == "none"
    assert f"f/{victim} (step_cap)" in capsys.readouterr().err
    if kind != "convergence":                    # a ladder leaves the seed out inside its own dataset
        used = ds.attrs["scenes"].split(", ")
        assert victim not in used and len(used) == len(sims) - 1
    # every member of every ensemble capped: nothing to leave out to; drawn, flagged
    for k in sims:
        sims[k] = _unsettled(sims[k])
    ds = postprocess.build("f", fig_cfg, sims, context)
    assert len(run_checks.flagged(ds.attrs["not_at_equilibrium"])) == len(sims) and ds.attrs["left_out"] == "none"
