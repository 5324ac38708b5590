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

import contextlib
from pathlib import Path
from typing import Any

from .scenes import Scene, SceneError
from .studies import REFINEMENT

FIGURE_KINDS = ("transmitted_force", "force_profile", "convergence", "time_vs_error", "stability_map")
SWEEP_ONLY = {"dt_factor": "explicit", "dx_max": "implicit"}  # step knobs that exist for one solver only
RESULTS = Path("results")


class ConfigError(ValueError):
    """Invalid pipeline configuration; the message names the config path and the value."""


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


def build_scene(config: dict[str, Any], figure: str, scene: str) -> Scene:
    try:
        return Scene.from_dict(scene_params(config, figure, scene))
    except (SceneError, TypeError) as e:
        raise ConfigError(f"figures.{figure}.scenes.{scene}: {e}") from None


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
    mine = _key(scene_params(config, figure, scene))
    for f in figures(config):
        for s in scenes(config, f):
            if _key(scene_params(config, f, s)) == mine:
                return f, s
    raise KeyError(f"{figure}/{scene}")  # unreachable: the scene finds itself


def _key(params: dict[str, Any]) -> str:
    try:
        d = Scene.from_dict(params).to_dict()
    except (SceneError, TypeError):
        d = dict(params)
    d.pop("name", None)
    return repr(sorted(d.items()))


def probe_path(figure: str, scene: str) -> str:
    return str(RESULTS / "probes" / figure / f"{scene}.nc")


def figure_sims(config: dict[str, Any], figure: str) -> list[str]:
    """Scene dataset files of a figure, in its scene order (shared scenes point to one file;
    the points of a stability map are probes, which record failures instead of raising)."""
    if config["figures"][figure]["kind"] == "stability_map":
        return [probe_path(figure, s) for s in scenes(config, figure)]
    return [sim_path(*canonical_scene(config, figure, s)) for s in scenes(config, figure)]


def expand_sweeps(config: dict[str, Any]) -> None:
    """Turn each stability map's ``sweeps`` into scenes, in place: for every solver a
    base point ('<solver>-base', the figure's defaults) and one point per swept value
    ('<solver>-<parameter>-<value>'); dt_factor is swept for the explicit and dx_max for
    the implicit solver only."""
    for f in figures(config):
        fig = config["figures"][f]
        if fig.get("kind") != "stability_map" or not fig.get("sweeps"):
            continue
        out = fig.setdefault("scenes", {}) or {}
        for solver in fig.get("solvers", ["implicit", "explicit"]):
            out.setdefault(f"{solver}-base", {"solver": solver})
            for param, values in fig["sweeps"].items():
                if SWEEP_ONLY.get(param, solver) != solver:
                    continue
                for v in values:
                    tag = f"{v:g}".replace(".", "p").replace("-", "m").replace("+", "")
                    out.setdefault(f"{solver}-{param}-{tag}", {"solver": solver, param: v})
        fig["scenes"] = out


def check_path(figure: str) -> str:
    return str(RESULTS / "checks" / f"{figure}.txt")


def convergence_figures(config: dict[str, Any]) -> list[str]:
    return [f for f in figures(config) if config["figures"][f]["kind"] == "convergence"]


def publication_value(config: dict[str, Any], figure: str) -> float:
    """The value of a convergence figure's parameter in the publication settings:
    scene_defaults if set there, else the Scene default."""
    param = config["figures"][figure]["parameter"]
    defaults = config.get("scene_defaults") or {}
    if param in defaults:
        return float(defaults[param])
    return float(getattr(Scene(**{k: v for k, v in defaults.items() if k != param}), param))


def expected_outputs(config: dict[str, Any]) -> dict[str, list[str]]:
    """Every artifact a full run of this config produces, by kind."""
    out: dict[str, list[str]] = {"sims": [], "datasets": [], "figures": [], "checks": []}
    for f in figures(config):
        out["sims"] += [p for p in figure_sims(config, f) if p not in out["sims"]]
        out["datasets"].append(dataset_path(f))
        out["figures"] += list(figure_paths(f))
    out["checks"] = [check_path(f) for f in convergence_figures(config)]
    return out


