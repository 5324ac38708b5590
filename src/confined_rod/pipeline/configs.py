"""The figure -> scenes -> parameters configuration of the reproduction pipeline.

Plain Python: the Snakemake workflow (workflow/) imports this module, the
package never imports Snakemake.  A config is a mapping

    scene_defaults: {<Scene field>: value, ...}          # optional, every scene
    figures:
      <figure id>:
        kind: <a figure kind: a module of confined_rod/analysis/figures>
        paper_figure: <number in the paper>
        title: <one line>
        defaults: {<Scene field>: value, ...}            # every scene of this figure
        scenes:
          <scene id>: {<Scene field>: value, ...}
        ... the kind's own entries (its OPTIONS; the schema lists them per kind)

A scene's parameters are scene_defaults, then the figure's defaults, then its
own entries.  The JSON schema (workflow/schemas/config.schema.yaml) checks
types and keys; :func:`validate` builds every Scene (so every value passes the
physics validation) and checks the figure-kind rules, all before any job runs.
"""
from __future__ import annotations

import copy
import math
from pathlib import Path
from typing import Any

from .. import layout
from ..analysis import ensembles
from ..analysis import figures as kinds
from ..analysis.figure_quantities import NUMERICS
from ..errors import ConfigError, SceneError, shorten
from ..quantities import QUANTITIES, pretty_unit
from ..sim.scenes import Scene

ROOT = Path(__file__).resolve().parents[3]


SCHEMA = ROOT / "workflow" / "schemas" / "config.schema.yaml"


MAX_CONFIG_BYTES = 10 << 20


MAX_CONFIG_NODES = 100_000  # with YAML aliases written out (the publication config has ~2000)


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


class Expanded(dict):
    """A config whose sweeps and seed ensembles are scenes (made by :func:`expand` only). It
    pickles as a plain dict: Snakemake hands the config to every job's script, which must not
    import this package before the job's own checkout is on the path (workflow/scripts/_checkout.py)."""

    def __reduce__(self):
        return dict, (dict(self),)


def _expand_sweeps(config: dict[str, Any]) -> None:
    """Let every figure kind that has sweeps (stability maps) turn them into scenes, in place
    (expand calls it on its copy)."""
    for f in figures(config):
        fig = config["figures"][f]
        if fig.get("kind") in kinds.kinds():
            expand = getattr(kinds.get(fig["kind"]), "expand_sweeps", None)
            if expand:
                try:
                    expand(fig)
                except ConfigError as e:
                    raise ConfigError(f"figures.{f}.{e}") from None


def _expand_ensembles(config: dict[str, Any]) -> None:
    """Turn every scene that asks for ``seeds`` (in its own entry, its figure's defaults or
    scene_defaults) into one scene per seed, ``<scene>-s<seed>``, in place (expand calls it on
    its copy); idempotent.
    Only figure kinds with ``ENSEMBLES = True`` accept them (ConfigError otherwise)."""

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
                _add_scene(out, origin, f, ensembles.member_name(name, seed), {**entry, "seed": seed}, name)
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


def expand(config: dict[str, Any]) -> Expanded:
    """The config with its sweeps and seed ensembles turned into scenes: a new mapping, the
    given one left as it is; a config expand made is returned as it is (the functions that need
    the scenes call it, so the workflow expands once, at start-up: ``check``)."""
    if isinstance(config, Expanded):
        return config
    out = Expanded(copy.deepcopy(dict(config)))
    _expand_sweeps(out)
    _expand_ensembles(out)
    return out


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


def read_config(path: str | Path) -> dict[str, Any]:
    """Read a config file strictly: one-line errors with the line number, no duplicate
    keys, aliases only up to MAX_CONFIG_NODES nodes written out (io.read_yaml)."""
    from ..io import read_yaml

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
    from ..limits import estimated_wall_time

    config = expand(config)
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


def check(config: dict[str, Any], files: list[str | Path] = (), schema_path: str | Path = SCHEMA) -> Expanded:
    """Everything the workflow checks at start-up, before any job: each config file read
    strictly, the schema, every scene built (its physics validation) and the figure-kind
    rules. Returns the expanded config (sweeps and seed ensembles as scenes) the rules use;
    the given one is left as it is."""
    for f in files:
        read_config(f)
    check_schema(config, schema_path)
    config = expand(config)
    validate(config)
    check_paper(config)
    return config


def check_paper(config: dict[str, Any], root: str | Path = ROOT) -> None:
    """The paper section: its files exist, the claims file is well formed, and every figure a
    claim reads is built by this config (else the claims rule could not decide it)."""
    paper = config.get("paper")
    if not paper:
        return
    from .. import claims

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


