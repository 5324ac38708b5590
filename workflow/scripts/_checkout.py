"""Put this checkout's src/ first on sys.path, so every job runs the code of the checkout
it belongs to (with the venv's editable install this changes nothing; in a conda env
it is how the package is found). Snakemake puts the scripts folder on sys.path."""
import sys
from pathlib import Path

_SRC = str(Path(__file__).resolve().parents[2] / "src")
if _SRC not in sys.path:
    sys.path.insert(0, _SRC)
