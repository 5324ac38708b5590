"""Input/output: the xarray Dataset of a run, its provenance, and safe writing."""
from __future__ import annotations

import contextlib
import datetime as _dt
import os
import platform
import subprocess
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from .quantities import attrs

CONVENTIONS = "CF-1.10"
UNITS_NOTE = ("units are combinations of the scene's cylinder radius R and bending stiffness EI "
              "(and beta_ph, the drag per length, for time); with R = EI = 1 they are the internal units")


def git_commit() -> str:
    """Commit of the source tree the package was imported from ('-dirty' if modified)."""
    env = os.environ.get("CONFINED_ROD_GIT_COMMIT")
    if env:
        return env
    here = Path(__file__).resolve().parent
    try:
        sha = subprocess.run(["git", "-C", str(here), "rev-parse", "HEAD"], capture_output=True,
                             text=True, timeout=10, check=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(here), "status", "--porcelain", "--", "."],
                               capture_output=True, text=True, timeout=10).stdout.strip()
        return sha + ("-dirty" if dirty else "")
    except (OSError, subprocess.SubprocessError):
        return "unknown"


def provenance() -> dict[str, str]:
    """Package version, git commit and library versions (read from the installed
    distributions, so post-processing records numba's version without importing it)."""
    from importlib.metadata import PackageNotFoundError, version

    from . import __version__

    def v(dist: str) -> str:
        try:
            return version(dist)
        except PackageNotFoundError:
            return "not installed"

    return {
        "confined_rod_version": __version__,
        "git_commit": git_commit(),
        "python_version": platform.python_version(),
        "numpy_version": np.__version__,
        "numba_version": v("numba"),
        "xarray_version": xr.__version__,
        "netCDF4_version": v("netCDF4"),
        "scipy_version": v("scipy"),
        "matplotlib_version": v("matplotlib"),
    }


def netcdf_attr(value: Any) -> Any:
    """netCDF attributes cannot be None or bool: store them as strings / ints."""
    if value is None:
        return "none"
    if isinstance(value, bool):
        return int(value)
    if isinstance(value, (list, tuple)):
        if all(isinstance(v, str) for v in value):
            return ", ".join(value)
        return np.asarray(value, dtype=float)
    return value


def variable(dims, data, name: str) -> xr.Variable:
    return xr.Variable(dims, np.asarray(data), attrs=attrs(name))


def finalize(ds: xr.Dataset, title: str, params: dict[str, Any]) -> xr.Dataset:
    """Global CF attributes, parameters and provenance."""
    now = _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")
    ds.attrs.update({"Conventions": CONVENTIONS, "title": title, "units_note": UNITS_NOTE})
    for k, v in params.items():
        ds.attrs[k] = netcdf_attr(v)
    prov = provenance()
    ds.attrs.update(prov)
    ds.attrs["history"] = f"{now}: created by confined_rod {prov['confined_rod_version']} (git {prov['git_commit']})"
    return ds


def check_finite(ds: xr.Dataset, action: str = "write the dataset") -> None:
    """Raise ValueError naming the first floating-point variable with NaN or inf."""
    for name, var in ds.variables.items():
        if np.issubdtype(var.dtype, np.floating) and not np.all(np.isfinite(var.values)):
            raise ValueError(f"variable {name!r} contains non-finite values; refusing to {action}")


def write_dataset(ds: xr.Dataset, path: str | Path) -> Path:
    """Write netCDF4 atomically: a temporary file in the same folder, renamed on success,
    so a failed job leaves no half-written file."""
    check_finite(ds)
    return _atomic(path, lambda tmp: ds.to_netcdf(tmp, engine="netcdf4", format="NETCDF4"))


def write_text(text: str, path: str | Path) -> Path:
    """Write a text file atomically (same scheme as write_dataset)."""
    return _atomic(path, lambda tmp: tmp.write_text(text))


def _atomic(path: str | Path, write) -> Path:
    """Call write(tmp) on a temporary file in the target's folder, then rename it
    over the target; on any error the temporary file is removed."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        write(tmp)
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()
    return path


@contextlib.contextmanager
def logged(path: str | Path):
    """Send stdout, stderr and any traceback of the block to the log file ``path``."""
    import traceback

    Path(path).parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", buffering=1) as log, contextlib.redirect_stdout(log), contextlib.redirect_stderr(log):
        try:
            yield log
        except BaseException:
            traceback.print_exc(file=log)
            raise
