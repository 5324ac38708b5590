"""A convergence ladder of a config (the publication's by default) extended by seeds beyond what
the build affords, and by rungs it does not have, paired seed by seed against its finest rung: for
a ladder the build leaves undecided only because its ensembles are too small (issue 43: the dx_max
bias at 2 %, the ramp of Fig 4(b)). Writes benchmarks/results/study_seeds_<figure>.json.

Every run is the ladder's own scene (pipeline.scene_params of the config, seed and name set per
run), so a seed's run here is the build's run of that seed. Finished runs are kept in the JSON
(per rung and seed: |F_z(L)| in EI/R^2, the local relations of analysis.local_relations, the
loosely wound flag, the run time, converged), so a later call with more ``--seeds`` runs only the
new ones, across sessions; ``--from-build DIR`` reads the seeds a publication build already ran
(DIR/results/sims/<figure>/ and the figure scenes the ladder shares; any result file whose scene
differs from the ladder's is refused: analysis.run_checks.problem).

Reported per quantity and coarser rung against the finest (analysis.distributions.compare,
paired): the shift of the ensemble mean with its standard error, the 95 % bound, the resolution
at 95 % power, the AD p-value, the verdict against ``--tolerance`` (for ``--quantity``; the others
against 1, as descriptions) and the seeds that would decide; and the loosely wound seeds per rung.
A run that does not reach equilibrium (its time cap) is left out of both rungs and named.

A rung the config does not have (``--extra-rung n1024 ramp_steps=1024``) is the ladder's finest
rung with one parameter changed. Each coarser rung is compared with the finest and with the next
finer one; the loosely wound share with McNemar's exact test, against the same two.

Usage: python benchmarks/study_ladder_seeds.py --figure conv_dx_max_L640 [--rungs dx002 dx0005]
           [--quantity F_transmitted] [--tolerance 0.02] [--seeds 52] [--from-build /tmp/pub] [--jobs 2]
       python benchmarks/study_ladder_seeds.py --figure conv_ramp_steps_b --rungs n256 n512 n1024
           --extra-rung n1024 ramp_steps=1024 --quantity decay_ratio --tolerance 0.0534 --seeds 64
       python benchmarks/study_ladder_seeds.py --config config/jamming_map.yaml
           --figure conv_dx_max_L1280 --rungs dx002 dx0005 --seeds 64
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
QUANTITIES = ("F_transmitted", "decay_ratio", "wall_force_ratio", "pitch_ratio", "helix_balance")


CONFIG = ROOT / "config" / "config.yaml"


def _config(path: Path = CONFIG):
    from confined_rod import pipeline

    return pipeline.read_config(path)


def _scene(figure: str, rung: str, seed: int, extra: tuple = (), config_path: Path = CONFIG):
    """The ladder's scene of rung ``rung`` for one seed; a rung the config does not have is one of
    ``extra`` ((name, parameter, value)): the ladder's finest rung with that parameter set."""
    from confined_rod import pipeline

    config = _config(config_path)
    fig = config["figures"][figure]
    fig["defaults"] = {**fig["defaults"], "seeds": 1, "seed": seed}
    added = {name: (param, value) for name, param, value in extra}
    if rung in added:
        param, value = added[rung]
        scene = {**list(fig["scenes"].values())[-1], param: value}
    else:
        scene = fig["scenes"][rung]
    fig["scenes"] = {rung: {k: v for k, v in scene.items() if k not in ("seeds", "seed")}}
    expanded = pipeline.expand(config)
    (name,) = pipeline.scenes(expanded, figure)
    return pipeline.build_scene(expanded, figure, name)


def values(ds) -> dict:
    """What the study keeps of one run's dataset."""
    from confined_rod.analysis import local_relations

    rel = local_relations.measure(ds)
    loose = local_relations.loosely_wound(rel)
    return {"F_transmitted": float(ds["F_transmitted"]), **rel, "loosely_wound": loose,
            "wall_s": float(ds["wall_time"]), "converged": bool(int(ds["converged"]))}