def _seeds_text(built: dict[str, Scene]) -> str:
    seeds = sorted({sc.seed for sc in built.values()})
    if len(seeds) == 1:
        return f"seed {seeds[0]}"
    runs = len(seeds) == seeds[-1] - seeds[0] + 1
    return f"seeds {seeds[0]}-{seeds[-1]}" if runs else "seeds " + ", ".join(map(str, seeds))


def validate(config: dict[str, Any]) -> None:
    """Build every scene and check the figure-kind rules; raise ConfigError naming the entry."""
    config = expand(config)
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
        if fig.get("serves"):
            served(config, f)


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
    if "parameter" not in fig:
        return {}
    return {"publication_value": publication_value(config, figure), "served": served(config, figure)}


#: Scene fields that say how a run is stored or named, not which rod it is: a ladder serves a
#: figure's scene when every other field agrees
_NOT_PHYSICS = ("name", "seed", "snapshot_interval", "snapshot_growth")


def served(config: dict[str, Any], figure: str) -> list[dict[str, Any]]:
    """The figure scenes whose ensemble means a convergence ladder vouches for (its ``serves``:
    '<figure>.<scene>'), each as {"name", "seeds", "reports"}: the scene's ensemble size and the
    quantities its kind reports (the kind's REPORTS). ConfigError if a named figure or scene is
    missing, its kind reports nothing a ladder compares, or its rod is not the ladder's
    publication rung (every Scene field but the seed and the stored snapshots)."""
    config = expand(config)
    fig = config["figures"][figure]
    entries = fig.get("serves") or []
    if not entries:
        return []
    param, pub = fig.get("parameter"), publication_value(config, figure)
    rung = [sc for sc in built_scenes(config, figure).values()
            if pub is not None and math.isclose(float(getattr(sc, param)), pub, rel_tol=1e-9)]
    out = []
    for entry in entries:
        where = f"figures.{figure}.serves: {entry!r}"
        other, _, scene = str(entry).partition(".")
        if other not in config["figures"] or other == figure or not scene:
            raise ConfigError(f"{where} is not '<figure>.<scene>' of another figure of this config "
                              f"(figures: {', '.join(figures(config))})")
        reports = tuple(getattr(kinds.get(config["figures"][other]["kind"]), "REPORTS", ()))
        if not reports:
            raise ConfigError(f"{where}: figure {other!r} (kind {config['figures'][other]['kind']!r}) reports no "
                              "ensemble mean a ladder compares (kinds that do: "
                              + ", ".join(k for k in kinds.kinds() if getattr(kinds.get(k), "REPORTS", ())) + ")")
        members = {n: sc for n, sc in built_scenes(config, other).items()
                   if n == scene or ensembles.base_name(n, sc.seed) == scene}
        if not members:
            raise ConfigError(f"{where}: figure {other!r} has no scene {scene!r} (scenes: "
                              + ", ".join(sorted({ensembles.base_name(n, sc.seed) for n, sc in
                                                  built_scenes(config, other).items()})) + ")")
        if rung:
            mine = {k: v for k, v in rung[0].to_dict().items() if k not in _NOT_PHYSICS}
            theirs = {k: v for k, v in next(iter(members.values())).to_dict().items() if k not in _NOT_PHYSICS}
            differ = [f"{k} {theirs[k]!r} against {mine[k]!r}" for k in mine if mine[k] != theirs[k]]
            if differ:
                raise ConfigError(f"{where}: that scene is not the rod of this ladder's publication rung ("
                                  + "; ".join(differ[:4]) + ")")
        out.append({"name": f"{other}.{scene}", "seeds": len(members), "reports": list(reports)})
    return out


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
        out[name] = layout.dataset_path(name)
    return out


def caption(config: dict[str, Any], figure: str) -> str:
    """Plain-text caption: what the figure shows and with which parameters (those common to
    all its scenes; the ones it varies are named in the body)."""
    config = expand(config)
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
              f"friction cap {sc.friction_cap:g} EI/R^2 per link",
              "protocol varied" if "protocol" in varied else f"protocol '{sc.protocol}'", _seeds_text(built),
              "perturbation varied" if "perturbation" in varied else f"perturbation {sc.perturbation:g} R"]
    units = {k: pretty_unit(QUANTITIES[k].units) for k in NUMERICS}
    numerics = [f"{k} = {getattr(sc, k):g}" + (f" {units[k]}" if units[k] else "") for k in NUMERICS]
    numerics = [t if t.split(" =")[0] not in varied else f"{t.split(' =')[0]} varied" for t in numerics]
    numerics.insert(3, f"solver '{sc.solver}'" if "solver" not in varied else "solver varied")
    if sc.bending_constant != "corrected":
        numerics.append(f"bending constant '{sc.bending_constant}' (C = EI/l0^2 as printed)")
    return (head + " " + body + " Parameters: " + ", ".join(common) + "; numerics: " + ", ".join(numerics)
            + ".")
