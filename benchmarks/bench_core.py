"""Benchmark of the core model and the explicit solver; writes its numbers to a file.

1. Force kernel: nanoseconds per link per evaluation of all forces and torques
   (conservative_loads, and conservative_loads + coulomb_friction), and of a full
   explicit Euler step, on a helical state, for several N. Median of repeats;
   both variants are timed in the same run, interleaved.
2. Time to equilibrium of the explicit (paper-faithful) solver for L/R = 20, 40,
   80 at load 0.25 EI/R^2, k_fr = 0.8, default numerics: wall time, simulated
   time, steps, transmitted force.

Usage: python benchmarks/bench_core.py [--lengths 20 40 80] [-o benchmarks/results/core.json]
Single core: NUMBA_NUM_THREADS=1 is set; the kernels are serial anyway.
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

import numpy as np  # noqa: E402

from confined_rod import Scene, simulate  # noqa: E402
from confined_rod.io import provenance  # noqa: E402
from confined_rod.sim.model import kernels as K  # noqa: E402
from confined_rod.sim.model.forces import Workspace  # noqa: E402


def helical_state(scene: Scene):
    s = (np.arange(scene.N) + 0.5) * scene.l0
    w = 0.35
    r = np.stack([np.cos(w * s), np.sin(w * s), s * np.sqrt(1 - w**2)], axis=1) * 1.0001
    t = np.stack([-w * np.sin(w * s), w * np.cos(w * s), np.full_like(s, np.sqrt(1 - w**2))], axis=1)
    return np.ascontiguousarray(r), np.ascontiguousarray(t)


def kernel_timings(sizes, repeats=15):
    rows = []
    for N in sizes:
        sc = Scene(L=N * 0.5, l0=0.5, k_fr=0.8)
        r, t = helical_state(sc)
        par = sc.params()
        ws = Workspace.for_links(N)
        inner = max(10, 200_000 // N)

        def forces():
            for _ in range(inner):
                K.conservative_loads(r, t, par, ws.Fm, ws.Fp, ws.F, ws.M, ws.Nw)

        def forces_friction():
            for _ in range(inner):
                K.conservative_loads(r, t, par, ws.Fm, ws.Fp, ws.F, ws.M, ws.Nw)
                K.coulomb_friction(r, par, ws.Nw, ws.F, ws.Ff, ws.stuck)

        def steps():
            rr, tt = r.copy(), t.copy()
            K.explicit_steps(rr, tt, par, 1e-9, inner, ws.Fm, ws.Fp, ws.F, ws.M, ws.Nw, ws.Ff, ws.stuck)

        variants = {"forces": forces, "forces+friction": forces_friction, "explicit_step": steps}
        for f in variants.values():
            f()  # compile / warm up
        samples = {k: [] for k in variants}
        for _ in range(repeats):
            for name, f in variants.items():  # interleaved: same machine state for all
                t0 = time.perf_counter()
                f()
                samples[name].append((time.perf_counter() - t0) / (inner * N) * 1e9)
        for name, xs in samples.items():
            rows.append({"N": N, "what": name, "ns_per_link_per_eval_median": statistics.median(xs),
                         "ns_min": min(xs), "ns_max": max(xs), "repeats": repeats})
            print(f"N = {N:5d}  {name:16s} {statistics.median(xs):7.1f} ns/link (median of {repeats})", flush=True)
    return rows


def equilibrium_timings(lengths, load=0.25, k_fr=0.8):
    rows = []
    for L in lengths:
        sc = Scene(L=float(L), load=load, k_fr=k_fr, name=f"bench_L{L}")
        t0 = time.perf_counter()
        ds = simulate(sc, progress=True)
        wall = time.perf_counter() - t0
        row = {"L_over_R": L, "load": load, "k_fr": k_fr, "N": sc.N, "l0": sc.l0, "k_ph": sc.k_ph,
               "k_w": sc.k_w, "tol": sc.tol, "dt": sc.dt(), "wall_time_s": wall,
               "simulated_time": float(ds.t_final), "steps": int(ds.n_steps),
               "converged": int(ds.converged), "escaped": int(ds.escaped),
               "F_transmitted": float(ds.F_transmitted), "L_z": float(ds.L_z),
               "links_in_contact": int(ds.contact.sum())}
        rows.append(row)
        print(json.dumps(row), flush=True)
    return rows


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--lengths", type=int, nargs="*", default=[20, 40, 80])
    ap.add_argument("--sizes", type=int, nargs="*", default=[40, 160, 640, 1280])
    ap.add_argument("-o", "--output", type=Path, default=Path(__file__).parent / "results" / "core.json")
    args = ap.parse_args()
    out = {"machine": {"platform": platform.platform(), "processor": platform.processor(),
                       "cpu_count": os.cpu_count()},
           "provenance": provenance(),
           "kernel": kernel_timings(args.sizes),
           "equilibrium_explicit": equilibrium_timings(args.lengths)}
    args.output.parent.mkdir(parents=True, exist_ok=True)
    tmp = args.output.with_suffix(".tmp")
    tmp.write_text(json.dumps(out, indent=2))
    tmp.replace(args.output)
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