def one(args: tuple[str, str, int, tuple, Path]) -> tuple[str, int, dict]:
    from confined_rod.sim.simulation import simulate

    figure, rung, seed, extra, config_path = args
    t0 = time.perf_counter()
    ds = simulate(_scene(figure, rung, seed, extra, config_path), progress=False)
    out = values(ds)
    out["wall_s"] = time.perf_counter() - t0
    return rung, seed, out


def from_build(figure: str, rungs: list[str], seeds: int, build: Path, config_path: Path = CONFIG) -> dict:
    """The runs a publication build made of this ladder: its own files and the figure scenes it
    shares (pipeline.canonical_scene), each checked against the ladder's scene."""
    import xarray as xr

    from confined_rod import layout, pipeline
    from confined_rod.analysis.run_checks import problem
    from confined_rod.pipeline.targets import wanted_scene

    config = pipeline.expand(_config(config_path))
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
            out.setdefault(rung, {})[s] = values(d)
    return out


def compare(runs: dict, rungs: list[str], quantity: str, tolerance: float) -> dict:
    """Per quantity, each coarser rung against the finest (keyed by the rung) and, where they
    differ, against the next finer one (keyed '<rung>_vs_<next>'); the loosely wound seeds per
    rung, with McNemar's exact test of each rung against the next finer one and the finest (the
    seeds loosely wound on one rung only)."""
    from scipy.stats import binomtest

    from confined_rod.analysis import distributions

    finest = rungs[-1]
    pairs = [(r, finest, r) for r in rungs[:-1]]
    pairs += [(r, nxt, f"{r}_vs_{nxt}") for r, nxt in zip(rungs[:-2], rungs[1:-1])]
    out: dict = {}
    # every pair over all seeds, and the ratios to the torque-free helix also over the seeds tight on
    # both rungs ('<key>_tight'): the relation within the state it presumes
    tight_only = ("decay_ratio", "wall_force_ratio", "pitch_ratio")
    for q, rung, ref, key in ([(q, *p) for q in QUANTITIES for p in pairs]
                              + [(q, r, f, k + "_tight") for q in tight_only for r, f, k in pairs]):
        both = set(runs.get(rung, {})) & set(runs.get(ref, {}))
        if key.endswith("_tight"):
            both = {s for s in both if runs[rung][s].get("loosely_wound") is False
                    and runs[ref][s].get("loosely_wound") is False}
        ok = sorted(int(s) for s in both if runs[rung][s]["converged"] and runs[ref][s]["converged"]
                    and runs[rung][s].get(q) is not None and runs[ref][s].get(q) is not None)
        if len(ok) < 2:
            continue
        a = np.array([runs[rung][str(s)][q] for s in ok])
        b = np.array([runs[ref][str(s)][q] for s in ok])
        tol = tolerance if q == quantity and not key.endswith("_tight") else 1.0
        c = distributions.compare(a, b, tol, paired=True)
        out.setdefault(q, {})[key] = {
            "seeds": len(ok), "left_out": sorted(int(s) for s in both if int(s) not in ok),
            "shift": c.shift, "se": c.se, "bound95": c.bound, "resolution": c.resolution, "p_ad": c.p_ad,
            "verdict": c.verdict if tol != 1.0 else "described", "tolerance": tol,
            "seeds_needed": c.seeds_needed if tol != 1.0 else None, "jumps": c.jumps,
            "median_run_s": float(np.median([runs[rung][str(s)]["wall_s"] for s in ok])),
            "median_run_s_finest": float(np.median([runs[ref][str(s)]["wall_s"] for s in ok]))}
    out["loosely_wound"] = {r: {"seeds": len(runs.get(r, {})),
                                "loosely_wound": sum(1 for v in runs.get(r, {}).values() if v.get("loosely_wound"))}
                            for r in rungs}
    shares = list(zip(rungs[:-1], rungs[1:])) + [(r, finest) for r in rungs[:-2]]
    for rung, nxt in shares:
        both = sorted(set(runs.get(rung, {})) & set(runs.get(nxt, {})), key=int)
        flags = [(runs[rung][s].get("loosely_wound"), runs[nxt][s].get("loosely_wound")) for s in both]
        flags = [(bool(x), bool(y)) for x, y in flags if x is not None and y is not None]
        only_a = sum(1 for x, y in flags if x and not y)
        only_b = sum(1 for x, y in flags if y and not x)
        p = binomtest(min(only_a, only_b), only_a + only_b, 0.5).pvalue if only_a + only_b else 1.0
        out["loosely_wound"][rung][f"vs_{nxt}"] = {"paired_seeds": len(flags), "only_here": only_a,
                                                    "only_there": only_b, "mcnemar_p": float(p)}
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--figure", required=True, help="a convergence ladder of --config")
    ap.add_argument("--config", type=Path, default=CONFIG, help="the config the ladder is in (default: %(default)s)")
    ap.add_argument("--rungs", nargs="+", default=["dx002", "dx0005"], help="coarse to fine; the last is the reference")
    ap.add_argument("--quantity", default="F_transmitted", choices=QUANTITIES, help="the quantity decided")
    ap.add_argument("--tolerance", type=float, default=0.02, help="relative tolerance of --quantity")
    ap.add_argument("--seeds", type=int, default=52)
    ap.add_argument("--from-build", type=Path, default=None)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--extra-rung", nargs=2, action="append", default=[], metavar=("NAME", "PARAM=VALUE"),
                    help="a rung the config does not have: its finest rung with PARAM set to VALUE (a number)")
    a = ap.parse_args()
    extra = []
    for name, setting in a.extra_rung:
        param, sep, value = setting.partition("=")
        try:
            extra.append((name, param, int(value) if value.isdigit() else float(value)))
        except ValueError:
            raise SystemExit(f"--extra-rung {name}: {setting!r} is not PARAM=<number>") from None
        if not sep or not param:
            raise SystemExit(f"--extra-rung {name}: {setting!r} is not PARAM=<number>")
    extra = tuple(extra)
    path = RESULTS / f"study_seeds_{a.figure}.json"
    old = json.loads(path.read_text()) if path.exists() else {}
    runs: dict = old.get("runs", {})
    if a.from_build:
        for rung, by_seed in from_build(a.figure, a.rungs, a.seeds, a.from_build, a.config).items():
            runs.setdefault(rung, {}).update(by_seed)
    # seed by seed, every rung of a seed together: a study stopped part way leaves complete pairs
    todo = [(a.figure, r, s, extra, a.config.resolve()) for s in range(a.seeds) for r in a.rungs
            if str(s) not in runs.get(r, {})]
    print(f"{len(todo)} runs to make", flush=True)

    def save() -> dict:
        commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True,
                                text=True).stdout.strip()
        out = {"what": f"convergence ladder {a.figure} of {a.config.resolve().relative_to(ROOT)} extended by "
                       f"seeds: each rung against {a.rungs[-1]}, paired seed by seed "
                       f"(analysis.distributions.compare); {a.quantity} decided against {a.tolerance:g}",
               "figure": a.figure, "commit": commit, "rungs": a.rungs,
               "quantity": a.quantity, "tolerance": a.tolerance, "runs": runs,
               "comparisons": compare(runs, a.rungs, a.quantity, a.tolerance)}
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_suffix(".json.tmp")
        tmp.write_text(json.dumps(out, indent=1) + "\n")
        tmp.replace(path)
        return out

    with ProcessPoolExecutor(a.jobs) as pool:
        for k, (rung, seed, v) in enumerate(pool.map(one, todo)):
            runs.setdefault(rung, {})[str(seed)] = v
            print(f"{rung} s{seed}: F {v['F_transmitted']:.5g} in {v['wall_s']:.0f} s"
                  f"{'' if v['converged'] else ' (not converged)'}", flush=True)
            if k % 10 == 9:
                save()              # an interrupted study keeps what it ran
    print(json.dumps(save()["comparisons"], indent=1))


if __name__ == "__main__":
    main()
