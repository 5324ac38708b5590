"""Check every artifact a pipeline config promises: it exists, opens, and holds no NaN.

    python tools/check_artifacts.py config/ci.yaml [--report results/report.html] [--report results/report.zip]
    python tools/check_artifacts.py config/config.yaml --figure fig6_FonL   # one figure's artifacts

netCDF files must open with xarray, carry CF attributes, and have no NaN or inf in
any floating-point variable; figures must be non-empty images (PNG decodes to a
non-blank picture, PDF has a PDF header and pages); the 3-D views folder holds its index,
its plotly.js and one page per simulation.  Exit status 1 lists every failure.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
import xarray as xr
import yaml

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

from confined_rod import layout, pipeline  # noqa: E402


def check_netcdf(path: Path) -> list[str]:
    errors = []
    with xr.open_dataset(path) as ds:
        for key in ("Conventions", "title", "history", "git_commit", "confined_rod_version"):
            if key not in ds.attrs:
                errors.append(f"{path}: global attribute {key!r} missing")
        for name, var in ds.variables.items():
            if "units" not in var.attrs and var.dtype.kind not in "OSU":
                errors.append(f"{path}: variable {name!r} has no units")
            if "long_name" not in var.attrs:
                errors.append(f"{path}: variable {name!r} has no long_name")
            if var.dtype.kind == "f":
                bad = int(np.size(var.values) - np.count_nonzero(np.isfinite(var.values)))
                if bad:
                    errors.append(f"{path}: variable {name!r} has {bad} NaN/inf values")
            if var.size == 0 and name in ds.data_vars and var.dims and var.dims[0] not in ("s_helix", "t"):
                errors.append(f"{path}: variable {name!r} is empty")
        if "converged" in ds and int(np.min(ds["converged"].values)) == 0:
            print(f"note: {path}: not every run converged", file=sys.stderr)
    return errors


def check_png(path: Path) -> list[str]:
    import matplotlib.image as mpimg

    img = mpimg.imread(path)
    if img.ndim != 3 or img.shape[0] < 200 or img.shape[1] < 200:
        return [f"{path}: image too small or not RGB(A): shape {img.shape}"]
    if float(np.std(img[..., :3])) < 1e-3:
        return [f"{path}: image is blank"]
    return []


def check_pdf(path: Path) -> list[str]:
    """A PDF with at least one page (pdfinfo where installed: pdflatex compresses its page
    objects into object streams, so '/Page' need not appear in the bytes)."""
    import shutil
    import subprocess

    data = path.read_bytes()
    if not data.startswith(b"%PDF-") or len(data) < 2000:
        return [f"{path}: not a non-empty PDF ({len(data)} bytes)"]
    if shutil.which("pdfinfo"):
        out = subprocess.run(["pdfinfo", str(path)], capture_output=True, text=True)
        pages = [ln.split()[-1] for ln in out.stdout.splitlines() if ln.startswith("Pages:")]
        if out.returncode != 0 or not pages or int(pages[0]) < 1:
            return [f"{path}: pdfinfo finds no pages ({out.stderr.strip()[:200]})"]
    elif b"/Page" not in data and b"/ObjStm" not in data:
        return [f"{path}: no page objects ({len(data)} bytes)"]
    return []


def check_csv(path: Path) -> list[str]:
    """A table: the claims (a verdict column) or the error budget (a limited_by column) with at
    least one row, every row with that column filled, no NaN."""
    import csv

    column, key = (("limited_by", "headline") if path.name == Path(layout.ERROR_BUDGET_CSV).name
                   else ("verdict", "id"))
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows or column not in rows[0]:
        return [f"{path}: no rows or no {column} column"]
    errors = [f"{path}: row {r.get(key)!r} has no {column}" for r in rows if not r[column]]
    errors += [f"{path}: row {r.get(key)!r} contains NaN" for r in rows
               if any(v.strip().lower() == "nan" for v in r.values())]
    return errors


def check_verdict(path: Path) -> list[str]:
    """A convergence check's verdict: pass, inconclusive, or fail (a fail the config reports with
    ``on_fail: warn``; any other stops the build before the file is written)."""
    text = path.read_text().strip()
    if not any(f": {word}" in text for word in ("pass", "inconclusive", "fail")):
        return [f"{path}: not a convergence verdict: {text[:80]!r}"]
    return []


def check_views(path: Path, config: dict) -> list[str]:
    """The 3-D views (rule views): the folder holds its index, the plotly.js its pages share and one
    non-empty page per simulation of the figures; each page loads that plotly.js and holds a tube."""
    errors = []
    for f in map(Path, pipeline.view_pages(config)):
        if not f.is_file() or f.stat().st_size == 0:
            errors.append(f"{f}: missing or empty")
        elif f.suffix == ".html" and f.name != Path(layout.VIEWS_INDEX).name:
            text = f.read_text()
            if f'src="../{layout.VIEWS_PLOTLY}"' not in text or '"type":"mesh3d"' not in text:
                errors.append(f"{f}: not a view page (no plotly.js or no tube)")
    return errors


def figure_outputs(config: dict, names: list[str]) -> dict[str, list[str]]:
    """The artifacts of the named figures only (a partial build, such as CI's publication part)."""
    unknown = [f for f in names if f not in pipeline.figures(config)]
    if unknown:
        raise SystemExit(f"--figure: {unknown[0]!r} is not a figure of this config")
    checks = set(pipeline.convergence_figures(config))
    return {"sims": [p for f in names for p in pipeline.figure_sims(config, f)],
            "datasets": [layout.dataset_path(f) for f in names],
            "figures": [p for f in names for p in layout.figure_paths(f)],
            "checks": [layout.check_path(f) for f in names if f in checks]}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("config")
    ap.add_argument("--report", action="append", default=[],
                    help="also check this report, HTML or zip (exists, mentions every figure; a zip report carries "
                         "every 3-D view); repeatable")
    ap.add_argument("--figure", action="append", default=[],
                    help="check only this figure's simulations, dataset, images and check (repeatable)")
    args = ap.parse_args(argv)
    config = pipeline.expand(yaml.safe_load(Path(args.config).read_text()))   # seeds and sweeps as scenes
    expected = pipeline.expected_outputs(config)
    if args.figure:
        expected = figure_outputs(config, args.figure)
    errors: list[str] = []
    n = 0
    for kind, paths in expected.items():
        for p in map(Path, paths):
            n += 1
            if kind == "views":
                errors += check_views(p, config)
                continue
            if not p.is_file() or p.stat().st_size == 0:
                errors.append(f"{p}: missing or empty")
                continue
            try:
                check = {".nc": check_netcdf, ".png": check_png, ".pdf": check_pdf, ".txt": check_verdict,
                         ".csv": check_csv}[p.suffix]
                errors += check(p)
            except Exception as e:  # noqa: BLE001 - any failure to open is a failed check
                errors.append(f"{p}: cannot be read: {type(e).__name__}: {e}")
    for report in args.report:
        rp = Path(report)
        if not rp.is_file():
            errors.append(f"{rp}: report missing")
            continue
        members: list[str] = []
        if rp.suffix == ".zip":                         # a zip report: its page and the files it carries
            import zipfile

            with zipfile.ZipFile(rp) as z:
                members = z.namelist()
                page = next((m for m in members if m.endswith("/report.html")), None)
                html = z.read(page).decode(errors="replace") if page else ""
        else:
            html = rp.read_text(errors="replace")
        for f in pipeline.figures(config):
            if f"{f}.png" not in html:
                errors.append(f"{rp}: figure {f} not in the report")
        if pipeline.view_outputs(config) and layout.VIEWS_INDEX not in html:
            errors.append(f"{rp}: the report does not name the 3-D views ({layout.VIEWS_INDEX})")
        if members:                                     # a zip report carries every view page
            carried = {m.split("/", 4)[-1] for m in members if m.count("/") >= 4}   # REPORT/data/raw/ID/...
            for v in pipeline.view_pages(config):
                if str(Path(v).relative_to(layout.VIEWS)) not in carried:
                    errors.append(f"{rp}: the 3-D view {v} is not in the report")
        if html.count("Parameters:") < len(pipeline.figures(config)):
            errors.append(f"{rp}: a figure caption is missing")
    for e in errors:
        print("FAIL", e, file=sys.stderr)
    print(f"checked {n} artifacts of {args.config}" + (f" and {', '.join(args.report)}" if args.report else "")
          + f": {len(errors)} failure(s)")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
