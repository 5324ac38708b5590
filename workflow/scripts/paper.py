"""Snakemake script of rule `paper`: latexmk on the manuscript and its generated parts."""
import _checkout  # noqa: F401  (this checkout's src/ first on sys.path)

# isort: split
from confined_rod.claims import manuscript as paper
from confined_rod.io import logged

sm = snakemake  # noqa: F821 (injected by Snakemake)
with logged(sm.log[0]):
    paper.build_pdf(sm.input.tex, sources=sm.input.sources, figures=sm.input.figures, output=sm.output[0])
