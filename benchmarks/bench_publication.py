"""The solver at the numerics the figures are built with (issue: fast at the numerics we
publish); writes benchmarks/results/publication.json.

Setup: Fig 6's rods, load 0.25 EI/R^2, k_fr = 0.8, l0 = 0.5 R, k_ph = 1e4, k_w = 1e3, tol 1e-5,
the straight start (the paper's protocol), seeds 0-4, one core.  For each length and seed, in the
same run and interleaved (the machine is shared: only same-run ratios are compared):

* ``now``: the default numerics (dx_max = 0.02 R, k_t = k_w/10, no cut of dt after slow
  Newton steps, the Newton direction solved again on the branches the step predicts);
* ``previous``: the solver before this change (k_t = k_w, dt halved after a step of more than
  10 Newton iterations, the plain Newton direction without the active-set guess), which built
  the figures until now; only the friction bound at rest (which acts once the rod has stopped)
  is new in it;
* ``reference`` (lengths up to --ref-max): dx_max = 0.005 R and k_t = k_w, the dx_max-refined
  reference of the same seed.

Reported per length: the median wall time of each setting (solver only: the process start-up is
the subject of bench_startup), the ratio previous/now per seed and its median, the work counters,
and the exponent of the median wall time of ``now`` against N = L/l0 (least-squares slope of
log t against log N over all lengths).  Accuracy per seed: |F_z(L)| of now and previous against
the reference, and whether the final state is the same (number of reversals of handedness, and
their places within SAME_PLACE of each other: ensembles.shape).  A difference of more than 1 %
with a different final state is a different equilibrium, not an error of the path; how often
that happens is counted for both settings.

Usage: python benchmarks/bench_publication.py [--lengths 80 160 320 640 1280] [--seeds 5]
       [--ref-max 640] [--wall-cap 600]
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
import xarray as xr  # noqa: E402

from confined_rod import Scene  # noqa: E402
from confined_rod.analysis import ensembles  # noqa: E402
from confined_rod.io import provenance  # noqa: E402
from confined_rod.sim import observables as obs  # noqa: E402
from confined_rod.sim.solvers.base import run_protocol  # noqa: E402
from confined_rod.sim.solvers.implicit import ImplicitStepper  # noqa: E402

PUBLICATION = dict(load=0.25, k_fr=0.8, l0=0.5, k_ph=1e4, k_w=1e3, tol=1e-5)
SETTINGS = {  # scene parameters, stepper options
    "now": ({}, {}),
    "previous": ({"k_t": 1e3}, {"newton_slow": 10, "active_set": False}),
    "reference": ({"k_t": 1e3, "dx_max": 0.005}, {}),
}
SAME_PLACE = 5.0  # R: two reversals of handedness within this distance are the same defect
ACCURACY = 0.01  # the bound on |F_z(L)| against the reference


class WallCap(Exception):
    pass


def _alarm(*_):
    raise WallCap()


def run(L: float, seed: int, setting: str, wall_cap: float) -> dict:
    extra, options = SETTINGS[setting]
    sc = Scene(L=L, seed=seed, name=f"bench/L{L:g}-s{seed}-{setting}", **PUBLICATION, **extra)
    signal.signal(signal.SIGALRM, _alarm)
    signal.setitimer(signal.ITIMER_REAL, wall_cap)
    t0 = time.perf_counter()
    try:
        st = run_protocol(sc, lambda s: ImplicitStepper(s, **options), progress=False)
    except WallCap:
        return {"L": L, "seed": seed, "setting": setting, "wall_s": time.perf_counter() - t0,
                "converged": False, "stopped": f"wall-clock cap of {wall_cap:g} s"}
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
    wall = time.perf_counter() - t0
    o = obs.compute(sc, st.r, st.t)
    sim = xr.Dataset({c: ("link", st.r[:, k]) for k, c in enumerate("xyz")} | {"s_link": ("link", o.s_link)},
                     attrs={"R": sc.R})
    shape = ensembles.shape(sim)
    return {"L": L, "seed": seed, "setting": setting, "N": sc.N, "wall_s": wall, "converged": bool(st.converged),
            "F_transmitted": float(o.F_transmitted), "steps": st.steps, "work": dict(st.work),
            "reversals": [float(v) for v in shape.reversals], "net_turns": shape.net_turns}


def same_state(a: dict, b: dict) -> bool:
    ra, rb = a["reversals"], b["reversals"]
    return len(ra) == len(rb) and all(abs(x - y) <= SAME_PLACE for x, y in zip(sorted(ra), sorted(rb)))


def accuracy(rows: list[dict], ref: dict) -> dict:
    out = {}
    for r in rows:
        if not (r.get("converged") and ref.get("converged")):
            continue
        err = abs(r["F_transmitted"] - ref["F_transmitted"]) / abs(ref["F_transmitted"])
        out[r["setting"]] = {"rel_error": err, "same_state": same_state(r, ref),
                             "within": err <= ACCURACY}
    return out


def slope(x, y) -> float:
    return float(np.polyfit(np.log(x), np.log(y), 1)[0])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--lengths", type=float, nargs="+", default=[80, 160, 320, 640, 1280])
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--ref-max", type=float, default=640.0, help="largest length with a refined reference")
    ap.add_argument("--wall-cap", type=float, default=600.0, help="seconds; a run beyond is stopped and reported")
    ap.add_argument("-o", "--output", default=str(Path(__file__).parent / "results" / "publication.json"))
    a = ap.parse_args()
    run(20.0, 0, "now", a.wall_cap)                      # numba's cache loaded before anything is timed
    per_length = []
    for L in a.lengths:
        runs, acc = [], []
        for seed in range(a.seeds):
            pair = [run(L, seed, s, a.wall_cap) for s in (("now", "previous") if seed % 2 == 0 else ("previous", "now"))]
            runs += pair
            if L <= a.ref_max:
                ref = run(L, seed, "reference", 4 * a.wall_cap)
                runs.append(ref)
                acc.append({"seed": seed, "F_reference": ref.get("F_transmitted"), **accuracy(pair, ref)})
            print(json.dumps({"L": L, "seed": seed, **{r["setting"]: round(r["wall_s"], 2) for r in pair}}), flush=True)
        by = {s: [r for r in runs if r["setting"] == s] for s in SETTINGS}
        med = {s: statistics.median(r["wall_s"] for r in v) for s, v in by.items() if v}
        ratios = [p["wall_s"] / n["wall_s"] for p, n in zip(by["previous"], by["now"])]
        entry = {"L": L, "N": int(round(L / PUBLICATION["l0"])), "median_wall_s": med,
                 "median_ratio_previous_over_now": statistics.median(ratios), "runs": runs}
        if acc:
            entry["accuracy"] = acc
            for s in ("now", "previous"):
                rows = [x[s] for x in acc if s in x]
                entry[f"{s}_within_1pct"] = sum(x["within"] for x in rows)
                entry[f"{s}_beyond_1pct_other_state"] = sum((not x["within"]) and not x["same_state"] for x in rows)
                entry[f"{s}_beyond_1pct_same_state"] = sum((not x["within"]) and x["same_state"] for x in rows)
                entry[f"{s}_median_rel_error"] = statistics.median(x["rel_error"] for x in rows) if rows else None
        per_length.append(entry)
    N = [e["N"] for e in per_length]
    result = {
        "machine": platform.machine(), "provenance": provenance(),
        "setup": "Fig 6's rods at the publication numerics: " + ", ".join(f"{k} {v:g}" for k, v in PUBLICATION.items())
                 + f"; straight start; seeds 0-{a.seeds - 1}; one core; solver time only",
        "settings": {k: {"scene": v[0], "stepper": v[1]} for k, v in SETTINGS.items()},
        "lengths": per_length,
        "exponent_now": slope(N, [e["median_wall_s"]["now"] for e in per_length]) if len(N) > 1 else None,
        "exponent_previous": slope(N, [e["median_wall_s"]["previous"] for e in per_length]) if len(N) > 1 else None,
        "targets": {"L640_s": 5.0, "L1280_s": 20.0, "exponent": 1.4, "accuracy": ACCURACY},
    }
    Path(a.output).parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(a.output).with_suffix(".tmp")
    tmp.write_text(json.dumps(result, indent=1))
    tmp.replace(a.output)
    print(json.dumps({e["L"]: e["median_wall_s"] for e in per_length}), "exponent now", result["exponent_now"])


if __name__ == "__main__":
    main()
