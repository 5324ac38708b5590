"""Snakemake script of rule `batch`: the members of one batch run in this process, each to its
own dataset in the batch's folder (confined_rod.sim.runs.run_batch), then the manifest."""
import _checkout  # noqa: F401  (this checkout's src/ first on sys.path)

# isort: split
import shutil

from confined_rod.io import logged
from confined_rod.sim.runs import run_batch

with logged(snakemake.log[0]):  # noqa: F821 (injected by Snakemake)
    job = snakemake.params.job  # noqa: F821
    shutil.rmtree(job["folder"], ignore_errors=True)  # copies of an earlier run of this batch are stale
    run_batch(snakemake.wildcards.kind, job["members"], job["outputs"], snakemake.output[0])  # noqa: F821
