"""The figure -> scenes -> parameters configuration of the reproduction pipeline.

Plain Python: the Snakemake workflow (workflow/) imports this module, the
package never imports Snakemake.  A config is a mapping

    scene_defaults: {<Scene field>: value, ...}          # optional, every scene
    figures:
      <figure id>:
        kind: transmitted_force | force_profile | convergence | time_vs_error
        paper_figure: <number in the paper>
        title: <one line>
        defaults: {<Scene field>: value, ...}            # every scene of this figure
        scenes:
          <scene id>: {<Scene field>: value, ...}
        ... kind-specific entries (panel_parameter, fit_trim; parameter, tolerance,
            on_inconclusive; reference)

A scene's parameters are scene_defaults, then the figure's defaults, then its
own entries.  The JSON schema (workflow/schemas/config.schema.yaml) checks
types and keys; :func:`validate` builds every Scene (so every value passes the
physics validation) and checks the figure-kind rules, all before any job runs.
"""
from __future__ import annotations

import functools
from pathlib import Path
from typing import Any

from . import figures as kinds
from .errors import ConfigError, SceneError, shorten
from .io import logged  # noqa: F401  (re-exported for the workflow scripts)
from .scenes import Scene

RESULTS = Path("results")
ROOT = Path(__file__).resolve().parents[2]
SCHEMA = ROOT / "workflow" / "schemas" / "config.schema.yaml"
MAX_CONFIG_BYTES = 10 << 20
MAX_CONFIG_NODES = 100_000  # with YAML aliases written out (the publication config has ~2000)
__all__ = ["ConfigError", "validate", "caption", "context", "expected_outputs", "logged"]


def figures(config: dict[str, Any]) -> list[str]:
    return list(config.get("figures", {}))


def scenes(config: dict[str, Any], figure: str) -> list[str]:
    return list(config["figures"][figure].get("scenes", {}))


def scene_params(config: dict[str, Any], figure: str, scene: str) -> dict[str, Any]:
    """Merged Scene parameters of one scene of one figure (name = '<figure>/<scene>')."""
    fig = config["figures"][figure]
    params: dict[str, Any] = {}
    params.update(config.get("scene_defaults") or {})
    params.update(fig.get("defaults") or {})
    params.update(fig["scenes"][scene] or {})
    params["name"] = f"{figure}/{scene}"
    return params


_SCENES: dict[str, Scene] = {}


def _text(params: dict[str, Any]) -> str:
    """Scene parameters as text, independent of their order (a memo key)."""
    return repr(sorted(params.items(), key=lambda kv: str(kv[0])))


def build_scene(config: dict[str, Any], figure: str, scene: str) -> Scene:
    """The validated Scene of one scene of the config, memoised by its parameters (a Scene is
    immutable; a DAG build asks for each one several times: priority, run time, the file check)."""
    try:
        return _scene_of(scene_params(config, figure, scene))
    except (SceneError, TypeError) as e:
        raise ConfigError(f"figures.{figure}.scenes.{scene}: {e}") from None


def _scene_of(params: dict[str, Any]) -> Scene:
    """Scene.from_dict(params), memoised by the parameters' text (raises as it does)."""
    key = _text(params)
    if key not in _SCENES:
        _SCENES[key] = Scene.from_dict(dict(params))
    return _SCENES[key]


def built_scenes(config: dict[str, Any], figure: str) -> dict[str, Scene]:
    return {s: build_scene(config, figure, s) for s in scenes(config, figure)}


# -- code dependencies -----------------------------------------------------------
PACKAGE = Path(__file__).resolve().parent


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


# -- file layout ----------------------------------------------------------------
def sim_path(figure: str, scene: str) -> str:
    return str(RESULTS / "sims" / figure / f"{scene}.nc")


def dataset_path(figure: str) -> str:
    return str(RESULTS / "datasets" / f"{figure}.nc")


def figure_paths(figure: str) -> tuple[str, str]:
    return str(RESULTS / "figures" / f"{figure}.pdf"), str(RESULTS / "figures" / f"{figure}.png")


