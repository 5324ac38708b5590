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
    parser = argparse.ArgumentParser(prog="python -m confined_rod",
                                     description="Confined elastic rod simulations")
    sub = parser.add_subparsers(dest="command", required=True)
    p_run = sub.add_parser("run", help="run one scene (YAML mapping of Scene fields) and write a netCDF dataset")
    p_run.add_argument("scene", type=Path, help="scene YAML file")
    p_run.add_argument("-o", "--output", type=Path, required=True, help="output netCDF file")
    p_run.add_argument("-q", "--quiet", action="store_true", help="no progress messages")
    p_run.add_argument("--budget", type=float, default=None, metavar="SECONDS",
                       help="refuse a scene whose estimated wall time exceeds this (default 3600 s; "
                            "the estimate comes from measured runs: confined_rod.limits.estimated_wall_time)")
    p_check = sub.add_parser("check-config", help="check a pipeline config as the workflow does at start-up "
                                                  "(strict YAML with line numbers, schema, every scene), without "
                                                  "Snakemake; exit 2 with a one-line message if it is invalid")
    p_check.add_argument("config", type=Path, nargs="?", default=Path("config/config.yaml"))
    p_show = sub.add_parser("show-defaults", help="print every scene field with its resolved default")
    p_show.add_argument("--R", type=float, default=1.0)
    p_show.add_argument("--EI", type=float, default=1.0)
    p_schema = sub.add_parser("schema", help="print (or write, or check) the pipeline config's JSON schema, "
                                             "generated from the scene parameters and the figure kinds")
    p_schema.add_argument("-o", "--output", type=Path, help="write it to this file")
    p_schema.add_argument("--check", type=Path, metavar="FILE", help="exit 1 if FILE differs from it")
    args = parser.parse_args(argv)

    if args.command == "schema":
        from .pipeline.schema import render

        text = render()
        if args.check:
            if not args.check.is_file() or args.check.read_text() != text:
                print(f"error: {args.check} is not the generated schema; regenerate it with "
                      f"python -m confined_rod schema -o {args.check}", file=sys.stderr)
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
        import yaml

        try:
            defaults = Scene(R=args.R, EI=args.EI).to_dict()
        except SceneError as exc:
            print(f"error: {str(exc).replace('scene ' + repr('scene') + ': ', '')} (--{_flag(exc)})", file=sys.stderr)
            return 2
        print(yaml.safe_dump(defaults, sort_keys=False), end="")
        return 0
    return run(args)


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
        scene = Scene.from_yaml(args.scene)
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
        summary = (f"{scene.name}: {status.replace('_', ' ')} ({ds.attrs['status_reason']}); "
                   f"F_transmitted = {float(ds.F_transmitted):.6g} (axial force on the lower support; negative: "
                   f"a pull), L_z = {float(ds.L_z):.6g}, {int(ds.n_steps)} steps, {float(ds.wall_time):.1f} s")
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
