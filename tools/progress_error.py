"""How well a build's progress lines told the time left: each line's estimate against the real
time left (the build's last line gives its end), from 10 % of the jobs on.

Usage: python tools/progress_error.py BUILD_LOG [-o benchmarks/results/progress_error.json] [--note TEXT]
"""
from __future__ import annotations

import argparse
import json
import re
import sys
from pathlib import Path

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
    late = [r["ratio"] for r in rows if r["done"] >= 0.1 and r["ratio"] is not None and r["true_left_s"] >= 60]
    return {"wall_s": end, "lines": len(rows),
            "from_10_percent": {"lines": len(late), "min_ratio": min(late, default=None),
                                "max_ratio": max(late, default=None),
                                "worst_factor": max((max(x, 1 / x) for x in late), default=None)},
            "rows": rows}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("log")
    ap.add_argument("-o", "--out")
    ap.add_argument("--note", default="")
    a = ap.parse_args(argv)
    out = read(Path(a.log).read_text(errors="replace")) | {"note": a.note}
    summary = out["from_10_percent"]
    print(f"progress_error: {out['lines']} lines, build {out['wall_s']:.0f} s; from 10 % of the jobs on "
          f"(and >= 1 min left) the estimate was {summary['min_ratio']}-{summary['max_ratio']} x the real time left")
    if a.out:
        Path(a.out).write_text(json.dumps(out, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
