"""What sets the force a helical start transmits?

    python benchmarks/study_helix_start.py [--seeds 5] [--k-ph 1000 10000]
                                           [-o benchmarks/results/study_helix_start.json]

Protocol 'helix' starts the rod of the protocol comparison (L/R = 320, load 0.25, k_fr 0.8,
publication numerics) as a helix on the wall whose pitch rate w is that of a torque-free helix
carrying the full load, 2 EI w^2 c = load with c = sqrt(1 - R^2 w^2) (sim.scenes). A helix of
pitch rate w on the wall that carries the axial force F presses on it with
K = R w^2 (F/c - EI w^2) (analysis/torque.py, the torque eliminated), which vanishes at
F = c EI w^2 = load/2: if the bulk keeps the start's pitch, it can carry half the load with no
wall force, hence no friction and no decay. Per run this records the pitch rate and |F_z| over
the middle of the rod (s from L/4 to 3L/4: its median and range over the load), the median wall
force there over R F^2/(4EI), and F(L)/F(0), at each bond stiffness k_ph (the start's end regions,
where the force leaves the plateau, are set by the numerics, not by a loading path).
"""
from __future__ import annotations

import argparse
import json
import statistics
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))
from confined_rod import Scene  # noqa: E402
from confined_rod.io import provenance  # noqa: E402
from confined_rod.sim import simulation  # noqa: E402
from confined_rod.theory import helix_pitch_rate  # noqa: E402

ROD = dict(L=320.0, load=0.25, k_fr=0.8, l0=0.5, k_w=1e3, tol=1e-5, protocol="helix")


def one(seed: int, k_ph: float) -> dict:
    sc = Scene(seed=seed, k_ph=k_ph, name=f"helix_start/k{k_ph:g}-s{seed}", **ROD)
    ds = simulation.simulate(sc, progress=False)
    load, L, R, EI = sc.load, sc.L, sc.R, sc.EI
    s, F = ds["s"].values, np.abs(ds["F_z"].values)
    mid = (s >= L / 4) & (s <= 3 * L / 4)
    sl = ds["s_link"].values
    mid_l = (sl >= L / 4) & (sl <= 3 * L / 4)
    K = ds["wall_force_density"].values[mid_l]
    F_l = 0.5 * (F[:-1] + F[1:])[mid_l]
    sh = ds["s_helix"].values
    w = np.abs(ds["dphi_ds"].values[(sh >= L / 4) & (sh <= 3 * L / 4)])
    return {"seed": seed, "k_ph": k_ph, "status": int(ds["status"].values),
            "fraction": float(ds["F_transmitted"]) / load,
            "plateau": float(np.median(F[mid])) / load, "plateau_range": [float(F[mid].min() / load),
                                                                         float(F[mid].max() / load)],
            "pitch_rate": float(np.median(w)), "K_ratio": float(np.median(K / (R * F_l**2 / (4 * EI))))}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--k-ph", nargs="+", type=float, default=[1000.0, 10000.0])
    ap.add_argument("-o", "--output", default="benchmarks/results/study_helix_start.json")
    a = ap.parse_args()
    w = float(helix_pitch_rate(np.array([ROD["load"]]), 1.0, 1.0)[0])
    c = float(np.sqrt(1 - w**2))
    runs = [one(seed, k) for k in a.k_ph for seed in range(a.seeds)]
    summary = {}
    for k in a.k_ph:
        rs = [r for r in runs if r["k_ph"] == k]
        summary[f"{k:g}"] = {key: [min(r[key] for r in rs), max(r[key] for r in rs)]
                             for key in ("fraction", "plateau", "pitch_rate", "K_ratio")}
        summary[f"{k:g}"]["fraction_mean"] = statistics.mean(r["fraction"] for r in rs)
    pub = summary[f"{max(a.k_ph):g}"]
    macros = {"w_start": f"{w:.4f}", "zero_wall_force": f"{c * w**2 / ROD['load']:.3f}",
              "plateau": f"{pub['plateau'][0]:.3f} to {pub['plateau'][1]:.3f}",
              "pitch_rate": f"{pub['pitch_rate'][0]:.4f} to {pub['pitch_rate'][1]:.4f}",
              "K_ratio": f"{pub['K_ratio'][0]:.3f} to {pub['K_ratio'][1]:.3f}",
              "fraction_by_k_ph": ", ".join(f"{summary[f'{k:g}']['fraction_mean']:.2f} at k_ph = {k:g}"
                                            for k in a.k_ph)}
    out = {"setup": "the helix start of the protocol comparison: " + ", ".join(f"{k} {v}" for k, v in ROD.items())
           + f"; {a.seeds} seeds per bond stiffness; the middle of the rod is s from L/4 to 3L/4",
           "start_pitch_rate": w, "c": c, "zero_wall_force_load_share": c * w**2 / ROD["load"],
           "provenance": provenance(), "seeds": a.seeds, "macros": macros, "summary": summary, "runs": runs}
    path = Path(a.output)
    path = path if path.is_absolute() else Path.cwd() / path
    path.write_text(json.dumps(out, indent=1) + "\n")
    print(json.dumps({"macros": macros, "summary": summary}, indent=1))


if __name__ == "__main__":
    main()
