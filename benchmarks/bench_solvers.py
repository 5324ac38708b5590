"""Implicit against explicit solver: time to equilibrium and cost exponent; writes
benchmarks/results/solvers.json.

1. Same-run comparison at L/R = 40 and 80 (load 0.25 EI/R^2, k_fr = 0.8, the
   publication numerics l0 = 0.5 R, k_ph = k_w = 1000, tol 1e-5): both solvers, run
   alternately, ``--repeats`` times each for the implicit one (median quoted) and
   once for the explicit one (minutes per run).  Error of each against the other:
   the relative difference of |F_z(L)| and the number of links on the wall.
2. Implicit solver alone at L/R = 20 ... 640: median wall time to equilibrium, and
   the exponent of wall time against the number of links N = L/l0 (least-squares
   slope of log time against log N).

Usage: python benchmarks/bench_solvers.py [--lengths 20 40 80 160 320 640] [--compare 40 80]
One core: NUMBA_NUM_THREADS=1 (the kernels are serial), and scipy's banded solve
is called on a single right-hand side.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import time
from pathlib import Path

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from confined_rod import Scene, simulate  # noqa: E402
from confined_rod.io import provenance  # noqa: E402


def run(L: float, solver: str, **kw) -> dict:
    sc = Scene(L=L, load=0.25, k_fr=0.8, solver=solver, name=f"bench_L{L:g}_{solver}", **kw)
    t0 = time.perf_counter()
    ds = simulate(sc, progress=False)
    wall = time.perf_counter() - t0
    return {"L": L, "solver": solver, "N": sc.N, "wall_s": wall, "F_transmitted": float(ds.F_transmitted),
            "n_contact": int(ds.contact.sum()), "converged": bool(ds.converged), "t_final": float(ds.t_final),
            "steps": int(ds.n_steps)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--lengths", type=float, nargs="+", default=[20, 40, 80, 160, 320, 640])
    ap.add_argument("--compare", type=float, nargs="*", default=[40, 80])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("-o", "--output", default="benchmarks/results/solvers.json")
    args = ap.parse_args()
    run(10.0, "implicit")  # compile / load the numba cache
    run(10.0, "explicit")
    out: dict = {"machine": platform.processor() or platform.machine(), "provenance": provenance(),
                 "setup": "load 0.25, k_fr 0.8, l0 0.5, k_ph = k_w = 1000, tol 1e-5, one core",
                 "compare": [], "implicit": []}
    for L in args.compare:
        imp = [run(L, "implicit") for _ in range(args.repeats)]
        exp = run(L, "explicit")
        med = statistics.median(r["wall_s"] for r in imp)
        row = {"L": L, "explicit": exp, "implicit_runs": imp, "implicit_median_s": med,
               "speedup": exp["wall_s"] / med,
               "rel_diff_F": abs(imp[0]["F_transmitted"] - exp["F_transmitted"]) / exp["F_transmitted"],
               "contact_explicit": exp["n_contact"], "contact_implicit": imp[0]["n_contact"]}
        out["compare"].append(row)
        print(json.dumps({k: v for k, v in row.items() if k != "implicit_runs"}), flush=True)
    for L in args.lengths:
        reps = 1 if L >= 320 else args.repeats
        runs = [run(L, "implicit") for _ in range(reps)]
        row = {"L": L, "N": runs[0]["N"], "median_s": statistics.median(r["wall_s"] for r in runs), "runs": runs}
        out["implicit"].append(row)
        print(json.dumps({k: v for k, v in row.items() if k != "runs"} | runs[0]), flush=True)
    N = np.array([r["N"] for r in out["implicit"]], float)
    T = np.array([r["median_s"] for r in out["implicit"]])
    if N.size >= 2:
        out["cost_exponent"] = float(np.polyfit(np.log(N), np.log(T), 1)[0])
        big = N >= 160
        if big.sum() >= 2:
            out["cost_exponent_N_ge_160"] = float(np.polyfit(np.log(N[big]), np.log(T[big]), 1)[0])
    Path(args.output).parent.mkdir(parents=True, exist_ok=True)
    Path(args.output).write_text(json.dumps(out, indent=1))
    print("cost exponent", out.get("cost_exponent"), out.get("cost_exponent_N_ge_160"))


if __name__ == "__main__":
    main()