def canonical_scene(config: dict[str, Any], figure: str, scene: str) -> tuple[str, str]:
    """The first declared (figure, scene) with exactly the same parameters, so that a rod
    shared by several figures (e.g. Fig 4(c) and a point of Fig 6) is simulated once."""
    index, found = _canonical_index(config)
    if (figure, scene) not in found:  # a DAG build asks for each scene several times
        found[figure, scene] = index[_key(scene_params(config, figure, scene))]
    return found[figure, scene]


_INDEX: dict[int, tuple[dict[str, Any], tuple, dict[str, tuple[str, str]], dict]] = {}
_KEYS: dict[str, tuple[dict[str, Any], str]] = {}


def _config_stamp(config: dict[str, Any]) -> tuple:
    """What the canonical index depends on, cheaply: the defaults as text and, per figure, the
    identity and size of its scene table (text of every scene would make each lookup O(scenes),
    so a DAG build O(scenes^2)). A scene's parameters edited in place are not seen; the config
    of a run is fixed once expanded, and an expansion that adds scenes changes a size."""
    figs = config.get("figures") or {}
    return (repr(config.get("scene_defaults")),
            tuple((f, repr(figs[f].get("defaults")), id(figs[f].get("scenes")), len(figs[f].get("scenes") or {}))
                  for f in figs))


def _canonical_index(config: dict[str, Any]) -> tuple[dict[str, tuple[str, str]], dict]:
    """(scene key -> the first (figure, scene) declaring it, and the answers given so far, by
    (figure, scene)); rebuilt when the config's scenes change (a DAG build asks for every scene's
    canonical run, so this is built once, not once per scene). The cache holds the config
    itself, so that its id is not reused while the entry lives."""
    stamp = _config_stamp(config)
    cached = _INDEX.get(id(config))
    if cached is None or cached[0] is not config or cached[1] != stamp:
        index: dict[str, tuple[str, str]] = {}
        for f in figures(config):
            for s in scenes(config, f):
                index.setdefault(_key(scene_params(config, f, s)), (f, s))
        _INDEX[id(config)] = cached = (config, stamp, index, {})
    return cached[2], cached[3]


def _resolved(params: dict[str, Any]) -> tuple[dict[str, Any], str]:
    """(the scene's parameters with defaults filled in, name aside; the same as text), memoised:
    building a Scene validates it, which a DAG build would otherwise repeat for every scene it
    meets and every file it checks. Parameters that build no Scene are taken as they are."""
    raw = dict(params)
    raw.pop("name", None)
    raw_key = _text(raw)
    if raw_key not in _KEYS:
        try:
            d = _scene_of(params).to_dict()
        except (SceneError, TypeError):
            d = dict(params)
        d.pop("name", None)
        _KEYS[raw_key] = (d, repr(sorted(d.items())))
    return _KEYS[raw_key]


def _key(params: dict[str, Any]) -> str:
    return _resolved(params)[1]


def probe_path(figure: str, scene: str) -> str:
    return str(RESULTS / "probes" / figure / f"{scene}.nc")


def path_file(figure: str, scene: str) -> str:
    return str(RESULTS / "paths" / figure / f"{scene}.nc")


def path_spec(config: dict[str, Any], figure: str, scene: str) -> dict[str, Any]:
    """What the rule load_path runs for one scene of a path figure (the kind decides)."""
    fig = config["figures"][figure]
    return kinds.get(fig["kind"]).path_spec(fig, scene)


def figure_sims(config: dict[str, Any], figure: str) -> list[str]:
    """Scene dataset files of a figure, in its scene order (shared scenes point to one file;
    the points of a stability map are probes, which record failures instead of raising)."""
    source = kinds.source(config["figures"][figure]["kind"])
    if source == "probe":
        return [probe_path(figure, s) for s in scenes(config, figure)]
    if source == "path":
        return [path_file(figure, s) for s in scenes(config, figure)]
    return [sim_path(*canonical_scene(config, figure, s)) for s in scenes(config, figure)]


