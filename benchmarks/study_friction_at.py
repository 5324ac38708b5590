"""Where a contact's friction acts, and the frictional l0 ladder: does F(L)'s ensemble mean
converge in l0 with friction at the link ends? Writes benchmarks/results/study_friction_at.json
(docs/model.md, "Friction").

The rod of the ladder conv_l0 (L = 80 R, load 0.25 EI/R^2, k_fr = 0.8, straight start loaded at
once, the same continuous rod on every rung), at each link length of ``--l0``, with the wall
friction at the link centres (``centre``: a stuck link can still turn about its centre, so the
end that touches the wall slides, held only by bending; the default) and at the link ends
(``ends``: each end on the wall has its own normal force, bound and stick anchor, as the wall
force acts). Where a contact's friction acts should not matter as l0 -> 0; that it does at
finite l0 points at the centre model's contacts that press with one end only (the lower
region's). Reported per model and rung: the ensemble mean of |F_z(L)| with its
standard error, and the paired shift of every rung against the finest (mean of F/F_finest - 1
over the seeds, with its standard error), and the median run time. The same for the stick
stiffness k_t (part ``k_t``, stored as ``k_t_ladder``: at l0 = 0.5, the k_t ladder's rungs 100,
1000, 10000 EI/R^3, paired against the stiffest; the rigid Coulomb law is k_t -> infinity).

Usage: python benchmarks/study_friction_at.py [--seeds 64] [--l0 0.5 0.25 0.125 0.0625]
           [--k_t 100 1000 10000] [--parts l0 k_t] [--jobs 2]
(a part left out keeps its numbers from the existing file)
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
KT_L0 = 0.5  # the link length of the k_t part


def one(args: tuple[str, float, int, float]) -> tuple[str, float, int, float, float]:
    model, x, seed, kt = args
    l0 = x if kt == 0.0 else KT_L0
    extra = {"k_t": kt} if kt else {}
    scene = Scene(**BASE, l0=l0, seed=seed, friction_at=model, name=f"{model}-l0{l0:g}-kt{kt:g}-s{seed}", **extra)
    t0 = time.perf_counter()
    st = implicit.run(scene, progress=False)
    wall = time.perf_counter() - t0
    if not st.converged:
        raise RuntimeError(f"{scene.name}: not at equilibrium (eps_F {st.eps_F:.3g}); the study needs every run")
    return model, x, seed, observables.compute(scene, st.r, st.t).F_transmitted, wall


def mean_se(x: np.ndarray) -> tuple[float, float]:
    return float(x.mean()), float(x.std(ddof=1) / math.sqrt(x.size))


def ladder(values: list[float], models, seeds: int, jobs: int, kt: bool) -> dict:
    """Per model and rung: the ensemble mean of |F_z(L)|, its paired shift against the last rung
    of ``values`` (the finest l0 or the stiffest k_t), and the median run time."""
    tasks = [(m, x, s, x if kt else 0.0) for x in values for m in models for s in range(seeds)]
    F: dict = {}
    wall: dict = {}
    with ProcessPoolExecutor(jobs) as pool:
        for m, x, s, f, w in pool.map(one, tasks):
            F.setdefault(m, {}).setdefault(x, {})[s] = f
            wall.setdefault(m, {}).setdefault(x, []).append(w)
    out = {}
    for m in models:
        ref = np.array([F[m][values[-1]][s] for s in range(seeds)])
        rows = {}
        for x in values:
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
    ap.add_argument("--k_t", type=float, nargs="+", default=[100.0, 1000.0, 10000.0])
    ap.add_argument("--parts", nargs="+", default=["l0", "k_t"], choices=["l0", "k_t"])
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--models", nargs="+", default=list(MODELS), choices=MODELS)
    a = ap.parse_args()
    out = json.loads(OUT.read_text()) if OUT.exists() else {}
    out.update({"base": BASE, "seeds": a.seeds, "quantity": "|F_z(L)| (EI/R^2)"})
    if "l0" in a.parts:
        l0s = sorted(a.l0, reverse=True)
        out["l0"] = l0s
        out["models"] = ladder(l0s, a.models, a.seeds, a.jobs, kt=False)
    if "k_t" in a.parts:
        kts = sorted(a.k_t)
        out["k_t_ladder"] = {"l0": KT_L0, "k_t": kts, "shift_vs": "the stiffest k_t",
                             "models": ladder(kts, a.models, a.seeds, a.jobs, kt=True)}
    OUT.parent.mkdir(parents=True, exist_ok=True)
    tmp = OUT.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(out, indent=1) + "\n")
    tmp.replace(OUT)
    print(json.dumps({k: out[k] for k in ("models", "k_t_ladder") if k in out}, indent=1))


if __name__ == "__main__":
    main()
