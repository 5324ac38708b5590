"""Batches: the small scenes of a figure run in one process, each scene still its own dataset,
bitwise the one a run of that scene alone writes (confined_rod.sim.runs, pipeline.batches)."""
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml

from confined_rod import layout, pipeline
from confined_rod.sim.runs import run_batch, run_one

ROOT = Path(__file__).resolve().parents[1]
TIMING = {"wall_time"}
VOLATILE_ATTRS = {"history"}
# frictional, path-dependent scenes of two lengths and seeds: if a run left any state behind
# (a memo, a random stream, a solver cache), the second and third members would show it
SCENE = {"L": 12.0, "k_fr": 0.8, "load": 0.25, "seed": 3, "snapshot_interval": 50.0}
MEMBERS = [SCENE | {"name": "t/a"}, SCENE | {"name": "t/b", "L": 16.0, "seed": 1}, SCENE | {"name": "t/c", "seed": 5}]


def same(a_path, b_path):
    with xr.open_dataset(a_path) as a, xr.open_dataset(b_path) as b:
        assert set(a.variables) == set(b.variables)
        for name in a.variables:
            if name not in TIMING:
                assert a[name].values.tobytes() == b[name].values.tobytes(), name
        for k in set(a.attrs) | set(b.attrs):
            if k not in VOLATILE_ATTRS:
                assert np.array_equal(np.asarray(a.attrs[k]), np.asarray(b.attrs[k])), k


def test_plan_keeps_the_order_packs_to_the_budget_and_runs_a_long_scene_alone():
    names = list("abcdefg")
    plan = pipeline.plan_batches(names, [5, 5, 5, 5, 25, 3, 3], budget=20)
    assert plan == [["a", "b", "c", "d"], ["e"], ["f", "g"]]
    assert pipeline.plan_batches(names, [0.0] * 7, budget=20) == [names]
    assert pipeline.plan_batches(names, [30.0] * 7, budget=20) == [[n] for n in names]
    assert pipeline.batch_name(["L80-s0", "L80-s4"]) == "L80-s0-to-L80-s4"


@pytest.mark.parametrize("path", [ROOT / "config/config.yaml", ROOT / "config/ci.yaml"], ids=lambda p: p.name)
def test_every_scene_is_run_once_by_its_batch_or_alone(path):
    config = pipeline.expand(yaml.safe_load(path.read_text()))
    for f in pipeline.figures(config):
        kind = pipeline.run_kind(config, f)
        members = [s for b in pipeline.batches(config, f).values() for s in b]
        assert len(members) == len(set(members))
        for batch, scenes in pipeline.batches(config, f).items():
            job = pipeline.batch_job(config, kind, f, batch)
            assert len(scenes) > 1
            assert sum(pipeline.solver_estimate(config, f, s) for s in scenes) <= pipeline.BATCH_S
            assert job["members"] == [pipeline.scene_params(config, f, s) for s in scenes]
            for s, out in zip(scenes, job["outputs"]):
                assert pipeline.member_cache(config, kind, f, s) == out
                assert pipeline.member_batch(config, kind, f, s) == [layout.batch_manifest(kind, f, batch)]
        for s in pipeline.scenes(config, f):
            if kind == "simulate" and pipeline.canonical_scene(config, f, s) != (f, s):
                # a shared scene runs in its first figure: not again in a batch of this one
                assert s not in members and pipeline.member_cache(config, kind, f, s) == ""
    # the publication build: most of its runs are in batches
    if path.name == "config.yaml":
        sims = [p for p in pipeline.expected_outputs(config)["sims"] if "/paths/" not in p]
        batched = sum(len(m) for f in pipeline.figures(config) for m in pipeline.batches(config, f).values())
        assert batched > len(sims) / 2, (batched, len(sims))


def test_a_batch_writes_what_each_scene_alone_writes(tmp_path):
    outs = [tmp_path / "batch" / f"{m['name'][2:]}.nc" for m in MEMBERS]
    record = run_batch("simulate", MEMBERS, outs, tmp_path / "batch.json")
    assert [m["scene"] for m in record["members"]] == ["t/a", "t/b", "t/c"]
    assert json.loads((tmp_path / "batch.json").read_text()) == record
    # the last member alone, in a fresh process (nothing shared with the batch's process)
    alone = tmp_path / "alone.nc"
    proc = subprocess.run([sys.executable, str(ROOT / "workflow/scripts/run_scene.py"), "simulate", str(alone),
                           json.dumps(MEMBERS[2])], capture_output=True, text=True, timeout=300, env={**os.environ})
    assert proc.returncode == 0, proc.stderr
    same(alone, outs[2])
    # and the second member run alone in this process, after the batch
    run_one("simulate", MEMBERS[1], tmp_path / "b_again.nc")
    same(tmp_path / "b_again.nc", outs[1])


