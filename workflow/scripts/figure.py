"""Snakemake script of rule `figure`: a figure's dataset -> PDF and PNG."""
import _checkout  # noqa: F401  (this checkout's src/ first on sys.path)

# isort: split
import matplotlib

matplotlib.use("Agg")  # a job draws to files (the package forces no backend: a notebook keeps its own)
import xarray as xr  # noqa: E402

from confined_rod.analysis import plotting  # noqa: E402
from confined_rod.io import logged  # noqa: E402

with logged(snakemake.log[0]):  # noqa: F821 (injected by Snakemake)
    plotting.plot(xr.load_dataset(snakemake.input.data), snakemake.output.pdf, snakemake.output.png)  # noqa: F821
