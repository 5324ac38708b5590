"""Kill a build at a random job, resume it as the README says, compare with an uninterrupted build.

    python tools/kill_resume.py config/ci.yaml [--seed N] [--figure NAME ...]

Run after a complete, uninterrupted build of the same config in this checkout
(results/ is the reference).  In a copy of the checkout's tracked files (a fresh
results/), it starts ``snakemake --cores 2 --configfile CONFIG``, waits until a
random number of jobs has finished (one benchmark file each), kills the whole
build with SIGKILL, then recovers as the README says:

    snakemake --unlock --configfile CONFIG     # only if the rerun reports a stale lock
    snakemake --cores 2 --configfile CONFIG    # the profile sets --rerun-incomplete

Both builds stop at the datasets and the convergence checks (their files, found in the
reference, are the targets): the figures, the views, the claims and the manuscript are pure
functions of those, and leaving them out halves the test.  It compares every dataset (results/sims, probes,
paths, datasets) and every check verdict with the reference: all data variables bitwise equal except run times
(variables named wall_time), all attributes equal except run times (names
containing wall_time), ``history`` (a timestamp) and the git commits (``git_commit``,
``scene_git_commits``, ``boundary_git_commit``: the copy is not a git checkout).  No temporary
file may be left.  Writes a JSON summary to stdout; exit status 1 on any difference.
"""
from __future__ import annotations

import argparse
import json
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from compare_builds import compare_dataset, layout  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SNAKEMAKE = str(Path(sys.executable).with_name("snakemake"))


def tracked_copy(dest: Path) -> None:
    files = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True).stdout
    for rel in files.decode().split("\0"):
        if rel and (ROOT / rel).is_file():
            (dest / rel).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(ROOT / rel, dest / rel)


#: the rules the interrupted build runs (its targets are the datasets and checks of the reference)
RULES = ("batch", "simulate", "probe", "load_path", "postprocess", "convergence_check")
TARGETS: list[str] = []


FIGURES: list[str] = []        # --figure: only these figures' jobs (all if empty)


def ours(path: Path) -> bool:
    """A file of the figures under test: its folder, or its own name, is the figure's."""
    return not FIGURES or any(f in path.parts or path.stem == f for f in FIGURES)


def finished_jobs(results: Path) -> int:
    bench = layout.under(results, layout.BENCHMARKS)
    return sum(1 for r in RULES for p in (bench / r).rglob("*.tsv") if ours(p)) if bench.exists() else 0


def snakemake(work: Path, config: str, *extra: str) -> subprocess.CompletedProcess:
    return subprocess.run([SNAKEMAKE, *TARGETS, "--cores", "2", *extra, "--configfile", config],
                          cwd=work, capture_output=True, text=True)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("config", nargs="?", default="config/ci.yaml")
    ap.add_argument("--seed", type=int, default=None, help="random seed of the kill point (default: random)")
    ap.add_argument("--figure", action="append", default=[],
                    help="only this figure's jobs (repeatable; default: every figure of the config)")
    args = ap.parse_args(argv)
    FIGURES[:] = args.figure
    reference = ROOT / layout.RESULTS
    seed = args.seed if args.seed is not None else random.SystemRandom().randrange(2**31)
    rng = random.Random(seed)
    summary: dict = {"config": args.config, "seed": seed}
    with tempfile.TemporaryDirectory(prefix="kill_resume_") as tmp:
        work = Path(tmp)
        tracked_copy(work)
        planned = finished_jobs(reference)
        TARGETS[:] = [str(p.relative_to(reference.parent)) for p in
                      sorted(layout.under(reference, layout.DATASETS).glob("*.nc"))
                      + sorted(layout.under(reference, layout.CHECKS).glob("*.txt")) if ours(p)]
        summary["figures"] = FIGURES or "all"
        kill_after = rng.randrange(1, max(2, planned - 2))
        summary["jobs_in_build"], summary["kill_after_jobs"] = planned, kill_after
        t0 = time.perf_counter()
        proc = subprocess.Popen([SNAKEMAKE, *TARGETS, "--cores", "2", "--configfile", args.config], cwd=work,
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
        while proc.poll() is None and finished_jobs(work / layout.RESULTS) < kill_after:
            time.sleep(0.05)
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
        summary["killed_after_s"] = round(time.perf_counter() - t0, 1)
        summary["jobs_done_when_killed"] = finished_jobs(work / layout.RESULTS)
        rerun = snakemake(work, args.config)
        summary["rerun_without_unlock"] = "ok" if rerun.returncode == 0 else (
            "LockException" if "LockException" in rerun.stdout + rerun.stderr else "failed")
        if rerun.returncode != 0:
            unlock = snakemake(work, args.config, "--unlock")
            rerun = snakemake(work, args.config)
            if unlock.returncode != 0 or rerun.returncode != 0:
                print(rerun.stdout[-3000:], rerun.stderr[-3000:], file=sys.stderr)
                summary["result"] = "resume failed"
                print(json.dumps(summary, indent=1))
                return 1
        summary["resume_s"] = round(time.perf_counter() - t0 - summary["killed_after_s"], 1)
        diffs: dict[str, list[str]] = {}
        compared = 0
        for folder in (*layout.SCENE_FOLDERS, layout.DATASETS):
            for ref in sorted(layout.under(reference, folder).rglob("*.nc")):
                if not ours(ref):
                    continue
                rel = ref.relative_to(reference)
                mine = work / layout.RESULTS / rel
                compared += 1
                d = ["missing after the resumed build"] if not mine.exists() else compare_dataset(ref, mine)
                if d:
                    diffs[str(rel)] = d
        for ref in sorted(layout.under(reference, layout.CHECKS).glob("*.txt")):
            if not ours(ref):
                continue
            rel = ref.relative_to(reference)
            mine = work / layout.RESULTS / rel
            compared += 1
            if not mine.exists() or mine.read_text() != ref.read_text():
                diffs[str(rel)] = ["check verdict differs"]
        leftovers = sorted(str(p.relative_to(work)) for p in (work / layout.RESULTS).rglob("*.tmp"))
        summary.update({"files_compared": compared, "differences": diffs, "leftover_temporaries": leftovers})
        ok = compared > 0 and not diffs and not leftovers
        summary["result"] = "identical" if ok else "DIFFERENT"
    print(json.dumps(summary, indent=1))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
