# Shared set-up: config validation (before any job), file layout, code dependencies.
import glob
import json
from pathlib import Path

from snakemake_interface_executor_plugins.settings import DeploymentMethod

from confined_rod import layout, limits, pipeline
from confined_rod.claims import manuscript
from confined_rod.pipeline import code, progress

# Before any job: each config file re-read strictly (duplicate keys, aliases, line
# numbers), the JSON schema (workflow/schemas/config.schema.yaml, one-line errors),
# every scene built (limits.py) and the figure-kind rules; stability maps' sweeps
# become scenes.
try:
    config = pipeline.check(
        config,
        files=workflow.configfiles,
        schema_path=Path(workflow.basedir) / "workflow" / "schemas" / "config.schema.yaml",
    )
except pipeline.ConfigError as e:
    raise WorkflowError(f"invalid config: {e}")

# A config is a deliberate choice: scenes above the command line's budget are run, but
# named once here with their estimated cost (limits.estimated_wall_time).
for _f, _s, _cost in pipeline.costly_scenes(config, limits.DEFAULT_BUDGET_S):
    print(
        f"note: {_f}/{_s} is estimated at {_cost / 60:.0f} min on one core "
        f"(above the {limits.DEFAULT_BUDGET_S / 60:.0f} min budget of a single run)",
        file=sys.stderr,
    )


wildcard_constraints:
    figure=layout.NAME_PATTERN,
    scene=layout.NAME_PATTERN,


ALL_TARGETS = pipeline.expected_outputs(config)

# Code each step depends on, so that Snakemake's mtime trigger re-runs a step when its code
# changes, decided by where a module is (confined_rod.pipeline.code): sim/ -> the simulations;
# a figure kind's module and what it imports -> its datasets and figures; the styling -> the
# figures only; claims/ -> the claims and the manuscript. Post-processing never imports the
# simulator (checked by the import contracts in pyproject.toml).
# Each closure enters a rule as one stamp file of its modules' checksums (pipeline.code.stamp),
# computed once per part (an input function asks for it once per job).
_STAMPS = {}


def code_stamp(part, modules):
    """The stamp of ``part``; ``modules()`` gives its modules (called the first time only)."""
    if part not in _STAMPS:
        _STAMPS[part] = code.stamp(part, modules(), layout.code_stamp(part))
    return _STAMPS[part]


SIMULATION_CODE = code_stamp("simulation", code.simulation_code)
PATH_CODE = SIMULATION_CODE


def scene_sims(wildcards):
    return pipeline.figure_sims(config, wildcards.figure)


# A scene file that exists but is not the run the config asks for (unreadable, or another
# scene's parameters: copied over, or built from another config after .snakemake/ was lost) is
# rebuilt: its rule gets a freshly touched marker as input (pipeline.stale_inputs).
def stale_sim(wildcards):
    return pipeline.stale_inputs(
        config, wildcards.figure, wildcards.scene, layout.sim_path(wildcards.figure, wildcards.scene)
    )


def stale_path(wildcards):
    return pipeline.stale_inputs(
        config, wildcards.figure, wildcards.scene, layout.path_file(wildcards.figure, wildcards.scene)
    )


# -- running scenes: batches of small scenes in one process, or a scene alone (confined_rod.sim.runs)
# The interpreter of a job: the conda env's with --use-conda, else Snakemake's own (the venv's).
PYTHON = (
    "python"
    if DeploymentMethod.CONDA in workflow.deployment_settings.deployment_method
    else sys.executable
)
RUN_SCENE = f"{PYTHON} {Path(workflow.basedir) / 'workflow' / 'scripts' / 'run_scene.py'}"
# A scene's own job: its batch's copy moved into place (and stamped newer than the batch's
# manifest), or, with no copy, the scene run here. Doubled braces are Snakemake's, filled per job;
# the copy's path is double-quoted by hand (Snakemake's :q renders an empty string as nothing).
MEMBER_SHELL = (
    'if [ -n "{{params.cached}}" ] && [ -e "{{params.cached}}" ]; then'
    ' mv -f "{{params.cached}}" {{output:q}} && touch {{output:q}}'
    " && echo 'run in the batch {{input.batch}}; its log: {{params.batch_log}}' > {{log:q}};"
    " else {{params.run}} {kind} {{output:q}} {{params.scene:q}} > {{log:q}} 2>&1; fi"
)


