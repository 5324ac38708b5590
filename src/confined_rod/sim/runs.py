"""Run scenes and write one dataset per scene: the jobs of the workflow's run rules.

A job pays a start-up beyond its solver (interpreter, imports, loading numba's cache: about
1.5-2 s), as long as a small scene's solve. So the small scenes of a figure run as a *batch* in
one process (``run_batch``: the members of a seed ensemble together, pipeline.batches decides),
each member written to its own dataset; a scene alone, or a batch member whose dataset was lost,
runs by itself (``run_one``). Either way each scene's dataset is exactly what a run of that scene
alone writes (the solvers keep no state between runs; tested bitwise).

Kinds of run: ``simulate`` (a scene relaxed to equilibrium; a final state outside the model
fails the job and writes nothing) and ``probe`` (a stability-map point: how it ended, never an
error).
"""
from __future__ import annotations

import json
import sys
import time
from pathlib import Path
from typing import Any, Mapping, Sequence

from ..io import finalize, write_dataset, write_text


def run_simulation(params: Mapping[str, Any], output: str | Path) -> str:
    """Relax one scene and write its dataset; returns the log line of the run."""
    from .scenes import Scene
    from .simulation import simulate

    scene = Scene.from_dict(dict(params))
    ds = simulate(scene, progress=True)
    if ds.attrs["status"] == "model_violated":  # not a result: fail, write nothing
        raise RuntimeError(f"scene {scene.name!r}: the final state violates the model: {ds.attrs['status_reason']}")
    write_dataset(ds, output)
    return (f"{scene.name}: {ds.attrs['status']} ({ds.attrs['status_reason']}) "
            f"F_transmitted={float(ds.F_transmitted):.6g} L_z={float(ds.L_z):.6g} t={float(ds.t_final):.6g} "
            f"steps={int(ds.n_steps)} wall={float(ds.wall_time):.1f} s")


def run_probe(params: Mapping[str, Any], output: str | Path) -> str:
    """Run one stability-map point and write how it ended; returns the log line."""
    from .probe import probe

    params = dict(params)
    ds = probe(params)
    write_dataset(finalize(ds, f"stability probe {params['name']}", {k: str(v) for k, v in params.items()}), output)
    return f"{params['name']}: {ds.attrs['status_name']}: {ds.attrs['message']}"


_RUN = {"simulate": run_simulation, "probe": run_probe}
KINDS = tuple(_RUN)


def _check_kind(kind: str) -> None:
    if kind not in _RUN:
        raise ValueError(f"kind = {kind!r}: expected one of {', '.join(KINDS)}")


def run_one(kind: str, params: Mapping[str, Any], output: str | Path) -> str:
    """One scene of ``kind`` in this process, its dataset written atomically to ``output``."""
    _check_kind(kind)
    line = _RUN[kind](params, output)
    print(line, flush=True)
    return line


def run_batch(kind: str, members: Sequence[Mapping[str, Any]], outputs: Sequence[str | Path],
              manifest: str | Path) -> dict[str, Any]:
    """Run the members of a batch one after the other in this process, each written atomically
    to its own file, then write the manifest (JSON: per member its output, log line and the
    job's wall time). A member that fails does not stop the others; the batch then raises,
    naming every failed member, and writes no manifest."""
    _check_kind(kind)
    if len(members) != len(outputs):
        raise ValueError(f"members: {len(members)} scenes for {len(outputs)} outputs")
    done: list[dict[str, Any]] = []
    failed: list[str] = []
    for params, out in zip(members, outputs):
        name = params.get("name", "?")
        t0 = time.perf_counter()
        print(f"--- {name} -> {out}", flush=True)
        try:
            line = run_one(kind, params, out)
        except Exception as e:  # reported below, with the others
            import traceback

            traceback.print_exc()
            failed.append(f"{name}: {type(e).__name__}: {e}")
            continue
        done.append({"scene": name, "output": str(out), "log": line, "job_s": time.perf_counter() - t0})
    if failed:
        raise RuntimeError(f"{len(failed)} of {len(members)} members of the batch failed: " + "; ".join(failed))
    record = {"kind": kind, "members": done}
    write_text(json.dumps(record, indent=1) + "\n", manifest)
    return record


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m confined_rod.sim.runs KIND OUTPUT PARAMS_JSON``: one scene in this process (the
    workflow's fallback for a batch member whose dataset is not in the batch's cache)."""
    args = list(sys.argv[1:] if argv is None else argv)
    if len(args) != 3:
        print("usage: python -m confined_rod.sim.runs {simulate|probe} OUTPUT PARAMS_JSON", file=sys.stderr)
        return 2
    kind, output, text = args
    run_one(kind, json.loads(text), output)
    return 0


if __name__ == "__main__":
    sys.exit(main())
