"""`python workflow/scripts/run_scene.py {simulate|probe} OUTPUT PARAMS_JSON`: one scene run in
this process (rules simulate and probe, for a scene that is in no batch or whose batch copy is
gone); confined_rod.sim.runs.main."""
import _checkout  # noqa: F401  (this checkout's src/ first on sys.path)

# isort: split
import sys

from confined_rod.sim.runs import main

sys.exit(main())
