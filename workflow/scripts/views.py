"""Snakemake script of rule `views`: a figure's simulations -> their 3-D views (plotly JSON)."""
import _checkout  # noqa: F401  (this checkout's src/ first on sys.path)

# isort: split
from confined_rod.analysis import view
from confined_rod.io import logged

with logged(snakemake.log[0]):  # noqa: F821 (injected by Snakemake)
    view.write_figure_views(snakemake.wildcards.figure, snakemake.params.scenes,  # noqa: F821
                            list(snakemake.input.sims), snakemake.output[0])  # noqa: F821
