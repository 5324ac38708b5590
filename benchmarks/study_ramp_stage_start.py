"""Does a frictional ramp's outcome depend on how each stage starts its relaxation?

    python benchmarks/study_ramp_stage_start.py [--seeds 10] [--ramp-steps 256] [--starts 10 1 drift]
                                                [-o benchmarks/results/study_ramp_stage_start.json]

Every stage of protocol 'ramp' starts a new implicit stepper at its first step,
implicit.DT_START_FACTOR x the explicit stability limit (10 by default), and dt grows by at most
2x per step from there: the first steps resolve the transient that the load increment starts.
The alternative ``drift`` starts every stage after the first at the step the step control would
take after a step at the stage's forces: the fastest link end's drift under them (|F|/beta +
h |M x t|/gamma_r, i.e. the load increment) carried 0.9 dx_max, never less than the default
start (1.34x faster on this rod: benchmarks/results/ab_ramp_resume.json). This study runs Fig
4(b)'s rod (L/R = 320, k_fr = 0.3, load 0.25, publication numerics, a ramp of --ramp-steps
loads) for the same seeds with each start (a number: that factor) and records, per run, what
the ramp ladders compare (convergence._member_values: F(L), the ratios to the torque-free helix,
whether the helix is loosely wound), the steps, Newton iterations and solver time; per start
the loosely wound share, and per start against the first the paired mean shift of F(L) with its
95 % error and the seeds whose loosely wound state differs. One core, in turn per seed.
"""
from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))
from confined_rod import Scene  # noqa: E402
from confined_rod.analysis.figures import convergence  # noqa: E402
from confined_rod.io import provenance  # noqa: E402
from confined_rod.sim import simulation  # noqa: E402
from confined_rod.sim.model import kernels as K  # noqa: E402
from confined_rod.sim.model.forces import evaluate  # noqa: E402
from confined_rod.sim.solvers import base, implicit  # noqa: E402

ROD = dict(L=320.0, load=0.25, k_fr=0.3, l0=0.5, k_ph=1e4, k_w=1e3, tol=1e-5, protocol="ramp")


def drift_start(stepper: implicit.ImplicitStepper, st: base.RunState) -> None:
    """The ``drift`` start of a stage (module docstring)."""
    anchors = st.anchor if stepper.ends and st.anchor is not None else None
    evaluate(stepper.par, st.r, st.t, stepper.ws, anchors, stepper.kt)
    fmax, mmax = K.residuals(st.t, stepper.ws.F, stepper.ws.M)
    drift = fmax / stepper.beta + stepper.h * mmax / stepper.gamma_r
    if drift > 0.0:
        stepper.dt = max(stepper.dt, 0.9 * stepper.dx_max / drift)


def one(seed: int, ramp_steps: int, start: str) -> dict:
    sc = Scene(seed=seed, ramp_steps=ramp_steps, name=f"stage_start/{start}-s{seed}", **ROD)
    factor, orig = implicit.DT_START_FACTOR, base.relax

    def relax(stage, st, stepper, **kw):  # a stage after the first: a fresh stepper on a state that has moved
        if start == "drift" and st.steps > 0 and stepper.prev_dt == 0.0:
            drift_start(stepper, st)
        return orig(stage, st, stepper, **kw)

    try:
        if start != "drift":
            implicit.DT_START_FACTOR = float(start)
        base.relax = relax
        t0 = time.perf_counter()
        ds = simulation.simulate(sc, progress=False)
        wall = time.perf_counter() - t0
    finally:
        implicit.DT_START_FACTOR, base.relax = factor, orig
    v = convergence._member_values(ds)
    return {"seed": seed, "start": start, "wall_s": wall, "status": str(ds["status"].values),
            "steps": int(ds["n_steps"]), "newton_iterations": int(ds.attrs.get("work_newton_iterations", 0))} \
        | {k: (None if x is None or not np.isfinite(x) else float(x)) for k, x in v.items()}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--ramp-steps", type=int, default=256)
    ap.add_argument("--starts", nargs="+", default=["10", "1", "drift"])
    ap.add_argument("-o", "--output", default=str(ROOT / "benchmarks/results/study_ramp_stage_start.json"))
    a = ap.parse_args()
    runs = []
    for seed in range(a.seeds):
        for f in a.starts:
            runs.append(one(seed, a.ramp_steps, f))
            print(json.dumps(runs[-1]), flush=True)
    by = {f: {r["seed"]: r for r in runs if r["start"] == f} for f in a.starts}
    ref = a.starts[0]
    summary = {}
    for f in a.starts:
        rs = list(by[f].values())
        row = {"loosely_wound": sum(1 for r in rs if r.get("loosely_wound") == 1.0), "runs": len(rs),
               "mean_F_transmitted": statistics.mean(r["F_transmitted"] for r in rs),
               "median_wall_s": statistics.median(r["wall_s"] for r in rs),
               "median_steps": statistics.median(r["steps"] for r in rs)}
        if f != ref:
            d = [by[f][s]["F_transmitted"] / by[ref][s]["F_transmitted"] - 1 for s in by[f] if s in by[ref]]
            row["F_transmitted_paired_shift"] = statistics.mean(d)
            row["F_transmitted_shift_95"] = 1.96 * statistics.stdev(d) / len(d) ** 0.5 if len(d) > 1 else None
            row["seeds_changing_loose_state"] = [s for s in by[f] if s in by[ref] and
                                                 by[f][s].get("loosely_wound") != by[ref][s].get("loosely_wound")]
        summary[f] = row
    out = {"setup": "Fig 4(b)'s rod: " + ", ".join(f"{k} {v}" for k, v in ROD.items())
           + f", ramp of {a.ramp_steps} loads; first step of every stage: a number x the explicit limit, or"
           " 'drift' (module docstring); one core",
           "provenance": provenance(), "reference_start": ref, "summary": summary, "runs": runs}
    Path(a.output).write_text(json.dumps(out, indent=1) + "\n")
    print(json.dumps(summary, indent=1))


if __name__ == "__main__":
    main()
