"""Quick check of the numerical defaults on one scene (L = 20 R, load 0.25, k_fr = 0.8):
each numerical parameter is refined on its own and the change of the transmitted
force, L_z and the number of wall contacts is recorded. The systematic convergence
study (ladders, observed order, extrapolation) is part of the pipeline.

Usage: python benchmarks/defaults_check.py [-o benchmarks/results/defaults_check.json]
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from confined_rod import Scene, simulate

BASE = dict(L=20.0, load=0.25, k_fr=0.8, seed=0)
VARIANTS = {
    "defaults": {},
    "l0=0.25": {"l0": 0.25},
    "k_ph=3000": {"k_ph": 3000.0},
    "k_w=3000": {"k_w": 3000.0},
    "tol=1e-6": {"tol": 1e-6},
    "dt_factor=0.4": {"dt_factor": 0.4},
    "rotational_drag=rigid_link": {"rotational_drag": "rigid_link"},
}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("-o", "--output", type=Path,
                    default=Path(__file__).parent / "results" / "defaults_check.json")
    args = ap.parse_args()
    rows = []
    for name, change in VARIANTS.items():
        sc = Scene(**BASE, **change, name=name)
        t0 = time.perf_counter()
        ds = simulate(sc, progress=False)
        row = {"variant": name, "F_transmitted": float(ds.F_transmitted), "L_z": float(ds.L_z),
               "contacts": int(ds.contact.sum()), "contact_length": int(ds.contact.sum()) * sc.l0,
               "converged": int(ds.converged), "wall_time_s": time.perf_counter() - t0,
               "simulated_time": float(ds.t_final)}
        rows.append(row)
        print(json.dumps(row), flush=True)
    ref = rows[0]
    for row in rows:
        row["rel_change_F_transmitted"] = row["F_transmitted"] / ref["F_transmitted"] - 1
        row["change_L_z"] = row["L_z"] - ref["L_z"]
    args.output.parent.mkdir(parents=True, exist_ok=True)
    args.output.write_text(json.dumps({"base": BASE, "rows": rows}, indent=2))
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
