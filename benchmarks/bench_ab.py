"""This checkout's solver against another checkout's (an earlier commit), at the publication
numerics, in the same run; writes benchmarks/results/ab.json (or -o).

For a change of the solver: make a worktree of the commit before it
(``git worktree add /tmp/before <commit>``) and give its path.  For each length and seed the
two run in turn, each in a fresh process (``python benchmarks/bench_ab.py --one ...`` with
PYTHONPATH set to the checkout's src/ and a numba cache of its own, warmed first), so the
machine's drift hits both alike; reported per run: the solver's wall time (process start-up
excluded), steps, Newton iterations, |F_z(L)| and the number of reversals of handedness, and per
length the medians and the median of the per-seed ratios this/other.  The rods are Fig 6's
(load 0.25, k_fr 0.8, l0 0.5 R, k_ph 1e4, k_w 1e3, tol 1e-5, straight start), one core; with
``--ramp-steps n`` they are loaded by the quasi-static ramp of n loads instead (the protocol of
the ramped figures, Fig 4(c)'s rod with --lengths 320 --ramp-steps 128).

Usage: python benchmarks/bench_ab.py OTHER_CHECKOUT [--lengths 640 1280] [--seeds 5] [--ramp-steps N]
                                     [--k-fr K] [-o PATH]
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

PUBLICATION = dict(load=0.25, k_fr=0.8, l0=0.5, k_ph=1e4, k_w=1e3, tol=1e-5)
HERE = Path(__file__).resolve().parents[1]


def one(L: float, seed: int, ramp_steps: int = 0, k_fr: float | None = None) -> dict:
    """One run in this process (the child's side)."""
    import numpy as np
    import xarray as xr

    import confined_rod
    from confined_rod import Scene
    from confined_rod.analysis import ensembles
    from confined_rod.sim import observables as obs
    from confined_rod.sim.solvers.base import run_protocol
    from confined_rod.sim.solvers.implicit import ImplicitStepper

    protocol = dict(protocol="ramp", ramp_steps=ramp_steps) if ramp_steps else {}
    numerics = PUBLICATION | ({} if k_fr is None else {"k_fr": k_fr})
    sc = Scene(L=L, seed=seed, name=f"ab/L{L:g}-s{seed}", **numerics, **protocol)
    t0 = time.perf_counter()
    st = run_protocol(sc, ImplicitStepper, progress=False)
    wall = time.perf_counter() - t0
    o = obs.compute(sc, st.r, st.t)
    sim = xr.Dataset({c: ("link", np.ascontiguousarray(st.r[:, k])) for k, c in enumerate("xyz")}
                     | {"s_link": ("link", o.s_link)}, attrs={"R": sc.R})
    return {"L": L, "seed": seed, "wall_s": wall, "converged": bool(st.converged), "steps": st.steps,
            "newton_iterations": st.work.get("newton_iterations", 0), "F_transmitted": float(o.F_transmitted),
            "reversals": len(ensembles.shape(sim).reversals), "package": str(Path(confined_rod.__file__).parent)}


def child(checkout: Path, L: float, seed: int, ramp_steps: int = 0, k_fr: float | None = None) -> dict:
    env = dict(os.environ, PYTHONPATH=str(checkout / "src"), NUMBA_CACHE_DIR=str(checkout / ".numba_cache_ab"),
               NUMBA_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    out = subprocess.run([sys.executable, __file__, "--one", str(L), str(seed), str(ramp_steps)]
                         + ([] if k_fr is None else ["--k-fr", str(k_fr)]), env=env, check=True,
                         capture_output=True, text=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def git_commit(checkout: Path) -> str:
    return subprocess.run(["git", "-C", str(checkout), "rev-parse", "HEAD"], capture_output=True,
                          text=True).stdout.strip() or "unknown"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("other", nargs="?", help="the other checkout (a worktree of an earlier commit)")
    ap.add_argument("--lengths", type=float, nargs="+", default=[640, 1280])
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--ramp-steps", type=int, default=0, help="load by a ramp of this many loads (0: full load)")
    ap.add_argument("--k-fr", type=float, default=None,
                    help="wall friction k_fr instead of Fig 6's 0.8 (0.3: Fig 4(b))")
    ap.add_argument("--one", type=float, nargs=3, metavar=("L", "SEED", "RAMP"), help=argparse.SUPPRESS)
    ap.add_argument("-o", "--output", default="benchmarks/results/ab.json")
    args = ap.parse_args()
    if args.one:
        print(json.dumps(one(args.one[0], int(args.one[1]), int(args.one[2]), args.k_fr)))
        return
    if not args.other or not (Path(args.other) / "src" / "confined_rod").is_dir():
        raise SystemExit(f"bench_ab: the other checkout {args.other!r} has no src/confined_rod")
    sides = {"this": HERE, "other": Path(args.other).resolve()}
    for path in sides.values():  # compile or load each side's numba cache outside the timed runs
        child(path, 10.0, 0)
    out: dict = {"setup": "Fig 6's rods at the publication numerics, " + ", ".join(f"{k} {v:g}" for k, v in
                                                                                    PUBLICATION.items())
                 + ("" if args.k_fr is None else f", k_fr {args.k_fr:g} instead")
                 + (f"; ramp of {args.ramp_steps} loads" if args.ramp_steps else "; straight start")
                 + "; one core; solver time only; this and other in turn, fresh processes",
                 "this": {"path": str(HERE), "git_commit": git_commit(HERE)},
                 "other": {"path": str(sides["other"]), "git_commit": git_commit(sides["other"])},
                 "lengths": []}
    path = Path(args.output)
    path.parent.mkdir(parents=True, exist_ok=True)
    for L in args.lengths:
        runs = []
        for seed in range(args.seeds):
            pair = {side: child(p, L, seed, args.ramp_steps, args.k_fr) for side, p in sides.items()}
            runs.append(pair)
            print(json.dumps(pair), flush=True)
        row = {"L": L, "runs": runs}
        for side in sides:
            row[f"median_wall_s_{side}"] = statistics.median(r[side]["wall_s"] for r in runs)
            row[f"median_newton_iterations_{side}"] = statistics.median(r[side]["newton_iterations"] for r in runs)
        row["median_ratio_this_over_other"] = statistics.median(r["this"]["wall_s"] / r["other"]["wall_s"]
                                                                for r in runs)
        row["same_final_state"] = sum(r["this"]["reversals"] == r["other"]["reversals"]
                                      and abs(r["this"]["F_transmitted"] / r["other"]["F_transmitted"] - 1) < 0.01
                                      for r in runs)
        out["lengths"].append(row)
        path.write_text(json.dumps(out, indent=1))
        print(json.dumps({k: v for k, v in row.items() if k != "runs"}), flush=True)


if __name__ == "__main__":
    main()
