"""What each convergence ladder of a finished build would have decided with fewer seeds, and what
those seeds cost: the profile that sets a ladder's ensemble size (issue 44).

A ladder's rung of ``seeds: n`` runs seeds 0 .. n-1, each from the same start on every rung, and a
run does not depend on the ensemble it belongs to, so the ladder of ``seeds: m`` (m < n) is the
build's ladder restricted to seeds 0 .. m-1, bit for bit. For every ladder of seed ensembles in the
build's config and every m of ``--seeds`` this rebuilds the ladder's dataset from the build's own
scene files (analysis.postprocess.build, the rule's code, with the rule's context) and records:

* the verdict word (pass, fail, inconclusive) and the status line;
* the largest resolution at 95 % power over the comparisons that decide (quantities and rungs),
  relative to its tolerance (a passing ladder needs it <= 1; its margin says how many seeds the
  pass rests on);
* the solver time of the kept runs (the wall_time the runs store), against the full ladder's.

Reads results/ under ``--build`` (a checkout whose ``snakemake`` has finished) with its
config; writes benchmarks/results/ladder_subsets_<commit>.json. The verdicts at fewer seeds are
what a build of those seeds would print on this machine; on another machine round-off can move a
seed to a neighbouring equilibrium, which is why a ladder's seeds keep a margin over the
smallest m that decides.

Usage: python benchmarks/study_ladder_subsets.py --build /tmp/pub [--config config/config.yaml]
           [--figures conv_ramp_steps_b ...] [--seeds 4 6 8 10 12 16 20 24 32]
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
from pathlib import Path

import numpy as np

RESULTS = Path(__file__).resolve().parent / "results"


def ladder_subsets(figure: str, config: dict, seed_counts: list[int]) -> dict:
    """The ladder ``figure`` of the build in the current directory at each seed count (module
    docstring); ``config`` expanded (pipeline.expand)."""
    from confined_rod import pipeline
    from confined_rod.analysis import postprocess, run_checks
    from confined_rod.analysis.figures.convergence import verdict_word

    fig_cfg = config["figures"][figure]
    # the rule's own inputs (a rung may share another figure's runs), each checked against the scene
    # the config asks for, as rule postprocess checks them (a stale file is refused in one line)
    sims = {name: run_checks.load(path, wanted)
            for name, path, wanted in zip(pipeline.scenes(config, figure), pipeline.figure_sims(config, figure),
                                          pipeline.figure_wanted(config, figure))}
    read = {name: run_checks.load(path) for name, path in pipeline.read_figures(config, figure).items()}
    context = {**pipeline.context(config, figure), "datasets": read}
    seed_of = {name: int(ds.attrs.get("seed", 0)) for name, ds in sims.items()}
    wall = {name: float(ds["wall_time"]) for name, ds in sims.items()}
    n_max = max(seed_of.values()) + 1
    rows = []
    for m in sorted({*(c for c in seed_counts if c < n_max), n_max}):
        kept = {n: d for n, d in sims.items() if seed_of[n] < m}
        try:
            ds = postprocess.build(figure, fig_cfg, kept, context)
        except ValueError as exc:  # a subset too small for the ladder's tests
            rows.append({"seeds": m, "verdict": "error", "status": f"{type(exc).__name__}: {exc}"})
            continue
        status = str(ds.attrs["status"])
        res = None
        if "cmp_resolution" in ds and "cmp_verdict_code" in ds:
            # the comparisons that decide (codes 1-3: within, beyond, undecided; 4 only describes)
            deciding = np.isin(ds["cmp_verdict_code"].values, (1, 2, 3))
            tol = ds["cmp_compared_tolerance"].values
            r = ds["cmp_resolution"].values[deciding] / tol[deciding]
            res = float(np.max(r)) if r.size else None
        rows.append({"seeds": m, "runs": len(kept), "verdict": verdict_word(status), "status": status,
                     "max_resolution_over_tolerance": res,
                     "solver_s": round(sum(wall[n] for n in kept), 2)})
    full = rows[-1]
    for row in rows:
        row["solver_share"] = round(row.get("solver_s", 0.0) / full["solver_s"], 3) if full.get("solver_s") else None
    # the smallest seed count from which every larger one gives the full ladder's verdict
    stable = full["seeds"]
    for row in reversed(rows):
        if row["verdict"] != full["verdict"]:
            break
        stable = row["seeds"]
    return {"figure": figure, "seeds_in_build": n_max, "verdict": full["verdict"],
            "stable_from_seeds": stable, "subsets": rows}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", required=True, help="a checkout whose publication build has finished")
    ap.add_argument("--config", default="config/config.yaml", help="the build's config, relative to --build")
    ap.add_argument("--figures", nargs="*", help="ladders to study (default: every ladder of seed ensembles)")
    ap.add_argument("--seeds", nargs="*", type=int, default=[4, 6, 8, 10, 12, 16, 20, 24, 32])
    ap.add_argument("-o", "--out", help="default benchmarks/results/ladder_subsets_<commit>.json")
    args = ap.parse_args()
    build = Path(args.build).resolve()
    out_path = Path(args.out).resolve() if args.out else None  # relative to where it is called from
    os.chdir(build)  # layout's paths are relative to the checkout
    from confined_rod import pipeline

    config = pipeline.expand(pipeline.read_config(Path(args.config)))
    figures = args.figures or [f for f, c in config["figures"].items() if c.get("kind") == "convergence"
                               and any(sc.seed > 0 for sc in pipeline.built_scenes(config, f).values())]
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                            cwd=build).stdout.strip()
    out = {"what": __doc__.splitlines()[0], "build": str(build), "commit": commit, "config": args.config,
           "ladders": []}
    for figure in figures:
        r = ladder_subsets(figure, config, args.seeds)
        out["ladders"].append(r)
        print(f"{figure}: {r['verdict']} with {r['seeds_in_build']} seeds; same verdict from "
              f"{r['stable_from_seeds']} seeds on; "
              + ", ".join(f"{x['seeds']}:{x['verdict'][:4]}"
                          + (f"/{x['max_resolution_over_tolerance']:.2f}" if x.get("max_resolution_over_tolerance")
                             else "") + f"/{x.get('solver_s', 0):.0f}s" for x in r["subsets"]), flush=True)
    path = out_path or RESULTS / f"ladder_subsets_{commit}.json"
    path.write_text(json.dumps(out, indent=1) + "\n")
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
