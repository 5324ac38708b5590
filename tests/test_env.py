"""The conda environment of the rules is Python 3.11 and the lock CI installs, nothing else."""
from __future__ import annotations

from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]


def test_the_conda_env_is_the_lock():
    env = yaml.safe_load((ROOT / "workflow/envs/confined_rod.yaml").read_text())
    deps = env["dependencies"]
    conda = sorted(d.replace(" ", "") for d in deps if isinstance(d, str))
    pip = [d for d in deps if isinstance(d, dict)]
    assert conda == ["pip", "python=3.11"]
    assert pip == [{"pip": ["-r ../../requirements.lock"]}]
    # the path as conda resolves it from Snakemake's copy, .snakemake/conda/<hash>.yaml
    assert (ROOT / ".snakemake" / "conda" / "../../requirements.lock").resolve() == ROOT / "requirements.lock"
    lock = (ROOT / "requirements.lock").read_text()
    for needed in ("numba==", "sympy==", "xarray==", "netcdf4==", "matplotlib=="):   # the claims rule needs sympy
        assert needed in lock.lower(), needed