# -- batches: the small scenes of a figure run in one process (rule batch; confined_rod.runs) --
#: estimated solver seconds (limits.estimated_solver_time) a batch holds at most: a job's start-up
#: (limits.JOB_STARTUP_S, ~2 s) is then at most a tenth of its work, while a long build still
#: spreads over its cores (a scene estimated above this runs alone)
BATCH_S = 20.0
_BATCHES: dict[int, tuple[dict[str, Any], tuple, dict[str, Any]]] = {}


def run_kind(config: dict[str, Any], figure: str) -> str | None:
    """The rule that runs a figure's scenes, 'simulate' or 'probe' (None for load paths)."""
    source = kinds.source(config["figures"][figure]["kind"])
    return source if source in ("simulate", "probe") else None


def solver_estimate(config: dict[str, Any], figure: str, scene: str) -> float:
    """limits.estimated_solver_time of a scene of the config (0 for input that builds no Scene)."""
    from .limits import estimated_solver_time

    try:
        return estimated_solver_time(build_scene(config, figure, scene))
    except ConfigError:  # a probe of deliberately invalid input stops at once
        return 0.0


def plan_batches(names: list[str], cost: list[float], budget: float = BATCH_S) -> list[list[str]]:
    """Consecutive scenes (declaration order: a seed ensemble's members are neighbours) packed
    into batches of at most ``budget`` estimated seconds; a scene above it is a batch of its own."""
    out: list[list[str]] = []
    total = 0.0
    for name, c in zip(names, cost):
        if out and total + c <= budget:
            out[-1].append(name)
            total += c
        else:
            out.append([name])
            total = c
    return out


def batch_name(members: list[str]) -> str:
    """A batch is named by its first and last member (stable while they stay neighbours)."""
    return members[0] if len(members) == 1 else f"{members[0]}-to-{members[-1]}"


def _batch_index(config: dict[str, Any]) -> dict[str, Any]:
    """{'batches': {figure: {batch: [scenes]}}, 'of': {(figure, scene): batch}} for the scenes each
    figure runs itself (a shared scene runs in its first figure); single-scene batches are left
    out (such a scene runs in its own job). Built once per config, as the canonical index."""
    stamp = _config_stamp(config)
    cached = _BATCHES.get(id(config))
    if cached is None or cached[0] is not config or cached[1] != stamp:
        index: dict[str, Any] = {"batches": {}, "of": {}}
        for f in figures(config):
            kind = run_kind(config, f)
            if kind is None:
                continue
            own = [s for s in scenes(config, f) if kind == "probe" or canonical_scene(config, f, s) == (f, s)]
            for members in plan_batches(own, [solver_estimate(config, f, s) for s in own]):
                if len(members) > 1:
                    name = batch_name(members)
                    index["batches"].setdefault(f, {})[name] = members
                    index["of"].update({(f, s): name for s in members})
        _BATCHES[id(config)] = cached = (config, stamp, index)
    return cached[2]


def batches(config: dict[str, Any], figure: str) -> dict[str, list[str]]:
    """The batches of a figure: name -> its scenes (scenes that run alone are in none)."""
    return _batch_index(config)["batches"].get(figure, {})


def batch_of(config: dict[str, Any], figure: str, scene: str) -> str | None:
    return _batch_index(config)["of"].get((figure, scene))


def batch_manifest(kind: str, figure: str, batch: str) -> str:
    return str(RESULTS / "batches" / kind / figure / f"{batch}.json")


def batch_log(kind: str, figure: str, batch: str) -> str:
    return str(RESULTS / "logs" / "batch" / kind / figure / f"{batch}.log")


def batch_folder(kind: str, figure: str, batch: str) -> str:
    """Where a batch leaves its members' datasets, for their own jobs to move into place."""
    return str(RESULTS / "batches" / kind / figure / batch)


def batch_member(kind: str, figure: str, batch: str, scene: str) -> str:
    return str(Path(batch_folder(kind, figure, batch)) / f"{scene}.nc")


