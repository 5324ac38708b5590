"""Does how strictly the intermediate stages of a ramp are relaxed move its outcome?

    python benchmarks/study_ramp_stage_tol.py [--seeds 10] [--ramp-steps 256] [--factors 1 10]
                                              [--k-ph 1e4] [--jobs 2]
                                              [-o benchmarks/results/study_ramp_stage_tol.json]

Protocol 'ramp' relaxes every intermediate stage to the scene's tol or to the round-off floor at
the stage's load, whichever is larger (solvers.base.ramp_stage). The residual is normalised by
the stage's load, and the floor is an absolute force, so the stage tolerance grows as 1/load:
the first stages of a 256-step ramp at L/R = 320 are held to ~1e-3 of their load, the last to
the scene's 1e-5. Every intermediate stage is held to `factor` x the tolerance the pipeline uses
at the publication numerics (1: the pipeline's; 10: ten times looser; never above
limits.TOL_MAX). Below 1 the pipeline's round-off floor stands in the way. It is set by the bond
stiffness (round-off of positions of size L times k_ph), so with a softer bond (`--k-ph 1250`: a
floor 8x lower) factors below 1 can be reached: they say whether the pipeline's stages are strict
enough, i.e. whether the outcome has stopped moving at factor 1. A factor below the rod's own
floor is refused, unless `--floor-factor f` lowers the floor to f times the pipeline's at every
stage, the last one too (limits.roundoff_tol carries a factor 8 over eps k L, where the measured
stall of the Newton iteration is 1.6 eps k L, so f >= 0.2 can be reached at the publication's
bond); a run whose stage cannot get there ends at the time cap (or after `--max-steps`) and is
left out of the comparison. If a tenfold looser stage moves the final states (the paired
shift of F(L), the seeds whose loosely wound state changes) no more than the seed-to-seed changes
of the ramp ladders do, the stage tolerance is not what makes the ramp drift. Fig 4(b)'s rod
(L/R = 320, k_fr = 0.3, load 0.25, publication numerics), the same seeds with each factor;
records per run what the ramp ladders compare (convergence._member_values), the steps and the
solver time, and the stage tolerances of the pipeline's ramp at a few loads.
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import statistics
import sys
import time
from multiprocessing import Pool
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))
from confined_rod import Scene, limits  # noqa: E402
from confined_rod.analysis.figures import convergence  # noqa: E402
from confined_rod.io import provenance  # noqa: E402
from confined_rod.sim import simulation  # noqa: E402
from confined_rod.sim.solvers import base  # noqa: E402

ROD = dict(L=320.0, load=0.25, k_fr=0.3, l0=0.5, k_ph=1e4, k_w=1e3, tol=1e-5, protocol="ramp")
#: the pipeline's stage (one() replaces base.ramp_stage while it runs)
PIPELINE_STAGE = base.ramp_stage
PIPELINE_TOL = base.equilibrium_tol


def stage_tol(scene: Scene, load: float, factor: float, floor_factor: float = 1.0) -> float:
    """factor x the stage tolerance of the publication's rod (ROD's k_ph) at this load; at
    least floor_factor x the scene's own round-off floor there (ValueError if the factor asks
    for less)."""
    ref = PIPELINE_STAGE(dataclasses.replace(scene, k_ph=ROD["k_ph"]), load).tol
    tol = min(factor * ref, limits.TOL_MAX)
    floor = floor_factor * limits.roundoff_tol(scene, load)
    if tol < floor * (1 - 1e-9):   # equal up to round-off is reachable
        raise ValueError(f"factor {factor:g}: stage tolerance {tol:.3g} at load {load:.3g} is below the "
                         f"round-off floor {floor:.3g} of k_ph = {scene.k_ph:g}; use a softer bond")
    return tol


def one(args: tuple[int, int, float, float, float, int]) -> dict:
    seed, ramp_steps, factor, k_ph, floor_factor, max_steps = args
    sc = Scene(seed=seed, ramp_steps=ramp_steps, name=f"stage_tol/x{factor:g}-s{seed}", max_steps=max_steps,
               **(ROD | {"k_ph": k_ph}))

    def ramp_stage(scene, load):
        return dataclasses.replace(PIPELINE_STAGE(scene, load), tol=stage_tol(scene, load, factor, floor_factor))

    def equilibrium_tol(scene):
        # relax() tests equilibrium at the larger of the tol and the round-off floor: the floor taken
        # floor_factor x the pipeline's (every stage and the final one alike)
        return max(scene.tol, floor_factor * limits.roundoff_tol(scene))

    base.ramp_stage, base.equilibrium_tol = ramp_stage, equilibrium_tol
    try:
        t0 = time.perf_counter()
        ds = simulation.simulate(sc, progress=False)
        wall = time.perf_counter() - t0
    finally:
        base.ramp_stage, base.equilibrium_tol = PIPELINE_STAGE, PIPELINE_TOL
    v = convergence._member_values(ds)
    return {"seed": seed, "factor": factor, "k_ph": k_ph, "wall_s": wall, "status": str(ds["status"].values),
            "steps": int(ds["n_steps"])} | {k: (None if x is None or not np.isfinite(x) else float(x))
                                             for k, x in v.items()}


def _se(values) -> float | None:
    """The standard error of the mean of paired differences (None for fewer than two)."""
    values = list(values)
    return statistics.stdev(values) / len(values) ** 0.5 if len(values) > 1 else None


def _mean(rs: list[dict], key: str) -> float | None:
    """The mean of a bulk relation over the runs that determine it (None if none does)."""
    v = [r[key] for r in rs if r.get(key) is not None]
    return statistics.mean(v) if v else None


def summarise(runs: list[dict], factors: list[float], seeds: int) -> tuple[dict, dict]:
    """Per factor: the runs at equilibrium (status 0; a step-capped stage is not), the counts of
    loosely wound and unclassified ones among them, their mean F(L), and against the first factor
    the paired shift of F(L) and the seeds that change, over the seeds at equilibrium at both;
    the manuscript's texts."""
    by = {f: {r["seed"]: r for r in runs if r["factor"] == f and str(r["status"]) == "0"} for f in factors}
    ref = factors[0]
    summary = {}
    for f in factors:
        rs = list(by[f].values())
        row = {"runs": sum(1 for r in runs if r["factor"] == f), "at_equilibrium": len(rs),
               "loosely_wound": sum(1 for r in rs if r.get("loosely_wound") == 1.0),
               # no bulk helix whose wall force could be read: neither loosely wound nor not
               "unclassified": sum(1 for r in rs if r.get("loosely_wound") is None),
               "mean_F_transmitted": statistics.mean(r["F_transmitted"] for r in rs) if rs else None,
               # the bulk helix: wall force over the torque-free helix's, pitch over w(F), decay over the law
               **{f"mean_{k}": _mean(rs, k) for k in ("wall_force_ratio", "pitch_ratio", "decay_ratio",
                                                      "lower_length", "lower_friction_use")},
               "median_wall_s": statistics.median(r["wall_s"] for r in runs if r["factor"] == f),
               "median_steps": statistics.median(r["steps"] for r in runs if r["factor"] == f)}
        both = sorted(set(by[f]) & set(by[ref]))
        if f != ref and both:
            d = {s: by[f][s]["F_transmitted"] / by[ref][s]["F_transmitted"] - 1 for s in both}
            row["paired_seeds"] = len(both)
            row["F_transmitted_paired_shift"] = statistics.mean(d.values())
            se = _se(d.values())
            row["F_transmitted_shift_95"] = None if se is None else 1.96 * se
            row["largest_single_change"] = max(d.values(), key=abs)
            row["seeds_changing_by_more_than_2_percent"] = [s for s in both if abs(d[s]) > 0.02]
            row["seeds_changing_loose_state"] = [s for s in both if
                                                 by[f][s].get("loosely_wound") != by[ref][s].get("loosely_wound")]
        summary[f"{f:g}"] = row
    macros = {"loose": ", ".join(f"{summary[f'{f:g}']['loosely_wound']} of "
                                 f"{summary[f'{f:g}']['at_equilibrium'] - summary[f'{f:g}']['unclassified']} at {f:g}x"
                                 for f in factors),
              "unclassified": ", ".join(f"{summary[f'{f:g}']['unclassified']} at {f:g}x" for f in factors),
              "at_equilibrium": ", ".join(f"{summary[f'{f:g}']['at_equilibrium']} of {summary[f'{f:g}']['runs']} "
                                          f"at {f:g}x" for f in factors),
              "wall_force": ", ".join(f"{summary[f'{f:g}']['mean_wall_force_ratio']:.2f} at {f:g}x" for f in factors
                                      if summary[f"{f:g}"]["mean_wall_force_ratio"] is not None),
              "lower": ", ".join(f"{summary[f'{f:g}']['mean_lower_length']:.0f} R with its friction at "
                                 f"{summary[f'{f:g}']['mean_lower_friction_use']:.2f} of the limit at {f:g}x"
                                 for f in factors if summary[f"{f:g}"]["mean_lower_length"] is not None
                                 and summary[f"{f:g}"]["mean_lower_friction_use"] is not None),
              "seeds": str(seeds), "factors": ", ".join(f"{f:g}" for f in factors)}
    for f in factors[1:]:
        row = summary[f"{f:g}"]
        if row.get("F_transmitted_shift_95") is not None:
            macros["shift_x" + f"{f:g}".replace(".", "_")] = (f"{100 * row['F_transmitted_paired_shift']:+.0f} +- "
                                                             f"{100 * row['F_transmitted_shift_95'] / 1.96:.0f} %")
    return summary, macros


