"""The three regions of a loaded frictional rod, and the local decay law in its bulk.

A long rod pushed into the pore is not one power law. Read from the loaded end (s = 0,
link 0 in every dataset) it has

* a **tip** region: the detached end and its few concentrated wall contacts, where the force
  drops over a few R;
* the **bulk** helix: on the wall, the friction at its Coulomb limit and mostly axial; this is
  where the simple model's argument applies, d|F_z|/ds = -k_fr K with K = R F_z^2/(4EI)
  (corrected; the paper has 2EI), i.e. the *local decay law*

      d(1/|F_z|)/ds = k_fr R / (4 EI)      (paper: k_fr R / (2 EI));

* a **lower** region: on the wall or not, but with friction that is stuck or mostly azimuthal,
  so that it carries little axial force and |F_z| stays nearly flat.

The regions are detected from the data alone, per link: q = f_z / f_max, the axial friction
force over the largest the wall can give (f_max = min(k_fr N, friction_cap)), which is the
product of the share of the Coulomb limit that is used and the axial share of the friction.
q is 1 on a link that slides axially at the limit and 0 on a link off the wall, stuck with
no axial load, or slipping azimuthally. Smoothed over a window of ``WINDOW_R`` (a turn of
the bulk helix is 2 pi / w ~ 9 R at the paper's load, so a window of ~ 4 R averages the
contact pattern of half a turn but resolves region boundaries to a few R), the bulk is the
longest stretch where the smoothed q is at least ``Q_BULK``; the tip is everything before it
and the lower region everything after it.

The decay rate in the bulk is the slope of a straight-line fit of 1/|F_z| against s over the
joints of the bulk less half a smoothing window at each end (the running mean blurs a boundary
by that much); its uncertainty is the larger of the fit's standard error and half the
difference of the slopes over the two halves of the bulk (the window effect: a law that holds
locally gives the same slope on both halves).

Post-processing: reads datasets only and never imports the simulator. Test twin: every
function here works on plain arrays (see ``tests/test_regions.py``).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import xarray as xr

REGIONS = ("tip", "bulk", "lower")
WINDOW_R = 4.0       # smoothing window of the axial friction utilisation, in units of R
Q_BULK = 0.5         # smoothed axial utilisation above which a stretch is bulk helix
MIN_BULK_R = 8.0     # a bulk shorter than this (about one turn) is no bulk: no local law measured
MIN_JOINTS = 8       # joints a decay-rate fit needs


@dataclass(frozen=True)
class Regions:
    """Boundaries of the regions along s (from the loaded end) and their lengths."""
    s_bulk_start: float     # end of the tip region = start of the bulk
    s_bulk_end: float       # end of the bulk = start of the lower region
    L: float
    has_bulk: bool

    @property
    def tip_length(self) -> float:
        return self.s_bulk_start

    @property
    def bulk_length(self) -> float:
        return self.s_bulk_end - self.s_bulk_start

    @property
    def lower_length(self) -> float:
        return self.L - self.s_bulk_end

    def of_links(self, s_link: np.ndarray) -> np.ndarray:
        """Region index (0 tip, 1 bulk, 2 lower) of each link centre."""
        s_link = np.asarray(s_link, dtype=float)
        if not self.has_bulk:
            return np.zeros(s_link.shape, dtype=np.int8)
        return np.where(s_link < self.s_bulk_start, 0, np.where(s_link <= self.s_bulk_end, 1, 2)).astype(np.int8)


@dataclass(frozen=True)
class DecayRate:
    """Slope of 1/|F_z| against s over a window, with its uncertainty."""
    rate: float         # d(1/|F_z|)/ds  [R/EI]
    err: float          # max(standard error, half the difference of the halves)
    se: float           # standard error of the straight-line fit
    halves: tuple[float, float]
    n: int              # joints in the fit


def friction_limit(wall_force, k_fr: float, friction_cap: float) -> np.ndarray:
    """The largest friction force per link, f_max = min(k_fr N, friction_cap) (no cap if 0)."""
    f_max = k_fr * np.asarray(wall_force, dtype=float)
    return np.minimum(f_max, friction_cap) if friction_cap > 0 else f_max


def axial_utilisation(contact, wall_force, friction_z, k_fr: float, friction_cap: float) -> np.ndarray:
    """q = f_z / f_max per link (0 off the wall): positive where friction carries axial load
    away from the loaded end (reduces |F_z| along s)."""
    contact = np.asarray(contact) > 0
    f_max = friction_limit(wall_force, k_fr, friction_cap)
    q = np.zeros(f_max.shape)
    ok = contact & (f_max > 0)
    q[ok] = np.asarray(friction_z, dtype=float)[ok] / f_max[ok]
    return q


def smooth(values: np.ndarray, n: int) -> np.ndarray:
    """Running mean over n samples (centred, shrinking at the ends)."""
    values = np.asarray(values, dtype=float)
    n = max(1, min(int(n), values.size))
    c = np.concatenate([[0.0], np.cumsum(values)])
    i = np.arange(values.size)
    lo = np.clip(i - n // 2, 0, values.size)
    hi = np.clip(lo + n, 0, values.size)
    lo = np.clip(hi - n, 0, values.size)
    return (c[hi] - c[lo]) / (hi - lo)


def detect(s_link, q, l0: float, L: float, R: float = 1.0) -> Regions:
    """The regions from the per-link axial utilisation q (links ordered from the loaded end)."""
    s_link = np.asarray(s_link, dtype=float)
    qs = smooth(q, int(round(WINDOW_R * R / l0)))
    on = qs >= Q_BULK
    idx = np.flatnonzero(on)
    if idx.size == 0:
        return Regions(L, L, L, False)
    runs = np.split(idx, np.flatnonzero(np.diff(idx) > 1) + 1)
    best = max(runs, key=len)
    start = float(s_link[best[0]] - 0.5 * l0)
    end = float(s_link[best[-1]] + 0.5 * l0)
    if end - start < MIN_BULK_R * R:
        return Regions(L, L, L, False)
    return Regions(start, end, L, True)


def decay_rate(s: np.ndarray, F_abs: np.ndarray, lo: float, hi: float) -> DecayRate | None:
    """Slope of 1/|F_z| against s over the joints lo <= s <= hi; None if fewer than
    MIN_JOINTS joints (per half: MIN_JOINTS // 2)."""
    s, F_abs = np.asarray(s, dtype=float), np.asarray(F_abs, dtype=float)
    tiny = 1e-9 * max(abs(hi), 1.0)
    w = (s >= lo - tiny) & (s <= hi + tiny) & (F_abs > 0)
    if w.sum() < MIN_JOINTS:
        return None
    x, y = s[w], 1.0 / F_abs[w]
    slope, se = _line(x, y)
    mid = 0.5 * (x[0] + x[-1])
    h1, h2 = x <= mid, x >= mid
    a, _ = _line(x[h1], y[h1])
    b, _ = _line(x[h2], y[h2])
    return DecayRate(slope, max(se, 0.5 * abs(a - b)), se, (a, b), int(w.sum()))


def _line(x, y) -> tuple[float, float]:
    """Least-squares slope and its standard error."""
    A = np.vstack([x, np.ones_like(x)]).T
    coef, *_ = np.linalg.lstsq(A, y, rcond=None)
    n = x.size
    if n <= 2:
        return float(coef[0]), 0.0
    resid = y - A @ coef
    sxx = float(np.sum((x - x.mean()) ** 2))
    se = float(np.sqrt(np.sum(resid**2) / (n - 2) / sxx)) if sxx > 0 else 0.0
    return float(coef[0]), se


def model_rates(k_fr: float, R: float, EI: float) -> tuple[float, float]:
    """The local decay law d(1/|F_z|)/ds: corrected k_fr R/(4EI) and the paper's k_fr R/(2EI)."""
    return k_fr * R / (4.0 * EI), k_fr * R / (2.0 * EI)


@dataclass(frozen=True)
class Analysis:
    regions: Regions
    q: np.ndarray               # axial utilisation per link
    q_smooth: np.ndarray
    bulk: DecayRate | None      # decay rate over the bulk
    whole: DecayRate | None     # ... over the whole wall-contact stretch
    model: float                # k_fr R/(4EI)
    paper: float                # k_fr R/(2EI)


def analyse(sim: xr.Dataset) -> Analysis:
    """Regions and decay rates of one scene dataset (results/sims/...)."""
    from .measure import contact_range

    a = sim.attrs
    R, EI, l0, L, k_fr = (float(a[k]) for k in ("R", "EI", "l0", "L", "k_fr"))
    cap = float(a.get("friction_cap", 0.0))
    q = axial_utilisation(sim["contact"].values, sim["wall_force"].values, sim["friction_z"].values, k_fr, cap)
    s_link = np.asarray(sim["s_link"].values, dtype=float)
    reg = detect(s_link, q, l0, L, R)
    s, F = np.asarray(sim["s"].values, dtype=float), np.abs(np.asarray(sim["F_z"].values, dtype=float))
    edge = 0.5 * WINDOW_R * R       # the smoothing blurs a boundary by up to half a window
    bulk = decay_rate(s, F, reg.s_bulk_start + edge, reg.s_bulk_end - edge) if reg.has_bulk else None
    s_h, s_e = contact_range(sim)
    whole = decay_rate(s, F, s_h, s_e) if s_e > s_h else None
    model, paper = model_rates(k_fr, R, EI) if k_fr > 0 else (0.0, 0.0)
    return Analysis(reg, q, smooth(q, int(round(WINDOW_R * R / l0))), bulk, whole, model, paper)


#: the scalars of summary(), in the order the figure datasets store them (quantities.py names)
SUMMARY_KEYS = ("has_bulk", "s_bulk_start", "s_bulk_end", "tip_length", "bulk_length", "lower_length",
                "lower_q_mean", "lower_force_drop", "bulk_decay_rate", "bulk_decay_rate_err", "whole_decay_rate",
                "whole_decay_rate_err", "decay_rate_model", "decay_rate_paper", "decay_ratio")


def force_parts(sim: xr.Dataset, a: Analysis | None = None) -> dict[str, float] | None:
    """What each region adds to 1/|F_z| from the loaded end (s = 0) to the support (s = L): tip
    1/|F(s_bulk_start)| - 1/|F(0)|, bulk 1/|F(s_bulk_end)| - 1/|F(s_bulk_start)|, lower 1/|F(L)| -
    1/|F(s_bulk_end)| (in R^2/EI), |F_z| interpolated linearly between the joints; their sum is
    1/|F(L)| - 1/|F(0)|. A change dX of a part moves the transmitted force by dF(L)/F(L) =
    -F(L) dX to first order, which is how a ladder splits the shift of F(L) by region. None
    without a bulk or with a force that vanishes."""
    a = a or analyse(sim)
    reg = a.regions
    s, F = np.asarray(sim["s"].values, dtype=float), np.abs(np.asarray(sim["F_z"].values, dtype=float))
    if not reg.has_bulk or np.any(F <= 0.0):
        return None
    inv = 1.0 / np.interp([0.0, reg.s_bulk_start, reg.s_bulk_end, s[-1]], s, F)
    return dict(zip(REGIONS, np.diff(inv).tolist()))


def friction_use(sim: xr.Dataset, region: str = "lower", a: Analysis | None = None) -> float | None:
    """The share of the Coulomb limit a region's friction carries axially, weighted by force:
    sum f_z / sum f_max over the region's links on the wall (f_z positive where it lowers |F_z|
    along s; f_max = min(k_fr N, friction_cap)). 1 where every contact slides axially at the
    limit (the bulk), below 1 where contacts stick or slip azimuthally, negative where the stuck
    friction holds a compression that grows along s (the lower region of a rod loaded at once: a
    few concentrated contacts whose friction the path set). Unlike the per-link mean q, it does
    not change when one contact is resolved by more link ends. None without a bulk or without
    wall contact in the region."""
    a = a or analyse(sim)
    if not a.regions.has_bulk:
        return None
    at = a.regions.of_links(np.asarray(sim["s_link"].values, dtype=float)) == REGIONS.index(region)
    at &= np.asarray(sim["contact"].values) > 0
    f_max = friction_limit(sim["wall_force"].values, float(sim.attrs["k_fr"]),
                           float(sim.attrs.get("friction_cap", 0.0)))
    total = float(f_max[at].sum())
    if total <= 0.0:
        return None
    return float(np.asarray(sim["friction_z"].values, dtype=float)[at].sum()) / total


def summary(sim: xr.Dataset, a: Analysis | None = None) -> dict[str, float]:
    """The scalars a figure dataset stores per run (quantities.py names; 0 with has_bulk = 0
    where there is no bulk): region boundaries and lengths, the lower region's mean axial
    utilisation and force drop, and the decay rates over the bulk and the whole stretch."""
    a = a or analyse(sim)
    reg = a.regions
    s, F = np.asarray(sim["s"].values, dtype=float), np.abs(np.asarray(sim["F_z"].values, dtype=float))
    s_link = np.asarray(sim["s_link"].values, dtype=float)
    lower = (s_link > reg.s_bulk_end) & (np.asarray(sim["contact"].values) > 0)
    out = {"has_bulk": int(reg.has_bulk and a.bulk is not None), "s_bulk_start": reg.s_bulk_start,
           "s_bulk_end": reg.s_bulk_end,
           "tip_length": reg.tip_length, "bulk_length": reg.bulk_length, "lower_length": reg.lower_length,
           "lower_q_mean": float(a.q[lower].mean()) if reg.has_bulk and lower.any() else 0.0,
           "lower_force_drop": float(np.interp(reg.s_bulk_end, s, F) / F[-1]) if reg.has_bulk and F[-1] > 0 else 0.0,
           "decay_rate_model": a.model, "decay_rate_paper": a.paper}
    for name, d in (("bulk", a.bulk), ("whole", a.whole)):
        out[f"{name}_decay_rate"] = d.rate if d else 0.0
        out[f"{name}_decay_rate_err"] = d.err if d else 0.0
    out["decay_ratio"] = a.bulk.rate / a.model if a.bulk and a.model > 0 else 0.0
    return out
