"""Where along a load ramp do two ramp resolutions send a seed to different final states?

    python benchmarks/study_ramp_divergence.py [--seeds 12] [--steps 256 512] [--jobs 2]
                                               [-o benchmarks/results/study_ramp_divergence.json]

Fig 4(b)'s rod (L/R = 320, k_fr = 0.3, load 0.25, publication numerics) is ramped with two
numbers of steps from the same straight start (same seed). After every stage the state is
described by what the ramp ladders compare at the end: the turns of the wall-contact stretch,
the wall force of the bulk helix over the torque-free helix's (K/(R F^2/4EI), median over the
middle half of the contact stretch, F the local axial force; below
local_relations.LOOSE_WALL_RATIO the helix is loosely wound: a proxy that can be read at every
stage, where the ramp ladders read the same ratio over the bulk helix that
analysis.regions finds in the final state, so the two can class a seed differently), the
transmitted fraction, and the
share of the contact links that are stuck. Between consecutive stages it records the slip
events: the largest jump of the turns and of the wall-force ratio, the stage where it happens,
and the stretch of the rod (s from the loaded end) whose azimuth moved most.

For each seed whose final states differ between the two ramps (loose state, or F(L) by more than
5 %), the first load at which the two descriptor paths part (turns more than half a turn apart,
or the loose state differs, compared at the nearest stage of the finer ramp) is reported as a
multiple of Euler's load and of the full load, beside the intermediate stage tolerance at that
load (solvers.base.ramp_stage: the round-off floor where it is above the scene's tol). A parting
at small loads, where the stage tolerance is largest, points at how strictly the early stages
are relaxed; a parting near the full load at the slips of the last stages.
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import math
import sys
import time
from multiprocessing import Pool
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))
from confined_rod import Scene  # noqa: E402
from confined_rod.analysis.local_relations import LOOSE_WALL_RATIO  # noqa: E402
from confined_rod.io import provenance  # noqa: E402
from confined_rod.sim import observables as obs  # noqa: E402
from confined_rod.sim.solvers import base, implicit  # noqa: E402

ROD = dict(L=320.0, load=0.25, k_fr=0.3, l0=0.5, k_ph=1e4, k_w=1e3, tol=1e-5, protocol="ramp")


def describe(scene: Scene, st, load: float, prev_phi: np.ndarray | None) -> tuple[dict, np.ndarray]:
    """The descriptors of one relaxed stage (module docstring) and the azimuth of every link."""
    o = obs.compute(scene, st.r, st.t, st.anchor)
    on = np.flatnonzero(o.contact > 0)
    phi_links = np.unwrap(np.arctan2(o.r[:, 1], o.r[:, 0]))
    out = {"load": load, "F_fraction": float(o.F_transmitted) / load,
           "turns": float((o.phi[-1] - o.phi[0]) / (2 * math.pi)) if o.phi.size > 1 else 0.0,
           "contacts": int(on.size), "stuck_share": float(o.stuck[on].mean()) if on.size else 0.0,
           "K_ratio": None}
    if on.size >= 8:
        lo, hi = on[0], on[-1]
        mid = np.arange(lo + (hi - lo) // 4, hi - (hi - lo) // 4 + 1)
        mid = mid[o.contact[mid] > 0]
        F_link = 0.5 * np.abs(o.F_z[mid] + o.F_z[mid + 1])
        K = o.wall_force[mid] / scene.l0
        ok = F_link > 0
        if ok.any():
            out["K_ratio"] = float(np.median(K[ok] / (scene.R * F_link[ok] ** 2 / (4 * scene.EI))))
    if prev_phi is not None:
        d = np.abs(phi_links - prev_phi)
        k = int(np.argmax(d))
        out["largest_azimuth_move"] = float(d[k])
        out["largest_move_at_s"] = float(o.s_link[k])
    return out, phi_links


def one(args: tuple[int, int, int]) -> dict:
    seed, steps, kicks = args
    sc = Scene(seed=seed, ramp_steps=steps, name=f"divergence/n{steps}-s{seed}", **ROD)
    stages: list[dict] = []
    prev = {"phi": None}
    orig = base.relax

    def relax(scene, st, stepper, **kw):
        out = orig(scene, st, stepper, **kw)
        if kw.get("label", "").startswith(" ramp"):
            if kicks:
                # the experiment: a stage that stops on the straight saddle is kicked off it, as a
                # run's end is (solvers.base.leave_saddles), so the ramp follows the buckled branch
                base.leave_saddles(dataclasses.replace(scene, saddle_kicks=kicks), st, implicit.ImplicitStepper,
                                   progress=False)
            d, prev["phi"] = describe(scene, st, float(scene.load), prev["phi"])
            d["stage_tol"] = float(scene.tol)
            stages.append(d)
        return out

    base.relax = relax
    try:
        t0 = time.perf_counter()
        implicit.run(sc, progress=False)
        wall = time.perf_counter() - t0
    finally:
        base.relax = orig
    euler = math.pi ** 2 * sc.EI / sc.L ** 2
    for d in stages:
        d["load_over_euler"] = d["load"] / euler
        d["loose"] = None if d["K_ratio"] is None else d["K_ratio"] < LOOSE_WALL_RATIO
    return {"seed": seed, "steps": steps, "wall_s": wall, "stages": stages}


def _jumps(stages: list[dict]) -> dict:
    """The largest change of turns and of K_ratio between consecutive stages, with where."""
    best_turns = max(range(1, len(stages)), key=lambda i: abs(stages[i]["turns"] - stages[i - 1]["turns"]))
    ks = [i for i in range(1, len(stages)) if stages[i]["K_ratio"] is not None and stages[i - 1]["K_ratio"] is not None]
    best_k = max(ks, key=lambda i: abs(stages[i]["K_ratio"] - stages[i - 1]["K_ratio"])) if ks else None
    out = {"turns_jump": stages[best_turns]["turns"] - stages[best_turns - 1]["turns"],
           "turns_jump_at_load_over_euler": stages[best_turns]["load_over_euler"],
           "turns_jump_s": stages[best_turns].get("largest_move_at_s")}
    if best_k is not None:
        out |= {"K_ratio_jump": stages[best_k]["K_ratio"] - stages[best_k - 1]["K_ratio"],
                "K_ratio_jump_at_load_over_euler": stages[best_k]["load_over_euler"],
                "K_ratio_jump_s": stages[best_k].get("largest_move_at_s")}
    return out


def parting(a: list[dict], b: list[dict]) -> dict | None:
    """The first stage of ramp a whose state differs from the nearest stage (in log load) of b."""
    lb = np.log([d["load"] for d in b])
    for d in a:
        e = b[int(np.argmin(np.abs(lb - math.log(d["load"]))))]
        turns_apart = abs(d["turns"] - e["turns"]) > 0.5
        loose_apart = d["loose"] is not None and e["loose"] is not None and d["loose"] != e["loose"]
        if turns_apart or loose_apart:
            return {"load_over_euler": d["load_over_euler"], "load_over_full": d["load"] / ROD["load"],
                    "why": "turns" if turns_apart else "loose state", "turns": [d["turns"], e["turns"]],
                    "K_ratio": [d["K_ratio"], e["K_ratio"]], "stage_tol": [d["stage_tol"], e["stage_tol"]]}
    return None


def _g(x: float) -> str:
    """Three significant digits, no exponent ('91.5', '1359')."""
    return f"{x:.3g}" if abs(x) < 1000 else f"{x:.0f}"


def summarise(runs: list[dict], seeds_n: int, steps: list[int]) -> tuple[list, dict, dict]:
    """Per seed: the final states of both ramps, whether they differ, where the paths part and
    the largest jumps; the summary; the manuscript's summary texts."""
    by = {(r["seed"], r["steps"]): r for r in runs}
    seeds = []
    for s in range(seeds_n):
        ra, rb = by[(s, steps[0])]["stages"], by[(s, steps[1])]["stages"]
        fa, fb = ra[-1], rb[-1]
        differs = (fa["loose"] != fb["loose"]) or abs(fb["F_fraction"] / fa["F_fraction"] - 1) > 0.05
        keys = ("F_fraction", "turns", "K_ratio", "loose")
        seeds.append({"seed": s, "final": {str(steps[0]): {k: fa[k] for k in keys},
                                           str(steps[1]): {k: fb[k] for k in keys}},
                      "final_states_differ": bool(differs), "loose_state_differs": fa["loose"] != fb["loose"],
                      "parting": parting(ra, rb) if differs else None,
                      "jumps": {str(steps[0]): _jumps(ra), str(steps[1]): _jumps(rb)}})
    differ = [x for x in seeds if x["final_states_differ"]]
    parted = [x["parting"] for x in differ if x["parting"]]
    summary = {"seeds": seeds_n, "steps": steps, "seeds_whose_final_state_differs": [x["seed"] for x in differ],
               "seeds_whose_loose_state_differs": [x["seed"] for x in seeds if x["loose_state_differs"]],
               "parting_load_over_euler": [p["load_over_euler"] for p in parted],
               "parting_load_over_full": [p["load_over_full"] for p in parted],
               "parting_stage_tol": [p["stage_tol"] for p in parted],
               "no_parting_found": [x["seed"] for x in differ if not x["parting"]]}
    # the stage at which each run's helix forms: its largest jump of the turns
    jumps = [j for x in seeds for j in x["jumps"].values()]
    size = [abs(j["turns_jump"]) for j in jumps]
    at = [j["turns_jump_at_load_over_euler"] for j in jumps]
    where = [j["turns_jump_s"] for j in jumps if j["turns_jump_s"] is not None]
    # how far the rod stays off the wall (an unstable straight equilibrium that a stage accepts)
    straight = [max((d["load_over_euler"] for d in r["stages"] if d["contacts"] == 0), default=0.0) for r in runs]
    summary["straight_until_load_over_euler"] = straight
    lo = [p["load_over_euler"] for p in parted]
    macros = {"seeds": str(seeds_n), "steps": f"{steps[0]} and {steps[1]}",
              "straight_until": f"{_g(min(straight))} to {_g(max(straight))}",
              "differ": f"{len(differ)} of {seeds_n}",
              "loose_differ": f"{len(summary['seeds_whose_loose_state_differs'])} of {seeds_n}",
              "parting": (f"{_g(min(lo))} to {_g(max(lo))} times the Euler load" if len(lo) > 1 else
                          f"{_g(lo[0])} times the Euler load" if lo else "nowhere along the ramp"),
              "parting_full": (f"{min(p['load_over_full'] for p in parted):.2g} to "
                               f"{max(p['load_over_full'] for p in parted):.2g} of the full load"
                               if parted else "none"),
              "jump_turns": f"{min(size):.2g} to {max(size):.2g}",
              "jump_load": f"{_g(min(at))} to {_g(max(at))}",
              "jump_s": f"{min(where):.0f} to {max(where):.0f}" if where else "none"}
    return seeds, summary, macros


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=12)
    ap.add_argument("--steps", nargs=2, type=int, default=[256, 512])
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--summarise", metavar="JSON", help="summarise the runs of an earlier output again, run nothing")
    ap.add_argument("--stage-kicks", type=int, default=0,
                    help="kick a stage that stops on the straight saddle off it, up to this many times (experiment)")
    ap.add_argument("-o", "--output", default="benchmarks/results/study_ramp_divergence.json")
    a = ap.parse_args()
    if a.summarise:
        old = json.loads(Path(a.summarise).read_text())
        runs, a.seeds, a.steps, prov = old["runs"], old["summary"]["seeds"], old["summary"]["steps"], old["provenance"]
        setup = old["setup"]
    else:
        with Pool(a.jobs) as pool:
            runs = pool.map(one, [(s, n, a.stage_kicks) for s in range(a.seeds) for n in a.steps])
        prov = provenance()
        setup = ("Fig 4(b)'s rod: " + ", ".join(f"{k} {v}" for k, v in ROD.items())
                 + f"; ramps of {a.steps[0]} and {a.steps[1]} loads from the same straight start per seed; one core "
                 "per run" + (f"; every stage that stops on the straight saddle kicked off it (up to {a.stage_kicks} "
                              "kicks)" if a.stage_kicks else ""))
    seeds, summary, macros = summarise(runs, a.seeds, a.steps)
    out = {"setup": setup,
           "provenance": prov, "summary": summary, "macros": macros, "seeds": seeds,
           "runs": [{k: r[k] for k in ("seed", "steps", "wall_s")} | {"stages": r["stages"]} for r in runs]}
    path = Path(a.output)
    path = path if path.is_absolute() else Path.cwd() / path
    path.write_text(json.dumps(out, indent=1) + "\n")
    print(json.dumps(summary, indent=1))
    print(json.dumps(macros, indent=1))


if __name__ == "__main__":
    main()
