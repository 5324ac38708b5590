"""Snakemake script of rule `claims`: every claim of the original, evaluated on the datasets."""
import _checkout  # noqa: F401  (this checkout's src/ first on sys.path)

# isort: split
import xarray as xr

from confined_rod import claims, layout
from confined_rod.analysis import run_checks
from confined_rod.io import logged, write_dataset, write_text

sm = snakemake  # noqa: F821 (injected by Snakemake)
with logged(sm.log[0]):
    datasets = {f: xr.load_dataset(p) for f, p in zip(sm.params.figures, sm.input.datasets)}
    sims = {k: run_checks.load(p, w) for k, p, w in zip(sm.params.sim_keys, sm.input.sims, sm.params.wanted)}
    files = {k: str(p) for k, p in zip(sm.params.sim_keys, sm.input.sims)}
    verdicts = claims.evaluate(claims.load(sm.input.claims), claims.Evidence(datasets, sims, files))
    unsettled = [v for v in verdicts if v.note.startswith("evidence not at equilibrium")]
    if unsettled:
        run_checks.warn(f"warning: {len(unsettled)} claims are not testable because their evidence is not at "
                      "equilibrium: " + "; ".join(f"{v.id}: {v.note}" for v in unsettled[:5])
                      + (f"; and {len(unsettled) - 5} more ({layout.CLAIMS_CSV})" if len(unsettled) > 5 else ""))
    for v in verdicts:
        print(f"{v.id:28s} {v.verdict:26s} paper {v.paper[:30]!r:34s} ours {v.ours[:30]!r:34s} {v.evidence}")
    write_dataset(claims.to_dataset(verdicts, claims.finding_titles(sm.input.claims)), sm.output.nc)
    write_text(claims.to_csv(verdicts), sm.output.csv)
