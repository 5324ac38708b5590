"""How well a build's progress lines told the time left: each line's estimate against the real
time left (the build's last line gives its end), from 10 % of the jobs on.

Usage: python tools/progress_error.py BUILD_LOG [--replay [--reestimate CONFIG]] [-o OUT.json] [--note TEXT]

--replay: instead of the lines the build printed, replay the jobs' start and finish times that
Snakemake logged (with each job's est_s) through the current estimator (pipeline.progress), so a
change of the estimator is measured on a real build's timeline.
--reestimate CONFIG (with --replay): each job's estimate from the current cost model
(limits.estimated_solver_time) for the scenes its wildcards name in CONFIG, as the rules' est_s
would give it now, instead of the logged est_s: a change of the cost model measured on the same
timeline (the jobs keep their logged order and times; a build with the new estimates would
schedule them a little differently).
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


def reestimator(config_path: str):
    """est(rule, wildcards, logged est_s): a job's estimate from the current cost model, as the
    rules' est_s gives it (workflow/rules/common.smk: a scene's job its solver estimate and the
    start-up, 0 for one moved into place from its batch; a batch its members' sum and one start-up,
    the members named by the batch, first-to-last in the figure's order; a load path one start-up
    and ten runs' solver estimates;
    rule views its simulations, workflow/rules/views.smk)."""
    from confined_rod import pipeline
    from confined_rod.pipeline import progress

    config = pipeline.check(pipeline.read_config(config_path))  # expanded, as the rules see it

    def est(rule: str, wc: dict[str, str], logged: float | None) -> float | None:
        if rule in ("simulate", "probe") and "scene" in wc:
            return 0.0 if logged == 0 else pipeline.job_estimate_s(config, wc["figure"], wc["scene"])
        if rule == "batch" and "batch" in wc:
            names = pipeline.scenes(config, wc["figure"])
            first, _, last = wc["batch"].partition("-to-")
            members = names[names.index(first): names.index(last or first) + 1]
            return pipeline.batch_estimate_s(config, wc["figure"], members)
        if rule == "load_path" and "scene" in wc:
            return pipeline.job_estimate_s(config, wc["figure"], wc["scene"], runs=10)
        if rule == "views":
            return progress.views_estimate(len(pipeline.view_sims(config)))
        return logged

    return est


def replay(log: str, cores: int = 2, reestimate=None) -> dict:
    """The estimator's time left after each finished job of the build that wrote ``log`` (each
    job's estimate from ``reestimate(rule, wildcards, logged est_s)`` if given)."""
    stamp, job, events = None, None, []
    for line in log.splitlines():
        text = line.strip()
        m = re.match(r"^\[(\w{3} \w{3} +\d+ [\d:]+ \d{4})\]$", text)
        if m:
            stamp = datetime.datetime.strptime(m[1], "%a %b %d %H:%M:%S %Y").timestamp()
            continue
        m = re.match(r"^(?:local)?rule (\w+):$", text)
        if m:
            job = {"rule": m[1], "t": stamp, "est": None, "id": None, "wc": {}}
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
            if text.startswith("wildcards:"):
                job["wc"] = dict(kv.split("=", 1) for kv in text[len("wildcards:"):].replace(" ", "").split(","))
            if job["id"] is not None and (text.startswith("resources") or not text):
                est = job["est"] if reestimate is None else reestimate(job["rule"], job["wc"], job["est"])
                events.append(("start", job["id"], job["t"], job["rule"], est))
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
    ap.add_argument("--reestimate", metavar="CONFIG", help="with --replay: the jobs' estimates from the current "
                    "cost model for this config instead of the logged est_s")
    a = ap.parse_args(argv)
    if a.reestimate and not a.replay:
        raise SystemExit("progress_error: --reestimate needs --replay")
    text = Path(a.log).read_text(errors="replace")
    out = (replay(text, reestimate=reestimator(a.reestimate) if a.reestimate else None) if a.replay
           else read(text)) | {"note": a.note, "replayed": a.replay, "reestimated": a.reestimate or ""}
    summary = out["from_10_percent"]
    print(f"progress_error: {out['lines']} lines, build {out['wall_s']:.0f} s; from 10 % of the jobs on "
          f"(and >= 1 min left) the estimate was {summary['min_ratio']}-{summary['max_ratio']} x the real time left")
    if a.out:
        Path(a.out).write_text(json.dumps(out, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
