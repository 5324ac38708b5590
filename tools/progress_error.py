"""How well a build's progress lines told the time left: each line's estimate against the real
time left (the build's last line gives its end), from 10 % of the jobs on.

Usage: python tools/progress_error.py BUILD_LOG [--replay] [-o benchmarks/results/progress_error.json] [--note TEXT]

--replay: instead of the lines the build printed, replay the jobs' start and finish times that
Snakemake logged (with each job's est_s) through the current estimator (pipeline.progress), so a
change of the estimator is measured on a real build's timeline.
"""
from __future__ import annotations

import argparse
import datetime
import json
import re
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))
from confined_rod.pipeline.progress import BuildProgress, job_estimate  # noqa: E402

UNIT_S = {"s": 1.0, "min": 60.0, "h": 3600.0}
LINE = re.compile(r"progress: (\d+) of (\d+) jobs done \((\d+) %\), ([\d.]+) (s|min|h) elapsed, "
                  r"about ([\d.]+) (s|min|h) left")
LAST = re.compile(r"progress: (\d+) of (\d+) jobs done in ([\d.]+) (s|min|h)")


def read(log: str) -> dict:
    said, end = [], None
    for m in LINE.finditer(log):
        done, total = int(m[1]), int(m[2])
        said.append((done / total, float(m[4]) * UNIT_S[m[5]], float(m[6]) * UNIT_S[m[7]]))
    last = LAST.search(log)
    if last is None:
        raise SystemExit("progress_error: the log has no final progress line (the build did not finish)")
    end = float(last[3]) * UNIT_S[last[4]]
    rows = [{"done": round(f, 4), "elapsed_s": t, "said_left_s": left, "true_left_s": end - t,
             "ratio": left / (end - t) if end > t else None} for f, t, left in said]
    return _summary(rows, end)


def replay(log: str, cores: int = 2) -> dict:
    """The estimator's time left after each finished job of the build that wrote ``log``."""
    stamp, job, events = None, None, []
    for line in log.splitlines():
        text = line.strip()
        m = re.match(r"^\[(\w{3} \w{3} +\d+ [\d:]+ \d{4})\]$", text)
        if m:
            stamp = datetime.datetime.strptime(m[1], "%a %b %d %H:%M:%S %Y").timestamp()
            continue
        m = re.match(r"^(?:local)?rule (\w+):$", text)
        if m:
            job = {"rule": m[1], "t": stamp, "est": None, "id": None}
            continue
        m = re.search(r"Finished jobid: (\d+)", line)
        if m:
            events.append(("finish", int(m[1]), stamp, None, None))
        if job is not None:
            m = re.match(r"^jobid: (\d+)$", text)
            if m:
                job["id"] = int(m[1])
            m = re.search(r"est_s=(\d+)", text)
            if m:
                job["est"] = float(m[1])
            if job["id"] is not None and (text.startswith("resources") or not text):
                events.append(("start", job["id"], job["t"], job["rule"], job["est"]))
                job = None
    starts = {e[1]: e for e in events if e[0] == "start"}
    if not starts:
        raise SystemExit("progress_error: no job starts in the log (was it written with --printshellcmds?)")
    t0, end = min(e[2] for e in events), max(e[2] for e in events)
    p = BuildProgress(cores=cores, t0=t0)
    p.set_plan({j: (e[3], job_estimate(e[3], e[4])) for j, e in starts.items()})
    rows = []
    for kind, jobid, t, rule, est in events:
        if kind == "start":
            p.start(jobid, rule, est, now=t)
        elif jobid in p.running:
            p.finish(jobid, now=t)
            left = p.wall_left(t)
            rows.append({"done": round(p.done / p.total, 4), "elapsed_s": t - t0, "said_left_s": left,
                         "true_left_s": end - t, "ratio": left / (end - t) if end > t else None})
    return _summary(rows, end - t0)


def _summary(rows: list[dict], wall: float) -> dict:
    late = [r["ratio"] for r in rows if r["done"] >= 0.1 and r["ratio"] is not None and r["true_left_s"] >= 60]
    return {"wall_s": wall, "lines": len(rows),
            "from_10_percent": {"lines": len(late), "min_ratio": min(late, default=None),
                                "max_ratio": max(late, default=None),
                                "worst_factor": max((max(x, 1 / x) for x in late), default=None)},
            "rows": rows}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("log")
    ap.add_argument("-o", "--out")
    ap.add_argument("--note", default="")
    ap.add_argument("--replay", action="store_true", help="replay the logged jobs through the current estimator")
    a = ap.parse_args(argv)
    text = Path(a.log).read_text(errors="replace")
    out = (replay(text) if a.replay else read(text)) | {"note": a.note, "replayed": a.replay}
    summary = out["from_10_percent"]
    print(f"progress_error: {out['lines']} lines, build {out['wall_s']:.0f} s; from 10 % of the jobs on "
          f"(and >= 1 min left) the estimate was {summary['min_ratio']}-{summary['max_ratio']} x the real time left")
    if a.out:
        Path(a.out).write_text(json.dumps(out, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
