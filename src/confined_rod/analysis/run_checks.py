"""Is a stored run the evidence it claims to be?  Checks shared by the workflow's DAG
construction, post-processing and the claims (datasets only; never the simulator).

- :func:`problem`, :func:`check_file`: a scene file (``results/sims``, ``results/paths``) opens, and its stored
  scene name and parameters equal the ones the config asks for. Snakemake's parameter trigger
  relies on its metadata in ``.snakemake/``; this check relies only on the file, so a file
  copied over another, or a tree built from another config whose metadata was lost, is
  refused with one line naming the file and the first differing parameter.
- :func:`not_at_equilibrium`: the runs of a set whose status is not ``converged`` (a step or
  time cap, an escape), as ``"figure/scene (status)"``; figure datasets store them in their
  ``not_at_equilibrium`` attribute, and no verdict, fit or convergence rung is decided on them.
"""
from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Iterable, Mapping

import numpy as np

from ..io import netcdf_attr

#: the value of a figure dataset's ``not_at_equilibrium`` attribute when every run converged
NONE = "none"
#: the status of a run at equilibrium (quantities.RUN_STATUS)
EQUILIBRIUM = "converged"


class EvidenceError(ValueError):
    """A stored file is unreadable or is not the run the config asks for (one line)."""


def _rebuild_hint(path: str | Path) -> str:
    return f"delete it or run snakemake --forcerun {path} to rebuild it (and what reads it)"


def _unreadable(path: str | Path, e: Exception) -> str:
    return f"{path}: cannot be read ({type(e).__name__}: {str(e).splitlines()[0] if str(e) else 'no detail'})"


def _same(stored: Any, wanted: Any) -> bool:
    wanted = netcdf_attr(wanted)
    if isinstance(wanted, str) or isinstance(stored, str):
        return str(stored) == str(wanted)
    a, b = np.atleast_1d(np.asarray(stored, dtype=float)), np.atleast_1d(np.asarray(wanted, dtype=float))
    if a.shape != b.shape:
        return False
    return bool(np.all((a == b) | np.isclose(a, b, rtol=1e-12, atol=0.0) | (np.isnan(a) & np.isnan(b))))


def mismatch(stored: Mapping[str, Any], wanted: Mapping[str, Any]) -> str | None:
    """The first parameter of ``wanted`` (the config's scene, ``name`` first) that the stored
    attributes lack or hold with another value, as text; None if all agree."""
    keys = ["name"] + sorted(k for k in wanted if k != "name")
    for k in keys:
        if k not in wanted:
            continue
        if k not in stored:
            return f"has no attribute {k!r} (the config asks for {k} = {_show(wanted[k])})"
        if not _same(stored[k], wanted[k]):
            return f"holds {k} = {_show(stored[k])} but the config asks for {k} = {_show(wanted[k])}"
    return None


def _show(v: Any) -> str:
    if isinstance(v, float) and math.isfinite(v):
        return f"{v:.10g}"
    if isinstance(v, np.ndarray):
        return "[" + ", ".join(f"{x:.10g}" for x in v.ravel()) + "]"
    return repr(v) if isinstance(v, str) else str(v)


def problem(path: str | Path, wanted: Mapping[str, Any]) -> str | None:
    """What is wrong with a scene file, in a few words naming it (unreadable, or the first
    parameter it holds other than the config's scene ``wanted``); None if nothing. Reads only
    its global attributes."""
    import netCDF4

    try:
        with netCDF4.Dataset(str(path)) as nc:
            stored = {k: nc.getncattr(k) for k in nc.ncattrs()}
    except (OSError, RuntimeError, ValueError, KeyError) as e:
        return _unreadable(path, e)
    diff = mismatch(stored, wanted)
    return f"{path} {diff}" if diff else None


def _refuse(path: str | Path, what: str):
    return EvidenceError(f"{what}: it is not the run this config asks for (a file copied over another, or built "
                         f"from another config); {_rebuild_hint(path)}")


def check_file(path: str | Path, wanted: Mapping[str, Any]) -> None:
    """Raise EvidenceError (one line) unless the file opens and stores the scene ``wanted``."""
    what = problem(path, wanted)
    if what:
        raise _refuse(path, what)


def load(path: str | Path, wanted: Mapping[str, Any] | None = None):
    """xarray.load_dataset with one-line errors for an unreadable file, checked against the
    config's scene ``wanted`` when given (on the loaded attributes: one read)."""
    import xarray as xr

    try:
        ds = xr.load_dataset(path)
    except (OSError, RuntimeError, ValueError, KeyError) as e:
        raise EvidenceError(f"{_unreadable(path, e)}; {_rebuild_hint(path)}") from None
    diff = mismatch(ds.attrs, wanted) if wanted is not None else None
    if diff:
        raise _refuse(path, f"{path} {diff}")
    return ds


#: what a run's ``saddle`` flag means, as its status here (observables.SADDLES)
SADDLE_STATUS = {1: "converged on a saddle: straight above Euler's load",
                 2: "converged on a saddle: planar above the second threshold"}


def status(ds) -> str:
    """A run's status attribute, or the saddle it converged on (a residual test cannot tell an
    unstable equilibrium from a stable one; the claims and figures need the stable, buckled
    state); without a status (a constructed dataset), its ``converged`` flag."""
    if "status" in ds.attrs:
        flag = int(ds["saddle"]) if "saddle" in getattr(ds, "variables", {}) else 0
        if ds.attrs["status"] == EQUILIBRIUM and flag:
            return SADDLE_STATUS.get(flag, f"converged on saddle {flag}")
        return str(ds.attrs["status"])
    if "converged" in getattr(ds, "variables", {}):
        return EQUILIBRIUM if int(ds["converged"]) == 1 else "not converged"
    return "no status attribute"


def unsettled(sims: Mapping[str, Any]) -> dict[str, str]:
    """name -> status of every run of ``sims`` (name -> dataset) not at a stable equilibrium."""
    found = {name: status(d) for name, d in sims.items()}
    return {name: st for name, st in found.items() if st != EQUILIBRIUM}


def not_at_equilibrium(sims: Mapping[str, Any]) -> list[str]:
    """'scene (status)' of every run of ``sims`` (name -> dataset) not at a stable equilibrium."""
    return [f"{name} ({st})" for name, st in unsettled(sims).items()]


def flagged(attr: str | None) -> list[str]:
    """The runs a figure dataset's ``not_at_equilibrium`` attribute names (none: [])."""
    if not attr or attr == NONE:
        return []
    return [p.strip() for p in str(attr).split(";") if p.strip()]


def join(runs: Iterable[str]) -> str:
    runs = list(runs)
    return "; ".join(runs) if runs else NONE


def warn(message: str) -> None:
    """Print a warning to the job's log and to the terminal the build runs in (a workflow
    script's stderr goes to its log file; sys.__stderr__ is the terminal's)."""
    import sys

    print(message, file=sys.stderr)
    if sys.__stderr__ is not None and sys.stderr is not sys.__stderr__:
        print(message, file=sys.__stderr__)
