"""Check what a code change re-runs: styling must not re-run simulations, physics must, and a new
module re-runs what the part it lands in feeds (sim/: the simulations; analysis/: nothing until a
kind imports it; claims/: the claims and the manuscript).

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
    PKG / "analysis" / "plotting.py": ({"figure"}, {"simulate", "batch", "probe", "load_path", "postprocess"}),
    PKG / "analysis" / "fits.py": ({"postprocess", "figure"}, {"simulate", "batch", "probe", "load_path"}),
    PKG / "analysis" / "measure.py": ({"postprocess", "figure"}, {"simulate", "batch", "probe", "load_path"}),
    PKG / "analysis" / "regions.py": ({"postprocess", "figure"}, {"simulate", "batch", "probe", "load_path"}),
    PKG / "analysis" / "torque.py": ({"postprocess", "figure", "claims"},
                                     {"simulate", "batch", "probe", "load_path"}),
    PKG / "analysis" / "figures" / "force_profile.py": ({"postprocess", "figure"},
                                           {"simulate", "batch", "probe", "load_path", "convergence_check"}),
    PKG / "analysis" / "figures" / "pitch_profile.py": ({"postprocess", "figure"},
                                           {"simulate", "batch", "probe", "load_path", "convergence_check"}),
    PKG / "analysis" / "figures" / "bifurcation.py": ({"postprocess", "figure"},
                                         {"simulate", "batch", "probe", "load_path", "convergence_check"}),
    PKG / "analysis" / "figures" / "convergence.py": ({"postprocess", "convergence_check", "figure"},
                                         {"simulate", "batch", "probe", "load_path"}),
    # a helper shared by kinds: side_strip, imported by the transition and escape kinds
    PKG / "analysis" / "figures" / "helix_views.py": ({"postprocess", "figure"},
                                         {"simulate", "batch", "probe", "load_path", "convergence_check"}),
    PKG / "sim" / "load_paths.py": ({"load_path"}, set()),
    PKG / "sim" / "runs.py": ({"simulate", "batch", "probe"}, set()),
    # the manuscript: its generated parts and the claims re-run, never a simulation or a dataset
    PKG / "claims" / "manuscript.py": ({"paper_sources", "paper"},
                       {"simulate", "batch", "probe", "load_path", "postprocess", "figure", "claims"}),
    PKG / "claims" / "verdicts.py": ({"claims", "paper_sources", "paper"},
                                     {"simulate", "batch", "probe", "load_path", "postprocess"}),
    PKG / "sim" / "model" / "kernels.py": ({"simulate", "batch", "postprocess", "figure"}, set()),
    PKG / "sim" / "solvers" / "explicit.py": ({"simulate", "batch"}, set()),
    PKG / "sim" / "solvers" / "implicit.py": ({"simulate", "batch"}, set()),
}
SIM_RULES = {"simulate", "batch", "probe", "load_path"}
PROBES.update({
    # the table of figure quantities extends the shared one: a new figure quantity re-runs no simulation
    PKG / "analysis" / "figure_quantities.py": ({"postprocess", "figure"}, SIM_RULES),
    PKG / "quantities.py": (SIM_RULES, set()),
})
# a new, empty module in each part (created, planned, deleted): the rules' code inputs follow where it is
NEW_MODULES = {
    PKG / "sim" / "rerun_probe_new.py": (SIM_RULES, set()),
    PKG / "analysis" / "rerun_probe_new.py": (set(), SIM_RULES | {"postprocess", "figure", "claims"}),
    PKG / "claims" / "rerun_probe_new.py": ({"claims", "paper_sources", "paper"},
                                           SIM_RULES | {"postprocess", "figure"}),
    PKG / "pipeline" / "rerun_probe_new.py": (set(), SIM_RULES | {"postprocess", "figure", "claims"}),
}
# how many figures a one-kind edit may re-run at most (the kind's own figures, not all)
ONE_KIND = {PKG / "analysis" / "figures" / "pitch_profile.py": 1, PKG / "analysis" / "figures" / "bifurcation.py": 1}
# how many figures an edit must re-run at least (every kind that imports the module)
SHARED = {PKG / "analysis" / "figures" / "helix_views.py": 3}


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
        failures += not report(probe, "edit", plan, must, must_not)
    for probe, (must, must_not) in NEW_MODULES.items():
        if probe.exists():
            raise SystemExit(f"{probe} exists: remove the leftover of an interrupted check")
        try:
            probe.write_text('"""rerun-trigger probe: a new, empty module"""\n')
            plan = planned_rules(config)
        finally:
            probe.unlink(missing_ok=True)
        failures += not report(probe, "new", plan, must, must_not)
    return 1 if failures else 0


def report(probe: Path, what: str, plan: dict[str, int], must: set[str], must_not: set[str]) -> bool:
    ran = set(plan)
    ok = must <= ran and not (must_not & ran)
    if probe in ONE_KIND and plan.get("figure", 0) > ONE_KIND[probe]:
        ok = False
    if probe in SHARED and plan.get("figure", 0) < SHARED[probe]:
        ok = False
    print(f"{'ok  ' if ok else 'FAIL'} {what} {probe.relative_to(ROOT)} -> would run {plan or 'nothing'}"
          f" (expected {sorted(must)}, never {sorted(must_not)})")
    return ok


if __name__ == "__main__":
    sys.exit(main())
