"""Check the built manuscript against the datasets it was generated from.

    python tools/check_paper.py config/ci.yaml               # the PDF of that config's build
    python tools/check_paper.py config/ci.yaml --perturb     # and: a config change reaches the PDF

Checks (pdfinfo, pdftotext of poppler-utils):
* the PDF exists and has the config's expected number of pages (paper.pages: [min, max]);
* it has one numbered figure per figure of the config;
* no unresolved reference ("??");
* the abstract has at most ABSTRACT_WORDS words (a reader's budget, not the config's);
* every generated value the manuscript quotes (\\ours, \\paperval, \\verdict, \\val) appears in
  the text exactly as results/paper/expected.json (from the datasets) says;
* the main part (before the supplement, Appendix A) has at most MAIN_PAGES pages;
* every row of the results table (C1, C2, ...) carries its claim's verdict, and every row of the
  claims table its verdict, paper value and ours;
* results/claims.csv has one row per claim of paper/claims.yaml, each with a verdict.
With --perturb: change one scene parameter (the short rod of fig1_short_long: L -> L + 4 R) in a
copy of the config, rebuild the PDF with Snakemake, and check that the load/Euler ratio quoted in
the text changed and equals the new dataset's value.
"""
from __future__ import annotations

import argparse
import csv
import json
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import xarray as xr
import yaml

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

from confined_rod import claims as claims_mod  # noqa: E402
from confined_rod import layout  # noqa: E402
from confined_rod.claims import fmt  # noqa: E402
from confined_rod.claims import manuscript as paper  # noqa: E402

RESULTS = ROOT / layout.RESULTS
#: words of the abstract as pdftotext gives them back (a number or a symbol counts as a word)
ABSTRACT_WORDS = 200
#: pages of the main part, up to the supplement (Appendix A: after a \clearpage, on a page of
#: its own): a reader's budget for the text, the results table and the main figures
MAIN_PAGES = 12
SUPPLEMENT = re.compile(r"Appendix\s+A:\s*Supplement", re.I)
MACRO = re.compile(r"\\(ours|paperval|verdict|val)\{([^}]*)\}")
FAMILY = {"ours": "ours", "paperval": "paper", "verdict": "verdict", "val": "val"}


def fail(msg: str) -> None:
    print(f"check_paper: FAIL: {msg}")
    sys.exit(1)


def pdf_text(pdf: Path, layout: bool = False) -> str:
    args = ["pdftotext"] + (["-layout"] if layout else []) + [str(pdf), "-"]
    return subprocess.run(args, capture_output=True, text=True, check=True).stdout


def in_order(value: str, segment: str) -> bool:
    """The words of `value` appear in `segment` in order (a cell's lines may be interleaved
    with its neighbours' in the text)."""
    pos = 0
    for word in value.split():
        pos = segment.find(paper.normalize(word), pos)
        if pos < 0:
            return False
        pos += len(paper.normalize(word))
    return True


def pages(pdf: Path) -> int:
    out = subprocess.run(["pdfinfo", str(pdf)], capture_output=True, text=True, check=True).stdout
    return int(re.search(r"^Pages:\s+(\d+)", out, re.M).group(1))


def used_macros(tex: Path, numbers: Path) -> set[tuple[str, str]]:
    """Macro calls in the manuscript and in the generated tables that use \\val."""
    text = tex.read_text() + numbers.read_text()
    return {(FAMILY[f], k) for f, k in MACRO.findall(text) if k != "#1" and not k.startswith("#")}


def _built(path: str | Path) -> Path:
    """A file of the layout in the build checked (--results)."""
    return layout.under(RESULTS, path)


def abstract_words(raw: str) -> int:
    """Words of the abstract in the PDF's text: from the line after the date to the first
    section heading ('I.')."""
    m = re.search(r"\(Dated:[^)]*\)\s*(.*?)\n\s*I\.\s*\n", raw, re.S)
    if not m:
        fail("the abstract was not found between the date and section I")
    return len(m.group(1).split())


