"""Snakemake script of rule `views`: every simulation of the figures -> its 3-D view (results/views/)."""
import _checkout  # noqa: F401  (this checkout's src/ first on sys.path)

# isort: split
from confined_rod.analysis import view
from confined_rod.io import logged

with logged(snakemake.log[0]):  # noqa: F821 (injected by Snakemake)
    view.write_views(snakemake.output[0], snakemake.params.figures)  # noqa: F821