# -- validation -----------------------------------------------------------------
def validate(config: dict[str, Any]) -> None:
    """Build every scene and check the figure-kind rules; raise ConfigError naming the entry."""
    if not figures(config):
        raise ConfigError("config has no figures: nothing to build")
    for f in figures(config):
        fig = config["figures"][f]
        kind = fig.get("kind")
        if kind not in FIGURE_KINDS:
            raise ConfigError(f"figures.{f}.kind: {kind!r} is not one of {', '.join(FIGURE_KINDS)}")
        names = scenes(config, f)
        if kind == "stability_map":  # its points may be invalid on purpose: the probes record that
            if not names and not fig.get("sweeps"):
                raise ConfigError(f"figures.{f}: a stability map needs sweeps (or scenes)")
            for p in fig.get("sweeps", {}):
                if p not in Scene.__dataclass_fields__:
                    raise ConfigError(f"figures.{f}.sweeps: {p!r} is not a Scene field")
            continue
        if not names:
            raise ConfigError(f"figures.{f}.scenes: a figure needs at least one scene")
        built = {s: build_scene(config, f, s) for s in names}
        if kind == "transmitted_force":
            _same_except(f, built, ("L", "pore_length"), "a transmitted-force figure varies only L")
            if len(names) < 2:
                raise ConfigError(f"figures.{f}.scenes: a transmitted-force curve needs at least 2 lengths")
        elif kind == "force_profile":
            p = fig.get("panel_parameter")
            if p is not None and p not in Scene.__dataclass_fields__:
                raise ConfigError(f"figures.{f}.panel_parameter: {p!r} is not a Scene field")
            varied = (p,) if p else ()
            _same_except(f, built, varied, f"the panels of a force-profile figure differ only in "
                                           f"panel_parameter ({p!r})")
            if p and len({getattr(s, p) for s in built.values()}) != len(built):
                raise ConfigError(f"figures.{f}.scenes: two panels have the same {p} value")
        elif kind == "convergence":
            p = fig.get("parameter")
            if "tolerance" not in fig:
                raise ConfigError(f"figures.{f}: a convergence figure needs a 'tolerance' (relative, e.g. 0.01)")
            if p not in REFINEMENT:
                raise ConfigError(f"figures.{f}.parameter: {p!r} is not one of {', '.join(REFINEMENT)}")
            _same_except(f, built, (p,), f"the rungs of a convergence ladder differ only in {p}")
            vals = sorted({getattr(s, p) for s in built.values()})
            if len(vals) < 3:
                raise ConfigError(f"figures.{f}.scenes: a convergence ladder needs at least 3 values of {p}")
            pub = publication_value(config, f)
            if not any(abs(v - pub) <= 1e-9 * abs(pub) for v in vals):
                raise ConfigError(f"figures.{f}.scenes: the ladder over {p} ({', '.join(f'{v:g}' for v in vals)}) "
                                  f"must contain the publication value {p} = {pub:g}")
        elif kind == "time_vs_error":
            ref = fig.get("reference")
            if ref not in built:
                raise ConfigError(f"figures.{f}.reference: {ref!r} is not one of its scenes ({', '.join(built)})")
            _same_except(f, built, ("solver", "l0", "dx_max", "dt_factor", "tol", "t_max"),
                         "the runs of a time-vs-error figure differ only in their numerics")


def _same_except(figure: str, built: dict[str, Scene], varied: tuple[str, ...], why: str) -> None:
    ref_name, ref = next(iter(built.items()))
    for name, sc in built.items():
        for key in Scene.__dataclass_fields__:
            if key in varied or key == "name":
                continue
            if getattr(sc, key) != getattr(ref, key):
                raise ConfigError(f"figures.{figure}.scenes.{name}: {key} = {getattr(sc, key)!r} differs from "
                                  f"{getattr(ref, key)!r} in scene {ref_name!r}; {why}")


