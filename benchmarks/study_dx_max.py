"""Does a coarser path accuracy dx_max bias the ensemble mean of F(L)? The dx_max ladder of the
publication config (figure ``conv_dx_max_L<L>``) extended by seeds beyond what the build affords,
paired seed by seed against its finest rung. Writes benchmarks/results/study_dx_max_L<L>.json
(issue 43: "with enough seeds to see a 2 % bias").

Every run is the ladder's own scene (pipeline.build_scene of the config, seed and name set per
run), so a seed's run here is the build's run of that seed. Finished runs are kept in the JSON
(per rung and seed: |F_z(L)| in EI/R^2, the run time, converged), so a later call with more
``--seeds`` only runs the new ones; ``--from-build DIR`` reads the seeds a publication build
already ran (DIR/results/sims/conv_dx_max_L<L>/ and the figure scenes the ladder shares; any
result file whose scene differs from the ladder's is refused: analysis.run_checks.problem).

Reported per coarser rung against the finest (analysis.distributions.compare, paired, tolerance
``--tolerance``): the shift of the ensemble mean with its standard error, the 95 % bound, the
resolution at 95 % power, the AD p-value, the verdict and the seeds that would decide. A run
that does not reach equilibrium (its time cap) is left out of both rungs and named.

Usage: python benchmarks/study_dx_max.py [--L 640] [--seeds 52] [--rungs dx002 dx0005]
           [--from-build /tmp/pub] [--jobs 2]
"""
from __future__ import annotations

import argparse
import json
import subprocess
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
RESULTS = Path(__file__).resolve().parent / "results"


def _scene(L: int, rung: str, seed: int):
    from confined_rod import pipeline

    config = pipeline.read_config(ROOT / "config" / "config.yaml")
    figure = f"conv_dx_max_L{L}"
    fig = config["figures"][figure]
    fig["defaults"] = {**fig["defaults"], "seeds": 1, "seed": seed}
    fig["scenes"] = {rung: fig["scenes"][rung]}
    expanded = pipeline.expand(config)
    (name,) = pipeline.scenes(expanded, figure)
    return pipeline.build_scene(expanded, figure, name)


def one(args: tuple[int, str, int]) -> tuple[str, int, float, float, bool]:
    from confined_rod.sim import observables
    from confined_rod.sim.solvers import implicit

    L, rung, seed = args
    scene = _scene(L, rung, seed)
    t0 = time.perf_counter()
    st = implicit.run(scene, progress=False)
    wall = time.perf_counter() - t0
    F = observables.compute(scene, st.r, st.t, st.anchor).F_transmitted
    return rung, seed, float(F), wall, bool(st.converged)


def from_build(L: int, rungs: list[str], seeds: int, build: Path) -> dict:
    """The runs a publication build made of this ladder: its own files and the figure scenes it
    shares (pipeline.canonical_scene), each checked against the ladder's scene."""
    import xarray as xr

    from confined_rod import layout, pipeline
    from confined_rod.analysis.run_checks import problem
    from confined_rod.pipeline.targets import wanted_scene

    config = pipeline.expand(pipeline.read_config(ROOT / "config" / "config.yaml"))
    figure = f"conv_dx_max_L{L}"
    out: dict = {}
    for name in pipeline.scenes(config, figure):
        rung, _, s = name.rpartition("-s")
        if rung not in rungs or int(s) >= seeds:
            continue
        fig, scene = pipeline.canonical_scene(config, figure, name)
        path = build / layout.sim_path(fig, scene)
        if not path.exists():
            continue
        why = problem(path, wanted_scene(config, figure, name))
        if why:
            raise SystemExit(f"{path}: {why}")
        with xr.open_dataset(path) as d:
            out.setdefault(rung, {})[s] = {"F": float(d["F_transmitted"]), "wall_s": float(d["wall_time"]),
                                           "converged": bool(int(d["converged"]))}
    return out


def compare(runs: dict, rungs: list[str], tolerance: float) -> dict:
    from confined_rod.analysis import distributions

    finest = rungs[-1]
    out = {}
    for rung in rungs[:-1]:
        common = sorted(int(s) for s in set(runs.get(rung, {})) & set(runs.get(finest, {}))
                        if runs[rung][s]["converged"] and runs[finest][s]["converged"])
        left = sorted(int(s) for s in set(runs.get(rung, {})) | set(runs.get(finest, {})) if int(s) not in common)
        if len(common) < 2:
            continue
        a = np.array([runs[rung][str(s)]["F"] for s in common])
        b = np.array([runs[finest][str(s)]["F"] for s in common])
        c = distributions.compare(a, b, tolerance, paired=True)
        out[rung] = {"seeds": len(common), "left_out": left, "shift": c.shift, "se": c.se, "bound95": c.bound,
                     "resolution": c.resolution, "p_ad": c.p_ad, "verdict": c.verdict,
                     "tolerance": tolerance, "seeds_needed": c.seeds_needed, "jumps": c.jumps,
                     "median_run_s": float(np.median([runs[rung][str(s)]["wall_s"] for s in common])),
                     "median_run_s_finest": float(np.median([runs[finest][str(s)]["wall_s"] for s in common]))}
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--L", type=int, default=640)
    ap.add_argument("--seeds", type=int, default=52)
    ap.add_argument("--rungs", nargs="+", default=["dx002", "dx0005"], help="coarse to fine; the last is the reference")
    ap.add_argument("--tolerance", type=float, default=0.02)
    ap.add_argument("--from-build", type=Path, default=None)
    ap.add_argument("--jobs", type=int, default=2)
    a = ap.parse_args()
    path = RESULTS / f"study_dx_max_L{a.L}.json"
    old = json.loads(path.read_text()) if path.exists() else {}
    runs: dict = old.get("runs", {})
    if a.from_build:
        for rung, by_seed in from_build(a.L, a.rungs, a.seeds, a.from_build).items():
            runs.setdefault(rung, {}).update(by_seed)
    todo = [(a.L, r, s) for r in a.rungs for s in range(a.seeds) if str(s) not in runs.get(r, {})]
    print(f"{len(todo)} runs to make", flush=True)
    with ProcessPoolExecutor(a.jobs) as pool:
        for rung, seed, F, wall, ok in pool.map(one, todo):
            runs.setdefault(rung, {})[str(seed)] = {"F": F, "wall_s": wall, "converged": ok}
            print(f"{rung} s{seed}: F {F:.5g} in {wall:.0f} s{'' if ok else ' (not converged)'}", flush=True)
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True,
                            text=True).stdout.strip()
    out = {"what": f"dx_max ladder conv_dx_max_L{a.L} of config/config.yaml extended to {a.seeds} seeds: |F_z(L)| "
                   f"(EI/R^2) of each rung against {a.rungs[-1]}, paired seed by seed "
                   "(analysis.distributions.compare)",
           "commit": commit, "rungs": a.rungs, "runs": runs,
           "comparisons": compare(runs, a.rungs, a.tolerance)}
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(out, indent=1) + "\n")
    tmp.replace(path)
    print(json.dumps(out["comparisons"], indent=1))


if __name__ == "__main__":
    main()
