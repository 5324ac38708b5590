"""Per-rule totals of a Snakemake build, from its benchmark files.

Reads results/benchmarks/<rule>/.../*.tsv (one per job: wall seconds first) and
writes a JSON summary: the wall time of the whole build (if given), the number
of jobs and the summed job seconds per rule, and the longest jobs.

Usage: python tools/build_times.py [--results results] [--wall SECONDS] [--note TEXT]
                                   [-o benchmarks/results/publication_build.json]
"""
from __future__ import annotations

import argparse
import csv
import json
import os
import platform
from pathlib import Path


def job_times(results: Path) -> list[dict]:
    rows = []
    for tsv in sorted((results / "benchmarks").rglob("*.tsv")):
        with tsv.open() as fh:
            records = list(csv.DictReader(fh, delimiter="\t"))
        if not records:
            continue
        rel = tsv.relative_to(results / "benchmarks")
        rows.append({"rule": rel.parts[0], "job": str(rel.with_suffix("")), "s": float(records[-1]["s"])})
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--results", default="results")
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
           "longest_jobs": sorted(jobs, key=lambda j: -j["s"])[:15]}
    Path(args.output).parent.mkdir(parents=True, exist_ok=True)
    Path(args.output).write_text(json.dumps(out, indent=1))
    for name, r in out["rules"].items():
        print(f"{name:20s} {r['jobs']:4d} jobs {r['job_s']:8.1f} s (longest {r['longest_s']:.1f} s)")
    print(f"total {out['job_s_total']:.1f} job-s in {len(jobs)} jobs; wall {args.wall} s")


if __name__ == "__main__":
    main()
