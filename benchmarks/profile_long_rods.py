"""Where the implicit solver's time goes on long rods, by friction law and stick stiffness
(issue: the whole paper in 10 minutes; target L/R = 1280 <= 10 s); writes
benchmarks/results/profile_long_rods.json.

Setup: Fig 6's rods at the publication numerics (load 0.25 EI/R^2, k_fr = 0.8, l0 = 0.5 R,
k_ph = 1e4, k_w = 1e3, tol 1e-5, dx_max 0.02 R), the straight start, one core. Settings, run
interleaved per seed (the machine is shared: compare within a run):

* ``ends``: the default, friction at the link ends with the stick spring k_t = k_ph/l0;
* ``ends_one_pass``: the same with the active-set model of one pass that switches ends from slip
  to stick only (no end_slip_model): the solver before the slip switch;
* ``ends_soft_kt``: friction at the ends with k_t = k_w (= k_ph/(10 l0) here), off the rigid-stick
  limit the ends law needs (its F(L) depends on k_t l0/k_ph below about 0.5), kept to show what the
  stiffness costs;
* ``centre``: friction at the link centres with its default k_t = k_w/10 (the law before the
  ends law; its F(L) drifts with l0).

Per run: wall time (solver only), accepted steps, the work counters, and each implicit step's
Newton iterations (``_newton`` calls, accepted or not), summarised by tenth of the run's steps:
where in the run the iterations and the failed Newton solves fall, and the median dt there. The
stick spring sets how far one Newton iteration carries a change of axial force into a stuck
stretch, sqrt(k_ph/(l0 k_t)) links (solvers/implicit.py): 1 link at the default.

Usage: python benchmarks/profile_long_rods.py [--lengths 320 640] [--seeds 3]
       [--long 1280] [--wall-cap 400] [--note TEXT]
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import signal
import statistics
import time
from pathlib import Path

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from confined_rod import Scene  # noqa: E402
from confined_rod.io import provenance  # noqa: E402
from confined_rod.sim.solvers import implicit  # noqa: E402
from confined_rod.sim.solvers.base import run_protocol  # noqa: E402

PUBLICATION = dict(load=0.25, k_fr=0.8, l0=0.5, k_ph=1e4, k_w=1e3, tol=1e-5)
SETTINGS = {  # scene parameters, stepper options
    "ends": ({}, {}),
    "ends_one_pass": ({}, {"slip_model": False, "active_set_passes": 1}),
    "ends_soft_kt": ({"k_t": 1e3}, {}),
    "centre": ({"friction_at": "centre"}, {}),
}
TENTHS = 10


class WallCap(Exception):
    pass


def _alarm(*_):
    raise WallCap()


class RecordingStepper(implicit.ImplicitStepper):
    """The implicit stepper, recording every Newton solve: its iterations, whether it converged
    and the step's dt (beta/cr)."""

    def __init__(self, scene: Scene, **options):
        super().__init__(scene, **options)
        self.record: list[tuple[int, bool, float]] = []

    def _newton(self, r, t, st):
        before = st.work.get("newton_iterations", 0)
        ok = False
        try:
            super()._newton(r, t, st)
            ok = True
        finally:
            self.record.append((st.work.get("newton_iterations", 0) - before, ok, self.beta / self.cr))


def by_tenth(record: list[tuple[int, bool, float]]) -> dict:
    its = np.array([x[0] for x in record])
    ok = np.array([x[1] for x in record])
    dt = np.array([x[2] for x in record])
    parts = np.array_split(np.arange(its.size), TENTHS)
    return {"newton_iterations": [int(its[p].sum()) for p in parts],
            "failed_solves": [int((~ok[p]).sum()) for p in parts],
            "median_dt": [float(np.median(dt[p])) if p.size else None for p in parts],
            "iterations_per_solve_p50_p90_max": [float(np.percentile(its, 50)), float(np.percentile(its, 90)),
                                                 int(its.max())] if its.size else None}


def run(L: float, seed: int, setting: str, wall_cap: float) -> dict:
    extra, options = SETTINGS[setting]
    sc = Scene(L=L, seed=seed, name=f"profile/L{L:g}-s{seed}-{setting}", **PUBLICATION, **extra)
    steppers: list[RecordingStepper] = []

    def make(s):
        steppers.append(RecordingStepper(s, **options))
        return steppers[-1]

    signal.signal(signal.SIGALRM, _alarm)
    signal.setitimer(signal.ITIMER_REAL, wall_cap)
    t0 = time.perf_counter()
    row = {"L": L, "seed": seed, "setting": setting, "N": sc.N, "k_t": sc.k_t, "friction_at": sc.friction_at}
    try:
        st = run_protocol(sc, make, progress=False)
    except WallCap:
        row.update(wall_s=time.perf_counter() - t0, converged=False, stopped=f"wall-clock cap of {wall_cap:g} s")
    else:
        row.update(wall_s=time.perf_counter() - t0, converged=bool(st.converged), steps=st.steps, work=dict(st.work))
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
    record = [x for s in steppers for x in s.record]
    if record:
        row["by_tenth_of_run"] = by_tenth(record)
    return row


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--lengths", type=float, nargs="+", default=[320, 640])
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--long", type=float, nargs="*", default=[1280], help="lengths run for seed 0 only")
    ap.add_argument("--wall-cap", type=float, default=400.0, help="seconds; a run beyond is stopped and reported")
    ap.add_argument("--note", default="", help="how the machine was used meanwhile (stored with the numbers)")
    ap.add_argument("-o", "--output", default=str(Path(__file__).parent / "results" / "profile_long_rods.json"))
    a = ap.parse_args()
    run(20.0, 0, "ends", a.wall_cap)  # numba's cache loaded before anything is timed
    plan = [(L, s) for L in a.lengths for s in range(a.seeds)] + [(L, 0) for L in a.long]
    rows = []
    for k, (L, seed) in enumerate(plan):
        order = list(SETTINGS) if k % 2 == 0 else list(SETTINGS)[::-1]
        for setting in order:
            rows.append(run(L, seed, setting, a.wall_cap))
            r = rows[-1]
            print(json.dumps({x: r.get(x) for x in ("L", "seed", "setting", "wall_s", "steps", "converged")}),
                  flush=True)
    summary = {}
    for L in sorted({r["L"] for r in rows}):
        summary[f"{L:g}"] = {s: {"median_wall_s": statistics.median(r["wall_s"] for r in rows
                                                                    if r["L"] == L and r["setting"] == s),
                                 "median_newton_iterations": statistics.median(
                                     r["work"]["newton_iterations"] for r in rows
                                     if r["L"] == L and r["setting"] == s and "work" in r) if any(
                                     "work" in r for r in rows if r["L"] == L and r["setting"] == s) else None,
                                 "runs": sum(1 for r in rows if r["L"] == L and r["setting"] == s)}
                             for s in SETTINGS}
    result = {"machine": platform.machine(), "provenance": provenance(), "note": a.note,
              "setup": "Fig 6's rods at the publication numerics: " + ", ".join(f"{k} {v:g}" for k, v in
                                                                               PUBLICATION.items())
                       + "; dx_max 0.02; straight start; one core; solver time only",
              "settings": {k: {"scene": v[0], "stepper": v[1]} for k, v in SETTINGS.items()},
              "summary": summary, "runs": rows}
    out = Path(a.output)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_suffix(".tmp")
    tmp.write_text(json.dumps(result, indent=1))
    tmp.replace(out)
    print(json.dumps(summary, indent=1))


if __name__ == "__main__":
    main()
