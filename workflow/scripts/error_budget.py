"""Snakemake script of rule `error_budget`: every figure dataset -> the error budget of the headline numbers."""
import _checkout  # noqa: F401  (this checkout's src/ first on sys.path)

# isort: split
import xarray as xr

from confined_rod.analysis import error_budget, figures
from confined_rod.io import logged, write_dataset, write_text

sm = snakemake  # noqa: F821 (injected by Snakemake)
with logged(sm.log[0]):
    datasets = {f: xr.load_dataset(p) for f, p in zip(sm.params.figures, sm.input.datasets)}
    ds = error_budget.build(datasets, figures.headlines)
    for r in error_budget.rows(ds):
        stat, bias = (("not measured" if r[k] is None else f"{r[k]:.2g} %") for k in ("stat_95_percent",
                                                                                     "bias_95_percent"))
        bias = (">= " if r["lower_bound"] and r["bias_95_percent"] is not None else "") + bias
        print(f"{r['headline']:45s} {r['value']:10.4g}  statistics {stat:>12s}  numerics {bias:>12s}  "
              f"({r['largest_bias']}; limited by {r['limited_by']})")
    write_dataset(ds, sm.output.nc)
    write_text(error_budget.to_csv(ds), sm.output.csv)