def _kind_batch(config: dict[str, Any], kind: str, figure: str, scene: str) -> str | None:
    """The batch of ``kind`` that runs this scene, or None if it runs alone."""
    batch = batch_of(config, figure, scene)
    return batch if batch and run_kind(config, figure) == kind else None


def member_batch(config: dict[str, Any], kind: str, figure: str, scene: str) -> list[str]:
    """[the manifest of the batch that runs this scene], or [] if it runs alone."""
    batch = _kind_batch(config, kind, figure, scene)
    return [batch_manifest(kind, figure, batch)] if batch else []


def member_cache(config: dict[str, Any], kind: str, figure: str, scene: str) -> str:
    """The batch's copy of this scene's dataset ('' if it runs alone)."""
    batch = _kind_batch(config, kind, figure, scene)
    return batch_member(kind, figure, batch, scene) if batch else ""


def batch_job(config: dict[str, Any], kind: str, figure: str, batch: str) -> dict[str, Any]:
    """What rule batch runs: the members' parameters and where each dataset goes."""
    members = batches(config, figure).get(batch)
    if not members or run_kind(config, figure) != kind:
        raise ConfigError(f"figures.{figure}: no {kind} batch named {batch!r}")
    return {"members": [scene_params(config, figure, s) for s in members],
            "outputs": [batch_member(kind, figure, batch, s) for s in members],
            "folder": batch_folder(kind, figure, batch)}


def batch_outputs(config: dict[str, Any]) -> list[str]:
    """Every batch manifest of the config."""
    return [batch_manifest(run_kind(config, f), f, b) for f in figures(config) for b in batches(config, f)]


def wanted_scene(config: dict[str, Any], figure: str, scene: str, shared: bool = True) -> dict[str, Any] | None:
    """What the file of a scene must store (evidence.check_file): every Scene parameter, defaults
    filled in, under the name of the run that makes the file (with ``shared``, a shared run's
    first figure; without, the scene is the file's own run). None for a stability-map probe,
    whose file records its raw input and how it ended."""
    source = kinds.source(config["figures"][figure]["kind"])
    if source == "probe":
        return None
    f, s = canonical_scene(config, figure, scene) if source == "simulate" and shared else (figure, scene)
    params = scene_params(config, f, s)
    return {**_resolved(params)[0], "name": params["name"]}


def figure_wanted(config: dict[str, Any], figure: str) -> list[dict[str, Any] | None]:
    """wanted_scene of each of a figure's scene files, in the order of figure_sims."""
    return [wanted_scene(config, figure, s) for s in scenes(config, figure)]


def rebuild_marker(figure: str, scene: str) -> Path:
    """An empty file whose fresh mtime makes Snakemake rebuild a scene file that is not the
    run the config asks for (see stale_inputs)."""
    return RESULTS / ".rebuild" / figure / f"{scene}.stale"


_CHECKED: dict[tuple, str | None] = {}


def stale_inputs(config: dict[str, Any], figure: str, scene: str, path: str) -> list[str]:
    """[marker] if the existing file ``path`` of this scene is unreadable or stores another scene
    than the config's (a file copied over another, or built from another config after
    Snakemake's metadata in .snakemake/ was lost), else []. The marker is touched now, so the
    rule that makes the file sees an input newer than its output and rebuilds it (and so
    everything downstream); a note names the file and the first differing parameter."""
    from .evidence import problem

    marker = rebuild_marker(figure, scene)
    file = Path(path)
    if not file.is_file():
        return []
    wanted = wanted_scene(config, figure, scene, shared=False)
    if wanted is None:
        return []
    st = file.stat()
    key = (str(file), st.st_mtime_ns, st.st_size, repr(sorted(wanted.items())))
    if key not in _CHECKED:
        _CHECKED[key] = problem(file, wanted)
        if _CHECKED[key]:
            import sys

            print(f"note: {_CHECKED[key]}: it will be rebuilt", file=sys.stderr)
    if _CHECKED[key] is None:
        if marker.exists():
            marker.unlink()
        return []
    marker.parent.mkdir(parents=True, exist_ok=True)
    if not marker.exists() or marker.stat().st_mtime_ns <= st.st_mtime_ns:
        marker.touch()
        if marker.stat().st_mtime_ns <= st.st_mtime_ns:  # a file stamped in the future
            import os

            os.utime(marker, ns=(st.st_atime_ns, st.st_mtime_ns + 1_000_000_000))
    return [str(marker)]