def check(config_path: str) -> dict:
    config = yaml.safe_load(Path(config_path).read_text())
    spec = config.get("paper")
    if not spec:
        fail(f"{config_path} has no paper section")
    name = Path(spec["manuscript"]).stem
    pdf = _built(layout.paper_pdf(name))
    if not pdf.is_file():
        fail(f"{pdf} does not exist")
    expected = json.loads(_built(layout.paper_source("expected")).read_text())
    n_pages = pages(pdf)
    lo, hi = spec.get("pages", [1, 10_000])
    if not lo <= n_pages <= hi:
        fail(f"{pdf.name} has {n_pages} pages, expected {lo}-{hi} (paper.pages of {config_path})")
    raw = pdf_text(pdf)
    text = paper.normalize(raw)
    if "??" in raw:
        fail(f"{pdf.name} has an unresolved reference ('??')")
    first = next((i for i, page in enumerate(raw.split("\f")) if SUPPLEMENT.search(page)), None)
    if first is None:
        fail(f"{pdf.name}: no supplement (Appendix A) found")
    if first > MAIN_PAGES:
        fail(f"{pdf.name}: the main part has {first} pages before the supplement, at most {MAIN_PAGES}")
    n_words = abstract_words(raw)
    if n_words > ABSTRACT_WORDS:
        fail(f"{pdf.name}: the abstract has {n_words} words, at most {ABSTRACT_WORDS}")
    figs = sorted({int(n) for n in re.findall(r"FIG\.\s*(\d+)\.", raw)})
    if figs != list(range(1, expected["n_figures"] + 1)):
        fail(f"{pdf.name}: numbered figures {figs}, expected 1..{expected['n_figures']} (one per figure of the config)")
    missing = []
    for family, key in sorted(used_macros(ROOT / spec["manuscript"], _built(layout.paper_source("numbers")))):
        plain = expected["macros"].get(f"{family}@{key}")
        if plain is None:
            fail(f"the manuscript uses \\{family}{{{key}}}, which the build does not generate")
        # a number must appear exactly; a text of several words in order (a table cell's lines
        # can come out of pdftotext interleaved with its neighbours')
        found = paper.normalize(plain) in text if paper.is_number(plain) else in_order(plain, text)
        if not found:
            missing.append(f"{family}{{{key}}} = {plain!r}")
    if missing:
        fail(f"{len(missing)} generated values are not in the PDF text: " + "; ".join(missing[:10]))
    # the results table (main text) and the claims table (supplement), row by row (labels C1, C2,
    # ... in order): the verdict, and the paper's value and ours where they are numbers (a text
    # spanning several lines of a cell comes out of pdftotext interleaved with the neighbouring cells)
    laid_out = pdf_text(pdf, layout=True)          # rows stay on their lines
    rows = expected["claims"]
    for name, start_text, end_text, values in (
            ("results table", "The results: every claim", "Table ", ("verdict",)),
            ("claims table", "Every checkable statement", "Thereadings", ("verdict", "ours", "paper"))):
        at = laid_out.find(start_text)
        if at < 0:
            fail(f"{pdf.name}: the {name} ({start_text!r} ...) is not in the PDF")
        table, start = paper.normalize(laid_out[at:]), 0
        for i, row in enumerate(rows):
            start = table.find(row["label"], start)
            if start < 0:
                fail(f"{name}: row {row['label']} ({row['id']}) not found")
            end = table.find(rows[i + 1]["label"], start + 1) if i + 1 < len(rows) else table.find(end_text, start)
            seg = table[start:end if end > 0 else len(table)]
            for what in values:
                if what != "verdict" and not paper.is_number(row[what].split(" ")[0]):
                    continue
                if not in_order(row[what], seg):
                    fail(f"{name} row {row['label']} ({row['id']}): {what} {row[what]!r} not in {seg[:200]!r}")
    listed = claims_mod.load(ROOT / spec["claims"])
    with open(_built(layout.CLAIMS_CSV)) as f:
        table_rows = list(csv.DictReader(f))
    if [r["id"] for r in table_rows] != [c["id"] for c in listed]:
        fail(f"{layout.CLAIMS_CSV} does not have one row per claim of " + spec["claims"])
    bad = [r["id"] for r in table_rows if r["verdict"] not in claims_mod.VERDICTS]
    if bad:
        fail(f"{layout.CLAIMS_CSV}: claims without a verdict: {bad}")
    counts = {v: sum(r["verdict"] == v for r in table_rows) for v in claims_mod.VERDICTS}
    print(f"check_paper: {pdf.name}: {n_pages} pages ({first} before the supplement), {len(figs)} figures, "
          f"{len(used_macros(ROOT / spec['manuscript'], _built(layout.paper_source('numbers'))))} generated "
          f"values and {len(rows)} claim rows found in the text; verdicts {counts}")
    return expected


def perturb(config_path: str) -> None:
    """A scene parameter changed in the config changes the number in the PDF."""
    config = yaml.safe_load(Path(config_path).read_text())
    fig = config["figures"]["fig1_short_long"]
    short = min(fig["scenes"], key=lambda s: fig["scenes"][s].get("L", 0))
    before = json.loads(_built(layout.paper_source("expected")).read_text())["macros"]["ours@euler_ratio_short"]
    fig["scenes"][short]["L"] = float(fig["scenes"][short]["L"]) + 4.0
    with tempfile.NamedTemporaryFile("w", suffix=".yaml", dir=ROOT / "config", delete=False) as f:
        yaml.safe_dump(config, f, sort_keys=False)
        tmp = Path(f.name)
    try:
        target = layout.paper_pdf(Path(config['paper']['manuscript']).stem)
        subprocess.run([str(ROOT / ".venv" / "bin" / "snakemake"), target, "--cores", "2", "--configfile", str(tmp),
                        "--quiet", "rules"], cwd=ROOT, check=True)
    finally:
        tmp.unlink()
    expected = check(config_path)
    after = expected["macros"]["ours@euler_ratio_short"]
    ds = xr.load_dataset(_built(layout.dataset_path("fig1_short_long")))
    spec = next(c for c in claims_mod.load(ROOT / "paper" / "claims.yaml") if c["id"] == "euler_ratio_short")
    value = fmt(float(ds.euler_ratio.isel(scene=0)), spec.get("format"))
    if after == before or after != value:
        fail(f"after L -> L + 4 R of fig1_short_long/{short}: the PDF quotes {after!r} (before {before!r}), "
             f"the dataset gives {value!r}")
    print(f"check_paper: fig1_short_long/{short} L + 4 R: the PDF's load/Euler ratio went from {before} to {after}, "
          "as in the rebuilt dataset")


def main() -> None:
    global RESULTS
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("config")
    ap.add_argument("--results", default=str(ROOT / layout.RESULTS),
                    help=f"the build's results folder (default: {layout.RESULTS}/)")
    ap.add_argument("--perturb", action="store_true", help="also check that a config change reaches the PDF")
    args = ap.parse_args()
    RESULTS = Path(args.results)
    check(args.config)
    if args.perturb:
        perturb(args.config)


if __name__ == "__main__":
    main()
