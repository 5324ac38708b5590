"""Snakemake script of rule `views_page`: every figure's 3-D views -> one page (the report's)."""
import _checkout  # noqa: F401  (this checkout's src/ first on sys.path)

# isort: split
from confined_rod.analysis import view
from confined_rod.io import logged

with logged(snakemake.log[0]):  # noqa: F821 (injected by Snakemake)
    view.write_index(list(snakemake.input.views), snakemake.output[0])  # noqa: F821