def expand_sweeps(config: dict[str, Any]) -> None:
    """Let every figure kind that has sweeps (stability maps) turn them into scenes, in place."""
    for f in figures(config):
        fig = config["figures"][f]
        if fig.get("kind") in kinds.kinds():
            expand = getattr(kinds.get(fig["kind"]), "expand_sweeps", None)
            if expand:
                try:
                    expand(fig)
                except ConfigError as e:
                    raise ConfigError(f"figures.{f}.{e}") from None


def expand_ensembles(config: dict[str, Any]) -> None:
    """Turn every scene that asks for ``seeds`` (in its own entry, its figure's defaults or
    scene_defaults) into one scene per seed, ``<scene>-s<seed>``, in place; idempotent.
    Only figure kinds with ``ENSEMBLES = True`` accept them (ConfigError otherwise)."""
    from . import ensembles

    top = config.get("scene_defaults") or {}
    for f in figures(config):
        fig = config["figures"][f]
        defaults = fig.get("defaults") or {}
        out: dict[str, Any] = {}
        origin: dict[str, str] = {}     # expanded name -> the config entry it came from
        for name, entry in (fig.get("scenes") or {}).items():
            entry = dict(entry or {})
            spec = entry.pop("seeds", defaults.get("seeds", top.get("seeds")))
            if spec is None:
                _add_scene(out, origin, f, name, entry, name)
                continue
            if not getattr(kinds.get(fig["kind"]), "ENSEMBLES", False):
                raise ConfigError(f"figures.{f}.scenes.{name}.seeds: kind {fig['kind']!r} does not support seed "
                                  "ensembles yet (kinds that do: "
                                  + ", ".join(k for k in kinds.kinds() if getattr(kinds.get(k), "ENSEMBLES", False))
                                  + ")")
            first = entry.get("seed", defaults.get("seed", top.get("seed", 0)))
            try:
                seeds = ensembles.seeds_of(spec, int(first))
            except ValueError as e:
                raise ConfigError(f"figures.{f}.scenes.{name}.seeds: {e}") from None
            for seed in seeds:
                _add_scene(out, origin, f, f"{name}-s{seed}", {**entry, "seed": seed}, name)
        if fig.get("scenes") is not None:
            fig["scenes"] = out
        defaults.pop("seeds", None)
    top.pop("seeds", None)


def _add_scene(out: dict[str, Any], origin: dict[str, str], figure: str, name: str, entry: dict, source: str) -> None:
    """One expanded scene; two config entries that give the same name are refused, naming both."""
    if name in out:
        a, b = origin[name], source
        what = (f"the entry {a!r}" if a == name else f"the seed ensemble {a!r}") + " and " + \
            (f"the entry {b!r}" if b == name else f"the seed ensemble {b!r}")
        raise ConfigError(f"figures.{figure}.scenes: {what} both give the scene {name!r}; rename one")
    out[name], origin[name] = entry, source


def expand(config: dict[str, Any]) -> dict[str, Any]:
    """Sweeps and seed ensembles turned into scenes, in place (idempotent); returns config."""
    expand_sweeps(config)
    expand_ensembles(config)
    return config


def check_path(figure: str) -> str:
    return str(RESULTS / "checks" / f"{figure}.txt")


def convergence_figures(config: dict[str, Any]) -> list[str]:
    """Figures whose kind defines a ``check`` (a verdict that can fail the build)."""
    return [f for f in figures(config) if hasattr(kinds.get(config["figures"][f]["kind"]), "check")]


