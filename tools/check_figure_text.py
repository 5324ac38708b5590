"""Check that no text in a figure is printed smaller than 7 pt in the manuscript.

    python tools/check_figure_text.py config/config.yaml                  # every figure of the config
    python tools/check_figure_text.py config/config.yaml --figure fig6_FonL --min 7 -v

For each figure of the config: rebuild it from results/datasets/<figure>.nc with its kind's
plot() under the shared style (as the rule `figure` does), save it as a PDF in memory (with
savefig's tight bounding box, as the figure files are saved), record every Text artist that is
drawn (visible, non-empty: tick labels, axis labels, titles, legends, annotations, figure texts)
and compute the size at which the manuscript prints it: its font size times the factor by which
figures.tex scales the figure (paper.figure_scale: 1 at the figure's natural size, less only if the
figure is wider than \\textwidth or taller than paper.FIGURE_MAX_HEIGHT \\textheight). Sizes are in
points of 1/72 in; sub- and superscripts of math text are drawn smaller than their text's size by
design and are not counted separately.

Prints one line per figure (PDF size, scale, the smallest printed size) and every text below the
minimum with its kind module; exits 1 if any text is too small or a dataset is missing.
"""
from __future__ import annotations

import argparse
import io
import re
import sys
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.text  # noqa: E402
import xarray as xr  # noqa: E402

from confined_rod import layout, pipeline  # noqa: E402
from confined_rod.analysis import figures, plotting  # noqa: E402
from confined_rod.claims import manuscript as paper  # noqa: E402

MIN_PT = 7.0


def drawn_texts(fig) -> tuple[list, float, float]:
    """Save fig as a PDF in memory; return the Text artists drawn (visible, non-empty) and the
    PDF's width and height in big points."""
    seen: dict[int, matplotlib.text.Text] = {}
    original = matplotlib.text.Text.draw

    def record(self, renderer):
        if self.get_visible() and self.get_text().strip():
            seen[id(self)] = self
        return original(self, renderer)

    matplotlib.text.Text.draw = record
    try:
        buf = io.BytesIO()
        fig.savefig(buf, format="pdf")
    finally:
        matplotlib.text.Text.draw = original
    box = re.search(rb"/MediaBox\s*\[\s*0\s+0\s+([\d.]+)\s+([\d.]+)\s*\]", buf.getvalue())
    return list(seen.values()), float(box.group(1)), float(box.group(2))


def printed_sizes(fig, min_pt: float = MIN_PT) -> dict:
    """A figure's texts as the manuscript prints them: {'width_in', 'height_in' (of the saved PDF),
    'scale' (paper.figure_scale), 'min_pt' (smallest printed size), 'n_texts',
    'small': [(text, font size, printed size)] below min_pt}. Call it under plotting.STYLE."""
    texts, w, h = drawn_texts(fig)
    scale = paper.figure_scale(w, h)
    sizes = [(t.get_text().replace("\n", " | "), float(t.get_fontsize())) for t in texts]
    small = sorted({(t, s, s * scale) for t, s in sizes if s * scale < min_pt - 1e-9}, key=lambda x: (x[2], x[0]))
    printed = min((s * scale for _, s in sizes), default=float("nan"))
    return {"width_in": w / 72, "height_in": h / 72, "scale": scale, "min_pt": printed, "small": small,
            "n_texts": len(sizes)}


def check_figure(name: str, results: Path, min_pt: float) -> dict:
    """printed_sizes() of a figure rebuilt from its dataset, with its 'kind'."""
    ds = xr.load_dataset(layout.under(results, layout.dataset_path(name)))
    kind = ds.attrs["kind"]
    with plotting.plt.rc_context(plotting.STYLE):
        fig = figures.get(kind).plot(ds)
        out = printed_sizes(fig, min_pt)
        plotting.plt.close(fig)
    return {"kind": kind, **out}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("config")
    ap.add_argument("--figure", action="append", help="only this figure (repeatable)")
    ap.add_argument("--min", type=float, default=MIN_PT, help=f"smallest printed size in pt (default {MIN_PT})")
    ap.add_argument("--results", default=str(ROOT / layout.RESULTS))
    ap.add_argument("-v", "--verbose", action="store_true", help="list every text that is too small")
    args = ap.parse_args(argv)
    config = yaml.safe_load(Path(args.config).read_text())
    names = args.figure or pipeline.figures(config)
    results = Path(args.results)
    failed: dict[str, list[str]] = {}
    for name in names:
        path = layout.under(results, layout.dataset_path(name))
        if not path.is_file():
            print(f"{name}: MISSING {path} (build the config first)")
            failed.setdefault("(missing datasets)", []).append(name)
            continue
        r = check_figure(name, results, args.min)
        status = "ok" if not r["small"] else f"{len(r['small'])} text(s) below {args.min:g} pt"
        print(f"{name:28s} {r['kind']:18s} {r['width_in']:5.2f} x {r['height_in']:5.2f} in, printed at "
              f"{r['scale']:.3f}: smallest text {r['min_pt']:.2f} pt ({r['n_texts']} texts): {status}")
        shown = r["small"] if args.verbose else r["small"][:5]
        for text, size, printed in shown:
            print(f"    {printed:5.2f} pt (font {size:g} pt): {text[:90]!r}")
        if len(shown) < len(r["small"]):
            print(f"    ... and {len(r['small']) - len(shown)} more (-v lists them)")
        if r["small"]:
            failed.setdefault(f"src/confined_rod/analysis/figures/{r['kind']}.py", []).append(name)
    if failed:
        print(f"check_figure_text: FAIL: text printed below {args.min:g} pt in "
              + "; ".join(f"{where} ({', '.join(names)})" for where, names in failed.items()))
        return 1
    print(f"check_figure_text: {len(names)} figures, no text printed below {args.min:g} pt")
    return 0


if __name__ == "__main__":
    sys.exit(main())
