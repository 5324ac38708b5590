"""Compare two builds' results file by file: are they the same data, run times and commits aside?

    python tools/compare_builds.py BEFORE/results AFTER/results [-o summary.json]

For a change that must not change any number (a move of code, a renamed module): build the same
config before and after, then compare. Every netCDF file of the layout's scene folders, of
``datasets/`` and ``claims.nc``: the same variables, each bitwise equal with the same attributes
(names and values), and the same global attributes, except run times (variables and attributes
named ``wall_time``), ``history`` (a timestamp) and the git commits. Every convergence verdict
(``checks/``), ``claims.csv`` and the manuscript's generated parts compare as text. Exit status 1
on any difference or missing file; the JSON summary lists them.

``--replace OLD=NEW`` (repeatable) first rewrites OLD to NEW in every text of the BEFORE build
(string variables and attributes, text files; also OLD with its underscores TeX-escaped): for
strings that name what the change renames (a module path in a provenance note, the commit in a
caption), so that everything else is still compared exactly.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np
import xarray as xr

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

from confined_rod import layout  # noqa: E402

TIMING_VARIABLES = {"wall_time"}
VOLATILE_ATTRS = {"history", "git_commit", "scene_git_commits", "boundary_git_commit"}


REPLACE: list[tuple[str, str]] = []


def _rewritten(text: str) -> str:
    for old, new in REPLACE:
        text = text.replace(old, new).replace(old.replace("_", r"\_"), new.replace("_", r"\_"))
    return text


def _same(u, v) -> bool:
    """u (of the build before, its texts rewritten) equals v, bit for bit."""
    u, v = np.asarray(u), np.asarray(v)
    if u.shape != v.shape:
        return False
    if u.dtype.kind in "OUS":
        u = np.vectorize(lambda s: _rewritten(s) if isinstance(s, str) else s, otypes=[object])(u) if u.size else u
        return bool(np.array_equal(u.astype(object), v.astype(object)))
    return u.tobytes() == v.tobytes()


def compare_dataset(a: Path, b: Path, attr_values: bool = True) -> list[str]:
    """The differences between two netCDF files (empty if none), run times and commits aside;
    ``attr_values=False`` compares the variables' attribute names only."""
    diffs = []
    with xr.open_dataset(a, decode_times=False) as x, xr.open_dataset(b, decode_times=False) as y:
        if set(x.variables) != set(y.variables):
            return [f"variables differ: {sorted(set(x.variables) ^ set(y.variables))}"]
        for name in x.variables:
            if name in TIMING_VARIABLES:
                continue
            if not _same(x[name].values, y[name].values):
                diffs.append(f"variable {name!r} differs")
            if x[name].attrs.keys() != y[name].attrs.keys():
                diffs.append(f"attributes of {name!r} differ")
            elif attr_values:
                diffs += [f"attribute {name}.{k} differs" for k in x[name].attrs
                          if not _same(x[name].attrs[k], y[name].attrs[k])]
        for k in set(x.attrs) | set(y.attrs):
            if k in VOLATILE_ATTRS or "wall_time" in k:
                continue
            u, v = x.attrs.get(k), y.attrs.get(k)
            if u is None or v is None or not _same(u, v):
                diffs.append(f"attribute {k!r}: {u!r} != {v!r}")
    return diffs


def compare(before: Path, after: Path) -> dict:
    rel = lambda p: str(Path(p).relative_to(layout.RESULTS))  # noqa: E731
    folders = [rel(f) for f in (*layout.SCENE_FOLDERS, layout.DATASETS)]
    netcdf = [p.relative_to(before) for sub in folders for p in sorted((before / sub).rglob("*.nc"))]
    netcdf += [Path(rel(p)) for p in (layout.CLAIMS_NC, layout.ERROR_BUDGET_NC)
               if (before / rel(p)).exists()]
    text = [p.relative_to(before) for p in sorted((before / rel(layout.CHECKS)).glob("*.txt"))]
    text += [Path(rel(p)) for p in (layout.CLAIMS_CSV, layout.ERROR_BUDGET_CSV,
                                    *map(layout.paper_source, layout.PAPER_SOURCES))
             if (before / rel(p)).exists()]
    diffs: dict[str, list[str]] = {}
    for r in netcdf:
        d = ["missing"] if not (after / r).exists() else compare_dataset(before / r, after / r)
        if d:
            diffs[str(r)] = d
    for r in text:
        if not (after / r).exists():
            diffs[str(r)] = ["missing"]
        elif (after / r).read_text() != _rewritten((before / r).read_text()):
            diffs[str(r)] = ["text differs"]
    extra = sorted(str(p.relative_to(after)) for sub in folders
                   for p in (after / sub).rglob("*.nc") if not (before / p.relative_to(after)).exists())
    return {"netcdf_compared": len(netcdf), "text_compared": len(text), "replaced": [f"{a} -> {b}" for a, b in REPLACE],
            "differences": diffs, "only_after": extra}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("before", type=Path)
    ap.add_argument("after", type=Path)
    ap.add_argument("--replace", action="append", default=[], metavar="OLD=NEW",
                    help="rewrite OLD to NEW in the texts of BEFORE first (repeatable)")
    ap.add_argument("-o", "--output", type=Path)
    args = ap.parse_args(argv)
    REPLACE[:] = [tuple(r.split("=", 1)) for r in args.replace]
    summary = compare(args.before, args.after)
    out = json.dumps(summary, indent=1)
    if args.output:
        args.output.write_text(out + "\n")
    print(out)
    return 1 if summary["differences"] or summary["only_after"] or not summary["netcdf_compared"] else 0


if __name__ == "__main__":
    sys.exit(main())
