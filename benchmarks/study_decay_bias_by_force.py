"""Is a ladder's bias of the bulk decay rate the same at every force along the bulk? Reads a
built ladder (default: the frictional l0 ladder, ``conv_l0``) and writes
benchmarks/results/study_decay_bias_by_force_<ladder>.json.

The error budget carries a ladder's shift of F(L) from its rod to a longer one by region
(analysis.error_budget.rescaled), taking the relative bias eps of the bulk's decay rate
d(1/|F_z|)/ds to be the same at every force. If instead eps grew with the force (a
discretisation error of order (w l0)^2, w^2 ~ |F_z|/(2EI)), the bulk's change of 1/|F_z| would
grow as ln(F_start/F_end) rather than as its length, and a long rod, whose bulk is mostly at
small forces, would carry less of it. The test: per seed, the decay rate (slope of 1/|F_z|
against s, least squares over the joints) in the upper half of the bulk (from the loaded end:
the larger forces) and in the lower half, on every rung; per half, the paired relative shift of
each coarser rung against the finest (analysis.distributions.compare) and the half's mean force;
and per seed the difference of the two halves' relative changes, with its mean and standard
error. The same eps in both halves within their errors supports the rescaling.

Usage: python benchmarks/study_decay_bias_by_force.py --build /tmp/pub [--ladder conv_l0]
"""
from __future__ import annotations

import argparse
import json
import subprocess
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
RESULTS = Path(__file__).resolve().parent / "results"


def halves(sim) -> tuple[float, float, float, float] | None:
    """(rate of the upper half, rate of the lower half, mean |F_z| of each) of the run's bulk;
    None without a bulk of at least 8 joints per half."""
    from confined_rod.analysis import regions

    a = regions.analyse(sim)
    if not a.regions.has_bulk:
        return None
    s = np.asarray(sim["s"].values, dtype=float)
    F = np.abs(np.asarray(sim["F_z"].values, dtype=float))
    lo, hi = a.regions.s_bulk_start, a.regions.s_bulk_end
    mid = 0.5 * (lo + hi)
    out = []
    for a_, b_ in ((lo, mid), (mid, hi)):
        m = (s >= a_) & (s <= b_)
        if m.sum() < 8:
            return None
        out.append((float(np.polyfit(s[m], 1.0 / F[m], 1)[0]), float(F[m].mean())))
    return out[0][0], out[1][0], out[0][1], out[1][1]


def main() -> None:
    import xarray as xr

    from confined_rod import layout, pipeline
    from confined_rod.analysis import distributions

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", type=Path, required=True, help="a checkout whose results/ holds the built ladder")
    ap.add_argument("--ladder", default="conv_l0")
    a = ap.parse_args()
    config = pipeline.expand(pipeline.read_config(ROOT / "config" / "config.yaml"))
    by_rung: dict[str, dict[int, tuple]] = {}
    values: dict[str, float] = {}
    param = config["figures"][a.ladder]["parameter"]
    for name in pipeline.scenes(config, a.ladder):
        rung, _, seed = name.rpartition("-s")
        fig, scene = pipeline.canonical_scene(config, a.ladder, name)
        path = a.build / layout.sim_path(fig, scene)
        if not path.exists():
            continue
        with xr.open_dataset(path) as d:
            h = halves(d)
            values[rung] = float(d.attrs[param])
        if h is not None:
            by_rung.setdefault(rung, {})[int(seed)] = h
    rungs = sorted(by_rung, key=lambda r: -values[r] if param in ("l0", "tol", "dx_max") else values[r])
    finest = rungs[-1]
    out = {"ladder": a.ladder, "parameter": param, "finest": values[finest], "rungs": {}}
    for r in rungs[:-1]:
        common = sorted(set(by_rung[r]) & set(by_rung[finest]))
        row = {"value": values[r], "seeds": len(common)}
        for k, half in ((0, "upper"), (1, "lower")):
            x = np.array([by_rung[r][s][k] for s in common])
            y = np.array([by_rung[finest][s][k] for s in common])
            c = distributions.compare(x, y, 1.0, paired=True)
            row[half] = {"shift": c.shift, "se": c.se, "mean_F": float(np.mean([by_rung[r][s][2 + k] for s in common]))}
        # per seed: the upper half's relative change less the lower half's (paired)
        e = np.array([by_rung[r][s][0] / by_rung[finest][s][0] - by_rung[r][s][1] / by_rung[finest][s][1]
                      for s in common])
        row["upper_minus_lower"] = {"mean": float(e.mean()), "se": float(e.std(ddof=1) / np.sqrt(e.size))}
        out["rungs"][f"{values[r]:g}"] = row
    out["commit"] = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True,
                                   text=True).stdout.strip()
    path = RESULTS / f"study_decay_bias_by_force_{a.ladder}.json"
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(out, indent=1) + "\n")
    tmp.replace(path)
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
