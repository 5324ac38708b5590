"""Figure kinds, one module each, found by name: ``confined_rod/analysis/figures/<kind>.py``.

A kind module holds everything about one kind of figure. What the pipeline asks of it (the
one place this protocol is written down):

Required
    OPTIONS                            JSON-schema properties of the kind's own config entries
                                       (the config schema is generated from them:
                                       ``python -m confined_rod schema``)
    validate(figure, fig_cfg, built)   built: scene id -> Scene; raise ConfigError naming the entry
                                       (may take ``publication_value=``: the ladder's setting)
    caption(figure, fig_cfg, built)    what the figure shows (the pipeline adds the title and the
                                       parameters its scenes share; may take ``publication_value=``)
    build(fig_cfg, sims, context)      scene id -> scene dataset  =>  the figure's dataset
    plot(ds)                           the figure's dataset  =>  a matplotlib Figure

Optional (absent: the default in brackets)
    SOURCE              "simulate", "probe" or "path": the rule that makes its scene files
                        ["simulate"]; a "path" kind also defines ``path_spec(fig_cfg, scene)``,
                        what the rule load_path runs (confined_rod.sim.load_paths.run_spec)
    varied(fig_cfg)     the scene parameters that differ between its scenes [none]
    ENSEMBLES           True if its scenes may be seed ensembles (``seeds: n``) [False]
    HANDLES_UNSETTLED   True if it sorts out runs not at equilibrium itself (the paired ladders
                        leave a seed out at every rung) [the postprocess step leaves them out of
                        their ensemble]
    READS               {option: kinds}: options naming another figure of the config whose
                        dataset the builder reads (context["datasets"][name]) [none]
    expand_sweeps(fig_cfg)      turns the kind's sweeps into scenes, in the config [none]
    validate_config(figure, fig_cfg, scene_fields)  for kinds whose scenes may be invalid on
                        purpose (a stability map's refused points): replaces validate and the
                        building of every scene; its caption is then caption(figure, fig_cfg)
    meta(fig_cfg, used)         the dataset's attributes in place of the shared scene
                                parameters [those of the first scene]
    check(ds, figure, on_inconclusive)  a verdict that can fail the build (rule
                        convergence_check: the convergence ladders) [none]
    headlines(figure, ds)  the numbers the figure reports, as analysis.error_budget.Headline
                        (value, statistical error, what decides its numerical bias), for the
                        error budget (rule error_budget) [none]

Adding a kind is one new module here and its entry in a config (then regenerate the schema).
The modules are post-processing: they read datasets and never import the simulator (the import
contracts in pyproject.toml); validation receives Scene objects built by
:mod:`confined_rod.pipeline`.
"""
from __future__ import annotations

import functools
import importlib
import pkgutil
from pathlib import Path
from types import ModuleType

from ...errors import ConfigError

HERE = Path(__file__).resolve().parent


def kinds() -> list[str]:
    """Every figure kind: the modules of this package whose names do not start with '_'."""
    return list(_kinds())


@functools.cache
def _kinds() -> tuple[str, ...]:
    """The kinds, listed once per process (a DAG build asks for a kind thousands of times)."""
    return tuple(sorted(m.name for m in pkgutil.iter_modules([str(HERE)]) if not m.name.startswith("_")))


def get(kind: str) -> ModuleType:
    if kind not in _kinds():
        raise ConfigError(f"figure kind {kind!r} is not one of {', '.join(kinds())}")
    return importlib.import_module(f"{__name__}.{kind}")


def module_path(kind: str) -> Path:
    return HERE / f"{kind}.py"


def source(kind: str) -> str:
    return getattr(get(kind), "SOURCE", "simulate")


def varied(kind: str, fig_cfg) -> tuple[str, ...]:
    fn = getattr(get(kind), "varied", None)
    return tuple(fn(fig_cfg)) if fn else ()


def has_headlines(kind: str) -> bool:
    return hasattr(get(kind), "headlines")


def headlines(figure: str, ds) -> list:
    """The error budget's numbers of one figure's dataset (its kind's ``headlines``; none if it
    has no such hook)."""
    fn = getattr(get(str(ds.attrs["kind"])), "headlines", None)
    return list(fn(figure, ds)) if fn else []


#: the original's figures named in words, so that a caption carries one numbering: ours
ORDINALS = ("first", "second", "third", "fourth", "fifth", "sixth", "seventh", "eighth")


def origin(fig_cfg) -> str:
    """Where a figure comes from, for its title and caption: "(the paper's fourth figure)", or
    '(not in the paper)' for the figures this package adds (convergence, benchmarks, maps)."""
    n = fig_cfg.get("paper_figure")
    return f"(the paper's {ORDINALS[int(n) - 1]} figure)" if n is not None else "(not in the paper)"
