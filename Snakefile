# confined_rod reproduction pipeline: scenes -> simulations -> per-figure datasets -> figures.
#
#   snakemake --cores 2                                   # publication config (config/config.yaml)
#   snakemake --cores 2 --configfile config/ci.yaml       # the small CI grid instead
#   snakemake --cores 2 results/figures/fig6_FonL.pdf     # one figure and what it needs
#   snakemake --report results/report.html                # HTML report of the figures
#
# The physics lives in src/confined_rod; rules and scripts only wire it up.
import os
import sys

from snakemake.utils import min_version

min_version("9.0")

# Use this checkout's package (jobs do the same: workflow/scripts/_checkout.py).
sys.path.insert(0, os.path.join(workflow.basedir, "src"))


# --configfile replaces the publication config rather than being merged into it,
# so a CI or user config declares exactly the figures and scenes it builds.
if not workflow.overwrite_configfiles:

    configfile: "config/config.yaml"


include: "workflow/rules/common.smk"
include: "workflow/rules/simulate.smk"
include: "workflow/rules/postprocess.smk"
include: "workflow/rules/figures.smk"
include: "workflow/rules/paper.smk"
include: "workflow/rules/views.smk"


report: "workflow/report/workflow.rst"


onstart:
    # the estimated wall time of every job to run, for the progress line (pipeline.progress)
    from snakemake.logging import logger as _logger
    from confined_rod.pipeline import progress as _progress

    _plan = _progress.plan_of(workflow.dag.needrun_jobs())
    _logger.info(_progress.plan_message(_plan), extra={_progress.PLAN_ATTRIBUTE: _plan})


# run on the submitting host under a cluster executor (profiles/slurm): the paper needs TeX there
localrules:
    all,
    paper,


rule all:
    default_target: True
    input:
        ALL_TARGETS["datasets"],
        ALL_TARGETS["figures"],
        ALL_TARGETS["checks"],
        ALL_TARGETS["budget"],
        ALL_TARGETS["paper"],
        ALL_TARGETS["views"],
