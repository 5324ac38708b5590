"""Input/output: the xarray Dataset of a run, its provenance, and safe writing."""
from __future__ import annotations

import contextlib
import datetime as _dt
import functools
import os
import platform
import subprocess
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

CONVENTIONS = "CF-1.10"
#: the global attribute 'units_note', by the scene's unit system (quantities.UNIT_SYSTEMS)
UNITS_NOTE = {
    "reduced": ("reduced units: every value is a multiple of the combination of the scene's cylinder radius R, "
                "bending stiffness EI and drag per length beta_ph named in the variable's 'units_reduced' "
                "attribute (so its CF 'units' is '1'); with R = EI = 1 these are the internal units"),
    "SI": ("SI units: the scene's R is in m, EI in J m, forces in N, and the drag per length beta_ph is 1 Pa s "
           "(times in s); each variable's 'units_reduced' names the combination of R, EI and beta_ph it scales "
           "with"),
}


@functools.cache
def git_commit() -> str:
    """Commit of the source tree the package was imported from ('-dirty' if modified), read once
    per process (the code a process runs is the code it imported; a batch of scenes would
    otherwise ask git twice per dataset)."""
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
    return dict(_provenance())


@functools.cache
def _provenance() -> dict[str, str]:
    from importlib.metadata import PackageNotFoundError, version

    from ._version import __version__

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


def finalize(ds: xr.Dataset, title: str, params: dict[str, Any]) -> xr.Dataset:
    """Global CF attributes, parameters and provenance; every variable's CF units for the unit
    system of ``params`` (its 'unit_system', default reduced: quantities.apply_unit_system)."""
    from .quantities import apply_unit_system

    system = str(params.get("unit_system", "reduced"))
    apply_unit_system(ds, system)
    now = _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")
    ds.attrs.update({"Conventions": CONVENTIONS, "title": title, "units_note": UNITS_NOTE[system]})
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
    so a failed job leaves no half-written file.  Refuses NaN and a reduced unit left as a
    variable's CF ``units`` (UDUNITS reads 'R' as the roentgen; io.finalize converts them)."""
    from .quantities import is_reduced

    check_finite(ds)
    for name, var in ds.variables.items():
        units = var.attrs.get("units")
        if isinstance(units, str) and is_reduced(units):
            raise ValueError(f"variable {name!r} has the reduced unit {units!r} as its CF units; refusing to write "
                             "the dataset (io.finalize gives every variable its CF units)")
    # no _FillValue: nothing is missing (check_finite), and CF forbids one on a coordinate variable
    encoding = {name: {"_FillValue": None} for name, var in ds.variables.items()
                if np.issubdtype(var.dtype, np.floating)}
    return atomic_write(path, lambda tmp: ds.to_netcdf(tmp, engine="netcdf4", format="NETCDF4", encoding=encoding))


def write_text(text: str, path: str | Path) -> Path:
    """Write a text file atomically (same scheme as write_dataset)."""
    return atomic_write(path, lambda tmp: tmp.write_text(text))


