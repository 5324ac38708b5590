"""Snakemake script of rule `figure`: a figure's dataset -> PDF and PNG."""
import _checkout  # noqa: F401  (this checkout's src/ first on sys.path)

# isort: split
import xarray as xr

from confined_rod.analysis import plotting
from confined_rod.io import logged

with logged(snakemake.log[0]):  # noqa: F821 (injected by Snakemake)
    plotting.plot(xr.load_dataset(snakemake.input.data), snakemake.output.pdf, snakemake.output.png)  # noqa: F821
