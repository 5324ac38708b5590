"""What running a scene costs beyond its solver, alone in a job or in a batch; writes
benchmarks/results/startup.json.

A workflow job that runs one scene pays the interpreter, the imports (xarray, numba, the
package), loading numba's cached kernels and the dataset writing, once per scene; a batch
(rule batch, confined_rod.sim.runs.run_batch) pays the start-up once for all its members. Setup: a
seed ensemble of the publication numerics (Fig 6's small rods: L/R = 20, 40, 80, seeds 0-3 each,
l0 = 0.5 R, k_ph = 1e4, k_w = 1e3, tol 1e-5, load 0.25, k_fr = 0.8), one core. In the same run and
interleaved, --repeats times:

* ``alone``: each scene in its own process (workflow/scripts/run_scene.py, what a job that runs
  one scene executes; Snakemake's own cost of a job, the same for both, is not included);
* ``batch``: all scenes in one process (the script rule batch runs, without Snakemake's
  preamble).

Per setting: the median wall time of the whole set, the solver times the datasets store, and
the overhead per scene, (wall - solver) / scenes, where solver is the batch's of the same repeat
for both (a process that runs one scene loads numba's cached kernels inside its first solve; in
a batch that happens once). Also, once each: the import times of the
heavy modules in a fresh interpreter, and the first-run cost of loading numba's cache (a tiny
scene run twice in one process: the first run's solver time less the second's).

Usage: python benchmarks/bench_startup.py [--repeats 3]
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RUN_SCENE = ROOT / "workflow" / "scripts" / "run_scene.py"
PUBLICATION = dict(load=0.25, k_fr=0.8, l0=0.5, k_ph=1e4, k_w=1e3, tol=1e-5)
SCENES = [PUBLICATION | {"L": float(L), "seed": s, "name": f"startup/L{L}-s{s}"} for L in (20, 40, 80)
          for s in range(4)]
ENV = {**os.environ, "NUMBA_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}
BATCH = """
import json, sys
sys.path.insert(0, {src!r})
from confined_rod.sim.runs import run_batch
members = json.loads({members!r})
run_batch("simulate", members, {outputs!r}, {manifest!r})
"""


def solver_seconds(files: list[Path]) -> float:
    import netCDF4

    total = 0.0
    for f in files:
        with netCDF4.Dataset(f) as ds:
            total += float(ds["wall_time"][...])
    return total


def run_alone(tmp: Path) -> tuple[float, float]:
    outs = [tmp / f"alone-{i}.nc" for i in range(len(SCENES))]
    t0 = time.perf_counter()
    for sc, out in zip(SCENES, outs):
        subprocess.run([sys.executable, str(RUN_SCENE), "simulate", str(out), json.dumps(sc)], env=ENV,
                       check=True, capture_output=True)
    return time.perf_counter() - t0, solver_seconds(outs)


def batch_process(members: list[dict], tmp: Path, tag: str) -> tuple[float, list[Path]]:
    """Run ``members`` as one batch in a fresh process: (its wall time, the datasets)."""
    outs = [str(tmp / f"{tag}-{i}.nc") for i in range(len(members))]
    code = BATCH.format(src=str(ROOT / "src"), members=json.dumps(members), outputs=outs,
                        manifest=str(tmp / f"{tag}.json"))
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-c", code], env=ENV, check=True, capture_output=True)
    return time.perf_counter() - t0, [Path(o) for o in outs]


def run_batched(tmp: Path) -> tuple[float, float]:
    wall, outs = batch_process(SCENES, tmp, "batch")
    return wall, solver_seconds(outs)


def import_times() -> dict[str, float]:
    """Seconds to import each module in a fresh interpreter (median of 3), and python alone."""
    out = {}
    for mod in ("", "numpy", "xarray", "numba", "confined_rod.sim.simulation", "confined_rod.sim.runs"):
        stmt = f"import {mod}" if mod else "pass"
        ts = []
        for _ in range(3):
            t0 = time.perf_counter()
            subprocess.run([sys.executable, "-c", f"import sys; sys.path.insert(0, {str(ROOT / 'src')!r}); {stmt}"],
                           env=ENV, check=True)
            ts.append(time.perf_counter() - t0)
        out[mod or "python"] = statistics.median(ts)
    return out


def numba_cache_load(tmp: Path) -> dict[str, float]:
    """A tiny scene run twice in one process: the first run loads the cached kernels."""
    tiny = [PUBLICATION | {"L": 6.0, "name": f"startup/tiny{i}"} for i in range(2)]
    _, outs = batch_process(tiny, tmp, "tiny")
    first, second = (solver_seconds([o]) for o in outs)
    return {"first_run_s": first, "second_run_s": second, "cache_load_s": first - second}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("-o", "--output", default=str(ROOT / "benchmarks" / "results" / "startup.json"))
    args = ap.parse_args()
    runs: dict[str, list[dict]] = {"alone": [], "batch": []}
    with tempfile.TemporaryDirectory() as tmpdir:
        tmp = Path(tmpdir)
        run_batched(tmp)  # numba's cache and the OS file cache warm for both settings
        for _ in range(args.repeats):
            done = {name: fn(tmp) for name, fn in (("alone", run_alone), ("batch", run_batched))}
            reference = done["batch"][1]
            for name, (wall, solver) in done.items():
                runs[name].append({"wall_s": wall, "solver_s": solver,
                                   "overhead_per_scene_s": (wall - reference) / len(SCENES)})
                print(f"{name:6s} wall {wall:6.2f} s solver {solver:6.2f} s "
                      f"overhead {runs[name][-1]['overhead_per_scene_s']:.2f} s/scene", flush=True)
        cache = numba_cache_load(tmp)
    imports = import_times()
    med = {k: {q: statistics.median(r[q] for r in v) for q in ("wall_s", "solver_s", "overhead_per_scene_s")}
           for k, v in runs.items()}
    out = {"machine": platform.processor() or platform.machine(), "cpus": os.cpu_count(),
           "scenes": len(SCENES), "setup": "L/R = 20, 40, 80 x seeds 0-3, publication numerics, one core",
           "median": med, "runs": runs,
           "ratio_alone_over_batch_overhead": med["alone"]["overhead_per_scene_s"]
           / max(med["batch"]["overhead_per_scene_s"], 1e-9),
           "import_s": imports, "numba_cache": cache}
    Path(args.output).parent.mkdir(parents=True, exist_ok=True)
    Path(args.output).write_text(json.dumps(out, indent=1) + "\n")
    print(json.dumps({"median": med, "import_s": imports, "numba_cache": cache}, indent=1))


if __name__ == "__main__":
    main()
