"""Where a contact's friction acts, and the frictional l0 ladder: does F(L)'s ensemble mean
converge in l0 with friction at the link ends? Writes benchmarks/results/study_friction_at.json
(docs/model.md, "Friction").

The rod of the ladder conv_l0 (L = 80 R, load 0.25 EI/R^2, k_fr = 0.8, straight start loaded at
once, the same continuous rod on every rung), at each link length of ``--l0``, with the wall
friction at the link centres (``centre``: a stuck link can still turn about its centre, so the
end that touches the wall slides, held only by bending) and at the link ends (``ends``, the
default: each end on the wall has its own normal force, bound and stick anchor, as the wall
force acts). Where a contact's friction acts should not matter as l0 -> 0; that it does at
finite l0 points at the centre model's contacts that press with one end only (the lower
region's). Reported per model and rung: the ensemble mean of |F_z(L)| with its
standard error, and the paired shift of every rung against the finest (mean of F/F_finest - 1
over the seeds, with its standard error), and the median run time; and how far apart the two
laws' means are per l0 (``centre_over_ends``). Each law runs at its own default stick stiffness
(centre: k_t = k_w/10; ends: the bond constant k_ph/l0).

Part ``k_t`` (stored as ``k_t_ladder``): the stick stiffness as the ratio k_t l0/k_ph (the stick
spring over the bond constant), at l0 = 0.5 and 0.125 R, paired against the stiffest ratio of
each law (the rigid Coulomb law is k_t -> infinity; the centre law runs up to 0.5, where its
F(L) no longer moves). The same ratio at both link lengths giving the same shift shows that
the ratio, not k_t, is what the ends law's F(L) depends on.

Usage: python benchmarks/study_friction_at.py [--seeds 64] [--l0 0.5 0.25 0.125 0.0625]
           [--ratio 0.005 0.05 0.15 0.5 1 2] [--kt-seeds 32] [--parts l0 k_t] [--jobs 2]
(a part left out keeps its numbers from the existing file; `--parts` alone only recomputes
centre_over_ends from them)
"""
from __future__ import annotations

import argparse
import json
import math
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from confined_rod.sim import observables
from confined_rod.sim.scenes import Scene
from confined_rod.sim.solvers import implicit

OUT = Path(__file__).resolve().parent / "results" / "study_friction_at.json"
BASE = {"L": 80, "load": 0.25, "k_fr": 0.8, "k_ph": 1.0e4, "k_w": 1.0e3, "tol": 1.0e-5}
MODELS = ("centre", "ends")
KT_L0 = (0.5, 0.125)  # the link lengths of the k_t part
RATIO_MAX = {"centre": 0.5, "ends": 2.0}  # the stiffest ratio k_t l0/k_ph run per law


def one(args: tuple[str, float, int, float]) -> tuple[str, float, int, float, float]:
    """One run: ``ratio`` = 0 runs the law's default k_t at link length ``l0``."""
    model, l0, seed, ratio = args
    extra = {"k_t": ratio * BASE["k_ph"] / l0} if ratio else {}
    scene = Scene(**BASE, l0=l0, seed=seed, friction_at=model, name=f"{model}-l0{l0:g}-r{ratio:g}-s{seed}", **extra)
    t0 = time.perf_counter()
    st = implicit.run(scene, progress=False)
    wall = time.perf_counter() - t0
    if not st.converged:
        raise RuntimeError(f"{scene.name}: not at equilibrium (eps_F {st.eps_F:.3g}); the study needs every run")
    return model, (ratio or l0), seed, observables.compute(scene, st.r, st.t, st.anchor).F_transmitted, wall


def mean_se(x: np.ndarray) -> tuple[float, float]:
    return float(x.mean()), float(x.std(ddof=1) / math.sqrt(x.size))


def ladder(values: list[float], models, seeds: int, jobs: int, l0: float | None = None) -> dict:
    """Per model and rung: the ensemble mean of |F_z(L)|, its paired shift against the model's
    last rung (the finest l0, or the stiffest ratio k_t l0/k_ph at link length ``l0``), and the
    median run time. ``l0`` None: the rungs are link lengths; else they are ratios."""
    runs = {m: [x for x in values if l0 is None or x <= RATIO_MAX[m]] for m in models}
    tasks = [(m, x if l0 is None else l0, s, 0.0 if l0 is None else x)
             for m in models for x in runs[m] for s in range(seeds)]
    F: dict = {}
    wall: dict = {}
    with ProcessPoolExecutor(jobs) as pool:
        for m, x, s, f, w in pool.map(one, tasks):
            F.setdefault(m, {}).setdefault(x, {})[s] = f
            wall.setdefault(m, {}).setdefault(x, []).append(w)
    out = {}
    for m in models:
        ref = np.array([F[m][runs[m][-1]][s] for s in range(seeds)])
        rows = {}
        for x in runs[m]:
            v = np.array([F[m][x][s] for s in range(seeds)])
            mu, se = mean_se(v)
            sh, sh_se = mean_se(v / ref - 1.0)
            rows[f"{x:g}"] = {"F_L": mu, "F_L_se": se, "shift_vs_finest": sh, "shift_vs_finest_se": sh_se,
                              "median_run_s": float(np.median(wall[m][x]))}
        out[m] = rows
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=64)
    ap.add_argument("--l0", type=float, nargs="+", default=[0.5, 0.25, 0.125, 0.0625])
    ap.add_argument("--ratio", type=float, nargs="+", default=[0.005, 0.05, 0.15, 0.5, 1.0, 2.0])
    ap.add_argument("--kt-seeds", type=int, default=32)
    ap.add_argument("--parts", nargs="*", default=["l0", "k_t"], choices=["l0", "k_t"])
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--models", nargs="+", default=list(MODELS), choices=MODELS)
    a = ap.parse_args()
    out = json.loads(OUT.read_text()) if OUT.exists() else {}
    out.update({"base": BASE, "quantity": "|F_z(L)| (EI/R^2)"})
    if "l0" in a.parts:
        l0s = sorted(a.l0, reverse=True)
        out.update({"seeds": a.seeds, "l0": l0s, "k_t": "each law's default (centre: k_w/10; ends: k_ph/l0)"})
        out["models"] = ladder(l0s, a.models, a.seeds, a.jobs)
    if "k_t" in a.parts:
        ratios = sorted(a.ratio)
        out["k_t_ladder"] = {"l0": list(KT_L0), "ratio": ratios, "ratio_is": "k_t l0 / k_ph", "seeds": a.kt_seeds,
                             "shift_vs": "the stiffest ratio of the law (RATIO_MAX)", "ratio_max": RATIO_MAX,
                             "by_l0": {f"{l0:g}": ladder(ratios, a.models, a.kt_seeds, a.jobs, l0) for l0 in KT_L0}}
    if {"centre", "ends"} <= set(out.get("models", {})):  # how far apart the two laws are per l0
        c, e = out["models"]["centre"], out["models"]["ends"]
        out["centre_over_ends"] = {
            x: {"ratio_minus_1": c[x]["F_L"] / e[x]["F_L"] - 1.0,
                "se": c[x]["F_L"] / e[x]["F_L"]
                * math.hypot(c[x]["F_L_se"] / c[x]["F_L"], e[x]["F_L_se"] / e[x]["F_L"])}
            for x in c if x in e}
    OUT.parent.mkdir(parents=True, exist_ok=True)
    tmp = OUT.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(out, indent=1) + "\n")
    tmp.replace(OUT)
    print(json.dumps({k: out[k] for k in ("models", "centre_over_ends", "k_t_ladder") if k in out}, indent=1))


if __name__ == "__main__":
    main()
