"""Check that swapped or corrupted evidence is rebuilt, never used, without Snakemake's metadata.

    python tools/check_integrity.py config/ci.yaml

Run after a complete build. In the built tree it copies one simulation file over another of
the same figure (the case that once put an L = 30 member into the L = 20 statistics), and cuts
a third one in half; it deletes Snakemake's metadata of both (as if .snakemake/ had been lost)
and asks for a dry run, which must plan exactly those two simulations again (and what reads
them), naming each file with what is wrong. It then restores the files, their mtimes and their
metadata, and checks that nothing is left to do. Exit status 1 if any expectation fails.
"""
from __future__ import annotations

import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))
SNAKEMAKE = str(Path(sys.executable).with_name("snakemake"))

from confined_rod import layout, pipeline  # noqa: E402


def dry_run(config: str, *targets: str) -> tuple[dict[str, int], str]:
    out = subprocess.run([SNAKEMAKE, "-n", *targets, "--quiet", "rules", "--configfile", config, "--cores", "1"],
                         cwd=ROOT, capture_output=True, text=True)
    if out.returncode != 0:
        raise SystemExit(f"snakemake dry run failed:\n{out.stdout}\n{out.stderr}")
    plan = {m.group(1): int(m.group(2)) for m in re.finditer(r"^(\w+)\s+(\d+)\s*$", out.stdout, re.M)
            if m.group(1) not in ("total", "all")}
    return plan, out.stdout + out.stderr


def main(argv=None) -> int:
    config_path = (argv or sys.argv[1:] or ["config/ci.yaml"])[0]
    config = pipeline.expand(yaml.safe_load((ROOT / config_path).read_text()))
    plan, _ = dry_run(config_path)
    if plan:
        raise SystemExit(f"the build is not complete (would run {plan}); run snakemake first")
    fig = next(f for f in pipeline.figures(config) if len(set(pipeline.figure_sims(config, f))) >= 3
               and pipeline.kinds.source(config["figures"][f]["kind"]) == "simulate")
    own = [p for p in dict.fromkeys(pipeline.figure_sims(config, fig)) if Path(p).parent.name == fig]
    source, target, cut = (ROOT / p for p in own[:3])
    failures = 0
    with tempfile.TemporaryDirectory() as tmp:
        saved = {p: Path(tmp) / f"{i}.nc" for i, p in enumerate((target, cut))}
        for p, keep in saved.items():
            shutil.copy2(p, keep)
        meta = [ROOT / ".snakemake" / "metadata" / _meta_name(p) for p in saved]
        meta_saved = {m: m.read_bytes() for m in meta if m.exists()}
        try:
            shutil.copy2(source, target)                        # same mtime as the source: not newer
            data = cut.read_bytes()
            cut.write_bytes(data[: len(data) // 2])
            for m in meta:
                m.unlink(missing_ok=True)
            plan, text = dry_run(config_path)
            rel = {p: str(p.relative_to(ROOT)) for p in (source, target, cut)}
            checks = {
                "exactly the two simulations are planned": plan.get("simulate", 0) == 2,
                "each alone: no batch runs again": plan.get("batch", 0) == 0,
                "the swapped file is named with the scene it holds":
                    f"{rel[target]} holds name = '{fig}/{source.stem}'" in text,
                "the cut file is named as unreadable": f"{rel[cut]}: cannot be read" in text,
                "what reads them is rebuilt": plan.get("postprocess", 0) >= 1,
            }
            for what, ok in checks.items():
                failures += not ok
                print(f"{'ok  ' if ok else 'FAIL'} {what}")
            if failures:
                print(text[-3000:])
        finally:
            for p, keep in saved.items():
                shutil.copy2(keep, p)
            for m, b in meta_saved.items():
                m.write_bytes(b)
    plan, text = dry_run(config_path)
    ok = not plan
    failures += not ok
    print(f"{'ok  ' if ok else 'FAIL'} restored: nothing left to do" + ("" if ok else f" (would run {plan})"))
    failures += deleted_member(config, config_path)
    return 1 if failures else 0


def deleted_member(config: dict, config_path: str) -> int:
    """A deleted member of a batch, asked for, is run again alone (the batch's other members are
    kept). (The default target asks for the datasets, the products: a simulation file deleted
    under an up-to-date dataset is not rebuilt unless asked for, as before batches.)"""
    fig, members = next((f, m) for f in pipeline.figures(config) for m in pipeline.batches(config, f).values()
                        if pipeline.run_kind(config, f) == "simulate")
    member = ROOT / layout.sim_path(fig, members[-1])
    with tempfile.TemporaryDirectory() as tmp:
        keep = Path(tmp) / "member.nc"
        shutil.move(member, keep)
        try:
            plan, text = dry_run(config_path, str(member.relative_to(ROOT)))
        finally:
            shutil.move(keep, member)
    ok = plan.get("simulate", 0) == 1 and plan.get("batch", 0) == 0
    print(f"{'ok  ' if ok else 'FAIL'} a deleted batch member ({fig}/{members[-1]}) runs again alone: {plan}")
    return int(not ok)


def _meta_name(path: Path) -> str:
    """Snakemake's metadata file of an output: the path relative to the workdir, base64 (urlsafe)."""
    import base64

    return base64.urlsafe_b64encode(str(path.relative_to(ROOT)).encode()).decode()


if __name__ == "__main__":
    sys.exit(main())
