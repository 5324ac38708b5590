"""The claims file (``paper/claims.yaml``): each claim, how it is tested, the findings several
claims share, and which figures and simulations the claims read (checked at start-up)."""
from __future__ import annotations

import re
from pathlib import Path
from typing import Any, Mapping

from ..io import read_yaml
from .evidence import ClaimError
from .measures import MEASURES

METHODS = ("derivation", "value", "measure", "not_testable")


KEYS = {"id", "where", "label", "quantity", "claim", "paper", "paper_from", "test", "tolerance", "reading", "why",
        "format", "finding", "protocol"}
#: a claim's label names it in the one-page results table: at most this many characters
LABEL_CHARS = 40


def _derivations():
    from .derivations import DERIVATIONS

    return DERIVATIONS


def finding_titles(path: str | Path) -> dict[str, str]:
    """The titles of the findings that several claims share (claims.yaml `findings`)."""
    data = read_yaml(path, what="claims file", error=ClaimError)
    titles = data.get("findings") or {}
    if not isinstance(titles, dict) or not all(isinstance(v, str) and v for v in titles.values()):
        raise ClaimError(f"claims file {str(path)!r}: 'findings' must map finding names to non-empty titles")
    for k, v in titles.items():
        # quoted in the abstract as plain text, which the PDF check finds word for word
        if re.search(r"['^_]", v):
            raise ClaimError(f"claims file {str(path)!r}: findings.{k}: {v!r} has an apostrophe, caret or "
                             "underscore; titles are quoted in the abstract as plain text")
    return {str(k): v for k, v in titles.items()}


def load(path: str | Path) -> list[dict[str, Any]]:
    data = read_yaml(path, what="claims file", error=ClaimError)
    if not isinstance(data, dict) or not isinstance(data.get("claims"), list):
        raise ClaimError(f"claims file {str(path)!r}: needs a list 'claims' at the top level")
    titles = finding_titles(path)
    claims, seen = data["claims"], set()
    for i, c in enumerate(claims):
        where = f"claims file {str(path)!r}, claim {i + 1}"
        if not isinstance(c, dict):
            raise ClaimError(f"{where}: must be a mapping")
        unknown = set(c) - KEYS
        if unknown:
            raise ClaimError(f"{where} ({c.get('id')!r}): unknown keys {sorted(unknown)}")
        for key in ("id", "where", "label", "claim", "test"):
            if key not in c:
                raise ClaimError(f"{where}: missing {key!r}")
        for key, limit in (("label", LABEL_CHARS), ("quantity", LABEL_CHARS)):
            if key in c and not (isinstance(c[key], str) and 0 < len(c[key]) <= limit):
                raise ClaimError(f"{where} ({c['id']!r}): {key} = {c[key]!r}, expected a text of 1-{limit} characters "
                                 f"(it is a cell of the results table)")
        if "protocol" in c and not (isinstance(c["protocol"], list) and c["protocol"]
                                    and all(isinstance(p, str) and p for p in c["protocol"])):
            raise ClaimError(f"{where} ({c['id']!r}): protocol = {c['protocol']!r}, expected a list of the loading "
                             "protocols of the runs the claim reads")
        if c["id"] in seen:
            raise ClaimError(f"{where}: duplicate id {c['id']!r}")
        if "finding" in c and c["finding"] not in titles:
            raise ClaimError(f"{where} ({c['id']!r}): finding {c['finding']!r} has no title in the file's 'findings' "
                             f"({', '.join(titles) or 'none'})")
        seen.add(c["id"])
        method = c["test"].get("method")
        if method not in METHODS:
            raise ClaimError(f"{where} ({c['id']!r}): test.method = {method!r}, expected one of {METHODS}")
        if "paper" not in c and "paper_from" not in c:
            raise ClaimError(f"{where} ({c['id']!r}): needs 'paper' or 'paper_from'")
        if method == "value" and "tolerance" not in c:
            raise ClaimError(f"{where} ({c['id']!r}): a value comparison needs 'tolerance' (rel or abs)")
        if method == "derivation" and c["test"].get("name") not in _derivations():
            raise ClaimError(f"{where} ({c['id']!r}): test.name = {c['test'].get('name')!r} is not a derivation of "
                             f"confined_rod.claims.derivations ({', '.join(_derivations())})")
        if method == "measure" and c["test"].get("name") not in MEASURES:
            raise ClaimError(f"{where} ({c['id']!r}): test.name = {c['test'].get('name')!r} is not a measure of "
                             f"confined_rod.claims.measures ({', '.join(MEASURES)})")
        paper = c.get("paper")
        numeric = "paper_from" in c or (isinstance(paper, (int, float)) and not isinstance(paper, bool))
        if "tolerance" in c and not numeric:
            raise ClaimError(f"{where} ({c['id']!r}): a tolerance needs a numeric paper value, got {c.get('paper')!r}")
        tol = c.get("tolerance")
        if tol is not None and (not isinstance(tol, dict) or set(tol) - {"rel", "abs"} or len(tol) != 1
                                or not float(next(iter(tol.values()))) > 0):
            raise ClaimError(f"{where} ({c['id']!r}): tolerance = {tol!r}, expected {{rel: x}} or {{abs: x}}, x > 0")
    return claims


# measures that read scene simulations (results/sims/), from the test's figure or figures
SIM_MEASURES = {"wall_force_coefficient", "capped_fraction", "boundary_wider", "pitch_exponent", "local_decay_law"}


def required_figures(claims: list[Mapping[str, Any]]) -> dict[str, list[str]]:
    """figure -> the claims that read its dataset or simulations."""
    out: dict[str, list[str]] = {}
    for c in claims:
        for spec in (c["test"], c.get("paper_from") or {}):
            for f in ([spec["figure"]] if "figure" in spec else []) + list(spec.get("figures", [])) + \
                    ([spec["protocols"]] if "protocols" in spec else []) + list((spec.get("ramp") or {}).values()):
                out.setdefault(f, []).append(c["id"])
    return out


def sim_figures(claims: list[Mapping[str, Any]]) -> list[str]:
    """The figures whose scene simulations the claims read."""
    out: list[str] = []
    for c in claims:
        t = c["test"]
        if t.get("method") == "measure" and t.get("name") in SIM_MEASURES:
            figs = ([t["figure"]] if "figure" in t else list(t.get("figures", [])))
            figs += [t["seeds_from"]] if "seeds_from" in t else []
            out += [f for f in figs if f not in out]
    return out
