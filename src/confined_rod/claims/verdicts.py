"""The claims of the original paper (``paper/claims.yaml``), evaluated on the datasets.

Each claim names how it is tested (see the header of ``paper/claims.yaml``): a symbolic
derivation (:mod:`confined_rod.claims.derivations`), a number from a dataset compared with the
paper's within a tolerance, a named measure (:data:`MEASURES`),
or a reason why it cannot be tested. :func:`evaluate` returns one :class:`Verdict` per
claim; the verdict is computed here, never typed, and a claim whose evidence (dataset,
variable, simulation) is missing raises :class:`ClaimError`, so the build fails.

Post-processing: reads datasets only and never imports the simulator.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass
from typing import Any, Mapping

import numpy as np
import xarray as xr

from .evidence import ClaimError, Evidence, pick
from .measures import MEASURES, Measured

#: "partly reproduced": a claim of several parts (both ends of a rod, say) of which one holds and
#: another fails; the note names the part that holds
VERDICTS = ("reproduced", "reproduced under reading", "partly reproduced", "refuted", "inconclusive", "not testable")


@dataclass
class Verdict:
    id: str
    where: str
    claim: str
    paper: str                  # the paper's value as text
    paper_value: float | None   # ... as a number, where it is one
    ours: str
    ours_value: float | None
    tolerance: str
    verdict: str
    evidence: str
    reading: str = ""
    note: str = ""
    finding: str = ""           # the independent finding it belongs to (claims.yaml `finding`, default its id)
    part: str = ""              # of a "partly reproduced" claim: the part that holds (e.g. "at the loaded end");
    #                             of an "inconclusive" one, where a measure says: what leaves it undecided
    label: str = ""             # a short name (claims.yaml `label`)
    quantity: str = ""          # what the numbers of `paper` and `ours` are (claims.yaml `quantity`)
    protocol: str = ""          # the loading protocols of the datasets and runs it read (", "-joined)
    ours_error: float | None = None   # the error of ours_value, where the measure gives one (its note says which)


def fmt(value: float, spec: str | None = None) -> str:
    """Plain-text number: the claim's format, else 3 significant digits without exponent
    where that is readable."""
    if spec:
        return format(value, spec)
    if value != 0 and (abs(value) >= 1e5 or abs(value) < 1e-3):
        return format(value, ".2e")
    return format(value, ".3g")


def _tolerance_text(tol):
    if not tol:
        return ""
    (kind, x), = tol.items()
    return f"{'relative' if kind == 'rel' else 'absolute'} {x:g}"


def _within(ours, paper, tol):
    (kind, x), = tol.items()
    if kind == "rel":
        return abs(ours - paper) <= x * abs(paper)
    return abs(ours - paper) <= x


#: our value where no window of the data determines it (an inconclusive verdict says why)
NOT_DETERMINED = "not determined"


def evaluate_one(c: Mapping[str, Any], ev: Evidence) -> Verdict:
    """A claim's verdict; if anything it read comes from a run that is not at equilibrium, the
    verdict is 'not testable' and the note names those runs (the measure is not trusted, and
    may not even complete, on such evidence)."""
    ev.touched.clear()
    try:
        verdict = _evaluate_one(c, ev)
    except (ClaimError, ValueError, KeyError, IndexError, ZeroDivisionError):
        if not ev.unsettled():
            raise
        verdict = None
    off = ev.unsettled()
    if off:
        verdict = unsettled_verdict(c, off)
    verdict.label, verdict.quantity = str(c.get("label", c["id"])), str(c.get("quantity", ""))
    verdict.protocol = ", ".join(read_protocols(c, ev))
    return verdict


def read_protocols(c: Mapping[str, Any], ev: Evidence) -> list[str]:
    """The loading protocols of the runs a claim read: its `protocol` list where a dataset it
    reads mixes several (each must be among the evidence's: ClaimError otherwise), else all of
    the evidence's (Evidence.protocols)."""
    found = ev.protocols()
    if "protocol" not in c:
        return found
    missing = [p for p in c["protocol"] if p not in found]
    if missing:
        raise ClaimError(f"claim {c['id']!r}: protocol = {c['protocol']!r}, but the runs it read have "
                         f"{', '.join(found) or 'no protocol'} (not {', '.join(missing)})")
    return sorted(c["protocol"])


def unsettled_verdict(c: Mapping[str, Any], runs: list[str]) -> Verdict:
    shown = "; ".join(runs[:4]) + (f"; and {len(runs) - 4} more" if len(runs) > 4 else "")
    paper = c.get("paper", "-")
    return Verdict(c["id"], c["where"], c["claim"], str(paper if "paper_from" not in c else "-"),
                   float(paper) if isinstance(paper, (int, float)) and not isinstance(paper, bool) else None,
                   "-", None, "", "not testable", "-", str(c.get("reading", "")),
                   f"evidence not at equilibrium ({shown})", str(c.get("finding", c["id"])))


def _evaluate_one(c: Mapping[str, Any], ev: Evidence) -> Verdict:
    from . import derivations

    test, cid = c["test"], c["id"]
    method = test["method"]
    reading = str(c.get("reading", ""))
    tol = c.get("tolerance")
    paper_value, paper_src = None, ""
    if "paper_from" in c:
        paper_value, paper_src = pick(ev, c["paper_from"], cid)
        paper_text = fmt(paper_value, c.get("format"))
    else:
        paper_text = str(c["paper"])
        if isinstance(c["paper"], (int, float)) and not isinstance(c["paper"], bool):
            paper_value = float(c["paper"])
    ours_value, note, part, ours_error = None, "", "", None
    if method == "not_testable":
        return Verdict(cid, c["where"], c["claim"], paper_text, paper_value, "-", None, "", "not testable",
                       "-", reading, str(test.get("reason", "")), str(c.get("finding", cid)))
    if method == "derivation":
        d = derivations.DERIVATIONS[test["name"]]()
        ours, holds, evidence, note = d.ours, d.agrees, f"{derivations.__name__}.{test['name']}", d.detail
    else:
        if method == "value":
            ours_value, evidence = pick(ev, test, cid)
            holds = True
        else:
            found = MEASURES[test["name"]](ev, test, cid)
            if not isinstance(found, Measured):
                raise TypeError(f"measure {test['name']} returned {type(found).__name__}, not a Measured")
            ours_value, holds, evidence, note, part, ours_error = found
            if part and holds is True:
                raise TypeError(f"measure {test['name']} names a part that holds ({part!r}) but does not "
                                "find the claim as stated to fail")
        if math.isnan(ours_value) and holds is None:
            # the measure found no window that determines the quantity (the note says why): no value
            ours, ours_value, ours_error = NOT_DETERMINED, None, None
        elif not math.isfinite(ours_value):
            raise ClaimError(f"claim {cid!r}: the measured value is not finite ({evidence})")
        else:
            ours = fmt(ours_value, c.get("format"))
        if tol and holds is not None:
            holds = holds and _within(ours_value, paper_value, tol)
    if paper_src:
        evidence += f"; paper value from {paper_src}"
    if holds is None:       # the measure found the answer to depend on an analysis choice (note: why)
        verdict = "inconclusive"
    elif part and not holds:
        verdict = "partly reproduced"
    else:
        verdict = ("reproduced under reading" if reading else "reproduced") if holds else "refuted"
    if ours_error is not None and not (math.isfinite(ours_error) and ours_error >= 0):
        raise ClaimError(f"claim {cid!r}: the measured error is {ours_error!r} ({evidence})")
    return Verdict(cid, c["where"], c["claim"], paper_text, paper_value, ours, ours_value, _tolerance_text(tol),
                   verdict, evidence, reading, note, str(c.get("finding", cid)),
                   part if verdict in ("partly reproduced", "inconclusive") else "", ours_error=ours_error)


def evaluate(claims: list[Mapping[str, Any]], ev: Evidence) -> list[Verdict]:
    return [evaluate_one(c, ev) for c in claims]


COLUMNS = ("id", "where", "claim", "paper", "ours", "verdict", "part", "tolerance", "reading", "evidence", "note",
           "finding", "label", "quantity", "ours_error", "protocol")


#: a finding's verdict from its claims' (the paper's claims only: claims of ours, whose `where`
#: says "our finding", do not decide it): the first of these that occurs
FINDING_ORDER = ("refuted", "partly reproduced", "inconclusive", "reproduced under reading", "reproduced",
                 "not testable")


def ours_only(v: Verdict) -> bool:
    return "our finding" in v.where


def findings(verdicts: list[Verdict]) -> dict[str, tuple[str, list[str]]]:
    """Independent findings: name -> (verdict, ids of its claims), in the order of first
    appearance; a finding whose claims are all ours gets their verdict."""
    groups: dict[str, list[Verdict]] = {}
    for v in verdicts:
        groups.setdefault(v.finding or v.id, []).append(v)
    out = {}
    for name, vs in groups.items():
        deciding = [v for v in vs if not ours_only(v)] or vs
        verdict = next(o for o in FINDING_ORDER if any(v.verdict == o for v in deciding))
        out[name] = (verdict, [v.id for v in vs])
    return out


def split_findings(verdicts: list[Verdict]) -> tuple[dict, dict]:
    """(the findings about the paper's claims, the findings of our own): a finding all of whose
    claims are ours ("our finding" in where) is ours; counts and the abstract keep them apart."""
    found = findings(verdicts)
    mine = {v.id for v in verdicts if ours_only(v)}
    own = {n: f for n, f in found.items() if set(f[1]) <= mine}
    return {n: f for n, f in found.items() if n not in own}, own


VARIABLE = {"claim": "statement"}   # the claim's text (the dimension is called claim)


def to_dataset(verdicts: list[Verdict], titles: Mapping[str, str] | None = None) -> xr.Dataset:
    """The verdicts as a CF-style dataset: text variables, and the numbers with a flag where
    a claim has one (no NaN)."""
    from ..io import finalize

    def text(name, long_name):
        return xr.Variable("claim", np.array([str(getattr(v, name)) for v in verdicts], dtype=object),
                           {"long_name": long_name, "units": "1"})

    def number(name, long_name):
        vals = [getattr(v, name) for v in verdicts]
        return (xr.Variable("claim", np.array([x if x is not None else 0.0 for x in vals], dtype=float),
                            {"long_name": long_name + " (0 where has_" + name + " is 0)", "units": "1"}),
                xr.Variable("claim", np.array([x is not None for x in vals], dtype=np.int8),
                            {"long_name": "1 where the claim has " + long_name, "units": "1"}))

    data = {VARIABLE.get(name, name): text(name, long) for name, long in (
        ("where", "section, equation or figure of the original"), ("claim", "what the paper says"),
        ("paper", "the paper's value as printed"), ("ours", "our value"),
        ("verdict", ", ".join(VERDICTS)),
        ("part", "of a partly reproduced claim: the part that holds; of an inconclusive one: what leaves it "
                 "undecided, where the measure says"),
        ("label", "short name of the claim"), ("quantity", "what the paper's value and ours are"),
        ("protocol", "loading protocols of the datasets and runs the claim read"),
        ("tolerance", "tolerance deciding the verdict"), ("reading", "interpretation the verdict needs"),
        ("evidence", "dataset and variable, or derivation, behind our value"), ("note", "how it was decided"),
        ("finding", "the independent finding the claim belongs to"))}
    for name, long in (("paper_value", "the paper's value"), ("ours_value", "our value"),
                       ("ours_error", "the error of our value the measure gives")):
        data[name], data["has_" + name] = number(name, long)
    ds = xr.Dataset(data, coords={"claim": ("claim", np.array([v.id for v in verdicts], dtype=object),
                                            {"long_name": "claim id (paper/claims.yaml)", "units": "1"})})
    paper_claims = [v for v in verdicts if not ours_only(v)]
    for verdict in VERDICTS:
        ds.attrs["n_" + verdict.replace(" ", "_")] = sum(v.verdict == verdict for v in paper_claims)
    ds.attrs["n_own_claims"] = len(verdicts) - len(paper_claims)
    found, own = split_findings(verdicts)
    ds.attrs["n_findings"] = len(found)
    for verdict in VERDICTS:
        ds.attrs["n_findings_" + verdict.replace(" ", "_")] = sum(f[0] == verdict for f in found.values())
    ds.attrs["n_own_findings"] = len(own)
    ds.attrs["finding_titles"] = json.dumps(dict(titles or {}))
    return finalize(ds, "Claims of Svensek & Podgornik, evaluated on this build's datasets", {})


def to_csv(verdicts: list[Verdict]) -> str:
    import csv
    import io

    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(COLUMNS)
    for v in verdicts:
        w.writerow(["" if getattr(v, c) is None else getattr(v, c) for c in COLUMNS])
    return buf.getvalue()
