"""Command line: ``python -m confined_rod run SCENE.yaml -o OUT.nc``.

Exit status of ``run``:
  0  equilibrium reached (or the rod escaped from the pore: a physical outcome);
  2  invalid input: a bad scene, an output that cannot be written, a run above the
     time budget, or the snapshot memory cap (nothing is computed, or nothing written);
  3  the run diverged (nothing is written);
  4  the run ended without equilibrium: time cap or step budget (max_steps) reached, or a final state that
     violates the model; the dataset is written with ``status`` and its reason;
  130 interrupted (nothing is written).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .errors import DivergenceError, OutputPathError, ResourceLimitError, SceneError


def main(argv: list[str] | None = None) -> int:
    prog = "confined-rod" if Path(sys.argv[0]).name == "confined-rod" else "python -m confined_rod"
    parser = argparse.ArgumentParser(prog=prog,
                                     description="Confined elastic rod simulations")
    parser.add_argument("--version", action="version", version=f"%(prog)s {_version()}")
    sub = parser.add_subparsers(dest="command", required=True)
    p_run = sub.add_parser("run", help="run one scene (YAML mapping of Scene fields) and write a netCDF dataset")
    p_run.add_argument("scene", type=Path, nargs="?", help="scene YAML file (default: every key at its default, "
                                                           "changed by --set)")
    p_run.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                       help="set one scene key, repeatable (--set L=40 --set k_fr=0.3); the value is read as YAML "
                            "and validated like a scene file")
    p_run.add_argument("-o", "--output", type=Path, required=True, help="output netCDF file")
    p_run.add_argument("-q", "--quiet", action="store_true",
                       help="no progress messages (the one-line summary at the end stays)")
    p_run.add_argument("--budget", type=float, default=None, metavar="SECONDS",
                       help="refuse a scene whose estimated wall time exceeds this (default 3600 s; "
                            "the estimate comes from measured runs: confined_rod.limits.estimated_wall_time)")
    p_check = sub.add_parser("check-config", help="check a pipeline config as the workflow does at start-up "
                                                  "(strict YAML with line numbers, schema, every scene), without "
                                                  "Snakemake; exit 2 with a one-line message if it is invalid")
    p_check.add_argument("config", type=Path, nargs="?", default=Path("config/config.yaml"))
    p_show = sub.add_parser("show-defaults", help="print a scene file with every key, its unit and description "
                                                  "(YAML comments); defaults that follow other keys are null")
    p_show.add_argument("--R", type=float, default=1.0)
    p_show.add_argument("--EI", type=float, default=1.0)
    p_schema = sub.add_parser("schema", help="print (or write, or check) the pipeline config's JSON schema, "
                                             "generated from the scene parameters and the figure kinds")
    p_schema.add_argument("-o", "--output", type=Path, help="write it to this file")
    p_schema.add_argument("--check", type=Path, metavar="FILE", help="exit 1 if FILE differs from it")
    p_docs = sub.add_parser("config-docs", help="print (or write, or check) config/README.md: every config file "
                                                "and every config key, generated from the config schema")
    p_docs.add_argument("-o", "--output", type=Path, help="write it to this file (config/README.md)")
    p_docs.add_argument("--check", type=Path, metavar="FILE", help="exit 1 if FILE differs from it")
    p_view = sub.add_parser("view", help="write a rod you can turn in a browser: one self-contained HTML page "
                                         "(plotly; pip install 'confined_rod[view]') of scene datasets")
    p_view.add_argument("dataset", type=Path, nargs="+", help="scene dataset(s): a simulation of a figure, or a "
                                                              "load path (several: one page with a selector)")
    p_view.add_argument("-o", "--output", type=Path, required=True, help="output HTML file")
    p_view.add_argument("--color", default="F_z", metavar="VAR",
                        help="colour the rod by F_z (|F_z|, the default), wall_force, stuck or friction_angle")
    args = parser.parse_args(argv)

    if args.command == "view":                  # reads datasets only: never imports the simulator
        from .analysis.view import main as view

        return view(args.dataset, args.output, args.color)

    if args.command in ("schema", "config-docs"):
        if args.command == "schema":
            from .pipeline.schema import render

            text, what = render(), "the generated schema"
        else:
            from .pipeline.config_docs import render as render_docs
            from .sim.scenes import Scene

            text, what = render_docs(Scene), "the generated config documentation"
        if args.check:
            if not args.check.is_file() or args.check.read_text(encoding="utf-8") != text:
                print(f"error: {args.check} is not {what}; regenerate it with "
                      f"python -m confined_rod {args.command} -o {args.check}", file=sys.stderr)
                return 1
            return 0
        if args.output:
            from .io import check_output_path, write_text

            try:
                check_output_path(args.output)          # a directory or a read-only place: one line, nothing written
                write_text(text, args.output)
            except (OutputPathError, OSError) as exc:
                print(f"error: {exc if isinstance(exc, OutputPathError) else _os_error(args.output, exc)}",
                      file=sys.stderr)
                return 2
        else:
            print(text, end="")
        return 0

    if args.command == "check-config":
        return check_config(args.config)

    from .sim.scenes import Scene

    if args.command == "show-defaults":
        try:
            scene = Scene(R=args.R, EI=args.EI)
        except SceneError as exc:
            print(f"error: {str(exc).replace('scene ' + repr('scene') + ': ', '')} (--{_flag(exc)})", file=sys.stderr)
            return 2
        print(f"# A scene file of confined_rod {_version()}: python -m confined_rod run THIS.yaml -o out.nc\n"
              "# Units in [..] are reduced (R = EI = beta_ph = 1 unless R, EI are given): multiples of the scene's\n"
              "# R and EI; with unit_system: SI they are SI (R in m, EI in J m, forces in N, times in s).\n"
              "# null: a default that follows other keys (its value for this R, EI and L in the comment).")
        print(scene.template(), end="")
        return 0
    return run(args)


def _version() -> str:
    from ._version import __version__

    return __version__


def _overrides(pairs: list[str]) -> dict:
    """``--set key=value`` pairs as a mapping (values read as YAML); SceneError names a bad one."""
    import yaml

    from .io import _yaml_loader
    from .sim.scenes import Scene

    out = {}
    for pair in pairs:
        key, eq, text = pair.partition("=")
        key = key.strip()
        if not eq or not key:
            raise SceneError(f"--set {pair!r}: expected KEY=VALUE, e.g. --set L=40")
        if key not in Scene.field_names():
            raise SceneError(f"--set {pair!r}: unknown key {key!r}; known keys: {', '.join(Scene.field_names())}")
        try:        # the scene files' reader: 1e-8 is a number (YAML 1.2), no aliases
            out[key] = yaml.load(text, Loader=_yaml_loader(SceneError, f"--set {pair!r}", False)) if text.strip() \
                else None
        except yaml.YAMLError:
            raise SceneError(f"--set {pair!r}: the value of {key!r} is not valid YAML") from None
    return out


def _kernels_cached() -> bool:
    """Whether numba's cache holds the implicit solver's compiled kernels (index files *.nbi,
    in NUMBA_CACHE_DIR or in __pycache__ beside the sources)."""
    import os

    place = Path(os.environ.get("NUMBA_CACHE_DIR") or Path(__file__).resolve().parent / "sim")
    return place.is_dir() and next(place.rglob("implicit_kernels.*.nbi"), None) is not None


def _flag(exc: SceneError) -> str:
    return "EI" if "'EI'" in str(exc) else "R"


def _os_error(path: Path, exc: OSError) -> str:
    return f"cannot write {str(path)!r} ({exc.strerror or type(exc).__name__})"


def check_config(path: Path) -> int:
    from . import pipeline

    try:
        config = pipeline.check(pipeline.read_config(path))
    except pipeline.ConfigError as exc:
        print(f"error: invalid config: {exc}", file=sys.stderr)
        return 2
    out = pipeline.expected_outputs(config)
    print(f"{path}: valid; {len(pipeline.figures(config))} figures, {len(out['sims'])} simulation/probe jobs, "
          f"{len(out['checks'])} convergence checks")
    return 0


def run(args: argparse.Namespace) -> int:
    from . import limits
    from .io import check_output_path
    from .sim.scenes import Scene

    def refuse(msg: str) -> int:
        print(f"error: {msg}", file=sys.stderr)
        return 2

    budget = limits.DEFAULT_BUDGET_S if args.budget is None else args.budget
    if not budget > 0:
        return refuse(f"invalid value for '--budget': {args.budget!r} (must be > 0 seconds)")
    try:
        check_output_path(args.output, suffix=".nc")
        overrides = _overrides(args.overrides)
        scene = (Scene.from_yaml(args.scene, overrides) if args.scene is not None
                 else Scene.from_dict({"name": "scene", **overrides}))
    except (SceneError, OutputPathError) as exc:
        return refuse(str(exc))
    cost = limits.estimated_wall_time(scene)
    if cost > budget:
        return refuse(f"scene {scene.name!r}: estimated wall time {cost:.3g} s ({scene.N} links, {scene.solver} "
                      f"solver) exceeds the budget of {budget:g} s; pass --budget {10 ** len(str(int(cost)))} "
                      "to run it anyway")

    # SIGTERM (a scheduler's or kill's) ends the run as Ctrl-C does: nothing written, exit 130
    import signal

    from .io import write_dataset
    from .sim.simulation import simulate

    def terminated(signum, frame):
        raise KeyboardInterrupt

    if not args.quiet:
        if not _kernels_cached():
            print("compiling the numba kernels (first run only, about 20 s; cached for later runs)",
                  file=sys.stderr, flush=True)
        if cost > 10.0:
            print(f"{scene.name}: {scene.N} links, estimated wall time ~{cost:.0f} s "
                  "(progress follows every few seconds)", file=sys.stderr, flush=True)

    previous = signal.signal(signal.SIGTERM, terminated)
    try:
        try:
            ds = simulate(scene, progress=not args.quiet)
        except DivergenceError as exc:
            print(f"error: {exc}", file=sys.stderr)
            return 3
        except ResourceLimitError as exc:
            return refuse(str(exc))
        status = ds.attrs["status"]
        force, length = ("N", "m") if scene.unit_system == "SI" else ("EI/R^2", "R")
        summary = (f"{scene.name}: {status.replace('_', ' ')} ({ds.attrs['status_reason']}); "
                   f"F_transmitted = {float(ds.F_transmitted):.6g} {force} (axial force on the lower support; "
                   f"negative: a pull), L_z = {float(ds.L_z):.6g} {length}, {int(ds.n_steps)} steps, "
                   f"{float(ds.wall_time):.1f} s wall time")
        try:
            write_dataset(ds, args.output)
        except OSError as exc:                  # a full disk, a folder removed meanwhile: the result is lost
            return refuse(f"{_os_error(args.output, exc)}; nothing written. The run gave: {summary}")
    except KeyboardInterrupt:
        print(f"interrupted: nothing written to {args.output}", file=sys.stderr)
        return 130
    finally:
        signal.signal(signal.SIGTERM, previous)
    print(f"{summary} -> {args.output}", file=sys.stderr)
    return 0 if status in ("converged", "escaped") else 4


if __name__ == "__main__":
    sys.exit(main())
