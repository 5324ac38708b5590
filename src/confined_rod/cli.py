"""Command line: ``python -m confined_rod run SCENE.yaml -o OUT.nc``.

Exit status: 0 on success, 2 for invalid input (nothing is computed or written),
3 if the run diverged (nothing is written).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .errors import DivergenceError, SceneError


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m confined_rod",
                                     description="Confined elastic rod simulations")
    sub = parser.add_subparsers(dest="command", required=True)
    p_run = sub.add_parser("run", help="run one scene (YAML mapping of Scene fields) and write a netCDF dataset")
    p_run.add_argument("scene", type=Path, help="scene YAML file")
    p_run.add_argument("-o", "--output", type=Path, required=True, help="output netCDF file")
    p_run.add_argument("-q", "--quiet", action="store_true", help="no progress messages")
    p_show = sub.add_parser("show-defaults", help="print every scene field with its resolved default")
    p_show.add_argument("--R", type=float, default=1.0)
    p_show.add_argument("--EI", type=float, default=1.0)
    p_schema = sub.add_parser("schema", help="print (or write, or check) the pipeline config's JSON schema, "
                                             "generated from the scene parameters and the figure kinds")
    p_schema.add_argument("-o", "--output", type=Path, help="write it to this file")
    p_schema.add_argument("--check", type=Path, metavar="FILE", help="exit 1 if FILE differs from it")
    args = parser.parse_args(argv)

    if args.command == "schema":
        from .config_schema import render

        text = render()
        if args.check:
            if not args.check.is_file() or args.check.read_text() != text:
                print(f"error: {args.check} is not the generated schema; regenerate it with "
                      f"python -m confined_rod schema -o {args.check}", file=sys.stderr)
                return 1
            return 0
        if args.output:
            from .io import write_text

            write_text(text, args.output)
        else:
            print(text, end="")
        return 0

    from .scenes import Scene

    if args.command == "show-defaults":
        import yaml

        print(yaml.safe_dump(Scene(R=args.R, EI=args.EI).to_dict(), sort_keys=False), end="")
        return 0
    try:
        if args.output.suffix != ".nc":
            raise SceneError(f"output file {str(args.output)!r} must end in .nc")
        scene = Scene.from_yaml(args.scene)
    except SceneError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2

    from .io import write_dataset
    from .simulation import simulate

    try:
        ds = simulate(scene, progress=not args.quiet)
    except DivergenceError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 3
    write_dataset(ds, args.output)
    status = "converged" if int(ds.converged) else ("escaped" if int(ds.escaped) else "NOT converged (time cap)")
    print(f"{scene.name}: {status}; |F_z(L)| = {float(ds.F_transmitted):.6g}, L_z = {float(ds.L_z):.6g}, "
          f"{int(ds.n_steps)} steps, {float(ds.wall_time):.1f} s -> {args.output}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
