"""Fit the solver's cost model (what limits.estimated_solver_time predicts) to the runs of a build.

    python tools/fit_cost_model.py RESULTS_DIR [-o src/confined_rod/cost_model.json] [--note TEXT]

Reads the solver's wall time (``wall_time``) and the scene (the dataset's attributes) of every
simulation and probe under RESULTS_DIR (results/sims, results/probes) and fits, per class of run
(solver, protocol, with or without friction), in logarithms:

    implicit:  ln t = b + a ln(L/640 R) + c ln(0.5 R/l0) + d ln(0.02 R/dx_max) + f ln(load/0.25)
                      + m ln(k_fr/0.8) + r ln(ramp_steps/128) [ramp only]
    explicit:  ln t = b + ln(limits.explicit_cost_shape(scene)) + c ln(0.5 R/l0) + e ln(1e-5/tol)

(limits.cost_regressors) by least squares with a weak pull (one pseudo-run of weight
``PRIOR_WEIGHT`` each) of the exponents towards PRIORS (the hand model's N^1.9 = L^1.9 l0^-1.9,
linear in the ramp's loads, dx_max^-1/2, no dependence on load or k_fr), so an exponent the build's runs do
not vary (one length, one dx_max) keeps its prior instead of an arbitrary value; a class of
fewer than MIN_RUNS_FOR_EXPONENTS runs fits its coefficient only. Writes the
coefficients, the number of runs and the fit's scatter per class (the rms of ln(measured /
predicted), and the median and range of that ratio), with the build's commit and the date, to
the package's cost model file, which limits.estimated_solver_time reads. The build's machine is
the reference: its other work (a second build, a test run) inflates the times, so fit on a
build that ran alone.
"""
from __future__ import annotations

import argparse
import dataclasses
import datetime
import json
import math
import sys
from collections import defaultdict
from pathlib import Path
from typing import NamedTuple

import numpy as np
import xarray as xr

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))
from confined_rod import limits  # noqa: E402
from confined_rod.sim.scenes import Scene  # noqa: E402

PRIORS = {"L": 1.9, "l0": 1.9, "ramp": 1.0, "dx": 0.5, "load": 0.0, "k_fr": 0.0}
EXPLICIT_PRIORS = {"l0": 0.0, "tol": 0.0}  # explicit: a correction of explicit_cost_shape's l0^-3
PRIOR_WEIGHT = 0.1  # the prior's pseudo-row counts a hundredth of a run in the sum of squares
MIN_RUNS_FOR_EXPONENTS = 10  # a class with fewer runs fits its coefficient only (exponents at their priors)
MIN_WALL_S = 0.5  # shorter runs time mostly the process's first call into numba's cache, not the solver


def _value(v):
    """An attribute as the scene takes it: numpy scalars as Python numbers, and the numbers a
    probe stores as text ('20', '1e-05') as numbers."""
    if hasattr(v, "item") and np.ndim(v) == 0:
        return v.item()
    if isinstance(v, str):
        for kind in (int, float):
            try:
                return kind(v)
            except ValueError:
                pass
    return v


def scene_of(ds: xr.Dataset) -> Scene | None:
    known = set(Scene.field_names())
    fields = {k: _value(v) for k, v in ds.attrs.items() if k in known}
    if "body_force" in fields:
        fields["body_force"] = [float(x) for x in np.atleast_1d(fields["body_force"])]
    for f in dataclasses.fields(Scene):  # netCDF stores booleans as integers
        if f.name in fields and isinstance(f.default, bool):
            fields[f.name] = bool(fields[f.name])
    try:
        return Scene(**fields)
    except Exception:  # a probe of deliberately invalid input has no scene to time
        return None


class Run(NamedTuple):
    scene: Scene
    wall: float
    path: str
    steps: int = 0
    capped: bool = False  # ended on its step budget (max_steps): its time is the cap's, not the model's


def runs(results: Path) -> list[Run]:
    out = []
    for path in sorted(list((results / "sims").rglob("*.nc")) + list((results / "probes").rglob("*.nc"))):
        with xr.open_dataset(path) as ds:
            if "wall_time" not in ds or "L" not in ds.attrs:
                continue
            wall = float(ds["wall_time"])
            steps = int(ds["n_steps"]) if "n_steps" in ds else 0
            capped = str(ds.attrs.get("status_name", ds.attrs.get("status", ""))) == "step_cap"
            sc = scene_of(ds)
        if sc is not None and wall >= MIN_WALL_S:
            out.append(Run(sc, wall, str(path.relative_to(results)), steps, capped))
    return out


