"""Is the frictional l0 ladder's shift of F(L) in the equilibria or in the path that selects
one? Writes benchmarks/results/study_l0_restart.json (issue 43).

The rod of the ladder conv_l0 (L = 80 R, load 0.25 EI/R^2, k_fr = 0.8, straight start loaded at
once), paired by seed, at a coarse link length (``coarse``, 0.25 R) and a fine one (``fine``,
0.0625 R). Three questions, each answered over the same seeds:

* ``restart``: the coarse chain's equilibrium, refined exactly (every link split into four
  collinear links of the fine length, the stick anchors likewise: the same rod, the same end
  points), relaxed again on the fine chain. If the coarse equilibrium is (nearly) an equilibrium
  of the fine chain, F(L) stays at the coarse value; if the equilibria themselves depend on l0,
  it moves to the fine one.
* ``switch``: the coarse chain's path up to time T (in beta_ph R^4/EI), refined there and
  continued on the fine chain to equilibrium, for several T: where along the path the two
  chains part. T = 0 is the fine run from the coarse chain's start (the same continuous rod).
* ``stiffness``: the fine chain with the wall and stick stiffnesses per link lowered so that
  their stiffness per length is that of the coarse chain's (k_w and k_t times fine/coarse), one
  at a time: whether the ladder's shift is the wall or the stick anchors growing stiffer per
  length as l0 shrinks (the k_w and k_t ladders vary them at one l0).

Reported: the paired relative shift of F(L) against the coarse run (mean of F/F_coarse - 1 over
the seeds, with its standard error) for every variant, and against the fine run for the
stiffness variants. Each run is one process's solver call, one core.

Usage: python benchmarks/study_l0_restart.py [--seeds 16]
"""
from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import numpy as np

from confined_rod.sim import observables
from confined_rod.sim.scenes import Scene
from confined_rod.sim.solvers import implicit
from confined_rod.sim.solvers.base import RunState

OUT = Path(__file__).resolve().parent / "results" / "study_l0_restart.json"
BASE = {"L": 80, "load": 0.25, "k_fr": 0.8, "k_ph": 1.0e4, "k_w": 1.0e3, "tol": 1.0e-5}
COARSE, FINE = 0.25, 0.0625
SWITCH_TIMES = (0.0, 100.0, 1000.0, 5000.0)


def refine(r: np.ndarray, t: np.ndarray, l0: float, parts: int) -> tuple[np.ndarray, np.ndarray]:
    """Every link of length l0 split into ``parts`` collinear links of l0/parts (link 0 stays at
    the support): the same rod, its joints kept, new joints on the old links' axes."""
    off = (np.arange(parts) + 0.5) / parts - 0.5          # centres of the parts along the link
    rr = (r[:, None, :] + l0 * off[None, :, None] * t[:, None, :]).reshape(-1, 3)
    tt = np.repeat(t, parts, axis=0)
    return np.ascontiguousarray(rr), np.ascontiguousarray(tt)


def _F(scene: Scene, st: RunState) -> float:
    if not st.converged:
        raise RuntimeError(f"{scene.name}: not at equilibrium; the study needs every run")
    return observables.compute(scene, st.r, st.t).F_transmitted


def _continue_fine(coarse: Scene, fine: Scene, st: RunState) -> float:
    """Refine the coarse state (and its anchors) onto the fine chain and relax it there."""
    parts = int(round(coarse.l0 / fine.l0))
    r, t = refine(st.r, st.t, coarse.l0, parts)
    new = RunState(r=r, t=t)
    if st.anchor is not None:
        new.anchor = refine(st.anchor, st.t, coarse.l0, parts)[0]
    implicit.relax(fine, new, progress=False)
    return _F(fine, new)


def _shift(x, ref) -> dict:
    d = np.asarray(x, dtype=float) / np.asarray(ref, dtype=float) - 1.0
    return {"percent": float(100 * d.mean()), "se_percent": float(100 * d.std(ddof=1) / math.sqrt(d.size))}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=16)
    args = ap.parse_args()
    ratio = COARSE / FINE
    F = {k: [] for k in ("coarse", "fine", "restart", *(f"switch_T{T:g}" for T in SWITCH_TIMES),
                         "fine_wall_per_length", "fine_stick_per_length")}
    t0 = time.perf_counter()
    for seed in range(args.seeds):
        coarse = Scene.from_dict({**BASE, "l0": COARSE, "seed": seed})
        fine = Scene.from_dict({**BASE, "l0": FINE, "seed": seed})
        stc = implicit.run(coarse, progress=False)
        F["coarse"].append(_F(coarse, stc))
        stf = implicit.run(fine, progress=False)
        F["fine"].append(_F(fine, stf))
        F["restart"].append(_continue_fine(coarse, fine, stc))
        for T in SWITCH_TIMES:
            r, t = coarse.initial_state()
            st = RunState(r=r, t=t)
            if T > 0:
                implicit.relax(coarse, st, t_end=T, progress=False)
            F[f"switch_T{T:g}"].append(_continue_fine(coarse, fine, st))
        for key, change in (("fine_wall_per_length", {"k_w": BASE["k_w"] / ratio, "k_t": fine.k_t}),
                            ("fine_stick_per_length", {"k_t": fine.k_t / ratio})):
            sc = Scene.from_dict({**BASE, "l0": FINE, "seed": seed, **change})
            F[key].append(_F(sc, implicit.run(sc, progress=False)))
        print(f"seed {seed}: " + ", ".join(f"{k} {v[-1]:.5f}" for k, v in F.items()), flush=True)
    out = {
        "description": __doc__.split("\n\n")[0],
        "rod": BASE, "coarse_l0": COARSE, "fine_l0": FINE, "seeds": args.seeds,
        "switch_times": list(SWITCH_TIMES),
        "mean_F_transmitted": {k: float(np.mean(v)) for k, v in F.items()},
        "shift_vs_coarse": {k: _shift(v, F["coarse"]) for k, v in F.items() if k != "coarse"},
        "shift_vs_fine": {k: _shift(F[k], F["fine"]) for k in ("fine_wall_per_length", "fine_stick_per_length")},
        "wall_seconds": time.perf_counter() - t0,
    }
    OUT.parent.mkdir(parents=True, exist_ok=True)
    tmp = OUT.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(out, indent=1) + "\n")
    tmp.replace(OUT)
    print(json.dumps(out["shift_vs_coarse"], indent=1), json.dumps(out["shift_vs_fine"], indent=1))


if __name__ == "__main__":
    main()
