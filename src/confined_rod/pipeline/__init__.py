"""The workflow glue: what the Snakemake rules (``workflow/``) ask of a config. Plain Python;
the package never imports Snakemake, and nothing outside this subpackage (but the command
line) imports it.

- :mod:`.configs`: a config read strictly, checked (JSON schema, every scene built, the figure
  kinds' rules), its sweeps and seed ensembles expanded into scenes, the captions;
- :mod:`.schema`: the config's JSON schema, generated from the scene parameters and the kinds;
- :mod:`.config_docs`: config/README.md, every config file and key, generated from that schema;
- :mod:`.targets`: the files each figure reads, what a stored file must hold, every artifact;
- :mod:`.batches`: small scenes run in one process;
- :mod:`.code`: the code each rule depends on (its re-run triggers).

The names the rules use are re-exported here (``pipeline.check``, ``pipeline.figure_sims``, ...);
the paths of results/ are :mod:`confined_rod.layout`'s alone.
"""
from ..errors import ConfigError
from .batches import (
                      BATCH_S,
                      batch_estimate_s,
                      batch_job,
                      batch_name,
                      batch_of,
                      batch_outputs,
                      batches,
                      job_estimate_s,
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
                      Expanded,
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
                      view_figures,
                      view_outputs,
                      view_pages,
                      view_scenes,
                      view_sims,
                      wanted_scene,
)

__all__ = [
    "ConfigError", "BATCH_S", "batch_job", "batch_name", "batch_estimate_s",
    "batch_of", "batch_outputs", "batches", "job_estimate_s",
    "member_batch",
    "member_cache", "plan_batches", "run_kind", "solver_estimate", "PACKAGE", "code_closure", "ROOT", "SCHEMA",
    "Expanded", "build_scene", "built_scenes", "canonical_scene", "caption", "check", "check_paper", "check_schema",
    "context", "convergence_figures", "costly_scenes", "expand", "figures", "kinds", "publication_value",
    "read_config", "read_figures", "scene_params", "scenes", "validate", "claim_sims", "claim_wanted",
    "expected_outputs", "figure_sims", "figure_wanted", "paper_outputs", "path_spec", "stale_inputs", "wanted_scene",
    "view_figures", "view_outputs", "view_pages", "view_scenes", "view_sims",
]
