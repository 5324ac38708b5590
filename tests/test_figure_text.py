"""tools/check_figure_text.py: the printed size of every drawn text of a figure."""
import importlib.util
from pathlib import Path

import pytest

from confined_rod.analysis import plotting
from confined_rod.claims import manuscript as paper

ROOT = Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location("check_figure_text", ROOT / "tools" / "check_figure_text.py")
check_figure_text = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(check_figure_text)


def _figure(width_in, height_in, fontsize):
    fig, ax = plotting.plt.subplots(figsize=(width_in, height_in))
    ax.plot([0, 1], [0, 1])
    ax.set_xlim(0, 1)
    ax.text(0.5, 0.5, "note", fontsize=fontsize)
    ax.text(0.5, 0.2, "hidden", fontsize=3, visible=False)     # not drawn: not counted
    ax.text(0.5, 0.3, "", fontsize=3)                          # empty: not counted
    ax.set_xlabel("x label")
    return fig


@pytest.mark.parametrize("width,fontsize,scaled,fails", [
    (5.0, 7.0, False, False),      # at its natural size: printed as drawn
    (5.0, 6.5, False, True),
    (14.0, 9.0, True, True),       # far wider than the text width: 9 pt printed at about 5.5 pt
])
def test_printed_sizes(width, fontsize, scaled, fails):
    with plotting.plt.rc_context(plotting.STYLE):
        fig = _figure(width, 3.0, fontsize)
        r = check_figure_text.printed_sizes(fig, 7.0)
        plotting.plt.close(fig)
    assert r["scale"] == pytest.approx(paper.figure_scale(72 * r["width_in"], 72 * r["height_in"]))
    assert (r["scale"] < 1.0) == scaled
    assert r["width_in"] < width + 0.01                       # the saved PDF: the tight bounding box
    small = {text for text, _, _ in r["small"]}
    assert ("note" in small) == fails
    assert scaled or small <= {"note"}                         # at the natural size only the 6.5 pt note
    assert r["min_pt"] == pytest.approx(min(fontsize, 8.5) * r["scale"])
    assert r["n_texts"] >= 4                                   # note, x label, tick labels


def test_the_shared_style_prints_nothing_below_the_minimum():
    """Every font size of plotting.STYLE is at least plotting.MIN_FONT_PT at the natural size."""
    import matplotlib.font_manager as fm
    with plotting.plt.rc_context(plotting.STYLE):
        base = plotting.plt.rcParams["font.size"]
        for key in ("font.size", "axes.labelsize", "axes.titlesize", "figure.titlesize", "xtick.labelsize",
                    "ytick.labelsize", "legend.fontsize"):
            value = plotting.plt.rcParams[key]
            size = value if isinstance(value, (int, float)) else fm.FontProperties(size=value).get_size_in_points()
            assert size >= plotting.MIN_FONT_PT, (key, size, base)
    assert plotting.TEXT_WIDTH_IN * 72 <= paper.TEXTWIDTH_PT * 72 / 72.27
    assert plotting.MAX_HEIGHT_IN * 72 <= paper.FIGURE_MAX_HEIGHT * paper.TEXTHEIGHT_PT * 72 / 72.27
