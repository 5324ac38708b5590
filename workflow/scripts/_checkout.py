"""Put this checkout's src/ first on sys.path, so every job runs the code of the checkout
it belongs to (with the venv's editable install of another checkout, or in a conda env, that
is how the package is found). Snakemake puts the scripts folder on sys.path.

Moved to the front even if it is already on the path: the preamble of a ``script:`` job
appends the workflow's search paths, this src/ among them, *after* the site-packages whose
editable install may point to another checkout. Only checking membership let the batch jobs of a
git worktree run the main checkout's code (seen in their datasets' git_commit); an earlier
import of the package from elsewhere is refused."""
import sys
from pathlib import Path

_SRC = str(Path(__file__).resolve().parents[2] / "src")
while _SRC in sys.path:
    sys.path.remove(_SRC)
sys.path.insert(0, _SRC)
_loaded = sys.modules.get("confined_rod")
if _loaded is not None and not Path(_loaded.__file__).resolve().is_relative_to(Path(_SRC).resolve()):
    raise ImportError(f"confined_rod was imported from {_loaded.__file__} before this checkout's {_SRC} "
                      "could be put first on sys.path")