def publication_value(config: dict[str, Any], figure: str) -> float | None:
    """The value of a convergence figure's parameter in the publication settings: the
    figure's own publication_value if given (a setting of some figures only, such as the
    ramp_steps of the ramped figures), else scene_defaults if set there, else the Scene
    default (None if the figure names no valid parameter: its validation says so)."""
    param = config["figures"][figure].get("parameter")
    if param not in Scene.field_names():
        return None
    if "publication_value" in config["figures"][figure]:
        return float(config["figures"][figure]["publication_value"])
    defaults = config.get("scene_defaults") or {}
    if param in defaults:
        return float(defaults[param])
    return float(getattr(Scene(**{k: v for k, v in defaults.items() if k != param}), param))


def expected_outputs(config: dict[str, Any]) -> dict[str, list[str]]:
    """Every artifact a full run of this config produces, by kind (sweeps and ensembles
    expanded into scenes, in place)."""
    expand(config)
    out: dict[str, list[str]] = {"sims": [], "datasets": [], "figures": [], "checks": []}
    for f in figures(config):
        out["sims"] += [p for p in figure_sims(config, f) if p not in out["sims"]]
        out["datasets"].append(dataset_path(f))
        out["figures"] += list(figure_paths(f))
    out["checks"] = [check_path(f) for f in convergence_figures(config)]
    out["paper"] = paper_outputs(config)
    return out


def paper_outputs(config: dict[str, Any]) -> list[str]:
    """The claims table and the manuscript PDF, if the config has a paper section."""
    paper = config.get("paper")
    if not paper:
        return []
    return [str(RESULTS / "claims.csv"), str(RESULTS / "claims.nc"),
            str(RESULTS / "paper" / (Path(paper["manuscript"]).stem + ".pdf"))]


def claim_sims(config: dict[str, Any]) -> dict[str, str]:
    """'figure/scene' -> simulation file, for the figures whose simulations the claims read."""
    from . import claims

    paper = config.get("paper")
    if not paper:
        return {}
    listed = claims.load(ROOT / paper["claims"])
    return {f"{f}/{s}": p for f in claims.sim_figures(listed)
            for s, p in zip(scenes(config, f), figure_sims(config, f))}


def claim_wanted(config: dict[str, Any]) -> list[dict[str, Any] | None]:
    """wanted_scene of each file of claim_sims, in its order."""
    return [wanted_scene(config, *key.split("/", 1)) for key in claim_sims(config)]


# -- reading and checking a config ---------------------------------------------------------
def read_config(path: str | Path) -> dict[str, Any]:
    """Read a config file strictly: one-line errors with the line number, no duplicate
    keys, aliases only up to MAX_CONFIG_NODES nodes written out (io.read_yaml)."""
    from .io import read_yaml

    data = read_yaml(path, what="config file", error=ConfigError, max_bytes=MAX_CONFIG_BYTES,
                     max_nodes=MAX_CONFIG_NODES)
    if not isinstance(data, dict):
        raise ConfigError(f"config file {str(path)!r}: must be a mapping with 'figures' at the top level, got "
                          f"{type(data).__name__}")
    return data


def check_schema(config: dict[str, Any], schema_path: str | Path = SCHEMA) -> None:
    """Validate against the JSON schema; the first (most relevant) error as one line
    naming the entry (the schema itself is never printed)."""
    import jsonschema
    import yaml

    schema = yaml.safe_load(Path(schema_path).read_text())
    validator = jsonschema.Draft202012Validator(schema)
    error = jsonschema.exceptions.best_match(validator.iter_errors(config))
    if error is None:
        return
    where = ".".join(str(p) for p in error.absolute_path) or "top level"
    if error.validator in ("additionalProperties", "unevaluatedProperties"):
        allowed = set(error.schema.get("properties", {}))
        kind = error.instance.get("kind") if isinstance(error.instance, dict) else None
        if kind in kinds.kinds():       # a figure entry: its kind's options are allowed too
            allowed |= set(getattr(kinds.get(kind), "OPTIONS", {}))
        allowed = sorted(allowed)
        extra = sorted(set(error.instance) - set(allowed)) if isinstance(error.instance, dict) else []
        detail = (f"unknown key {shorten(extra[0]) if extra else '?'}"
                  + (f"; allowed here: {', '.join(allowed)}" if allowed else ""))
    else:
        detail = f"{shorten(error.instance)}: {_schema_reason(error)}"
    raise ConfigError(f"{where}: {detail}")


