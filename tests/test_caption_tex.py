"""Captions typeset: paper.caption_tex (plain-text caption -> LaTeX) and the figure floats.

Each construct the captions use has an input/expected pair; every caption of the configs
converts to LaTeX that pdflatex compiles in the manuscript's document class; text the converter
does not recognise is escaped as by tex_escape, so no caption can break the build.
"""
from __future__ import annotations

import json
import random
import re
import shutil
import subprocess
from pathlib import Path

import pytest
import yaml

from confined_rod import layout, pipeline
from confined_rod.claims import manuscript as paper

ROOT = Path(__file__).resolve().parents[1]
CONFIGS = [ROOT / "config" / "config.yaml", ROOT / "config" / "ci.yaml"]
PDFLATEX = shutil.which("pdflatex")
needs_tex = pytest.mark.skipif(PDFLATEX is None, reason="pdflatex is not installed")

CASES = [
    # symbols with subscripts: coordinates italic, labels roman
    ("F_z", r"$F_{z}$"),
    ("L_z", r"$L_{z}$"),
    ("k_fr", r"$k_{\mathrm{fr}}$"),
    ("k_ph", r"$k_{\mathrm{ph}}$"),
    ("k_w", r"$k_{\mathrm{w}}$"),
    ("L_half", r"$L_{\mathrm{half}}$"),
    ("beta_ph", r"$\beta_{\mathrm{ph}}$"),
    # function values and absolute values
    ("F_z(0)", r"$F_{z}(0)$"),
    ("|F_z(0)| = 0.25 EI/R^2", r"$|F_{z}(0)| = 0.25\,EI/R^{2}$"),
    ("|F_z(s)|", r"$|F_{z}(s)|$"),
    ("|F_z(L)|/|F_z(0)|", r"$|F_{z}(L)|/|F_{z}(0)|$"),
    ("F(L)/F(0)", r"$F(L)/F(0)$"),
    ("f(L)/f(0)", r"$f(L)/f(0)$"),
    # letter + digit, primes
    ("l0", r"$l_{0}$"),
    ("l0'", r"$l_{0}'$"),
    ("l0 = 0.5 R", r"$l_{0} = 0.5\,R$"),
    ("A, l0', c in", r"$A$, $l_{0}'$, $c$ in"),
    ("fit A (l0' + s)^c over", r"fit $A\,(l_{0}' + s)^{c}$ over"),
    ("q0 = 2 pi/(dphi/ds)", r"$q_{0} = 2\,\pi/(\mathrm{d}\phi/\mathrm{d}s)$"),
    ("F0", r"$F_{0}$"),
    # ratios, units, exponents
    ("L/R = 320", r"$L/R = 320$"),
    ("L/R = 20, 40", r"$L/R = 20$, 40"),
    ("0.1 EI/R^3", r"$0.1\,EI/R^{3}$"),
    ("R^-1", r"$R^{-1}$"),
    ("x^2 and x^-1", r"$x^{2}$ and $x^{-1}$"),
    ("x^(1/2)", r"$x^{1/2}$"),
    ("L^2/EI", r"$L^{2}/EI$"),
    ("times R^2/EI by", r"times $R^{2}/EI$ by"),
    ("2EI", r"$2EI$"),
    ("(4EI)", r"$(4EI)$"),
    ("sqrt(L^2 - 4R^2)", r"$\sqrt{L^{2} - 4R^{2}}$"),
    ("4/(3 sqrt 3) EI/R^2", r"$4/(3\,\sqrt{3})\,EI/R^{2}$"),
    ("(1/|F_z(0)| + k_fr R L/(4EI))^-1", r"$(1/|F_{z}(0)| + k_{\mathrm{fr}}\,R\,L/(4EI))^{-1}$"),
    ("24 R of", r"$24\,R$ of"),
    ("w^2", r"$w^{2}$"),
    # derivatives, Greek words, functions
    ("dphi/ds", r"$\mathrm{d}\phi/\mathrm{d}s$"),
    ("dL_z/dF", r"$\mathrm{d}L_{z}/\mathrm{d}F$"),
    ("d(1/|F_z|)/ds", r"$\mathrm{d}(1/|F_{z}|)/\mathrm{d}s$"),
    ("ln|F_z|", r"$\ln|F_{z}|$"),
    ("pi^2 EI/L^2", r"$\pi^{2}\,EI/L^{2}$"),
    ("omega^2", r"$\omega^{2}$"),
    ("phi", r"$\phi$"),
    ("Delta", r"$\Delta$"),
    # operators
    ("+-R", r"$\pm R$"),
    ("x = +-R", r"$x = \pm R$"),
    ("mean +- standard deviation", r"mean $\pm$ standard deviation"),
    ("+-2 % about", r"$\pm 2$ \% about"),
    ("L_z >= 0.8 L", r"$L_{z} \geq 0.8\,L$"),
    ("L_z < 0.5 L", r"$L_{z} < 0.5\,L$"),
    ("of >= 3 links", r"of $\geq 3$ links"),
    ("c <= 1", r"$c \leq 1$"),
    ("planar -> helix", r"planar $\to$ helix"),
    ("~ 100", r"$\sim 100$"),
    ("(s - s_h)", r"$(s - s_{\mathrm{h}})$"),
    ("close to -0.9", r"close to $-0.9$"),
    # numbers
    ("tol = 1e-05", r"tol $= 10^{-5}$"),
    ("1e-5", r"$10^{-5}$"),
    ("2.5e-3", r"$2.5\times10^{-3}$"),
    ("4x the time", r"$4\times$ the time"),
    ("36 loads", "36 loads"),
    ("1000.0", "1000.0"),
    # single-letter variables, and where a letter is a word
    ("(s from the loaded end)", r"($s$ from the loaded end)"),
    ("shaded by depth y.", r"shaded by depth $y$."),
    ("A rod of", "A rod of"),
    ("the paper's", "the paper's"),
    ("a rod", "a rod"),
    # text: ranges, panel labels, planes, identifiers, files, quotes
    ("seeds 0-4", "seeds 0--4"),
    ("(a)-(c) A rod", "(a)--(c) A rod"),
    ("(c) the end", "(c) the end"),
    ("Fig 4(c)", "Fig 4(c)"),
    ("the x-z plane", r"the $x$--$z$ plane"),
    ("3-D", "3-D"),
    ("one-at-a-time", "one-at-a-time"),
    ("protocol planar_then_3d", r"protocol \texttt{planar\_then\_3d}"),
    ("in fig8_escape", r"in \texttt{fig8\_escape}"),
    ("(docs/model.md)", r"(\texttt{docs/model.md})"),
    ("(confined_rod.analysis.regions).", r"(\texttt{confined\_rod.analysis.regions})."),
    ("d(1/|F_z|)/ds = k_fr R/(4EI)", r"$\mathrm{d}(1/|F_{z}|)/\mathrm{d}s = k_{\mathrm{fr}}\,R/(4EI)$"),
    ("protocol 'straight'", "protocol `straight'"),
    ('"word"', "``word''"),
    # what it does not recognise is escaped as by tex_escape
    ("50 % & #1 $x {y} \\ ~", r"50 \% \& \#1 \$$x$ \{$y$\} \textbackslash{} $\sim$"),
    ("a_b_c x_", r"\texttt{a\_b\_c} x\_"),
    ("^2 |", r"\textasciicircum{}2 \textbar{}"),
    ("919d2e5abc12", "919d2e5abc12"),
    ("12345678e901x", "12345678e901x"),
    ("R(colours)", r"$R$(colours)"),
    ("(x", r"($x$"),
    ("F_z(0", r"$F_{z}$(0"),
    ("", ""),
]


