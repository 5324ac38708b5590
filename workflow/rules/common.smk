# Shared set-up: config validation (before any job), file layout, code dependencies.
from pathlib import Path

from confined_rod import pipeline

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
POSTPROCESS_CODE = [str(_PKG / f) for f in ("postprocess.py", "fits.py", "theory.py")]
FIGURE_CODE = [str(_PKG / "plotting.py")]
SIMULATION_CODE = sorted(
    str(p)
    for p in _PKG.rglob("*.py")
    if str(p) not in POSTPROCESS_CODE + FIGURE_CODE
    and p.name not in ("pipeline.py", "cli.py", "__main__.py")
)


def scene_sims(wildcards):
    return pipeline.figure_sims(config, wildcards.figure)


def simulate_runtime(wildcards):
    """Minutes, for a cluster scheduler: the explicit solver's measured cost grows
    roughly as L^2.5 (benchmarks/results/core.json: L/R = 80 took 7 min)."""
    L = pipeline.build_scene(config, wildcards.figure, wildcards.scene).L
    return int(10 + 8 * (L / 80.0) ** 2.5)
