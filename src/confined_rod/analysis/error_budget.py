"""The error budget of the headline numbers: numerical bias beside statistical error.

Every headline number of the reproduction (the transmitted fraction F(L)/F0 of Figs 4, 6 and 7,
the bulk decay rate of Figs 4 and 7 against the simple model's k_fr R/(4EI), the thresholds of
Figs 3 and 8, the share of Fig 2's seeds that end with a defect) carries two errors of different
nature:

* the **statistical error**: the spread of the final state over seeds (friction makes the
  equilibrium path-dependent), the standard error of the ensemble mean sd/sqrt(n); for a
  threshold found by bisection on one frictionless run there is none (the instability of the
  straight or planar rod does not depend on the seed); for one frictional run it is not measured;
* the **numerical bias**: how far the publication numerics sit from their limit. For each
  numerical parameter p it is the first-order distance of the publication rung's ensemble mean
  from the limit, the shift from the finest rung of the convergence ladder over p times
  1/(1 - h_fine/h_pub) (analysis.figures.convergence: the relative shift delta_p with its
  standard error sigma_p, paired seed by seed, both times that factor), read for the ladder's quantity
  that the headline is (F_transmitted for a transmitted fraction, decay_ratio for a decay
  rate). A ladder is measured at one rod; its relative shift is taken to hold for the headline's
  rod (the dx_max ladder nearest in L, the ramp ladder of the same friction and load, the l0,
  k_ph, k_w, k_t and tol ladders at L/R = 80): the table names where each shift was measured.
  A number that ran at coarser numerics than the ladder's publication rung (``Headline.numerics``:
  a long rod or a small load whose round-off floor raised its effective tolerance above the tol
  ladder's publication rung) reads the shift of the finest rung at least as coarse as it, from
  the finest rung (a bound where the bias grows with h); with no rung that coarse its term is
  not measured, and the table says so.
  For a threshold, the bisection's bracket (half its width) and the discretisation of the Euler
  load of the discrete chain, (sin x/x)^2 - 1 with x = pi l0/(2 lambda) for a buckling half-wave
  of length lambda (L for the first threshold, L/2 for the second, the free span for an escape
  of Fig 8), replace the ladders; where the figure bisected the same rod at a stiffer bond
  (Fig 3's bond checks), the shift of the threshold from it, to first order in 1/k_ph, is its
  k_ph term (a frictionless bisection has no seed spread, so no ladder is needed).

The bound of the number's bias is sum_p |delta_p| + t sqrt(sum_p sigma_p^2): a bias is not
random, so the terms' magnitudes add (no cancellation is assumed, their signs being measured at
other rods for most numbers), and only their measurement errors, independent ladders, add in
quadrature; t is the largest Student's quantile of the terms (paired seeds less one). It is set
beside the statistical 95 %
half-width t sd/sqrt(n) (n - 1 degrees of freedom; a share of seeds has its Wilson interval):
the larger one limits the number, and a number none of whose bias terms was measured is limited
by what is not known ("unknown"), however small its statistical error. A term read from a ladder
that *fails* on the headline's quantity (its publication rung beyond the tolerance from the finest
rung, with no asymptotic range: analysis.figures.convergence) is only a lower bound of the bias,
flagged per term (``bias_lower_bound``), and so is the number's bound: it limits the number where
it already exceeds the statistical error, and otherwise what limits the number is unknown. Two
caveats the table states: the shift is measured to the finest rung, not to the limit: for a term of order p,
f(h) = f* + a h^p, the publication rung h_pub sits 1/(1 - (h_fine/h_pub)^p) times the shift from
the limit, 1/(1 - h_fine/h_pub) at first order (``bias_limit_factor``: 4/3 for a ladder whose
finest rung is two halvings finer, 2 for one), and each term is that first-order distance, the
shift and its standard error times the factor (an overestimate where the order is higher); and
a shift measured at another rod than the
number's (another L, friction or load) is *transferred*, flagged per term (``bias_transferred``).
A transmitted force's shift measured at another length of the same friction, load and protocol
has its decay-rate part carried to the number's rod (:func:`rescaled`): the ladder's bias of the
local decay rate changes what the bulk adds to 1/|F_z| in proportion to it, on any rod; the rest
of the shift (the ends and the bulk's boundaries) is taken as the same relative shift. At another
friction, load or protocol there is no such model and the whole shift is taken as it is.

The headlines come from the figure kinds (an optional ``headlines(figure, ds)`` in a kind module,
returning :class:`Headline` objects); the ladders are every dataset of kind ``convergence`` with
seed ensembles."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable, Iterable, Mapping

import numpy as np
import xarray as xr

from ..io import finalize
from .distributions import BEYOND, t_quantiles
from .figure_quantities import variable

#: the large-sample factor of a 95 % interval (Student's t for few seeds: distributions.t_quantiles)
Z95 = 1.959963984540054
#: the numerical parameters a budget reads from the ladders, in the order of the table
LADDER_PARAMETERS = ("l0", "k_ph", "k_w", "k_t", "tol", "dx_max", "ramp_steps")
#: the bias terms of a threshold (no ladder varies one)
THRESHOLD_TERMS = ("bracket", "discretisation")
PARAMETERS = LADDER_PARAMETERS + THRESHOLD_TERMS
#: limited_by flag values
LIMITED_BY = ("statistics", "numerics", "unknown")


@dataclass(frozen=True)
class Headline:
    """One number a figure reports, with its statistical error and what decides its bias."""
    key: str                  # unique, e.g. 'fig6_FonL.fraction.L320'
    figure: str
    label: str                # what it is, for the table: 'F(L)/F0, L/R = 320'
    value: float
    stat_error: float | None  # standard error of `value` (absolute); None: not measured
    n_seeds: int
    quantity: str             # 'F_transmitted', 'decay_ratio' (read from the ladders) or 'threshold'
    L: float                  # the rod, to find the ladders measured nearest to it (in R)
    load: float
    k_fr: float
    protocol: str = "straight"
    #: relative bias terms known without a ladder (THRESHOLD_TERMS), as (value, why), or measured
    #: beside the number (a bond check) as (value, why, standard error, first-order limit factor)
    terms: Mapping[str, tuple] = field(default_factory=dict)
    note: str = ""
    #: the numerical parameters the number was computed at, where they may differ from a ladder's
    #: publication rung (tol: the effective tolerance, the round-off floor of a long rod or a small
    #: load); a ladder covers the number only if the number's value is at least as fine
    numerics: Mapping[str, float] = field(default_factory=dict)
    #: degrees of freedom of stat_error: None for n_seeds - 1 (a mean over seeds); inf where
    #: stat_error is already the 95 % half-width over Z95 (a Wilson interval)
    dof: float | None = None
    #: for a transmitted force: (mean |F_z(L)|, mean of what the bulk adds to 1/|F_z|) over the
    #: members with a bulk, the rod a ladder's split by region is rescaled to (:func:`rescaled`)
    force_parts: tuple[float, float] | None = None

    @property
    def stat_factor(self) -> float:
        """The factor of stat_error that gives its 95 % half-width (Student's t, or Z95)."""
        dof = self.n_seeds - 1.0 if self.dof is None else self.dof
        return t_quantiles(dof)[0] if dof > 0 else math.inf


def euler_discretisation(l0: float, wavelength: float) -> float:
    """Relative error of the Euler load of a chain of links l0 buckling in a half-wave of length
    ``wavelength``: (4 EI/l0^2) sin^2(pi l0/(2 lambda)) over pi^2 EI/lambda^2, minus 1, i.e.
    (sin x/x)^2 - 1 with x = pi l0/(2 lambda); -x^2/3 to lowest order (theory.first_threshold)."""
    x = math.pi * l0 / (2.0 * wavelength)
    return (math.sin(x) / x) ** 2 - 1.0


@dataclass(frozen=True)
class Ladder:
    """What a budget reads from one ensemble convergence ladder."""
    name: str
    parameter: str
    L: float
    load: float
    k_fr: float
    protocol: str
    #: quantity -> (relative shift of the publication rung from the finest, its standard error,
    #: the degrees of freedom of that error)
    shifts: Mapping[str, tuple[float, float, float]]
    #: distance of the publication rung from the limit over its shift from the finest rung, for a
    #: first-order term: 1/(1 - h_fine/h_pub) (module docstring)
    limit_factor: float = 1.0
    #: the refinement variable h of the publication rung (analysis.figures.convergence.REFINEMENT)
    h_pub: float = math.nan
    #: the rungs coarser than the publication one: (h, value, {quantity: (shift from the finest
    #: rung, its standard error, degrees of freedom)}, first-order limit factor), paired seed by seed
    #: from the members the dataset stores; they bound a number computed at coarser numerics
    coarser: tuple = ()
    #: the publication rung's shift of F(L) split by region (tip, bulk, lower), the covariance of
    #: the three shares, the rung's mean F(L) and bulk part over the split's seeds, and their
    #: number; None where the ladder has no split (analysis.figures.convergence._split_by_region)
    split: tuple | None = None
    #: the quantities whose publication rung lies beyond the ladder's tolerance from the finest
    #: rung when the ladder fails: no asymptotic range, so their first-order term is a lower bound
    beyond: frozenset = frozenset()


def bias_bound(bias: np.ndarray, se: np.ndarray, t: np.ndarray, has: np.ndarray) -> float:
    """95 % bound of a number's relative bias from its terms (module docstring): the magnitudes
    add, their standard errors in quadrature with the largest of their t factors."""
    on = (has == 1)
    if not on.any():
        return 0.0
    measured = on & (se > 0)
    spread = float(np.sqrt(np.sum(se[measured] ** 2)))
    return float(np.sum(np.abs(bias[on]))) + (float(np.max(t[measured])) * spread if measured.any() else 0.0)


def ladders_of(datasets: Mapping[str, xr.Dataset]) -> list[Ladder]:
    """The ensemble convergence ladders among the datasets, with the publication rung's shift from
    the finest rung per compared quantity."""
    out = []
    for name, ds in sorted(datasets.items()):
        if ds.attrs.get("kind") != "convergence" or "quantity" not in ds.coords:
            continue
        finest = ds.sizes["rung"] - 1
        shifts = {}
        for q, k in enumerate(ds["quantity"].values):
            if int(ds["cmp_verdict_code"].values[finest, q]) != 0:
                dof = float(ds["cmp_dof"].values[finest, q]) if "cmp_dof" in ds else -1.0   # -1: normal
                shifts[str(k)] = (float(ds["cmp_shift"].values[finest, q]),
                                  float(ds["cmp_shift_se"].values[finest, q]), dof if dof > 0 else math.inf)
        a = ds.attrs
        h, values = ds["h"].values, ds["value"].values
        ipub = int(np.flatnonzero(np.isclose(values, float(a["publication_value"]), rtol=1e-9))[0])
        coarser = tuple((float(h[i]), float(values[i]), _shifts_to_finest(ds, i, list(shifts)),
                         first_order_limit_factor(float(h[i]), float(h[finest]))) for i in range(ipub))
        split = None
        if "F_shift_by_region_cov" in ds and int(ds["F_shift_by_region_has"].values[ipub]):
            split = (ds["F_shift_by_region"].values[ipub].copy(), ds["F_shift_by_region_cov"].values[ipub].copy(),
                     float(ds["F_split_mean"].values[ipub]), float(ds["bulk_part_split_mean"].values[ipub]),
                     int(ds["F_shift_split_seeds"].values[ipub]))
        beyond = frozenset()
        if str(a.get("status", "")).startswith("fail"):
            from .figures.convergence import VERDICT_CODE
            beyond = frozenset(str(k) for q, k in enumerate(ds["quantity"].values)
                               if int(ds["cmp_verdict_code"].values[finest, q]) == VERDICT_CODE[BEYOND])
        out.append(Ladder(name, str(a["parameter"]), float(a["L"]), float(a["load"]), float(a["k_fr"]),
                          str(a.get("protocol", "straight")), shifts,
                          limit_factor=first_order_limit_factor(float(h[ipub]), float(h[finest])),
                          h_pub=float(h[ipub]), coarser=coarser, split=split, beyond=beyond))
    return out


def _shifts_to_finest(ds: xr.Dataset, i: int, quantities: list[str]) -> dict[str, tuple[float, float, float]]:
    """Rung i's shift from the finest rung per quantity, paired over the seeds both have a value
    for (distributions.compare), from the members a convergence dataset stores; a quantity with
    fewer than two such seeds is left out."""
    from .distributions import compare
    from .figures.convergence import aligned

    out = {}
    j = ds.sizes["rung"] - 1
    if "member_seed" not in ds:
        return out
    seeds = ds["member_seed"].values.astype(np.int64)
    for k in quantities:
        if f"{k}_member" not in ds:
            continue
        a, b = aligned(ds[f"{k}_member"].values, ds[f"{k}_has"].values, seeds, i, j)
        if b.size < 2 or b.mean() == 0.0:
            continue
        c = compare(a, b, 1.0, paired=True)
        out[k] = (c.shift, c.se, c.dof)
    return out


def rescaled(split: tuple, rod: tuple[float, float], rate: tuple[float, float, float]) -> tuple[float, float, float]:
    """A ladder's shift of F(L) carried to another rod of the same friction, load and protocol
    (module docstring): (shift, its standard error, degrees of freedom). With X_r what region r
    adds to 1/|F_z|, a seed's F_i/F_j - 1 = -F_i sum_r dX_r exactly. A relative bias eps of the
    bulk's decay rate (a local relation, the ladder's decay_ratio shift ``rate`` = (eps, se, dof))
    changes X_bulk by X_bulk eps/(1 + eps) (X of the biased rung), so its share of the shift is
    -F X_bulk eps/(1 + eps) on any rod, F X_bulk read at the number's rod. The rest of the ladder's
    shift (the tip, the lower region, and the bulk's boundaries moving between them) has no model
    that carries it to another length (the lower region of a long rod is several times longer than
    the ladder's), so it is taken as the same relative shift. The error: the shift's and eps's in
    quadrature, their correlation neglected."""
    shares, cov, F_l, X_l, n = split
    F_h, X_h = rod
    eps, eps_se, eps_dof = rate
    k = 1.0 / (1.0 + eps)
    rest = float(np.sum(shares)) + F_l * X_l * eps * k
    shift = -F_h * X_h * eps * k + rest
    se = math.sqrt(max(float(np.sum(cov)), 0.0) + ((F_h * X_h - F_l * X_l) * k * k * eps_se) ** 2)
    return float(shift), float(se), float(min(n - 1, eps_dof))


def first_order_limit_factor(h_pub: float, h_fine: float) -> float:
    """1/(1 - h_fine/h_pub): how many times its shift from the finest rung (refinement variable
    h_fine) a first-order term of the publication rung (h_pub) sits from the limit h -> 0; 1 where
    the publication rung is the finest (no shift measured)."""
    if not 0.0 < h_fine <= h_pub:
        raise ValueError(f"first_order_limit_factor needs 0 < h_fine <= h_pub, got h_fine = {h_fine!r}, "
                         f"h_pub = {h_pub!r}")
    return 1.0 if h_fine == h_pub else 1.0 / (1.0 - h_fine / h_pub)


def _same(x: float, y: float) -> bool:
    return math.isclose(x, y, rel_tol=1e-9, abs_tol=1e-12)


def match(h: Headline, parameter: str, ladders: Iterable[Ladder]) -> Ladder | None:
    """The ladder over ``parameter`` that stands for the headline's rod: only a frictional
    headline reads the (frictional) ladders; a ramp ladder only for a ramped rod of the same
    friction and load; otherwise one of the same friction and load if there is one, then the
    nearest in ln L."""
    if h.quantity == "threshold" or h.k_fr <= 0:
        return None
    cands = [x for x in ladders if x.parameter == parameter and h.quantity in x.shifts and x.k_fr > 0]
    if parameter == "ramp_steps":
        if h.protocol != "ramp":
            return None
        cands = [x for x in cands if _same(x.k_fr, h.k_fr) and _same(x.load, h.load)]
    same = [x for x in cands if _same(x.k_fr, h.k_fr) and _same(x.load, h.load)]
    cands = same or cands
    if not cands:
        return None
    return min(cands, key=lambda x: (abs(math.log(x.L / h.L)), x.name))


def covering(h: Headline, lad: Ladder) -> tuple[tuple[float, float, float] | None, float, str]:
    """The ladder's term for the number: (shift, se, dof) of the quantity, its first-order limit
    factor and a note. A number computed at numerics at least as fine as the publication rung
    (h no larger) reads the publication rung's shift; one computed at coarser numerics (a round-off
    floor above the tol ladder's publication rung) the shift of the finest rung at least as
    coarse as the number, from the finest rung: a bound where the bias grows with h; (None, 1,
    why) where no rung is that coarse."""
    pub = (lad.shifts.get(h.quantity), lad.limit_factor, "")
    if lad.parameter not in h.numerics or not math.isfinite(lad.h_pub):
        return pub
    from .figures.convergence import REFINEMENT

    v = float(h.numerics[lad.parameter])
    hv = REFINEMENT[lad.parameter][1](v)
    if hv <= lad.h_pub * (1.0 + 1e-9):
        return pub
    wide = [r for r in lad.coarser if r[0] >= hv * (1.0 - 1e-9) and h.quantity in r[2]]
    if not wide:
        return None, 1.0, (f"{lad.name}: the number ran at {lad.parameter} = {v:.3g}, coarser than every rung "
                           "compared: not covered")
    _, value, shifts, factor = min(wide, key=lambda r: r[0])
    return shifts[h.quantity], factor, f"; its rung {value:.3g} against the finest, covering the number's {v:.3g}"


def build(datasets: Mapping[str, xr.Dataset], headlines_of: Callable[[str, xr.Dataset], list[Headline]]) -> xr.Dataset:
    """The budget dataset: one row per headline of the datasets (``headlines_of(figure, ds)``),
    its statistical error and its bias per numerical parameter (module docstring)."""
    heads = [h for name, ds in sorted(datasets.items()) for h in headlines_of(name, ds)]
    keys = [h.key for h in heads]
    twice = sorted({k for k in keys if keys.count(k) > 1})
    if twice:
        raise ValueError(f"error budget: headline key(s) {', '.join(twice)} given by more than one number")
    ladders = ladders_of(datasets)
    H, P = len(heads), len(PARAMETERS)
    bias, bias_se, has_bias = np.zeros((H, P)), np.zeros((H, P)), np.zeros((H, P), dtype=np.int8)
    bias_t, moved, to_limit = np.full((H, P), Z95), np.zeros((H, P), dtype=np.int8), np.ones((H, P))
    lower = np.zeros((H, P), dtype=np.int8)
    source = np.full((H, P), "", dtype=object)
    value, stat, has_stat, stat_t = np.zeros(H), np.zeros(H), np.zeros(H, dtype=np.int8), np.full(H, Z95)
    bound, limited = np.zeros(H), np.zeros(H, dtype=np.int8)
    for i, h in enumerate(heads):
        value[i] = h.value
        if h.stat_error is not None and h.value != 0 and math.isfinite(h.stat_factor):
            # a relative error of 0 is undefined, one of a single seed unknown
            stat[i], has_stat[i], stat_t[i] = abs(h.stat_error) / abs(h.value), 1, h.stat_factor
        for p, name in enumerate(PARAMETERS):
            if name in h.terms:
                term = tuple(h.terms[name])
                bias[i, p], source[i, p] = term[:2]
                if len(term) == 4:      # a measured term: its standard error and limit factor
                    bias_se[i, p], to_limit[i, p] = term[2], term[3]
                has_bias[i, p] = 1
                continue
            lad = match(h, name, ladders) if name in LADDER_PARAMETERS else None
            if lad is None:
                continue
            term, factor, how = covering(h, lad)
            if term is None:
                source[i, p] = how
                continue
            moved[i, p] = not (_same(lad.L, h.L) and _same(lad.k_fr, h.k_fr) and _same(lad.load, h.load))
            if moved[i, p] and h.quantity == "F_transmitted" and not how and _same(lad.k_fr, h.k_fr) \
                    and _same(lad.load, h.load) and lad.protocol == h.protocol and lad.split is not None \
                    and h.force_parts is not None and "decay_ratio" in lad.shifts:
                term = rescaled(lad.split, h.force_parts, lad.shifts["decay_ratio"])
                how = (f"; its decay-rate part carried to this rod's bulk, {100 * lad.split[0].sum():+.2g} % at "
                       "the ladder's")
            # the term is the first-order distance to the limit: the shift from the finest rung
            # times 1/(1 - h_fine/h), with its error (module docstring)
            bias[i, p], bias_se[i, p], dof = factor * term[0], factor * term[1], term[2]
            bias_t[i, p], to_limit[i, p] = t_quantiles(dof)[0], factor
            has_bias[i, p] = 1
            lower[i, p] = h.quantity in lad.beyond
            source[i, p] = (f"{lad.name} (L/R = {lad.L:g}, k_fr = {lad.k_fr:g}, load = {lad.load:g}"
                            + ("; transferred" if moved[i, p] else "") + how + ")")
        bound[i] = bias_bound(bias[i], bias_se[i], bias_t[i], has_bias[i])
        # a bias known only from below limits the number if it already exceeds the statistics;
        # below them, what limits it is not known
        limited[i] = LIMITED_BY.index("unknown" if not has_stat[i] or not has_bias[i].any() else
                                      "numerics" if bound[i] > stat_t[i] * stat[i] else
                                      "unknown" if lower[i].any() else "statistics")
    coords = {"headline": variable(("headline",), np.array([h.key for h in heads], dtype=object), "headline"),
              "budget_parameter": variable(("budget_parameter",), np.array(PARAMETERS, dtype=object),
                                           "budget_parameter")}
    data = {
        "headline_label": variable(("headline",), np.array([h.label for h in heads], dtype=object), "headline_label"),
        "headline_figure": variable(("headline",), np.array([h.figure for h in heads], dtype=object),
                                    "headline_figure"),
        "headline_quantity": variable(("headline",), np.array([h.quantity for h in heads], dtype=object),
                                      "headline_quantity"),
        "headline_protocol": variable(("headline",), np.array([h.protocol for h in heads], dtype=object),
                                      "headline_protocol"),
        "headline_note": variable(("headline",), np.array([h.note for h in heads], dtype=object), "headline_note"),
        "headline_value": variable(("headline",), value, "headline_value"),
        "n_seeds": variable(("headline",), np.array([h.n_seeds for h in heads], dtype=np.int32), "n_seeds"),
        "stat_error": variable(("headline",), stat, "stat_error"),
        "stat_factor": variable(("headline",), stat_t, "stat_factor"),
        "has_stat_error": variable(("headline",), has_stat, "has_stat_error"),
        "bias": variable(("headline", "budget_parameter"), bias, "bias"),
        "bias_se": variable(("headline", "budget_parameter"), bias_se, "bias_se"),
        "has_bias": variable(("headline", "budget_parameter"), has_bias, "has_bias"),
        "bias_source": variable(("headline", "budget_parameter"), source, "bias_source"),
        "bias_factor": variable(("headline", "budget_parameter"), bias_t, "bias_factor"),
        "bias_transferred": variable(("headline", "budget_parameter"), moved, "bias_transferred"),
        "bias_limit_factor": variable(("headline", "budget_parameter"), to_limit, "bias_limit_factor"),
        "bias_lower_bound": variable(("headline", "budget_parameter"), lower, "bias_lower_bound"),
        "bias_bound": variable(("headline",), bound, "bias_bound"),
        "limited_by": variable(("headline",), limited, "limited_by"),
    }
    for flag in ("has_stat_error", "has_bias"):
        data[flag].attrs.update(flag_values=np.array([0, 1], dtype=np.int8), flag_meanings="not_measured measured")
    data["bias_transferred"].attrs.update(flag_values=np.array([0, 1], dtype=np.int8),
                                          flag_meanings="measured_at_this_rod measured_at_another_rod")
    data["bias_lower_bound"].attrs.update(flag_values=np.array([0, 1], dtype=np.int8),
                                          flag_meanings="first_order_estimate lower_bound")
    data["limited_by"].attrs.update(flag_values=np.arange(len(LIMITED_BY), dtype=np.int8),
                                    flag_meanings=" ".join(LIMITED_BY))
    return finalize(xr.Dataset(data, coords=coords),
                    "Error budget of the headline numbers: numerical bias beside statistical error",
                    {"z95": Z95, "method": __doc__.split("\n\n", 1)[1].replace("\n", " ")})


def expected(quantity: str, protocol: str) -> tuple[str, ...]:
    """The bias terms a headline of this quantity and protocol should have: the threshold terms
    for a threshold, else the ladders (ramp_steps only for a ramp)."""
    if quantity == "threshold":
        # and the bond's compliance, where the figure bisected the same rod at a stiffer bond
        return THRESHOLD_TERMS + ("k_ph",)
    return tuple(p for p in LADDER_PARAMETERS if p != "ramp_steps" or protocol == "ramp")


def rows(ds: xr.Dataset) -> list[dict[str, str | float]]:
    """One row per headline, for the CSV and the manuscript's table: value, the statistical and
    numerical 95 % errors in per cent, the largest bias term and what limits the number."""
    out = []
    params = [str(p) for p in ds["budget_parameter"].values]
    for i, key in enumerate(ds["headline"].values):
        per = (np.abs(ds["bias"].values[i]) + ds["bias_factor"].values[i] * ds["bias_se"].values[i]) \
            * ds["has_bias"].values[i]
        j = int(np.argmax(per))
        measured = [p for p, m in zip(params, ds["has_bias"].values[i]) if m]
        moved = [p for p, m in zip(params, ds["bias_transferred"].values[i]) if m]
        lower = [p for p, m in zip(params, ds["bias_lower_bound"].values[i]) if m] \
            if "bias_lower_bound" in ds else []
        out.append({
            "headline": str(key), "figure": str(ds["headline_figure"].values[i]),
            "label": str(ds["headline_label"].values[i]), "value": float(ds["headline_value"].values[i]),
            "n_seeds": int(ds["n_seeds"].values[i]),
            "stat_95_percent": (100 * float(ds["stat_factor"].values[i] * ds["stat_error"].values[i])
                                if ds["has_stat_error"].values[i] else None),
            "bias_95_percent": 100 * float(ds["bias_bound"].values[i]) if measured else None,
            "largest_bias": _term(params[j], float(ds["bias"].values[i, j]), float(ds["bias_se"].values[i, j]))
            if per[j] > 0 else "none measured",
            "largest_transferred": "yes" if params[j] in moved and per[j] > 0 else "no",
            "largest_lower_bound": "yes" if params[j] in lower and per[j] > 0 else "no",
            "lower_bound": " ".join(lower),
            "measured": " ".join(measured),
            "transferred": " ".join(moved),
            "not_measured": " ".join(p for p in expected(str(ds["headline_quantity"].values[i]),
                                                         str(ds["headline_protocol"].values[i]))
                                     if p not in measured),
            "limited_by": LIMITED_BY[int(ds["limited_by"].values[i])],
            "note": str(ds["headline_note"].values[i]),
        })
    return out


def _term(name: str, bias: float, se: float) -> str:
    """'l0 -1.6 +- 0.56 %', or 'bracket +0.39 %' for a term known exactly."""
    return f"{name} {100 * bias:+.2g}" + (f" +- {100 * se:.2g} %" if se > 0 else " %")


def to_csv(ds: xr.Dataset) -> str:
    import csv
    import io

    table = rows(ds)
    buf = io.StringIO()
    if table:
        w = csv.DictWriter(buf, fieldnames=list(table[0]), lineterminator="\n")
        w.writeheader()
        for r in table:
            w.writerow({k: ("not measured" if v is None else format(v, ".4g") if isinstance(v, float) else v)
                        for k, v in r.items()})
    return buf.getvalue()