def test_a_failed_member_stops_no_other_and_fails_the_batch(tmp_path):
    bad = SCENE | {"name": "t/bad", "l0": -1.0}
    members = [MEMBERS[0], bad, SCENE | {"name": "t/probe_me", "L": 8.0}]
    outs = [tmp_path / f"{i}.nc" for i in range(3)]
    with pytest.raises(RuntimeError, match=r"1 of 3 members of the batch failed: t/bad: .*l0"):
        run_batch("simulate", members, outs, tmp_path / "batch.json")
    assert outs[0].is_file() and not outs[1].exists() and outs[2].is_file()
    assert not (tmp_path / "batch.json").exists()
    # a probe records the same bad input as a status instead of failing
    record = run_batch("probe", [bad], [tmp_path / "p.nc"], tmp_path / "p.json")
    assert "l0" in record["members"][0]["log"]
    with pytest.raises(ValueError, match="kind = 'simulat'"):
        run_batch("simulat", members, outs, tmp_path / "x.json")


TINY = """
scene_defaults: {l0: 1.0, tol: 1.0e-4}
figures:
  ens:
    kind: force_profile
    title: a seed ensemble (one batch)
    panel_parameter: k_fr
    defaults: {L: 8, load: 0.25, k_fr: 0.8}
    scenes:
      a: {seeds: 2}
  one:
    kind: force_profile
    title: a scene alone
    panel_parameter: k_fr
    defaults: {L: 8, load: 0.25}
    scenes:
      b: {k_fr: 0.5}
"""


def _snakemake(tmp_path, config, *targets, dry=False):
    exe = Path(sys.executable).with_name("snakemake")
    if not exe.exists():
        pytest.skip("snakemake not installed (pip install -e .[workflow])")
    out = subprocess.run([str(exe), *(["-n"] if dry else []), "--snakefile", str(ROOT / "Snakefile"), "--directory",
                          str(tmp_path), *targets, "--configfile", str(config), "--cores", "1", "--quiet", "rules"],
                         cwd=ROOT, capture_output=True, text=True, timeout=600, env={**os.environ})
    msg = out.stdout + out.stderr
    assert out.returncode == 0, msg[-3000:]
    return msg, {line.split()[0]: int(line.split()[1]) for line in msg.splitlines()
                 if len(line.split()) == 2 and line.split()[1].isdigit() and line.split()[0] != "total"}


def test_snakemake_runs_a_batch_and_a_scene_alone_and_reruns_a_lost_member_alone(tmp_path):
    config = tmp_path / "tiny.yaml"
    config.write_text(TINY)
    cfg = pipeline.expand(yaml.safe_load(TINY))
    assert pipeline.batches(cfg, "ens") == {"a-s0-to-a-s1": ["a-s0", "a-s1"]} and pipeline.batches(cfg, "one") == {}
    sims = [layout.sim_path("ens", "a-s0"), layout.sim_path("ens", "a-s1"), layout.sim_path("one", "b")]
    _, planned = _snakemake(tmp_path, config, *sims)
    assert planned == {"batch": 1, "simulate": 3}, planned
    for p in sims:
        with xr.open_dataset(tmp_path / p) as ds:
            assert ds.attrs["status"] == "converged"
    logs = tmp_path / layout.LOGS / "simulate"
    assert "run in the batch" in (logs / "ens" / "a-s1.log").read_text()
    assert "one/b: converged" in (logs / "one" / "b.log").read_text()          # ran in its own job
    assert not any((tmp_path / layout.batch_folder("simulate", "ens", "a-s0-to-a-s1")).iterdir())
    _, planned = _snakemake(tmp_path, config, *sims, dry=True)
    assert planned == {}, planned                                              # nothing left to do
    (tmp_path / sims[1]).unlink()
    _, planned = _snakemake(tmp_path, config, *sims)
    assert planned == {"simulate": 1}, planned                                 # alone, its batch not again
    assert "ens/a-s1: converged" in (logs / "ens" / "a-s1.log").read_text()


def test_a_script_job_runs_the_code_of_its_own_checkout(tmp_path):
    """A ``script:`` job's preamble appends the workflow's search paths, the checkout's src/ among
    them, after the site-packages, whose editable install may point at another checkout: the
    batch jobs of a git worktree ran the main checkout's code (their datasets' git_commit said
    so). workflow/scripts/_checkout.py must put its own src/ first even when it is already on the
    path. A constructed checkout whose package is a stub, its src/ appended as the preamble does."""
    import shutil
    import subprocess
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    scripts = tmp_path / "workflow" / "scripts"
    scripts.mkdir(parents=True)
    shutil.copy(root / "workflow" / "scripts" / "_checkout.py", scripts)
    pkg = tmp_path / "src" / "confined_rod"
    pkg.mkdir(parents=True)
    (pkg / "__init__.py").write_text("STUB = True\n")
    code = (f"import sys; sys.path.append({str(tmp_path / 'src')!r}); sys.path.insert(0, {str(scripts)!r}); "
            "import _checkout, confined_rod; print(confined_rod.__file__)")
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True).stdout.strip()
    assert Path(out).resolve() == (pkg / "__init__.py").resolve()
