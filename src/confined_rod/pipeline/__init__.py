"""The workflow glue: what the Snakemake rules (``workflow/``) ask of a config. Plain Python;
the package never imports Snakemake, and nothing outside this subpackage (but the command
line) imports it.

- :mod:`.configs`: a config read strictly, checked (JSON schema, every scene built, the figure
  kinds' rules), its sweeps and seed ensembles expanded into scenes, the captions;
- :mod:`.schema`: the config's JSON schema, generated from the scene parameters and the kinds;
- :mod:`.targets`: the files each figure reads, what a stored file must hold, every artifact;
- :mod:`.batches`: small scenes run in one process;
- :mod:`.code`: the code each rule depends on (its re-run triggers).

The names the rules use are re-exported here (``pipeline.sim_path``, ``pipeline.check``, ...);
the file layout itself is :mod:`confined_rod.layout`.
"""
from ..errors import ConfigError
from ..layout import (
                      batch_log,
                      batch_manifest,
                      check_path,
                      dataset_path,
                      figure_paths,
                      path_file,
                      probe_path,
                      rebuild_marker,
                      sim_path,
)
from .batches import (
                      BATCH_S,
                      batch_job,
                      batch_name,
                      batch_of,
                      batch_outputs,
                      batches,
                      member_batch,
                      member_cache,
                      plan_batches,
                      run_kind,
                      solver_estimate,
)
from .code import PACKAGE, code_closure
from .configs import (
                      ROOT,
                      SCHEMA,
                      build_scene,
                      built_scenes,
                      canonical_scene,
                      caption,
                      check,
                      check_paper,
                      check_schema,
                      context,
                      convergence_figures,
                      costly_scenes,
                      expand,
                      expand_ensembles,
                      expand_sweeps,
                      figures,
                      kinds,
                      publication_value,
                      read_config,
                      read_figures,
                      scene_params,
                      scenes,
                      validate,
)
from .targets import (
                      claim_sims,
                      claim_wanted,
                      expected_outputs,
                      figure_sims,
                      figure_wanted,
                      paper_outputs,
                      path_spec,
                      stale_inputs,
                      wanted_scene,
)

__all__ = [
    "ConfigError", "batch_log", "batch_manifest", "check_path", "dataset_path", "figure_paths", "path_file",
    "probe_path", "rebuild_marker", "sim_path", "BATCH_S", "batch_job", "batch_name", "batch_of", "batch_outputs",
    "batches", "member_batch", "member_cache", "plan_batches", "run_kind", "solver_estimate", "PACKAGE",
    "code_closure", "ROOT", "SCHEMA", "build_scene", "built_scenes", "canonical_scene", "caption", "check",
    "check_paper", "check_schema", "context", "convergence_figures", "costly_scenes", "expand", "expand_ensembles",
    "expand_sweeps", "figures", "kinds", "publication_value", "read_config", "read_figures", "scene_params", "scenes",
    "validate", "claim_sims", "claim_wanted", "expected_outputs", "figure_sims", "figure_wanted", "paper_outputs",
    "path_spec", "stale_inputs", "wanted_scene",
]