@pytest.mark.parametrize("text,tex", CASES)
def test_caption_tex_constructs(text, tex):
    assert paper.caption_tex(text) == tex


def test_caption_tex_refuses_non_ascii_like_tex_escape():
    with pytest.raises(ValueError, match="non-ASCII"):
        paper.caption_tex("load 0.25 EI/R\u00b2")


def _well_formed(tex: str) -> None:
    """Balanced $ (outside \\$) and braces (outside \\{ \\}), and no unescaped special character."""
    plain = tex.replace(r"\$", "").replace(r"\{", "").replace(r"\}", "")
    assert plain.count("$") % 2 == 0, tex
    depth = 0
    for ch in plain:
        depth += {"{": 1, "}": -1}.get(ch, 0)
        assert depth >= 0, tex
    assert depth == 0, tex
    assert not re.search(r"(?<!\\)[%#&]", tex), tex
    text_parts = re.sub(r"\$[^$]*\$", "", plain)
    assert not re.search(r"(?<![\\{])_|(?<!\\)\^", text_parts), tex


def _captions() -> dict[str, str]:
    out = {}
    for path in CONFIGS:
        config = yaml.safe_load(path.read_text())
        for figure in pipeline.figures(config):
            out[f"{path.name}:{figure}"] = pipeline.caption(config, figure)
    return out


