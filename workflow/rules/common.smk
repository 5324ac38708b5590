# Shared set-up: config validation (before any job), file layout, code dependencies.
from pathlib import Path

from confined_rod import pipeline

pipeline.expand_sweeps(config)  # stability maps: sweep points -> scenes
try:
    pipeline.validate(config)
except pipeline.ConfigError as e:
    raise WorkflowError(f"invalid config: {e}")


wildcard_constraints:
    figure=r"[A-Za-z0-9_-]+",
    scene=r"[A-Za-z0-9_-]+",


ALL_TARGETS = pipeline.expected_outputs(config)

# Code each step depends on, so that Snakemake's mtime trigger re-runs a step when
# its code changes: a change to the physics re-runs the simulations, a change to
# the fits re-runs only the postprocessing, a change to the styling only the figures.
_PKG = Path(workflow.basedir) / "src" / "confined_rod"
POSTPROCESS_CODE = [str(_PKG / f) for f in ("postprocess.py", "fits.py", "theory.py", "studies.py")]
FIGURE_CODE = [str(_PKG / "plotting.py")]
SIMULATION_CODE = sorted(
    str(p)
    for p in _PKG.rglob("*.py")
    if str(p) not in POSTPROCESS_CODE + FIGURE_CODE
    and p.name not in ("pipeline.py", "cli.py", "__main__.py")
)


def scene_sims(wildcards):
    return pipeline.figure_sims(config, wildcards.figure)


def publication_value(wildcards):
    """Convergence figures: the parameter's value in the publication settings."""
    fig = config["figures"][wildcards.figure]
    if fig["kind"] != "convergence":
        return None
    return pipeline.publication_value(config, wildcards.figure)


def simulate_runtime(wildcards):
    """Minutes, for a cluster scheduler.  Explicit solver: its measured cost grows
    roughly as L^2.5 (benchmarks/results/core.json: L/R = 80 took 7 min).  Implicit
    solver: seconds up to L/R = 320 (benchmarks/results/solvers.json); generous."""
    sc = pipeline.build_scene(config, wildcards.figure, wildcards.scene)
    if sc.solver == "explicit":
        return int(10 + 8 * (sc.L / 80.0) ** 2.5 * (0.5 / sc.l0) ** 3)
    return int(10 + 30 * (sc.L / 320.0) ** 2 * (0.5 / sc.l0) ** 2)
