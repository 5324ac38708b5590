"""Snakemake script of rule `paper_sources`: the manuscript's generated numbers, tables and figures."""
import _checkout  # noqa: F401  (this checkout's src/ first on sys.path)

# isort: split
import json

import xarray as xr

from confined_rod import claims
from confined_rod.claims import manuscript as paper
from confined_rod.io import logged, write_text

sm = snakemake  # noqa: F821 (injected by Snakemake)
with logged(sm.log[0]):
    datasets = {f: xr.load_dataset(p) for f, p in zip(sm.params.figures, sm.input.datasets)}
    claims_ds = xr.load_dataset(sm.input.claims)
    verdicts = paper.verdicts_from_dataset(claims_ds)
    macros = paper.Macros()
    paper.claim_macros(verdicts, macros)
    paper.finding_macros(verdicts, json.loads(claims_ds.attrs.get("finding_titles", "{}")), macros)
    paper.dataset_macros(datasets, macros)
    paper.printed_fits_macros(claims.load(sm.input.claims_spec), datasets, macros)
    paper.budget_macros(xr.load_dataset(sm.input.budget[0]) if sm.input.budget else None, macros)
    paper.study_macros(sm.input.studies, macros)
    macros.add("val", "config", sm.params.config_name)
    order = [tuple(x) for x in sm.params.order]
    paper.figure_macros(order, macros)
    write_text(macros.tex(), sm.output.numbers)
    write_text(paper.claims_table(verdicts), sm.output.table)
    write_text(paper.readings_table(verdicts), sm.output.readings)
    write_text(paper.results_table(verdicts), sm.output.results)
    extra = set(sm.params.supplement)
    for part, names, placement in ((sm.output.figures, [f for f in order if f[0] not in extra], "tp"),
                                   (sm.output.supplement_figures, [f for f in order if f[0] in extra], "p")):
        write_text(paper.figures_tex(names, sm.params.captions, datasets, sm.params.config_name, placement), part)
    write_text(paper.write_expected(macros, len(order), verdicts), sm.output.expected)
    print(f"{len(verdicts)} claims, {len(macros.items)} macros, {len(order)} figures")
