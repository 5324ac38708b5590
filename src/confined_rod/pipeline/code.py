"""The code each rule depends on, so that Snakemake's mtime trigger re-runs a step when its code
changes. The package's parts decide it by where a file is:

- ``sim/``: every module under it, and the shared modules they import -> the simulations;
- ``analysis/``: a figure kind's module and every module it imports -> that kind's datasets and
  figures (the styling, ``analysis/plotting.py``, only the figures);
- ``claims/``: its modules and what they import -> the claims (the manuscript generator,
  ``claims/manuscript.py``, only the manuscript's generated parts).

The closures are read from the imports (:func:`code_closure`), so a helper shared by two kinds is
in both, and a new module lands on the side of the part it is in.  A rule's input is not the
modules themselves but one stamp per closure (:func:`stamp`): their checksums, dated like the
newest of them, so that Snakemake compares one file per job instead of some twenty (its
scheduler hashes and stats every input of every ready job each time a job ends)."""
from __future__ import annotations

import functools
import hashlib
import os
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1]


def _imported(path: Path) -> set[Path]:
    """The package's modules that ``path`` imports (at module level or inside a function)."""
    return set(_imported_at(path, path.stat().st_mtime_ns))


@functools.cache
def _imported_at(path: Path, mtime_ns: int) -> frozenset[Path]:
    """_imported of one version of a file (a workflow asks for several overlapping closures)."""
    import ast

    tree = ast.parse(path.read_text(), filename=str(path))
    here = path.parent
    found: set[Path] = set()

    def add(base: Path, dotted: str) -> None:
        target = base.joinpath(*dotted.split(".")) if dotted else base
        for cand in (target.with_suffix(".py"), target / "__init__.py"):
            if cand.is_file():
                found.add(cand)
                return

    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = here
                for _ in range(node.level - 1):
                    base = base.parent
            elif (node.module or "").split(".")[0] == PACKAGE.name:
                base = PACKAGE.parent
            else:
                continue
            module = node.module or ""
            add(base, module)
            for alias in node.names:                    # from . import x: x may be a module
                add(base, f"{module}.{alias.name}" if module else alias.name)
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.split(".")[0] == PACKAGE.name:
                    add(PACKAGE.parent, alias.name)
    return frozenset(found)


def code_closure(*modules: str | Path, skip: tuple[str | Path, ...] = ()) -> list[str]:
    """The package modules a step's code consists of: the given ones and, transitively, every
    package module they import, so that Snakemake re-runs the step when any of them changes
    (a figure kind's helper imported from another kind's module included). The package root
    (``confined_rod/__init__.py``, the public API that re-exports the simulator) is not
    followed: post-processing imports from it only the version string. ``skip``: modules not
    followed either (the styling, for a step that makes data: a kind module's plot uses it, its
    dataset builder does not)."""
    stop = {PACKAGE / "__init__.py"} | {Path(m).resolve() for m in skip}
    todo = [Path(m).resolve() for m in modules]
    seen: set[Path] = set()
    while todo:
        m = todo.pop()
        if m in seen or m in stop:
            continue
        seen.add(m)
        todo += sorted(_imported(m) - seen)
    return sorted(str(m) for m in seen)


SIM = PACKAGE / "sim"
ANALYSIS = PACKAGE / "analysis"
CLAIMS = PACKAGE / "claims"
#: the styling: figures only (a kind's plot uses it, its dataset builder does not)
STYLE = ANALYSIS / "plotting.py"
#: the manuscript generator: the manuscript's generated parts only (the claims never import it)
MANUSCRIPT = CLAIMS / "manuscript.py"
#: the rods in 3-D (confined-rod view and the rule views)
VIEW = ANALYSIS / "view.py"


def _part(folder: Path) -> list[Path]:
    return sorted(folder.rglob("*.py"))


def simulation_code() -> list[str]:
    """Every module of sim/ and the shared modules they import: the simulations, probes and load
    paths (a new module in sim/ re-runs them; nothing of analysis/, claims/ or pipeline/ can)."""
    return code_closure(*_part(SIM))


def postprocess_code(kind_module: str | Path) -> list[str]:
    """A figure's dataset: the postprocess step, the kind's module and what they import (not the styling)."""
    return code_closure(ANALYSIS / "postprocess.py", kind_module, skip=(STYLE,))


def figure_code(kind_module: str | Path) -> list[str]:
    """A figure: the styling, the kind's module and what they import."""
    return code_closure(STYLE, kind_module)


def budget_code(kind_modules) -> list[str]:
    """The error budget: its module, the figure kinds' headlines (their modules) and what they import."""
    return code_closure(ANALYSIS / "error_budget.py", *kind_modules, skip=(STYLE,))


def claims_code() -> list[str]:
    """The claims: every module of claims/ but the manuscript generator, and what they import."""
    return code_closure(*[p for p in _part(CLAIMS) if p != MANUSCRIPT], skip=(STYLE,))


def paper_code() -> list[str]:
    """The manuscript's generated parts: every module of claims/ and what they import."""
    return code_closure(*_part(CLAIMS), skip=(STYLE,))


def view_code() -> list[str]:
    """The 3-D views of the simulations: the view module and what it imports."""
    return code_closure(VIEW, skip=(STYLE,))


def stamp(part: str, modules: list[str], path: str | Path) -> str:
    """The file at ``path`` that stands for ``modules`` as a rule's input: one line per module,
    its SHA-256 and its path in the package, rewritten only when a checksum or the list changes,
    and given the mtime of the newest module. Snakemake then re-runs a step exactly when it did
    with the modules as inputs (an output older than a module; a content that changed). Written
    atomically: the jobs of a cluster parse the workflow too."""
    path = Path(path)
    text = f"# the code of the {part} steps (confined_rod.pipeline.code)\n" + "".join(
        f"{hashlib.sha256(Path(m).read_bytes()).hexdigest()}  {Path(m).relative_to(PACKAGE.parent).as_posix()}\n"
        for m in sorted(modules))
    newest = max(Path(m).stat().st_mtime_ns for m in modules)
    if not path.is_file() or path.read_text() != text:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(f".{path.name}.{os.getpid()}")
        tmp.write_text(text)
        os.replace(tmp, path)
    if path.stat().st_mtime_ns != newest:
        os.utime(path, ns=(newest, newest))
    return str(path)
