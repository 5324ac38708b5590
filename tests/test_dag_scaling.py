"""The DAG build of a large config (the full jamming map has 1920 runs) must grow linearly with
the number of scenes: every job's input functions used to rebuild and validate every Scene of the
config. Counted, not timed: a Snakemake dry run in this process's interpreter counts the Scene
constructions (Scene.__post_init__ validates) of configs of n and 2n scenes."""
import json
import os
import subprocess
import sys
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]

COUNTER = """
import atexit, json, os, sys
from confined_rod.sim import scenes
calls = [0]
orig = scenes.Scene.__post_init__
def counted(self):
    calls[0] += 1
    orig(self)
scenes.Scene.__post_init__ = counted
atexit.register(lambda: open(os.environ["SCENE_COUNT_FILE"], "w").write(json.dumps(calls[0])))
from snakemake.cli import main
sys.argv = ["snakemake"] + sys.argv[1:]
main()
"""


def _config(n_lengths: int) -> dict:
    return {"scene_defaults": {"l0": 1.0, "k_ph": 1000.0, "k_w": 1000.0, "tol": 1e-4},
            "figures": {"fig6_FonL": {"kind": "transmitted_force", "defaults": {"load": 0.25, "k_fr": 0.8, "seeds": 4},
                                      "scenes": {f"L{10 + i}": {"L": 10 + i} for i in range(n_lengths)}}}}


def _count(tmp_path: Path, n_lengths: int) -> int:
    cfg = tmp_path / f"n{n_lengths}.yaml"
    cfg.write_text(yaml.safe_dump(_config(n_lengths)))
    out = tmp_path / f"n{n_lengths}.json"
    env = {**os.environ, "SCENE_COUNT_FILE": str(out)}
    res = subprocess.run([sys.executable, "-c", COUNTER, "-n", "--quiet", "--cores", "1", "--configfile", str(cfg),
                          "--directory", str(tmp_path / f"w{n_lengths}"), "--snakefile", str(ROOT / "Snakefile")],
                         cwd=ROOT, env=env, capture_output=True, text=True, timeout=600)
    assert res.returncode == 0, res.stderr[-3000:]
    return json.loads(out.read_text())


def test_scene_constructions_grow_linearly_with_the_config(tmp_path):
    n1, n2 = _count(tmp_path, 8), _count(tmp_path, 16)          # 32 and 64 runs
    # linear: n2 <= 2 n1 (+ a constant for scenes every build makes, e.g. the defaults);
    # the quadratic builds this guards against gave n2 ~ 4 n1
    assert n2 <= 2 * n1 + 20, (n1, n2)
    assert n1 >= 32                                               # each run's Scene is built at least once


def test_the_canonical_index_stamp_does_not_grow_with_the_scenes():
    """Every job's input functions look up the canonical index, and its staleness stamp is
    computed per lookup: it must not hold the scenes' text (that made a DAG build O(scenes^2),
    24 s of the full map's dry run), only per-figure sizes and identities."""
    from confined_rod import pipeline
    from confined_rod.pipeline import configs

    small, large = _config(8), _config(800)
    assert len(repr(configs._config_stamp(large))) <= len(repr(configs._config_stamp(small))) + 4  # the count's digits
    # and a change that adds scenes is seen: the index is rebuilt
    assert pipeline.canonical_scene(small, "fig6_FonL", "L17") == ("fig6_FonL", "L17")
    small["figures"]["fig6_FonL"]["scenes"]["L99"] = {"L": 10}
    assert pipeline.canonical_scene(small, "fig6_FonL", "L99") == ("fig6_FonL", "L10")
