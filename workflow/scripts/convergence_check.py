"""Snakemake script of rule `convergence_check`: a convergence dataset -> verdict (or a failed build)."""
import _checkout  # noqa: F401  (this checkout's src/ first on sys.path)

# isort: split
import xarray as xr

from confined_rod.analysis import figures
from confined_rod.io import logged, write_text

with logged(snakemake.log[0]):  # noqa: F821 (injected by Snakemake)
    ds = xr.load_dataset(snakemake.input[0])  # noqa: F821
    check = figures.get(ds.attrs["kind"]).check
    line = check(ds, snakemake.wildcards.figure, snakemake.params.on_inconclusive,  # noqa: F821
                 snakemake.params.on_fail)  # noqa: F821
    print(line)
    # the verdict, then every comparison it was decided from (shift +- its standard error, 95 % bound,
    # resolution, Anderson-Darling p-value, tolerance), one per line
    details = ds.attrs.get("comparisons", "")
    write_text(line + "\n" + (f"comparisons:\n{details}\n" if details else ""), snakemake.output[0])  # noqa: F821