def fit_class(items: list[Run]) -> dict:
    """The class's coefficients (module docstring), from its runs that did not end on a step
    budget; with a step budget in any run, also the median time per step and link."""
    free = [r for r in items if not r.capped] or items
    explicit = free[0].scene.solver == "explicit"
    priors = EXPLICIT_PRIORS if explicit else PRIORS
    names = sorted({k for r in free for k in limits.cost_regressors(r.scene)[1]})
    rows, y = [], []
    for r in free:
        off, x = limits.cost_regressors(r.scene)
        rows.append([1.0] + [x.get(k, 0.0) for k in names])
        y.append(math.log(r.wall) - off)
    A, y = np.array(rows), np.array(y)
    prior = np.array([priors[k] for k in names])
    if len(free) < MIN_RUNS_FOR_EXPONENTS:  # too few to tell exponents apart: only the coefficient
        coef = np.concatenate([[float(np.mean(y - A[:, 1:] @ prior))], prior])
    else:  # the prior: one pseudo-row per exponent, PRIOR_WEIGHT x that exponent = its prior
        prior_rows = np.hstack([np.zeros((len(names), 1)), PRIOR_WEIGHT * np.eye(len(names))])
        coef = np.linalg.lstsq(np.vstack([A, prior_rows]), np.concatenate([y, PRIOR_WEIGHT * prior]), rcond=None)[0]
    out = {"log_coef": float(coef[0])} | {f"{k}_exponent": float(c) for k, c in zip(names, coef[1:])}
    if not explicit:  # the longest rod fitted: beyond it limits.estimated_solver_time extrapolates no cheaper
        out["L_max"] = float(max(r.scene.L / r.scene.R for r in free))  # than the hand model's N^1.9
    per_step = [r.wall / (r.steps * r.scene.N) for r in items if r.steps > 0]
    if any(r.scene.max_steps for r in items) and per_step:
        out["step_s_per_link"] = float(np.median(per_step))
    # the scatter of every run (capped ones included) about what limits.estimated_solver_time predicts
    pred = [limits.class_solver_time(out, r.scene) for r in items]
    resid = np.log([r.wall for r in items]) - np.log(pred)
    ratio = np.exp(resid)
    return out | {"runs": len(items), "step_capped_runs": len(items) - len(free) if free is not items else 0,
                  "rms_log_error": float(np.sqrt(np.mean(resid**2))),
                  "measured_over_predicted": {"median": float(np.median(ratio)), "min": float(ratio.min()),
                                              "max": float(ratio.max())},
                  "wall_s_total": float(sum(r.wall for r in items))}


def git_commit(results: Path) -> str:
    for path in sorted((results / "sims").rglob("*.nc"))[:1]:
        with xr.open_dataset(path) as ds:
            return str(ds.attrs.get("git_commit", "unknown"))
    return "unknown"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("results")
    ap.add_argument("-o", "--out", default=str(limits.COST_MODEL_FILE))
    ap.add_argument("--note", default="")
    a = ap.parse_args(argv)
    results = Path(a.results)
    data = runs(results)
    if not data:
        raise SystemExit(f"fit_cost_model: no timed simulation under {results}")
    by_class = defaultdict(list)
    for item in data:
        by_class[limits.cost_class(item.scene)].append(item)
    model = {"source": {"build_commit": git_commit(results), "date": datetime.date.today().isoformat(),
                        "runs": len(data), "note": a.note,
                        "priors": PRIORS, "explicit_priors": EXPLICIT_PRIORS, "prior_weight": PRIOR_WEIGHT,
                        "min_runs_for_exponents": MIN_RUNS_FOR_EXPONENTS, "min_wall_s": MIN_WALL_S},
             "classes": {k: fit_class(v) for k, v in sorted(by_class.items())}}
    Path(a.out).write_text(json.dumps(model, indent=1) + "\n")
    for k, c in model["classes"].items():
        r = c["measured_over_predicted"]
        print(f"{k:40s} {c['runs']:4d} runs  rms ln error {c['rms_log_error']:.2f}  "
              f"measured/predicted {r['min']:.2f}-{r['max']:.2f}  "
              + "  ".join(f"{n} {v:.2f}" for n, v in c.items() if n.endswith("exponent")))
    return 0


if __name__ == "__main__":
    sys.exit(main())