def test_random_text_converts_to_well_formed_latex():
    """Fragments of the real captions with random characters mixed in, and random ASCII."""
    rng = random.Random(3)
    pieces = re.findall(r"\S+|\s+", " ".join(_captions().values()))
    alphabet = [chr(c) for c in range(32, 127)]
    for _ in range(1500):
        if rng.random() < 0.4:
            text = "".join(rng.choice(alphabet) for _ in range(rng.randint(1, 30)))
        else:
            i = rng.randrange(len(pieces))
            text = "".join(c if rng.random() > 0.05 else rng.choice(alphabet)
                           for c in "".join(pieces[i:i + rng.randint(1, 14)]))
        _well_formed(paper.caption_tex(text))


def _pdflatex(tmp_path: Path, body: str, extra: dict[str, bytes] | None = None) -> str:
    """Compile body in the manuscript's class and packages; return the log."""
    preamble = (r"\documentclass[pre,twocolumn,superscriptaddress,floatfix]{revtex4-2}" "\n"
                r"\usepackage{graphicx}\usepackage{longtable}\usepackage{array}\usepackage{amsmath}"
                r"\usepackage[hidelinks]{hyperref}" "\n")
    for name, data in (extra or {}).items():
        (tmp_path / name).write_bytes(data)
    (tmp_path / "doc.tex").write_text(preamble + r"\begin{document}" "\n" + body + "\n" r"\end{document}" "\n")
    proc = subprocess.run([PDFLATEX, "-interaction=nonstopmode", "-halt-on-error", "doc.tex"], cwd=tmp_path,
                          capture_output=True, text=True, timeout=120)
    log = (tmp_path / "doc.log").read_text(errors="replace")
    assert proc.returncode == 0, "\n".join(ln for ln in log.splitlines() if ln.startswith("!"))[:2000]
    return log


@needs_tex
def test_every_caption_of_the_configs_compiles(tmp_path):
    floats = []
    for name, caption in _captions().items():
        tex = paper.caption_tex(caption)
        _well_formed(tex)
        assert "$" in tex, name                      # each caption has typeset notation
        floats.append(r"\begin{figure*}[p]\centering\rule{2in}{1in}" "\n"
                      rf"\caption{{{tex}}}\label{{fig:{name.replace('_', '-')}}}\end{{figure*}}\clearpage")
    log = _pdflatex(tmp_path, "\n".join(floats))
    assert "Undefined control sequence" not in log
    assert "Missing $ inserted" not in log


def _pdf_figure(width_in: float, height_in: float) -> bytes:
    import io

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig = plt.figure(figsize=(width_in, height_in))
    buf = io.BytesIO()
    fig.savefig(buf, format="pdf")                   # no tight bbox: the PDF is exactly this size
    plt.close(fig)
    return buf.getvalue()


@needs_tex
def test_figures_are_printed_at_their_natural_size_capped_at_the_text_width(tmp_path):
    """The REVTeX dimensions paper.figure_scale assumes, and \\crfigure: a narrow figure at scale 1,
    a wide one scaled to \\textwidth, a tall one to FIGURE_MAX_HEIGHT \\textheight."""
    sizes = {"narrow.pdf": (3.0, 2.0), "wide.pdf": (10.0, 4.0), "tall.pdf": (5.0, 9.0)}
    body = [paper.FIGURE_MACRO, r"\typeout{DIM textwidth=\the\textwidth, textheight=\the\textheight}"]
    for name in sizes:
        body.append(rf"\sbox1{{\crfigure{{{name}}}}}\typeout{{DIM {name}=\the\wd1}}")
    log = _pdflatex(tmp_path, "\n".join(body) + "\nx", {n: _pdf_figure(*s) for n, s in sizes.items()})
    dims = dict(re.findall(r"([\w.]+)=([\d.]+)pt", " ".join(ln for ln in log.splitlines() if "DIM" in ln)))
    assert float(dims["textwidth"]) == paper.TEXTWIDTH_PT
    assert float(dims["textheight"]) == paper.TEXTHEIGHT_PT
    for name, (w, h) in sizes.items():
        expected_pt = w * 72.27 * paper.figure_scale(72 * w, 72 * h)
        assert float(dims[name]) == pytest.approx(expected_pt, rel=2e-3), name
    assert paper.figure_scale(72 * 3.0, 72 * 2.0) == 1.0
    assert paper.figure_scale(72 * 10.0, 72 * 4.0) < 1.0


