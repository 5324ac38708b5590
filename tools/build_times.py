"""Per-rule totals of a Snakemake build, from its benchmark files.

Reads results/benchmarks/<rule>/.../*.tsv (one per job: wall seconds first) and
writes a JSON summary: the wall time of the whole build (if given), the number
of jobs and the summed job seconds per rule, the longest jobs, and what running a
scene costs beyond its solver (``run_overhead``: the job seconds of the rules that run
scenes, batch, simulate and probe, less the solver times their datasets store, per scene), the
job seconds per figure (``by_figure``: from the folder its benchmark files sit in), and
the solver seconds of the simulations per rod length L (``solver_by_L``: runs, sum, median and
longest solver time, and how many did not end at equilibrium).

Usage: python tools/build_times.py [--results results] [--wall SECONDS] [--note TEXT]
                                   [-o benchmarks/results/publication_build.json]
"""
from __future__ import annotations

import argparse
import csv
import json
import os
import platform
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))
from confined_rod import layout  # noqa: E402


def job_times(results: Path) -> list[dict]:
    rows = []
    for tsv in sorted(layout.under(results, layout.BENCHMARKS).rglob("*.tsv")):
        with tsv.open() as fh:
            records = list(csv.DictReader(fh, delimiter="\t"))
        if not records:
            continue
        rel = tsv.relative_to(layout.under(results, layout.BENCHMARKS))
        rows.append({"rule": rel.parts[0], "job": str(rel.with_suffix("")), "s": float(records[-1]["s"])})
    return rows


SCENE_RULES = ("batch", "simulate", "probe")
#: rules whose benchmark files sit under a folder named after a figure: <rule>/<figure>/... (the
#: batches one level deeper, batch/<what>/<figure>/...)
FIGURE_RULES = ("simulate", "probe", "load_path", "postprocess", "figure", "convergence_check")


def figure_of(job: str) -> str | None:
    """The figure a job's benchmark path belongs to, None for the build-wide rules (claims, paper)."""
    parts = Path(job).parts
    if parts[0] == "batch" and len(parts) >= 4:
        return parts[2]
    if parts[0] in FIGURE_RULES and len(parts) >= 2:
        return parts[1].split(".")[0]
    return None


def by_figure(jobs: list[dict]) -> dict:
    """Job seconds and jobs per figure, largest first: what each figure, ladder or study costs."""
    out: dict = {}
    for j in jobs:
        f = figure_of(j["job"]) or j["rule"]
        r = out.setdefault(f, {"jobs": 0, "job_s": 0.0})
        r["jobs"] += 1
        r["job_s"] += j["s"]
    return dict(sorted(out.items(), key=lambda kv: -kv[1]["job_s"]))


def run_overhead(results: Path, jobs: list[dict]) -> dict:
    """Job seconds of the scene-running rules beyond the solver times stored in their datasets."""
    import netCDF4

    solver, scenes = 0.0, 0
    for folder in (layout.SIMS, layout.PROBES):
        for nc in layout.under(results, folder).rglob("*.nc"):
            with netCDF4.Dataset(nc) as ds:
                solver += float(ds["wall_time"][...]) if "wall_time" in ds.variables else 0.0
            scenes += 1
    job_s = sum(j["s"] for j in jobs if j["rule"] in SCENE_RULES)
    return {"scenes": scenes, "job_s": job_s, "solver_s": solver,
            "per_scene_s": (job_s - solver) / scenes if scenes else None}


def solver_by_length(results: Path) -> dict:
    """Solver seconds of the simulations (results/sims) grouped by the rod length L."""
    import statistics

    import netCDF4

    by: dict = {}
    for nc in layout.under(results, layout.SIMS).rglob("*.nc"):
        with netCDF4.Dataset(nc) as ds:
            if "wall_time" not in ds.variables:
                continue
            L = float(ds.getncattr("L"))
            row = by.setdefault(L, {"times": [], "not_converged": 0})
            row["times"].append(float(ds["wall_time"][...]))
            row["not_converged"] += int(not int(ds["converged"][...])) if "converged" in ds.variables else 0
    return {f"{L:g}": {"runs": len(r["times"]), "solver_s": sum(r["times"]), "median_s": statistics.median(r["times"]),
                       "longest_s": max(r["times"]), "not_converged": r["not_converged"]}
            for L, r in sorted(by.items())}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--results", default=str(layout.RESULTS))
    ap.add_argument("--wall", type=float, default=None, help="measured wall time of the whole build, s")
    ap.add_argument("--note", default="")
    ap.add_argument("-o", "--output", default="benchmarks/results/publication_build.json")
    args = ap.parse_args()
    jobs = job_times(Path(args.results))
    if not jobs:
        raise SystemExit(f"no benchmark files under {args.results}/benchmarks: run the build first")
    rules: dict = {}
    for j in jobs:
        r = rules.setdefault(j["rule"], {"jobs": 0, "job_s": 0.0, "longest_s": 0.0})
        r["jobs"] += 1
        r["job_s"] += j["s"]
        r["longest_s"] = max(r["longest_s"], j["s"])
    out = {"machine": platform.processor() or platform.machine(), "cpus": os.cpu_count(), "note": args.note,
           "wall_s": args.wall, "jobs": len(jobs), "job_s_total": sum(j["s"] for j in jobs),
           "rules": dict(sorted(rules.items(), key=lambda kv: -kv[1]["job_s"])),
           "by_figure": by_figure(jobs),
           "longest_jobs": sorted(jobs, key=lambda j: -j["s"])[:15],
           "run_overhead": run_overhead(Path(args.results), jobs),
           "solver_by_L": solver_by_length(Path(args.results))}
    Path(args.output).parent.mkdir(parents=True, exist_ok=True)
    Path(args.output).write_text(json.dumps(out, indent=1))
    for name, r in out["rules"].items():
        print(f"{name:20s} {r['jobs']:4d} jobs {r['job_s']:8.1f} s (longest {r['longest_s']:.1f} s)")
    print(f"total {out['job_s_total']:.1f} job-s in {len(jobs)} jobs; wall {args.wall} s")
    o = out["run_overhead"]
    if o["scenes"]:
        print(f"running {o['scenes']} scenes: {o['job_s']:.1f} job-s, {o['solver_s']:.1f} s in their solvers, "
              f"{o['per_scene_s']:.2f} s per scene beyond them")
    for L, r in out["solver_by_L"].items():
        print(f"L/R = {L:>6s}: {r['runs']:4d} runs, {r['solver_s']:8.1f} s in their solvers (median "
              f"{r['median_s']:.2f} s, longest {r['longest_s']:.1f} s, {r['not_converged']} not at equilibrium)")


if __name__ == "__main__":
    main()
