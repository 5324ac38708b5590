"""Run the CF compliance checker (compliance-checker, pinned in the test extra) on one dataset
of each kind of a build: a simulation, a probe, a load path, every figure kind's dataset and the
claims.  Prints one line per file (score, errors, warnings) and every error; exit 1 if any file
has an error (a failed high-priority check), 2 if a kind has no dataset in the build.

    python tools/check_cf.py [--results results] [--test cf:1.10] [-o cf_report.json]
"""
from __future__ import annotations

import argparse
import contextlib
import io
import json
import sys
import tempfile
from pathlib import Path

import xarray as xr

from confined_rod import layout


def pick(results: Path) -> dict[str, Path]:
    """One file per dataset kind: the first in sorted order, so two runs check the same files."""
    chosen: dict[str, Path] = {}
    for kind, folder in (("simulation", layout.SIMS), ("probe", layout.PROBES), ("load path", layout.PATHS)):
        files = sorted(layout.under(results, folder).glob("*/*.nc"))
        if files:
            chosen[kind] = files[0]
        if kind == "simulation":          # and one that stores shapes at several times (a time axis t)
            for f in files:
                with xr.open_dataset(f) as ds:
                    if "t" in ds.dims:
                        chosen["simulation with snapshots"] = f
                        break
    for f in sorted(layout.under(results, layout.DATASETS).glob("*.nc")):
        with xr.open_dataset(f) as ds:
            chosen.setdefault(f"figure kind {ds.attrs.get('kind', '?')}", f)
    for name, path in (("claims", layout.CLAIMS_NC), ("error budget", layout.ERROR_BUDGET_NC)):
        if layout.under(results, path).is_file():
            chosen[name] = layout.under(results, path)
    return chosen


def check(path: Path, test: str) -> dict:
    """compliance-checker's JSON result of one file, reduced to score, errors and warnings."""
    from compliance_checker.runner import CheckSuite, ComplianceChecker

    CheckSuite.load_all_available_checkers()
    said = io.StringIO()
    with tempfile.TemporaryDirectory() as tmp, contextlib.redirect_stdout(said), contextlib.redirect_stderr(said):
        out = Path(tmp) / "report.json"
        ComplianceChecker.run_checker(str(path), [test], 0, "normal", output_filename=str(out),
                                      output_format="json")
        result = json.loads(out.read_text())[test]
    # a check that raised (compliance-checker 6.1's monotonicity check on a string-valued index
    # such as a figure's panel names): not a failed check, but reported apart (the checker's own
    # exit status is 2 for it)
    crashed = [ln.strip() for ln in said.getvalue().splitlines() if ln.startswith(f"{test}.check_")]

    def failed(level: str) -> list[str]:
        return [f"{r['name']}: {m}" for r in result.get(level, []) for m in r.get("msgs", [])]

    return {"file": str(path), "scored": result["scored_points"], "possible": result["possible_points"],
            "errors": failed("high_priorities"), "warnings": failed("medium_priorities"), "checker_exceptions": crashed}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--results", type=Path, default=Path("results"))
    ap.add_argument("--test", default="cf:1.10", help="compliance-checker test (default cf:1.10, the "
                                                       "Conventions attribute the datasets declare)")
    ap.add_argument("--require", nargs="*", default=["simulation", "probe", "load path", "claims"],
                    help="kinds that must be present")
    ap.add_argument("-o", "--output", type=Path, help="write the results as JSON")
    args = ap.parse_args(argv)
    chosen = pick(args.results)
    missing = [k for k in args.require if k not in chosen]
    if missing:
        print(f"error: no {', '.join(missing)} dataset under {args.results}", file=sys.stderr)
        return 2
    reports, bad = {}, 0
    for kind, path in chosen.items():
        r = check(path, args.test)
        reports[kind] = r
        bad += bool(r["errors"])
        print(f"{kind:32s} {path}: {r['scored']}/{r['possible']}, {len(r['errors'])} errors, "
              f"{len(r['warnings'])} warnings" + (f", a check raised: {'; '.join(r['checker_exceptions'])}"
                                                   if r["checker_exceptions"] else ""))
        for e in r["errors"]:
            print(f"    error: {e}")
    if args.output:
        args.output.write_text(json.dumps(reports, indent=1))
    print(f"{len(chosen)} datasets checked against {args.test}: {bad} with errors")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