def batch_log(kind):
    def log(wildcards):
        batch = pipeline.batch_of(config, wildcards.figure, wildcards.scene)
        return layout.batch_log(kind, wildcards.figure, batch) if batch else ""

    return log


def scene_json(wildcards):
    return json.dumps(pipeline.scene_params(config, wildcards.figure, wildcards.scene))


def batch_priority(wildcards):
    """A batch is scheduled as the sum of its members' estimated solver times and one start-up."""
    members = pipeline.batches(config, wildcards.figure).get(wildcards.batch, [])
    return int(pipeline.batch_estimate_s(config, wildcards.figure, members))


def batch_runtime(wildcards):
    """Minutes, for a cluster scheduler: three times the members' estimates, plus ten minutes."""
    return int(10 + 3 * batch_priority(wildcards) / 60.0)


def kind_module(wildcards):
    return pipeline.kinds.module_path(config["figures"][wildcards.figure]["kind"])


def postprocess_code(wildcards):
    kind = config["figures"][wildcards.figure]["kind"]
    return code_stamp(f"postprocess-{kind}", lambda: code.postprocess_code(kind_module(wildcards)))


def figure_code(wildcards):
    kind = config["figures"][wildcards.figure]["kind"]
    return code_stamp(f"figure-{kind}", lambda: code.figure_code(kind_module(wildcards)))


def read_datasets(wildcards):
    """Datasets of other figures this figure's builder reads (e.g. Fig 8's thresholds)."""
    return list(pipeline.read_figures(config, wildcards.figure).values())


def build_context(wildcards):
    """What the figure's dataset builder needs from the config beyond its own entry."""
    return pipeline.context(config, wildcards.figure)


def simulate_runtime(wildcards):
    """Minutes, for a cluster scheduler: three times the estimate from measured runs
    (limits.estimated_wall_time), plus ten minutes."""
    sc = pipeline.build_scene(config, wildcards.figure, wildcards.scene)
    return int(10 + 3 * limits.estimated_wall_time(sc) / 60.0)


def job_priority(wildcards):
    """Longest jobs first, so that the last jobs of a build finish together: the
    estimated wall time in seconds (limits.estimated_solver_time and the start-up; the
    start-up alone for a probe of deliberately invalid input)."""
    return int(pipeline.job_estimate_s(config, wildcards.figure, wildcards.scene))


def member_estimate(kind):
    """The job's estimated wall time (s) for the build's progress line (pipeline.progress): nothing
    for a scene its batch ran (its job moves the file), else its own run's estimate."""

    def estimate(wildcards):
        if pipeline.member_batch(config, kind, wildcards.figure, wildcards.scene):
            return 0      # a move of its batch's copy (measured: 0.01 s; the resource is whole seconds)
        return job_priority(wildcards)

    return estimate


def path_priority(wildcards):
    """A load path relaxes the rod at tens of loads in one process: one start-up and ten times one
    run's solver estimate (ten start-ups had made the CI grid's 17 paths 340 s for 63 measured)."""
    return int(pipeline.job_estimate_s(config, wildcards.figure, wildcards.scene, runs=10))


# -- the manuscript (rules in paper.smk) ----------------------------------------------------------
PAPER = config.get("paper") or {}
CLAIMS_CODE = code_stamp("claims", code.claims_code)
PAPER_CODE = code_stamp("paper", code.paper_code)
CONFIG_NAME = (os.path.relpath(workflow.configfiles[-1], workflow.basedir) if workflow.configfiles
               else "config/config.yaml")


def claims_file(wildcards):
    return PAPER["claims"]


def claim_sims(wildcards):
    """The scene simulations the claims read (paper/claims.yaml: measures on results/sims/)."""
    return list(pipeline.claim_sims(config).values())