def caption(config: dict[str, Any], figure: str) -> str:
    """Plain-text caption: what the figure shows and with which parameters."""
    fig = config["figures"][figure]
    head = f"{fig.get('title', figure)} (paper Fig. {fig.get('paper_figure', '?')})."
    if fig["kind"] == "stability_map":
        d = fig.get("defaults") or {}
        return (head + " How every point of a one-at-a-time sweep about "
                + ", ".join(f"{k} = {v}" for k, v in d.items())
                + " ended, for the solvers " + ", ".join(fig.get("solvers", [])) + ": equilibrium, time cap, "
                "escape, divergence (message in the dataset) or invalid input. Sweeps: "
                + "; ".join(f"{k}: {', '.join(f'{x:g}' for x in v)}" for k, v in fig.get("sweeps", {}).items())
                + ". Parameters: see the dataset.")
    built = [build_scene(config, figure, s) for s in scenes(config, figure)]
    sc = built[0]
    common = (f"R = {sc.R:g}, EI = {sc.EI:g}, load |F_z(0)| = {sc.load:g} EI/R^2, "
              f"friction cap {sc.friction_cap:g} EI/R^3, protocol '{sc.protocol}', seed {sc.seed}, "
              f"perturbation {sc.perturbation:g} R; numerics: l0 = {sc.l0:g} R, k_ph = {sc.k_ph:g} EI/R^2, "
              f"k_w = {sc.k_w:g} EI/R^3, solver '{sc.solver}', tol = {sc.tol:g}")
    if fig["kind"] == "convergence":
        p = fig["parameter"]
        vals = ", ".join(f"{getattr(s, p):g}" for s in built)
        body = (f" Convergence in {p} = {vals} (L/R = {sc.L:g}, k_fr = {sc.k_fr:g}): transmitted force, L_z and "
                f"bulk pitch against the refinement variable, with the Richardson limit from the three finest "
                f"rungs and the band of +-{100 * float(fig['tolerance']):g} % about it that the publication "
                f"value {p} = {publication_value(config, figure):g} must lie in.")
        common = common.replace(f"{p} = {getattr(sc, p):g}", f"{p} varied")
        return head + body + " Parameters: " + common + "."
    if fig["kind"] == "time_vs_error":
        body = (f" Wall time against the error of |F_z(L)|, L/R = {sc.L:g}, k_fr = {sc.k_fr:g}, both solvers "
                f"over ladders of their step knob and of l0; error against the reference run "
                f"'{fig['reference']}'.")
        return head + body + " Parameters: " + common + "."
    if fig["kind"] == "transmitted_force":
        Ls = ", ".join(f"{s.L:g}" for s in built)
        body = (f" Force |F_z(L)| transmitted to the lower piston against the rod length L/R = {Ls}, "
                f"k_fr = {sc.k_fr:g}; symbols: simulations (open = not converged), lines: the simple model "
                f"|F_z(L)| = (1/|F_z(0)| + k_fr R L/(4EI))^-1 (dashed, corrected) and the paper's form with "
                f"2EI (dotted); grey line: eye guide.")
    else:
        p = fig.get("panel_parameter")
        body = f" Axial force |F_z(s)| along the rod (s from the loaded end), L/R = {sc.L:g}"
        if p:
            body += ". Panels: " + "; ".join(f"({chr(97 + i)}) {p} = {getattr(s, p):g}"
                                             for i, s in enumerate(built)) + "."
        else:
            body += f", k_fr = {sc.k_fr:g}."
        body += (" Black: simulation; red: fit A (l0' + s)^c over the wall-contact stretch "
                 f"(trimmed by {fig.get('fit_trim', 0):g} R at each end; values and standard errors in the "
                 "legend and the dataset); blue dashed: simple model (1/|F_z(s_h)| + k_fr R (s - s_h)/(4EI))^-1 "
                 "from the first wall contact s_h; grey dotted: the same with the paper's 2EI.")
    return head + body + " Parameters: " + common + "."


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