def test_figure_floats_use_the_converter_and_natural_size():
    import xarray as xr
    ds = xr.Dataset(attrs={"git_commit": "0123456789abcdef", "confined_rod_version": "0.1"})
    tex = paper.figures_tex([("fig_x", 1)], {"fig_x": "Force |F_z(L)| against L/R = 20, k_fr = 0.8."},
                            {"fig_x": ds}, "config/ci.yaml")
    assert r"$|F_{z}(L)|$" in tex and r"$k_{\mathrm{fr}} = 0.8$" in tex
    assert r"\crfigure{fig_x.pdf}" in tex and r"\providecommand{\crfigure}" in tex
    assert r"\texttt{" + paper.tex_escape(layout.dataset_path("fig_x")) + "}" in tex and r"\texttt{0123456789ab}" in tex


def test_a_figure_caption_names_the_ladders_that_check_it_with_their_verdicts():
    """A ladder that serves a figure's scene (its ``serves`` attribute, as the convergence kind
    writes it) puts its verdict in that figure's caption, a failing one included; a figure no
    ladder serves gets no such sentence."""
    import xarray as xr
    plain = xr.Dataset(attrs={"git_commit": "0123456789abcdef"})
    lad = xr.Dataset(attrs={"kind": "convergence", "parameter": "ramp_steps", "status": "fail: decay ratio",
                            "serves": "fig4_Fonl_ramp.b (32 seeds configured: decay_ratio), fig6_FonL.L20 "
                                      "(5 seeds configured: F_transmitted)"})
    datasets = {"fig4_Fonl_ramp": plain, "fig6_FonL": plain, "fig7": plain, "conv_ramp_steps_b": lad}
    assert paper.served_checks("fig4_Fonl_ramp", datasets) == [("conv_ramp_steps_b", "b", "ramp_steps", "fail")]
    assert paper.served_checks("fig6_FonL", datasets) == [("conv_ramp_steps_b", "L20", "ramp_steps", "fail")]
    assert paper.served_checks("fig7", datasets) == []
    tex = paper.figures_tex([("fig4_Fonl_ramp", 4), ("fig7", 7)], {"fig4_Fonl_ramp": "A.", "fig7": "B."},
                            datasets, "config/config.yaml")
    fig4, fig7 = tex.split(r"\label{fig:fig4_Fonl_ramp}")
    assert r"\texttt{conv\_ramp\_steps\_b} (scene b, ramp\_steps): \textbf{fail}" in fig4
    assert "checked by" not in fig7


def test_the_supplement_figures_come_after_the_main_ones_in_one_numbering():
    """Main part: the paper's figures in the paper's order, then the others in config order; the
    figures marked ``supplement: true`` follow in config order (one numbering, so the main part's
    figures 1-8 are the original's 1-8 when the variants are in the supplement)."""
    config = {"figures": {"conv": {"kind": "convergence", "supplement": True},
                          "map": {"kind": "jamming_map"},
                          "f4": {"kind": "force_profile", "paper_figure": 4},
                          "f4_ramp": {"kind": "force_profile", "paper_figure": 4, "supplement": True},
                          "f1": {"kind": "helix_views", "paper_figure": 1}}}
    assert [n for n, _ in paper.figure_order(config)] == ["f1", "f4", "map", "conv", "f4_ramp"]
    assert paper.in_supplement(config) == {"conv", "f4_ramp"}
    for name in ("config/config.yaml", "config/ci.yaml"):
        cfg = yaml.safe_load((ROOT / name).read_text())
        main = [n for n, _ in paper.figure_order(cfg) if n not in paper.in_supplement(cfg)]
        numbered = {cfg["figures"][n].get("paper_figure"): i for i, n in enumerate(main, 1)}
        assert all(numbered[k] == k for k in numbered if k), (name, main)


def test_every_protocol_has_a_name_in_the_results_table():
    from confined_rod.quantities import QUANTITIES

    assert set(paper.PROTOCOL_NAMES) == set(QUANTITIES["protocol"].choices)