def _schema_reason(error) -> str:
    """The rule an instance broke, without repeating the (possibly huge) instance."""
    rule = error.validator_value
    words = {"type": "must be of type {}", "minimum": "must be >= {}", "maximum": "must be <= {}",
             "exclusiveMinimum": "must be > {}", "exclusiveMaximum": "must be < {}",
             "minItems": "needs at least {} items", "maxItems": "takes at most {} items",
             "minProperties": "needs at least {} entries", "pattern": "must match {}"}
    if error.validator in words:
        return words[error.validator].format(rule)
    if error.validator == "enum":
        return "must be one of " + ", ".join(map(str, rule))
    if error.validator == "required":
        return "needs the keys " + ", ".join(map(str, rule))
    return shorten(error.message, 200)


def costly_scenes(config: dict[str, Any], budget_s: float) -> list[tuple[str, str, float]]:
    """(figure, scene, estimated seconds) of every valid scene estimated above budget_s."""
    from .limits import estimated_wall_time

    expand(config)
    out = []
    for f in figures(config):
        for s in scenes(config, f):
            try:
                cost = estimated_wall_time(build_scene(config, f, s))
            except ConfigError:  # a stability map's invalid points
                continue
            if cost > budget_s:
                out.append((f, s, cost))
    return out


def check(config: dict[str, Any], files: list[str | Path] = (), schema_path: str | Path = SCHEMA) -> None:
    """Everything the workflow checks at start-up, before any job: each config file read
    strictly, the schema, every scene built (its physics validation) and the figure-kind
    rules.  Expands the stability maps' sweeps into scenes, in place."""
    for f in files:
        read_config(f)
    check_schema(config, schema_path)
    expand(config)
    validate(config)
    check_paper(config)


def check_paper(config: dict[str, Any], root: str | Path = ROOT) -> None:
    """The paper section: its files exist, the claims file is well formed, and every figure a
    claim reads is built by this config (else the claims rule could not decide it)."""
    paper = config.get("paper")
    if not paper:
        return
    from . import claims

    for key in ("manuscript", "claims"):
        if not (Path(root) / paper[key]).is_file():
            raise ConfigError(f"paper.{key}: {paper[key]!r} is not a file of this checkout")
    listed = claims.load(Path(root) / paper["claims"])
    for fig, ids in claims.required_figures(listed).items():
        if fig not in config["figures"]:
            raise ConfigError(f"paper.claims: claim {ids[0]!r} (and {len(ids) - 1} more) reads figure {fig!r}, "
                              "which this config does not build; add the figure or drop the paper section")
    pages = paper.get("pages")
    if pages and pages[0] > pages[1]:
        raise ConfigError(f"paper.pages: {pages!r}, expected [min, max] with min <= max")


# -- validation, captions, build context (dispatched to the figure kind's module) -----------
def _seeds_text(built: dict[str, Scene]) -> str:
    seeds = sorted({sc.seed for sc in built.values()})
    if len(seeds) == 1:
        return f"seed {seeds[0]}"
    runs = len(seeds) == seeds[-1] - seeds[0] + 1
    return f"seeds {seeds[0]}-{seeds[-1]}" if runs else "seeds " + ", ".join(map(str, seeds))