def atomic_write(path: str | Path, write) -> Path:
    """Call write(tmp) on a temporary file in the target's folder (``.<name>.<pid>.tmp``: a
    writer that picks its format by suffix must be told it), then rename it over the target;
    on any error the temporary file is removed.  Temporaries left by a killed writer (SIGKILL
    cannot be caught) are removed on the next write of the same file.  Every file the package
    writes goes through here (datasets, texts, figures)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    remove_stale_temporaries(path)
    tmp = _temporary(path, os.getpid())
    try:
        write(tmp)
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()
    return path


def _temporary(path: Path, pid: int) -> Path:
    return path.with_name(f".{path.name}.{pid}.tmp")


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # exists, owned by someone else
        return True
    return True


def remove_stale_temporaries(path: str | Path) -> list[Path]:
    """Remove ``.<name>.<pid>.tmp`` files next to ``path`` whose writer no longer runs."""
    path = Path(path)
    removed = []
    prefix, suffix = f".{path.name}.", ".tmp"
    try:
        candidates = list(path.parent.iterdir())
    except OSError:
        return removed
    for f in candidates:
        pid = f.name[len(prefix):-len(suffix)] if f.name.startswith(prefix) and f.name.endswith(suffix) else ""
        if pid.isdigit() and int(pid) != os.getpid() and not _alive(int(pid)):
            with contextlib.suppress(OSError):
                f.unlink()
                removed.append(f)
    return removed


def check_output_path(path: str | Path, suffix: str | None = None) -> Path:
    """Make sure a result can be written to ``path`` before any work is done: its
    folder exists or can be made, is a folder, and accepts a new file; ``path`` is
    not a folder.  Raises OutputPathError with a one-line message."""
    from .errors import OutputPathError

    path = Path(path)
    where = f"output {str(path)!r}"
    if path.is_dir():
        raise OutputPathError(f"{where} is a directory; name a file inside it")
    if suffix and path.suffix != suffix:
        raise OutputPathError(f"{where} must end in {suffix}")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        raise OutputPathError(f"{where}: {str(path.parent)!r} is a file, not a directory") from None
    except NotADirectoryError:
        raise OutputPathError(f"{where}: a parent of it is a file, not a directory") from None
    except OSError as exc:
        raise OutputPathError(f"{where}: cannot create its directory ({exc.strerror})") from None
    probe = _temporary(path, os.getpid())
    try:
        probe.write_bytes(b"")
    except OSError as exc:
        raise OutputPathError(f"{where}: cannot write in {str(path.parent)!r} ({exc.strerror})") from None
    finally:
        with contextlib.suppress(OSError):
            probe.unlink()
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


# -- YAML input ---------------------------------------------------------------------
def _yaml_loader(error: type[Exception], where: str, aliases: bool):
    """A SafeLoader that refuses duplicate keys and (unless ``aliases``) aliases, and
    reads 1e-3 as the number it is (YAML 1.2), naming the line of the problem."""
    import re

    import yaml

    class Loader(yaml.SafeLoader):
        def compose_node(self, parent, index):
            if not aliases and self.check_event(yaml.AliasEvent):
                mark = self.peek_event().start_mark
                raise error(f"{where}, line {mark.line + 1}: YAML aliases (*name) are not accepted; "
                            "write the value out")
            return super().compose_node(parent, index)

        def construct_mapping(self, node, deep=False):
            seen: dict[Any, int] = {}
            for key_node, _ in node.value:
                key = self.construct_object(key_node, deep=True)
                try:
                    first = seen.get(key)
                except TypeError:
                    raise error(f"{where}, line {key_node.start_mark.line + 1}: a key must be a plain value") from None
                if first is not None:
                    raise error(f"{where}, line {key_node.start_mark.line + 1}: duplicate key {key!r} (first "
                                f"given on line {first}); each key may appear once")
                seen[key] = key_node.start_mark.line + 1
            return super().construct_mapping(node, deep=deep)

    Loader.add_implicit_resolver("tag:yaml.org,2002:float",
                                 re.compile(r"^[-+]?(\d+\.?\d*|\.\d+)[eE][-+]?\d+$"), list("-+0123456789."))
    return Loader


def _expanded_size(node, memo: dict) -> int:
    """Number of nodes of a composed YAML document with every alias written out
    (a node shared by aliases counts once per use; each is computed once)."""
    import yaml

    key = id(node)
    if key not in memo:
        memo[key] = 1  # a recursive alias counts once
        total = 1
        if isinstance(node, yaml.MappingNode):
            total += sum(_expanded_size(k, memo) + _expanded_size(v, memo) for k, v in node.value)
        elif isinstance(node, yaml.SequenceNode):
            total += sum(_expanded_size(v, memo) for v in node.value)
        memo[key] = total
    return memo[key]


def read_yaml(path: str | Path, *, what: str, error: type[Exception], max_bytes: int = 1 << 20,
              max_nodes: int | None = None) -> Any:
    """Parse a YAML file strictly (see _yaml_loader); every problem raises ``error``
    with a one-line message naming the file (and the line where YAML knows it).
    Aliases are refused unless ``max_nodes`` is given; then the document with its
    aliases written out may have at most that many nodes (a 200-byte alias bomb
    expands to gigabytes)."""
    import yaml

    path = Path(path)
    where = f"{what} {str(path)!r}"
    try:
        size = path.stat().st_size
        if path.is_dir():
            raise error(f"{where} is a directory, not a YAML file")
        if size > max_bytes:
            raise error(f"{where} has {size} bytes, more than the {max_bytes} a {what} may have")
        text = path.read_bytes().decode("utf-8")
    except FileNotFoundError:
        raise error(f"{where} does not exist") from None
    except UnicodeDecodeError as exc:
        raise error(f"{where} is not a UTF-8 text file (byte {exc.start}: {exc.reason})") from None
    except OSError as exc:
        raise error(f"{where} cannot be read: {exc.strerror}") from None
    if "\x00" in text:
        raise error(f"{where} is not a text file (it contains NUL bytes)")
    loader = None
    try:
        loader = _yaml_loader(error, where, aliases=max_nodes is not None)(text)
        node = loader.get_single_node()
        if node is None:
            return None
        if max_nodes is not None:
            n = _expanded_size(node, {})
            if n > max_nodes:
                raise error(f"{where} expands to {n:.3g} YAML nodes with its aliases written out, more than "
                            f"{max_nodes}")
        return loader.construct_document(node)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line = f", line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        raise error(f"{where} is not valid YAML{line}: {exc.problem or exc.context}") from None
    except yaml.YAMLError as exc:
        raise error(f"{where} is not valid YAML: {str(exc).splitlines()[0]}") from None
    except RecursionError:
        raise error(f"{where} is nested too deeply") from None
    finally:
        if loader is not None:
            loader.dispose()
