"""Check what a code change re-runs: styling must not re-run simulations, physics must.

    python tools/check_rerun_triggers.py config/ci.yaml

Run after a complete build. For each probe file it appends a comment line (Snakemake
9 re-runs a job only if an input is newer *and* its checksum changed, so a bare
touch is not a change), asks Snakemake for a dry run, restores the file's content
and mtime, and compares the rules that would run with the expectation.
Exit status 1 if any expectation fails.
"""
from __future__ import annotations

import os
import re
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PKG = ROOT / "src" / "confined_rod"
SNAKEMAKE = str(Path(sys.executable).with_name("snakemake"))

# probe file -> (rules that must run, rules that must not)
# (a figure kind's module holds its dataset builder and its plot: editing it re-runs that
# kind's datasets and figures, never a simulation)
PROBES = {
    PKG / "plotting.py": ({"figure"}, {"simulate", "batch", "probe", "load_path", "postprocess"}),
    PKG / "fits.py": ({"postprocess", "figure"}, {"simulate", "batch", "probe", "load_path"}),
    PKG / "measure.py": ({"postprocess", "figure"}, {"simulate", "batch", "probe", "load_path"}),
    PKG / "regions.py": ({"postprocess", "figure"}, {"simulate", "batch", "probe", "load_path"}),
    PKG / "torque.py": ({"postprocess", "figure", "claims"}, {"simulate", "batch", "probe", "load_path"}),
    PKG / "figures" / "force_profile.py": ({"postprocess", "figure"},
                                           {"simulate", "batch", "probe", "load_path", "convergence_check"}),
    PKG / "figures" / "pitch_profile.py": ({"postprocess", "figure"},
                                           {"simulate", "batch", "probe", "load_path", "convergence_check"}),
    PKG / "figures" / "bifurcation.py": ({"postprocess", "figure"},
                                         {"simulate", "batch", "probe", "load_path", "convergence_check"}),
    PKG / "figures" / "convergence.py": ({"postprocess", "convergence_check", "figure"},
                                         {"simulate", "batch", "probe", "load_path"}),
    # a helper shared by kinds: side_strip, imported by the transition and escape kinds
    PKG / "figures" / "helix_views.py": ({"postprocess", "figure"},
                                         {"simulate", "batch", "probe", "load_path", "convergence_check"}),
    PKG / "paths.py": ({"load_path"}, set()),
    PKG / "runs.py": ({"simulate", "batch", "probe"}, set()),
    # the manuscript: its generated parts and the claims re-run, never a simulation or a dataset
    PKG / "paper.py": ({"paper_sources", "paper"},
                       {"simulate", "batch", "probe", "load_path", "postprocess", "figure", "claims"}),
    PKG / "claims.py": ({"claims", "paper_sources", "paper"}, {"simulate", "batch", "probe", "load_path", "postprocess"}),
    PKG / "model" / "kernels.py": ({"simulate", "batch", "postprocess", "figure"}, set()),
    PKG / "solvers" / "explicit.py": ({"simulate", "batch"}, set()),
    PKG / "solvers" / "implicit.py": ({"simulate", "batch"}, set()),
}
# how many figures a one-kind edit may re-run at most (the kind's own figures, not all)
ONE_KIND = {PKG / "figures" / "pitch_profile.py": 1, PKG / "figures" / "bifurcation.py": 1}
# how many figures an edit must re-run at least (every kind that imports the module)
SHARED = {PKG / "figures" / "helix_views.py": 3}


def planned_rules(config: str) -> dict[str, int]:
    out = subprocess.run([SNAKEMAKE, "-n", "--quiet", "rules", "--configfile", config, "--cores", "1"],
                         cwd=ROOT, capture_output=True, text=True)
    if out.returncode != 0:
        raise SystemExit(f"snakemake dry run failed:\n{out.stdout}\n{out.stderr}")
    return {m.group(1): int(m.group(2)) for m in re.finditer(r"^(\w+)\s+(\d+)\s*$", out.stdout, re.M)
            if m.group(1) not in ("total", "all")}


def main(argv=None) -> int:
    config = (argv or sys.argv[1:] or ["config/ci.yaml"])[0]
    base = planned_rules(config)
    if base:
        raise SystemExit(f"the build is not complete (would run {base}); run snakemake first")
    failures = 0
    for probe, (must, must_not) in PROBES.items():
        st = probe.stat()
        original = probe.read_bytes()
        try:
            probe.write_bytes(original + b"\n# rerun-trigger probe\n")
            now = time.time() + 1
            os.utime(probe, (now, now))
            plan = planned_rules(config)
        finally:
            probe.write_bytes(original)
            os.utime(probe, ns=(st.st_atime_ns, st.st_mtime_ns))
        ran = set(plan)
        ok = must <= ran and not (must_not & ran)
        if probe in ONE_KIND and plan.get("figure", 0) > ONE_KIND[probe]:
            ok = False
        if probe in SHARED and plan.get("figure", 0) < SHARED[probe]:
            ok = False
        failures += not ok
        print(f"{'ok  ' if ok else 'FAIL'} edit {probe.relative_to(ROOT)} -> would run {plan or 'nothing'}"
              f" (expected {sorted(must)}, never {sorted(must_not)})")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
