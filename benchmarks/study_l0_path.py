"""Where the frictional l0 ladder's shift of F(L) sits, under other relaxation paths (issue 43);
writes benchmarks/results/study_l0_path.json.

The ladder conv_l0 (L = 80 R, load 0.25 EI/R^2, k_fr = 0.8, the straight start loaded at once)
finds the transmitted force of the publication rung l0 = 0.5 R a per cent or two below that of
l0 = 0.125 R, split by region from the loaded end (regions.force_parts). This study runs the same
pair of rungs, paired by seed, with the publication path (``publication``) and with two other
paths that reach equilibria of the same model: a four times finer path accuracy (``dx_max``
0.005 R) and the rotational drag of a straight link turning about its centre (``rigid_link``,
beta l0^3/12 instead of the paper's beta l0 R^2). A shift that is a property of the
discretisation of the equilibrium stays; one that a path setting moves belongs to the path.

Reported per variant: the relative shift of the ensemble mean of |F_z(L)| (paired: mean of
F_pub/F_fine - 1 over the seeds, with its standard error), its split by region
(-F_fine(L) times the change of what each region adds to 1/|F_z|, over the seeds with a bulk on
both rungs), and the net share of the Coulomb limit the lower region's contacts carry axially
(regions.friction_use) on both rungs. Each run is one process's solver call, one core.

Usage: python benchmarks/study_l0_path.py [--seeds 64] [--variants publication dx_max rigid_link]
"""
from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import numpy as np

from confined_rod.analysis import regions
from confined_rod.sim.scenes import Scene
from confined_rod.sim.simulation import simulate

OUT = Path(__file__).resolve().parent / "results" / "study_l0_path.json"
BASE = {"L": 80, "load": 0.25, "k_fr": 0.8, "k_ph": 1.0e4, "k_w": 1.0e3, "tol": 1.0e-5}
VARIANTS = {"publication": {}, "dx_max": {"dx_max": 0.005}, "rigid_link": {"rotational_drag": "rigid_link"}}
RUNGS = (0.5, 0.125)


def _mean_se(x) -> tuple[float, float]:
    x = np.asarray(x, dtype=float)
    return float(x.mean()), float(x.std(ddof=1) / math.sqrt(x.size))


def run_variant(name: str, seeds: int) -> dict:
    shifts, parts, use = [], {r: [] for r in regions.REGIONS}, {str(l0): [] for l0 in RUNGS}
    wall = []
    for seed in range(seeds):
        out = {}
        for l0 in RUNGS:
            scene = Scene.from_dict({**BASE, **VARIANTS[name], "l0": l0, "seed": seed})
            t = time.perf_counter()
            sim = simulate(scene, progress=False)
            wall.append(time.perf_counter() - t)
            if not int(sim["converged"]):
                raise RuntimeError(f"{name}, seed {seed}, l0 {l0}: not at equilibrium; the study needs every run")
            an = regions.analyse(sim)
            out[l0] = (abs(float(sim["F_z"].values[-1])), regions.force_parts(sim, an),
                       regions.friction_use(sim, "lower", an))
        (f_pub, p_pub, u_pub), (f_fine, p_fine, u_fine) = out[RUNGS[0]], out[RUNGS[1]]
        shifts.append(f_pub / f_fine - 1.0)
        if p_pub is not None and p_fine is not None:
            for r in regions.REGIONS:
                parts[r].append(-f_fine * (p_pub[r] - p_fine[r]))
        if u_pub is not None and u_fine is not None:
            use[str(RUNGS[0])].append(u_pub)
            use[str(RUNGS[1])].append(u_fine)
    return {"settings": {**BASE, **VARIANTS[name]}, "seeds": seeds,
            "F_shift": _mean_se(shifts),
            "F_shift_by_region": {r: _mean_se(v) for r, v in parts.items()},
            "seeds_with_bulk": len(parts["tip"]),
            "lower_friction_use": {k: _mean_se(v) for k, v in use.items()},
            "median_wall_s": float(np.median(wall))}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seeds", type=int, default=64)
    ap.add_argument("--variants", nargs="+", default=list(VARIANTS), choices=list(VARIANTS))
    args = ap.parse_args()
    if args.seeds < 2:
        ap.error(f"--seeds {args.seeds}: a standard error needs at least 2 seeds")
    result = {"rungs_l0": list(RUNGS), "shift": "F(l0 = 0.5)/F(l0 = 0.125) - 1, mean and standard error over seeds",
              "variants": {v: run_variant(v, args.seeds) for v in args.variants}}
    OUT.parent.mkdir(parents=True, exist_ok=True)
    tmp = OUT.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(result, indent=1))
    tmp.replace(OUT)
    for v, r in result["variants"].items():
        parts = ", ".join(f"{k} {100 * m:+.2f} +- {100 * e:.2f} %" for k, (m, e) in r["F_shift_by_region"].items())
        print(f"{v}: F(L) shift {100 * r['F_shift'][0]:+.2f} +- {100 * r['F_shift'][1]:.2f} % ({parts})")


if __name__ == "__main__":
    main()