def _verdict(**kw):
    from confined_rod.claims import Verdict
    base = dict(id="x", where="Fig. 6", claim="c", paper="0.5", paper_value=0.5, ours="0.961", ours_value=0.961,
                tolerance="", verdict="inconclusive", evidence="results/datasets/f.nc:v", label="Decay law",
                quantity="rate/law", protocol="straight", ours_error=0.0172)
    return Verdict(**{**base, **kw})


def test_the_tables_print_ours_with_its_error_and_quantity_and_the_protocol_in_words():
    v = _verdict()
    assert paper.ours_text(v) == "0.961 +- 0.017"                  # rounded together
    assert paper.ours_text(_verdict(ours_error=None)) == "0.961"
    tex, plain = paper._value_cell(paper.ours_text(v), v.quantity)
    assert plain == "rate/law = 0.961+-0.017" and r"\ensuremath{\pm}" in tex
    assert paper._value_cell("falls, less than |F_z|", "drop")[1] == "falls, less than |F_z|"   # text: as it is
    results = paper.results_table([v, _verdict(id="y", protocol="", evidence="confined_rod.claims.derivations.x",
                                                paper="EI R w^2 [-sqrt(1-R^2w^2) e_phi + R w e_z]", quantity="",
                                                verdict="reproduced", ours_error=None),
                                   _verdict(id="z", protocol="helix, ramp, straight",
                                            quantity="a quantity of thirty-odd chars")])
    rows = [r for r in results.splitlines() if r.startswith("C")]
    assert len(rows) == 3 and "full load at once" in rows[0] and r"\textbf{\mbox{inconclusive}}" in rows[0]
    assert r"rate/law = 0.961\ensuremath{\pm}0.017" in rows[0]
    assert "derivation" in rows[1] and r"Table~\ref{tab:claims}" in rows[1]       # too long for a cell
    assert "3 protocols" in rows[2] and r"a quantity of thirty-odd chars = 0.961\ensuremath{\pm}0.017" in rows[2]
    assert r"\label{tab:results}" in results and "The results: every claim" in results
    claims = paper.claims_table([v])
    assert "where (original)" in claims and r"rate/law = 0.961\ensuremath{\pm}0.017" in claims
    expected = json.loads(paper.write_expected(paper.Macros(), 1, [v]))["claims"][0]
    assert expected["ours"] == "0.961+-0.017" and expected["paper"] == "0.5"
    macros = paper.Macros()
    paper.claim_macros([v], macros)
    assert macros.expected()["ours@x"] == "0.961+-0.017"


def test_study_macros_count_the_seeds_that_reached_equilibrium_on_every_rung(tmp_path):
    """A study of two rungs (benchmarks/study_ladder_seeds.py's layout): a seed missing on one
    rung or unconverged on one is not paired; a study that states its seed count gives it; the
    committed studies all give a count, so the manuscript's \\val{study.*} are defined."""
    import glob
    import json

    from confined_rod import layout
    runs = {"dx002": {"0": {"converged": True}, "1": {"converged": True}, "2": {"converged": False}},
            "dx0005": {"0": {"converged": True}, "1": {"converged": True}, "2": {"converged": True},
                       "3": {"converged": True}}}
    (tmp_path / "study_seeds_x.json").write_text(json.dumps({"runs": runs}))
    (tmp_path / "study_y.json").write_text(json.dumps({"seeds": 64}))
    macros = paper.Macros()
    paper.study_macros([str(p) for p in tmp_path.glob("*.json")], macros)
    assert macros.expected() == {"val@study.seeds_x.seeds": "2", "val@study.y.seeds": "64"}
    macros = paper.Macros()
    paper.study_macros(glob.glob(str(Path(__file__).resolve().parents[1] / layout.STUDIES_GLOB)), macros)
    cited = set(re.findall(r"\\val\{(study\.[^}]+)\}", (Path(__file__).resolve().parents[1]
                                                         / "paper" / "reproduction.tex").read_text()))
    assert cited and cited <= {k.split("@", 1)[1] for k in macros.expected()}


def test_no_caption_carries_an_unformatted_placeholder():
    """A '{name}' left in a caption is an f-string prefix forgotten on one line of it (the
    convergence captions printed 'The publication value {p} =')."""
    for name, caption in _captions().items():
        assert not re.search(r"\{[A-Za-z_][A-Za-z_0-9.]*(:[^}]*)?\}", caption), (name, caption)