def validate(config: dict[str, Any]) -> None:
    """Build every scene and check the figure-kind rules; raise ConfigError naming the entry."""
    expand(config)
    if not figures(config):
        raise ConfigError("config has no figures: nothing to build")
    for f in figures(config):
        fig = config["figures"][f]
        kind = fig.get("kind")
        if kind not in kinds.kinds():
            raise ConfigError(f"figures.{f}.kind: {kind!r} is not one of {', '.join(kinds.kinds())}")
        module = kinds.get(kind)
        read_figures(config, f)
        if hasattr(module, "validate_config"):  # kinds whose scenes may be invalid on purpose
            module.validate_config(f, fig, Scene.field_names())
            continue
        if not scenes(config, f):
            raise ConfigError(f"figures.{f}.scenes: a figure needs at least one scene")
        module.validate(f, fig, built_scenes(config, f), **_extra(module, config, f))


def _extra(module, config, figure) -> dict[str, Any]:
    """Keyword arguments a kind's validate/caption ask for (the publication value of a ladder)."""
    import inspect

    if "publication_value" in inspect.signature(module.validate).parameters:
        return {"publication_value": publication_value(config, figure)}
    return {}


def context(config: dict[str, Any], figure: str) -> dict[str, Any]:
    """What a figure's dataset builder needs from the config beyond its own entry (the
    datasets of the figures it reads are added by the postprocess rule: ``datasets``)."""
    fig = config["figures"][figure]
    return {"publication_value": publication_value(config, figure)} if "parameter" in fig else {}


def read_figures(config: dict[str, Any], figure: str) -> dict[str, str]:
    """Other figures whose datasets this figure's builder reads (the kind's ``READS``):
    figure name -> dataset file. ConfigError if a named figure is missing or of a kind the
    option does not accept."""
    fig = config["figures"][figure]
    out: dict[str, str] = {}
    for option, accepted in getattr(kinds.get(fig["kind"]), "READS", {}).items():
        name = fig.get(option)
        if name is None:
            continue
        other = config["figures"].get(name)
        if other is None or name == figure:
            raise ConfigError(f"figures.{figure}.{option}: {name!r} is not another figure of this config "
                              f"(figures: {', '.join(figures(config))})")
        if other.get("kind") not in accepted:
            raise ConfigError(f"figures.{figure}.{option}: figure {name!r} is of kind {other.get('kind')!r}; "
                              f"expected {' or '.join(accepted)}")
        out[name] = dataset_path(name)
    return out


def caption(config: dict[str, Any], figure: str) -> str:
    """Plain-text caption: what the figure shows and with which parameters (those common to
    all its scenes; the ones it varies are named in the body)."""
    expand(config)
    fig = config["figures"][figure]
    module = kinds.get(fig["kind"])
    head = f"{fig.get('title', figure)} {kinds.origin(fig)}."
    if hasattr(module, "validate_config"):
        return head + " " + module.caption(figure, fig)
    built = built_scenes(config, figure)
    body = module.caption(figure, fig, built, **_extra(module, config, figure))
    sc = next(iter(built.values()))
    varied = set(kinds.varied(fig["kind"], fig))
    common = [f"R = {sc.R:g}", f"EI = {sc.EI:g}", f"load |F_z(0)| = {sc.load:g} EI/R^2",
              f"friction cap {sc.friction_cap:g} EI/R^3",
              "protocol varied" if "protocol" in varied else f"protocol '{sc.protocol}'", _seeds_text(built),
              "perturbation varied" if "perturbation" in varied else f"perturbation {sc.perturbation:g} R"]
    numerics = [f"{k} = {getattr(sc, k):g}{u}" for k, u in (("l0", " R"), ("k_ph", " EI/R^2"), ("k_w", " EI/R^3"),
                                                              ("tol", ""))]
    numerics = [t if t.split(" =")[0] not in varied else f"{t.split(' =')[0]} varied" for t in numerics]
    numerics.insert(3, f"solver '{sc.solver}'" if "solver" not in varied else "solver varied")
    if sc.bending_constant != "corrected":
        numerics.append(f"bending constant '{sc.bending_constant}' (C = EI/l0^2 as printed)")
    return (head + " " + body + " Parameters: " + ", ".join(common) + "; numerics: " + ", ".join(numerics)
            + ".")