def _steps(data: dict) -> int:
    return int(data["setup"].split("ramp of ")[1].split(" ")[0])


def against(coarse: dict, fine: dict, name: str) -> tuple[dict, dict]:
    """The runs of `fine` against those of `coarse` (another number of ramp steps, or at the same
    steps another bond stiffness) at every factor both have, over the seeds at equilibrium in
    both: the paired shift of F(L) and of the decay ratio with their standard errors and the
    loosely wound counts; the manuscript's texts (keys steps_* or bond_*)."""
    out, macros = {"file": name, "steps": [_steps(coarse), _steps(fine)],
                   "k_ph": [coarse["runs"][0].get("k_ph"), fine["runs"][0].get("k_ph")]}, {}
    what = "steps" if out["steps"][0] != out["steps"][1] else "bond"
    for f in sorted({r["factor"] for r in fine["runs"]} & {r["factor"] for r in coarse["runs"]}):
        a = {r["seed"]: r for r in coarse["runs"] if r["factor"] == f and str(r["status"]) == "0"}
        b = {r["seed"]: r for r in fine["runs"] if r["factor"] == f and str(r["status"]) == "0"}
        both = sorted(set(a) & set(b))
        d = [b[s]["F_transmitted"] / a[s]["F_transmitted"] - 1 for s in both]
        loose = [sum(1 for s in both if x[s].get("loosely_wound") == 1.0) for x in (a, b)]
        dr = [b[s]["decay_ratio"] - a[s]["decay_ratio"] for s in both
              if b[s].get("decay_ratio") is not None and a[s].get("decay_ratio") is not None]
        row = {"paired_seeds": len(both), "F_transmitted_paired_shift": statistics.mean(d),
               "decay_ratio_paired_shift": statistics.mean(dr) if dr else None,
               "decay_ratio_shift_se": _se(dr), "F_transmitted_shift_se": _se(d), "loosely_wound": loose}
        out[f"{f:g}"] = row
        key = f"{f:g}".replace(".", "_")
        macros[f"{what}_shift_x{key}"] = (f"{100 * row['F_transmitted_paired_shift']:+.1f} +- "
                                         f"{100 * row['F_transmitted_shift_se']:.1f} %")
        if row["decay_ratio_shift_se"] is not None:
            macros[f"{what}_decay_shift_x{key}"] = (f"{row['decay_ratio_paired_shift']:+.3f} +- "
                                                   f"{row['decay_ratio_shift_se']:.3f}")
        macros[f"{what}_loose_x{key}"] = (f"{loose[0]} and {loose[1]} of {len(both)} at " + (
            f"{out['steps'][0]} and {out['steps'][1]} steps" if what == "steps" else
            f"k_ph = {out['k_ph'][0]:g} and {out['k_ph'][1]:g}"))
    return out, macros


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--ramp-steps", type=int, default=256)
    ap.add_argument("--factors", nargs="+", type=float, default=[1.0, 10.0])
    ap.add_argument("--k-ph", type=float, default=ROD["k_ph"], help="bond stiffness of the rod (ROD's by default)")
    ap.add_argument("--floor-factor", type=float, default=1.0,
                    help="let the stages go below the round-off floor, to this fraction of it (>= 0.2)")
    ap.add_argument("--max-steps", type=int, default=0, help="step budget of a run (0: none)")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--summarise", action="store_true",
                    help="summarise the runs of the output file again (its factors and seeds), run nothing")
    ap.add_argument("--against", metavar="JSON",
                    help="with --summarise: compare the output's runs with those of another ramp resolution "
                         "(same factor, same seeds; paired shift of F(L) and loosely wound shares)")
    ap.add_argument("-o", "--output", default="benchmarks/results/study_ramp_stage_tol.json")
    a = ap.parse_args()
    path = Path(a.output)
    path = path if path.is_absolute() else Path.cwd() / path
    if a.summarise:
        out = json.loads(path.read_text())
        runs = out["runs"]
        factors = list(dict.fromkeys(r["factor"] for r in runs))
        factors = [out.get("reference_factor", factors[0])] + [f for f in factors if f != out.get("reference_factor")]
        out["summary"], out["macros"] = summarise(runs, factors, len({r["seed"] for r in runs}))
        if a.against:
            other = json.loads(Path(a.against).read_text())
            out["against"], extra = against(other, out, Path(a.against).name)
            out["macros"] |= extra
        path.write_text(json.dumps(out, indent=1) + "\n")
        print(json.dumps(out["summary"], indent=1))
        return
    rod = ROD | {"k_ph": a.k_ph}
    sc = Scene(seed=0, ramp_steps=a.ramp_steps, **rod)
    loads = sc.ramp_loads()
    tols = {f"{float(F):.4g}": {"pipeline": base.ramp_stage(sc, float(F)).tol,
                                "floor": limits.roundoff_tol(sc, float(F)),
                                "factor_1": stage_tol(sc, float(F), 1.0)}
            for F in loads[[0, len(loads) // 16, len(loads) // 4, len(loads) // 2, -2]]}
    if a.floor_factor < 0.2:
        ap.error(f"--floor-factor {a.floor_factor:g}: below 0.2 the stages would ask for less than the measured "
                 "stall of the Newton iteration (1.6 eps k L)")
    for f in a.factors:  # refuse an unreachable factor before any run
        for F in loads[:-1]:
            stage_tol(sc, float(F), f, a.floor_factor)
    work = [(s, a.ramp_steps, f, a.k_ph, a.floor_factor, a.max_steps) for s in range(a.seeds) for f in a.factors]
    with Pool(a.jobs) as pool:
        runs = pool.map(one, work)
    summary, macros = summarise(runs, a.factors, a.seeds)
    ref = a.factors[0]
    out = {"setup": "Fig 4(b)'s rod: " + ", ".join(f"{k} {v}" for k, v in rod.items())
           + f", ramp of {a.ramp_steps} loads; every intermediate stage held to factor x the tolerance "
           f"of the publication's rod (k_ph {ROD['k_ph']:g}; module docstring), the round-off floor taken "
           f"{a.floor_factor:g} x the pipeline's, step budget {a.max_steps or 'none'}; one core per run",
           "stage_tolerance_at_load": tols, "provenance": provenance(), "reference_factor": ref,
           "macros": macros,
           "summary": summary, "runs": runs}
    path.write_text(json.dumps(out, indent=1) + "\n")
    print(json.dumps({"stage_tolerance_at_load": tols, "summary": summary}, indent=1))


if __name__ == "__main__":
    main()
