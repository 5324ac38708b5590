"""Compare the verdicts of two builds, claim by claim (for a change of the solver or the numerics:
are the verdicts the same, and where a value moved, by how much?).

    python tools/compare_claims.py OLD/results/claims.csv NEW/results/claims.csv [-o out.json]

Prints every claim whose verdict differs, every claim whose number (``ours``, its first number)
moved by more than --rel (default 1 %), the claims only one build has, and the verdict counts of
both; writes the same as JSON with -o. Exit status 0 whatever it finds: what a difference means
(a change of final state, an analysis choice a verdict hangs on) is for the reader to say.
"""
from __future__ import annotations

import argparse
import csv
import json
import re
from collections import Counter
from pathlib import Path

NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


def read(path: Path) -> dict[str, dict]:
    with path.open(newline="") as fh:
        return {row["id"]: row for row in csv.DictReader(fh)}


def first_number(text: str) -> float | None:
    m = NUMBER.search(text or "")
    return float(m.group()) if m else None


def compare(old: dict[str, dict], new: dict[str, dict], rel: float) -> dict:
    both = [k for k in old if k in new]
    changed = [{"id": k, "old": old[k]["verdict"], "new": new[k]["verdict"], "ours_old": old[k]["ours"],
                "ours_new": new[k]["ours"]} for k in both if old[k]["verdict"] != new[k]["verdict"]]
    moved = []
    for k in both:
        a, b = first_number(old[k]["ours"]), first_number(new[k]["ours"])
        if a is not None and b is not None and abs(b - a) > rel * max(abs(a), abs(b), 1e-300):
            moved.append({"id": k, "verdict_old": old[k]["verdict"], "verdict_new": new[k]["verdict"],
                          "old": a, "new": b, "rel_change": (b - a) / abs(a) if a else None})
    return {"claims_old": len(old), "claims_new": len(new),
            "only_old": sorted(set(old) - set(new)), "only_new": sorted(set(new) - set(old)),
            "verdicts_old": dict(Counter(r["verdict"] for r in old.values())),
            "verdicts_new": dict(Counter(r["verdict"] for r in new.values())),
            "verdict_changed": changed, "value_moved": moved, "rel_threshold": rel}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("old", type=Path)
    ap.add_argument("new", type=Path)
    ap.add_argument("--rel", type=float, default=0.01, help="report numbers that moved by more than this")
    ap.add_argument("-o", "--output", type=Path)
    args = ap.parse_args()
    out = compare(read(args.old), read(args.new), args.rel)
    print(f"claims: {out['claims_old']} old, {out['claims_new']} new; only old {out['only_old']}, "
          f"only new {out['only_new']}")
    print(f"verdicts old: {out['verdicts_old']}")
    print(f"verdicts new: {out['verdicts_new']}")
    print(f"{len(out['verdict_changed'])} verdicts changed:")
    for c in out["verdict_changed"]:
        print(f"  {c['id']}: {c['old']} -> {c['new']}  (ours: {c['ours_old']!r} -> {c['ours_new']!r})")
    print(f"{len(out['value_moved'])} numbers moved by more than {100 * args.rel:g} %:")
    for m in out["value_moved"]:
        print(f"  {m['id']}: {m['old']:.4g} -> {m['new']:.4g} ({m['verdict_old']} / {m['verdict_new']})")
    if args.output:
        args.output.write_text(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
