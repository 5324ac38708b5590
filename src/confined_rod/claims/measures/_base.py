"""What every measure shares: the named result, the registry, and the verdict that must not
change with the threshold an exponent needs (FALL_THRESHOLDS)."""
from __future__ import annotations

import math
from typing import Any, Callable, Mapping, NamedTuple

from ...analysis.fits import DEGENERATE_FALL
from ..evidence import Evidence


class Measured(NamedTuple):
    """What a measure finds."""
    value: float            # the number shown in the "ours" column
    holds: bool | None      # None: inconclusive (the answer flips with an analysis choice, or no data decides)
    evidence: str           # the files and variables read
    note: str               # how it was decided, and why where it is inconclusive
    #: with holds False: the part of the claim that holds, where the claim as stated fails in
    #: another part (the verdict is then "partly reproduced", e.g. "at the loaded end"); with
    #: holds None: what leaves it undecided, in a few words (printed beside the verdict)
    part: str = ""
    #: the error of `value` where the measure has one (the standard error of a mean over seeds; for
    #: a single rod or a threshold the error its note names): the tables print the value with it
    error: float | None = None


Measure = Callable[[Evidence, Mapping[str, Any], str], Measured]
MEASURES: dict[str, Measure] = {}


def measure(fn: Measure) -> Measure:
    """Register a measure under its function's name (the name claims.yaml gives)."""
    MEASURES[fn.__name__] = fn
    return fn


#: the threshold and a factor sqrt(2) either side: a verdict that changes among them rests on the
#: choice of the threshold, not on the data, and is inconclusive
FALL_THRESHOLDS = (DEGENERATE_FALL / math.sqrt(2), DEGENERATE_FALL, DEGENERATE_FALL * math.sqrt(2))


_WORD = {True: "holds", False: "fails", None: "undecided"}


def _threshold_robust(test: Callable[[float], Measured]) -> Measured:
    """test(fall_min) at DEGENERATE_FALL, its verdict kept only if the same at every threshold
    of FALL_THRESHOLDS (else inconclusive, the note saying how it changes)."""
    results = {fm: test(fm) for fm in FALL_THRESHOLDS}
    value, holds, evidence, note, _, error = results[DEGENERATE_FALL]
    if len({r.holds for r in results.values()}) > 1:
        holds = None
        note += ("; the verdict depends on the fall below which a window does not determine a fit: "
                 + ", ".join(f"{_WORD[r.holds]} at {fm:.3g}x" for fm, r in results.items()))
    return Measured(value, holds, evidence, note, error=error)


def _combine(parts: list[bool | None]) -> bool | None:
    """One verdict from several independent parts (panels, lengths): refuted if any part is,
    reproduced if every part is, else inconclusive."""
    if any(p is False for p in parts):
        return False
    return True if parts and all(p is True for p in parts) else None


def _two_windows(ok_whole: bool | None, ok_bulk: bool | None) -> bool | None:
    """A statement tested on the whole stretch and on the bulk: decided only if both agree."""
    return ok_whole if ok_whole == ok_bulk else None
