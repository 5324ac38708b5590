"""Kind ``convergence``: a ladder of scenes refining one numerical parameter, its
Richardson limit and the check of the publication setting (rule ``convergence_check``).

  The scenes differ in one numerical parameter
(l0, k_ph, k_w, k_t, tol, ramp_steps or dx_max).  Its refinement variable h -> 0 is l0,
1/k_ph, 1/k_w, 1/k_t, tol, 1/ramp_steps or dx_max.  From the three finest rungs h1 > h2 > h3
(ratio r = h1/h2 = h2/h3) and an
observable f, Richardson extrapolation gives

    observed order  p = ln((f1 - f2)/(f2 - f3)) / ln r
    limit           f_inf = f3 + (f3 - f2)/(r^p - 1),

valid when the differences have one sign (monotone convergence); differences
below a tenth of the tolerance count as converged (limit = finest value).  The check
compares the value at the publication setting with f_inf: |f_pub - f_inf| /
|f_inf| must not exceed the tolerance in config.

Like with like.  With friction a coarse and a fine rod started alike may settle
in different equilibria (a jammed near-planar state and a helix).  Extrapolating
across them is meaningless, so every rung is classified (helical: the contact
stretch winds at least one turn) and the check is declared *inconclusive* when
the classes or the winding numbers (to within half a turn) differ, or when the
differences change sign.  An inconclusive check says why; whether it fails the
build is the config's choice (``on_inconclusive``).

Seed ensembles per rung (:func:`ladder_verdict`). With friction a seed's final state is one of
many neighbouring equilibria, and any change of a numerical parameter can move it to another:
no per-seed question of the final state has an answer. Two questions do:

1. the **local relation** of the regular helix that holds in whichever equilibrium a seed
   reached, whatever axial torque the friction locked in: its lateral balance
   K = rho w^2 (|F_z|/c - EI w^2) (analysis.local_relations.helix_balance), within ``tolerance``
   of every finer rung;
2. the **distribution of final states** within ``distribution_tolerance``: F_transmitted, L_z
   and the ratios to the torque-free helix (bulk decay rate, wall force, pitch rate against the
   local force; they move with the locked torque, a property of the state): the shift of the
   ensemble mean, with the resolution at 95 % power and the Anderson-Darling k-sample p-value
   (analysis.distributions); the windings, reversals and the lower region's length are compared
   by their p-values in the notes, and so is the share of loosely wound seeds
   (analysis.local_relations.loosely_wound: a bulk whose wall force is below half the torque-free
   helix's, an unwinding torque locked in; McNemar's exact test on paired seeds, Fisher's
   unpaired), not deciding: the wall-force ratio itself is compared, and the cut at one half
   separates a distinct state at some rods and runs through a continuum at others.

What a ladder vouches for (``serves``). A ladder that names the figure scenes it stands behind
(the same rod as its publication rung) holds each final-state quantity those figures report to
the larger of ``distribution_tolerance`` and half the 95 % error of the figure's ensemble mean
(distributions.budget_tolerance, with the smaller spread of the ladder's publication and finest
rungs, and for the ratios to the torque-free helix the spread of the seeds that are not loosely
wound, so that a state some seeds of either rung fall into, a loosely wound stuck helix say,
cannot widen the tolerance its own shift is held to): the numerical bias then stays well below the
statistical error of what the figure reports, which is all the figure needs, and the ladder's
size follows from the figure's. Quantities no served
figure reports are compared and described but do not decide. Without ``serves`` every
final-state quantity decides against ``distribution_tolerance``.

pass when every comparison is within (its 95 % bound and its resolution inside the tolerance),
fail when one is beyond (outside the tolerance beyond its 95 % bound), inconclusive otherwise,
with the seeds per rung that would decide. Every rung starts a seed from the same continuous rod
(sim/perturbation.py), so each shift and its error come from the differences seed by seed
(distributions.compare, paired): the spread a seed carries on both rungs cancels, a seed that
moves to a neighbouring equilibrium adds its difference to the error. ``paired`` ladders (rungs
that differ only in the path: ramp_steps, k_t) also draw each seed's values across the rungs and
leave a seed that is unsettled on one rung out of all.
"""
from __future__ import annotations

import math
import re
import textwrap
from typing import Any, Mapping

import numpy as np
import xarray as xr

from ... import layout, theory
from ...errors import ConfigError
from .. import distributions, ensembles, local_relations, regions, run_checks
from .. import plotting as P
from ..figure_quantities import attrs, label, variable
from ..measure import bulk_pitch, n_turns
from ._common import same_except

REFINEMENT = {"l0": ("h = l0", lambda v: v), "tol": ("h = tol", lambda v: v),
              "k_ph": ("h = 1/k_ph", lambda v: 1.0 / v), "k_w": ("h = 1/k_w", lambda v: 1.0 / v),
              "k_t": ("h = 1/k_t", lambda v: 1.0 / v), "ramp_steps": ("h = 1/n_ramp", lambda v: 1.0 / v),
              "dx_max": ("h = dx_max", lambda v: v)}
OBSERVABLES = ("F_transmitted", "L_z", "pitch")
OPTIONS = {
    "parameter": {"enum": list(REFINEMENT), "description": "the numerical parameter the rungs differ in"},
    "tolerance": {"type": "number", "exclusiveMinimum": 0, "description": "largest relative distance of the "
                  "publication setting from the extrapolated limit (of F_transmitted, L_z and the bulk pitch) "
                  "before the build fails"},
    "on_inconclusive": {"enum": ["fail", "warn"], "description": "what an inconclusive check (rungs in different "
                        "equilibrium states, non-monotone differences) does to the build: fail, or warn and go on"},
    "on_fail": {"enum": ["fail", "warn"], "description": "what a failed check does to the build: fail (default), or "
                "warn and go on, for a ladder whose failure is a measured result the numerics cannot afford to remove "
                "(the verdict, its numbers and the error budget still carry it into the figures and the manuscript)"},
    "paired": {"type": "boolean", "description": "the rungs differ only in the path (ramp_steps, k_t, dx_max): the "
               "figure joins each seed's values across the rungs, and a seed unsettled on one rung is left out of "
               "all; default false (the verdict pairs the seeds of every ensemble ladder either way)"},
    "distribution_tolerance": {"type": "number", "exclusiveMinimum": 0, "description": "ensemble ladders: largest "
                               "relative shift of the mean final state (F_transmitted, L_z, the ratios to the "
                               "torque-free helix) from a finer rung; "
                               "default: tolerance, which then bounds the local relations only"},
    "serves": {"type": "array", "items": {"type": "string", "pattern": "^[^.]+[.][^.]+$"},
               "description": "ensemble ladders: the figure scenes ('<figure>.<scene>') whose ensemble means this "
               "ladder vouches for, each the rod of the publication rung; the final states are then decided on "
               "the quantities those figures report, each held to the larger of distribution_tolerance and "
               "half the 95 % error of the figure's mean (analysis.distributions.budget_tolerance); the other "
               "quantities are described, not deciding"},
    "publication_value": {"type": "number", "description": "the value the figures use when it is not a scene default "
                          "(e.g. the ramp_steps of the ramped figures); default: scene_defaults or the Scene default"},
}


ENSEMBLES = True


class ConvergenceError(RuntimeError):
    """The publication settings are further from the extrapolated limit than the tolerance."""


def varied(fig_cfg) -> tuple[str, ...]:
    return (fig_cfg.get("parameter"),)


def validate(figure, fig_cfg, built, publication_value=None) -> None:
    p = fig_cfg.get("parameter")
    if "tolerance" not in fig_cfg:
        raise ConfigError(f"figures.{figure}: a convergence figure needs a 'tolerance' (relative, e.g. 0.01)")
    if p not in REFINEMENT:
        raise ConfigError(f"figures.{figure}.parameter: {p!r} is not one of {', '.join(REFINEMENT)}")
    same_except(figure, built, (p, "seed"), f"the rungs of a convergence ladder differ only in {p} (and the seed)")
    vals = sorted({getattr(s, p) for s in built.values()})
    if len(vals) < 3:
        raise ConfigError(f"figures.{figure}.scenes: a convergence ladder needs at least 3 values of {p}")
    pub = publication_value
    if pub is not None and not any(abs(v - pub) <= 1e-9 * abs(pub) for v in vals):
        raise ConfigError(f"figures.{figure}.scenes: the ladder over {p} ({', '.join(f'{v:g}' for v in vals)}) "
                          f"must contain the publication value {p} = {pub:g}")


def caption(figure, fig_cfg, built, publication_value=None) -> str:
    p = fig_cfg["parameter"]
    sc = next(iter(built.values()))
    values = sorted({getattr(s, p) for s in built.values()}, reverse=True)
    vals = ", ".join(f"{v:g}" for v in values)
    per_rung = [sum(1 for s in built.values() if getattr(s, p) == v) for v in values]
    n = max(per_rung)
    if n > 1:
        runs = f"{n}" if min(per_rung) == n else f"{min(per_rung)} to {n}"
        tol = 100 * float(fig_cfg["tolerance"])
        dtol = 100 * float(fig_cfg.get("distribution_tolerance", fig_cfg["tolerance"]))
        states_tol = (f"{dtol:g} % for the final states" if not fig_cfg.get("serves") else
                      f"for the final states {dtol:g} % or, where that is larger, half the 95 % error of the mean "
                      "that a figure the ladder serves reports (from the 95 % lower bound of the smaller relative "
                      "spread of "
                      "the publication and the finest rung, for the ratios to the torque-free helix of their seeds "
                      "that are not loosely wound where at least two are; each panel's title gives the tolerance it "
                      "was held to)")
        same = (" Only the path differs between rungs; lines join a seed's values." if fig_cfg.get("paired") else "")
        return (f"Convergence in {p} = {vals} (L/R = {sc.L:g}, load = {sc.load:g} EI/R^2, k_fr = {sc.k_fr:g}), each "
                f"rung a seed ensemble of {runs} runs (a run not at a stable equilibrium is left out and named in the "
                "verdict). Two questions: the local relation of the regular helix that holds in whichever equilibrium "
                "a seed reached, whatever axial torque the friction locked in (its lateral balance: the wall force per "
                "length K over rho w^2 (|F_z|/c - EI w^2)), and the distribution of final states (the transmitted "
                "force, L_z, and the ratios to the torque-free helix, which move with the locked torque: the bulk "
                "decay rate over k_fr R/(4EI), the wall force per length over R F_z^2/(4EI), the pitch rate over that "
                f"of a torque-free helix at the local force). {P.words(P.SEEDS)} dots the single seeds, ensemble means "
                "with their 95 % intervals, the band the tolerance about the finest rung's mean; panel titles give "
                "the largest shift of the publication rung's mean from a finer rung (+- its standard error) and the "
                "resolution (the shift a "
                "5 % test of these ensembles detects with 95 % power); every rung starts a seed from the same rod, so "
                "shifts and their errors come from the differences seed by seed, over the seeds both rungs have "
                "(where a rung leaves a seed out, the title's shift differs from the ratio of the plotted means, "
                f"which are over all of a rung's seeds). The publication value {p} = "
                f"{publication_value:g} passes when every shift's 95 % bound and resolution are within the tolerance "
                f"({tol:g} % for the relations, {states_tol}) and fails when a shift exceeds it "
                "beyond its 95 % bound; otherwise the verdict is inconclusive and names the seeds per rung that would "
                f"decide (every comparison with its 95 % bound and Anderson-Darling p-value: {layout.CHECKS}).{same}")
    return (f"Convergence in {p} = {vals} (L/R = {sc.L:g}, k_fr = {sc.k_fr:g}): transmitted force, L_z and "
            f"bulk pitch against the refinement variable, with the limit (Richardson's extrapolation from the "
            f"three finest rungs, or the finest rung where the finest differences are already below a tenth of "
            f"the tolerance; the legend says which) and the band of +-{100 * float(fig_cfg['tolerance']):g} % "
            "about it that the publication "
            f"value {p} = {publication_value:g} must lie in.")


def richardson(h: np.ndarray, f: np.ndarray, resolved: float = 0.0) -> tuple[float, float, str]:
    """(observed order, limit, note) from the three finest rungs (h descending).

    ``resolved``: differences below this (absolute) are taken as converged: the
    finest value is the limit, and the order is reported where the differences still shrink
    monotonically (else 0: not measurable). Without it, noise at the level of the equilibrium
    tolerance would make a converged ladder look non-monotone."""
    h1, h2, h3 = h[-3:]
    f1, f2, f3 = f[-3:]
    r = h1 / h2
    if not math.isclose(h2 / h3, r, rel_tol=0.02):
        return 0.0, float(f3), "ladder not geometric; limit = finest value"
    d1, d2 = f1 - f2, f2 - f3
    if d2 == 0.0:
        return 0.0, float(f3), "converged to round-off"
    q = d1 / d2
    if max(abs(d1), abs(d2)) <= resolved:
        p = math.log(q) / math.log(r) if q > 1.0 else 0.0
        return p, float(f3), ("finest differences below a tenth of the tolerance (converged"
                              + (f"; observed order {p:.2f})" if p > 0 else ")"))
    if q <= 1.0:
        return 0.0, float(f3), "differences do not shrink monotonically (no asymptotic range)"
    p = math.log(q) / math.log(r)
    return p, float(f3 + (f3 - f2) / (r**p - 1.0)), ""


#: the ladder sorts out runs not at a stable equilibrium itself (postprocess.settle)
HANDLES_UNSETTLED = True


def build(fig_cfg: Mapping[str, Any], sims: Mapping[str, xr.Dataset], context=None) -> xr.Dataset:
    """The ladder's dataset and verdict, never decided on a run that is not at a stable
    equilibrium (a step or time cap, an escape, a known saddle: run_checks.status). In a ladder of
    seed ensembles such runs are left out (a paired ladder leaves out the seed at every rung) and
    named in ``left_out``; if a rung is left with fewer than two runs, or the ladder has one run
    per rung, the verdict is 'inconclusive: evidence not at equilibrium (...)'."""
    status = run_checks.unsettled(sims)
    off = list(status)
    if not off:
        ds = _ladder(fig_cfg, sims, context)
        ds.attrs["left_out"] = "none"
        return ds
    named = [f"{n} ({status[n]})" for n in off]
    drop = set(off)
    if fig_cfg.get("paired"):
        seeds = {int(sims[n].attrs.get("seed", 0)) for n in off}
        drop |= {n for n, d in sims.items() if int(d.attrs.get("seed", 0)) in seeds}
    kept = {n: d for n, d in sims.items() if n not in drop}
    groups = ensembles.group(list(sims), {n: sims[n].attrs for n in sims}, (fig_cfg["parameter"],))
    if all(len(g) > 1 for g in groups) and all(sum(n in kept for n in g) >= 2 for g in groups):
        ds = _ladder(fig_cfg, kept, context)
        ds.attrs["left_out"] = "; ".join(named)
        ds.attrs["notes"] = (f"{ds.attrs['notes']}; left out, not at a stable equilibrium: {ds.attrs['left_out']}"
                             + (" (paired: the seed left out at every rung)" if fig_cfg.get("paired") else ""))
        return ds
    ds = _ladder(fig_cfg, sims, context)
    ds.attrs["status"] = ("inconclusive: evidence not at equilibrium (" + "; ".join(named[:4])
                          + (f"; and {len(named) - 4} more" if len(named) > 4 else "") + ")")
    ds.attrs["left_out"] = "none"
    return ds


def _ladder(fig_cfg: Mapping[str, Any], sims: Mapping[str, xr.Dataset], context=None) -> xr.Dataset:
    param = fig_cfg["parameter"]
    groups = ensembles.group(list(sims), {n: sims[n].attrs for n in sims}, (param,))
    if any(len(g) > 1 for g in groups):
        return _build_ensemble(fig_cfg, sims, groups, float((context or {})["publication_value"]), context)
    publication_value = float((context or {})["publication_value"])
    hname, hfun = REFINEMENT[param]
    items = sorted(sims.items(), key=lambda kv: -hfun(float(kv[1].attrs[param])))
    values = np.array([float(d.attrs[param]) for _, d in items])
    h = np.array([hfun(v) for v in values])
    turns = np.array([n_turns(d) for _, d in items])
    helical = turns >= 1.0
    obs = {"F_transmitted": np.array([float(d["F_transmitted"]) for _, d in items]),
           "L_z": np.array([float(d["L_z"]) for _, d in items]),
           "pitch": np.array([bulk_pitch(d) for _, d in items])}
    tol = float(fig_cfg["tolerance"])
    reasons = []
    if helical.any() and not helical.all():
        reasons.append("the rungs settle in different states (helical: "
                       + ", ".join(f"{v:g}" for v in values[helical]) + "; not helical: "
                       + ", ".join(f"{v:g}" for v in values[~helical]) + ")")
    elif np.ptp(turns) > 0.5:
        reasons.append(f"the winding differs between rungs ({turns.min():.2f} to {turns.max():.2f} turns)")
    if not np.any(np.isclose(values, publication_value, rtol=1e-9)):
        raise ValueError(f"convergence ladder over {param} does not contain the publication value {publication_value}")
    ipub = int(np.flatnonzero(np.isclose(values, publication_value, rtol=1e-9))[0])
    checked = [k for k in OBSERVABLES if k != "pitch" or helical.all()]
    data, order, limit, dist, notes = {}, [], [], [], []
    for k in OBSERVABLES:
        data[k] = variable(("rung",), obs[k], k)
    pitch_theory = _discrete_helix_pitch(param, items) if helical.all() else None
    if pitch_theory is not None:
        data["pitch_theory"] = variable(("rung",), pitch_theory, "pitch_theory")
    for k in checked:
        p, lim, note = richardson(h, obs[k], resolved=0.1 * tol * abs(obs[k][-1]))
        order.append(p)
        limit.append(lim)
        dist.append(abs(obs[k][ipub] - lim) / abs(lim) if lim != 0 else abs(obs[k][ipub]))
        notes.append(note or "ok")
    if not reasons and any(n.startswith("differences") or n.startswith("ladder") for n in notes):
        reasons.append("; ".join(f"{k}: {n}" for k, n in zip(checked, notes) if n != "ok"))
    worst = max(dist)
    if reasons:
        status = "inconclusive: " + "; ".join(reasons)
    elif worst > tol:
        status = "fail"
    else:
        status = "pass"
    data["n_turns"] = variable(("rung",), turns, "n_turns")
    data["converged"] = variable(("rung",), [np.int8(d["converged"]) for _, d in items], "converged")
    data["wall_time"] = variable(("rung",), [float(d["wall_time"]) for _, d in items], "wall_time")
    data["observed_order"] = variable(("observable",), order, "observed_order")
    data["publication_distance"] = variable(("observable",), dist, "publication_distance")
    for k, lim, note in zip(checked, limit, notes):  # one variable per observable: they carry different units
        how = ("Richardson's extrapolation h -> 0" if note == "ok"
               else "finest rung's value (differences below a tenth of the tolerance)" if note.startswith("finest")
               else "finest rung's value")
        data[f"{k}_limit"] = xr.Variable((), lim, attrs={**attrs(k), "long_name": "limit h -> 0 of the "
                                                          + attrs(k)["long_name"], "comment": how})
    coords = {"rung": xr.Variable(("rung",), np.array([k for k, _ in items], dtype=object), attrs=attrs("scene")),
              "value": xr.Variable(("rung",), values, attrs={**attrs("value"), "long_name": f"value of {param}",
                                                              "parameter": param}),
              "h": xr.Variable(("rung",), h, attrs={**attrs("h"), "definition": hname}),
              "observable": xr.Variable(("observable",), np.array(checked, dtype=object), attrs=attrs("observable"))}
    ds = xr.Dataset(data, coords=coords)
    ds.attrs.update({"parameter": param, "refinement": hname, "publication_value": publication_value,
                     "tolerance": tol, "status": status, "worst_distance": worst,
                     "notes": "; ".join(f"{k}: {n}" for k, n in zip(checked, notes)),
                     "method": "Richardson extrapolation from the three finest rungs"})
    if pitch_theory is not None:
        ds.attrs["pitch_theory_deviation"] = float(np.max(np.abs(obs["pitch"] / pitch_theory - 1.0)))
    return ds


def _discrete_helix_pitch(param: str, items) -> np.ndarray | None:
    """The pitch of the discrete chain's torque-free helix at each rung's load and l0
    (theory.discrete_helix: the l0 dependence of a frictionless helix is the azimuth per link,
    x/asin(x) with x = w l0/2), for an l0 ladder of frictionless rods; None for any other."""
    need = ("k_fr", "load", "l0", "R", "EI")
    if param != "l0" or any(k not in d.attrs for _, d in items for k in need) \
            or any(float(d.attrs["k_fr"]) != 0.0 for _, d in items):
        return None
    try:
        return np.array([theory.discrete_helix(float(d.attrs["load"]), float(d.attrs["l0"]), float(d.attrs["R"]),
                                               float(d.attrs["EI"]))["pitch"] for _, d in items])
    except ValueError:          # a load no helix on the wall carries
        return None


TITLE_WIDTH, TITLE_LINES = 95, 2


def _keys_pattern() -> str:
    return "|".join(re.escape(k) for k in (*OBSERVABLES, *RELATION_KEYS, *STATE_KEYS, *DESCRIPTOR_KEYS))


def _first_clause(part: str) -> str:
    """'F_transmitted at 0.125: shift -1.5 +- 1.1 % (95 % bound 3.6 %), resolution ...: undecided 2 %'
    -> 'F_transmitted at 0.125: -1.5 +- 1.1 % (95 % bound 3.6 %)'; any other reason: its
    quantity and the text before the first parenthesis or comma."""
    m = re.match(rf"((?:{_keys_pattern()})(?: at [^:]+)?): (.*)", part)
    name, rest = (m[1] + ": ", m[2]) if m else ("", part)
    shift = re.search(r"shift ([+-]?[\d.e+-]+ \+- [\d.e+-]+ %) \(95 % bound ([^)]*)\)", rest)
    if shift:
        return f"{name}{shift[1]} (95 % bound {shift[2]})"
    return name + re.split(r" \(|, ", rest, maxsplit=1)[0].rsplit(": ", 1)[-1]


def brief_status(status: str) -> str:
    """A verdict by its headlines: its word and, per quantity that decides it, the shift and its
    95 % bound (or the first clause of its reason; a quantity that converged is left out). The
    full text is in results/checks."""
    word, _, reasons = status.partition(": ")
    if not reasons:
        return status
    if verdict_word(word) == "pass":                # 'pass: ... within 2 %, ... within 3 % (largest shifts: ...)'
        return status.split(" (largest shifts", 1)[0]
    parts = re.split(rf"; (?=(?:{_keys_pattern()})(?: at [^:]+)?: )", reasons)
    parts = [p for p in parts if not p.endswith("(converged)")] or parts[:1]
    return f"{verdict_word(word)}: " + "; ".join(_first_clause(p) for p in parts)


def verdict_word(status: str) -> str:
    """'pass', 'fail' or 'inconclusive' of a status text."""
    return re.split(r"[:( ]", status, maxsplit=1)[0]


#: how a figure title names the quantities a verdict text names by their dataset keys
DISPLAY = {"F_transmitted": "$|F_z(L)|$", "L_z": "$L_z$", "helix_balance": "helix balance",
           "decay_ratio": "decay ratio", "wall_force_ratio": "wall-force ratio", "pitch_ratio": "pitch ratio",
           "total_turns": "turns", "n_reversals": "reversals", "lower_length": "lower-region length",
           "lower_friction_use": "lower-region friction use"}


def _display(text: str) -> str:
    """A verdict text for a figure title: quantities by name instead of dataset key, and the served
    figures (named in full in results/checks) as 'the served figures'."""
    text = re.sub(r"final states that .*? report within their tolerances",
                  "final states within the served figures' tolerances", text)
    return re.sub(r"\b(" + "|".join(map(re.escape, sorted(DISPLAY, key=len, reverse=True))) + r")\b",
                  lambda m: DISPLAY[m[1]], text)


def _title_lines(head: str, status: str) -> list[str]:
    """The verdict as a figure title of at most TITLE_LINES lines: whole if it fits; else its
    headlines (brief_status) with a pointer to the full text; only then cut at a word."""
    def wrap(text):
        return textwrap.wrap(head + _display(text).replace(" +- ", " $\\pm$ "), width=TITLE_WIDTH)
    for text in (status, brief_status(status) + f" (full verdict: {layout.CHECKS})"):
        lines = wrap(text)
        if len(lines) <= TITLE_LINES:
            return lines
    return textwrap.wrap(head + _display(status).replace(" +- ", " $\\pm$ "), width=TITLE_WIDTH, max_lines=TITLE_LINES,
                         placeholder=f" ... (full verdict: {layout.CHECKS})")


#: the two questions an ensemble ladder decides (module docstring): the local relations per seed,
#: and the distribution of final states (its mean tested against ``distribution_tolerance``)
RELATION_KEYS = local_relations.UNIVERSAL
#: the final state and the ratios to the torque-free helix (decay rate, wall force, pitch), which
#: move with the torque the path locked in (local_relations): compared as distributions
STATE_KEYS = ("F_transmitted", "L_z", *(k for k in local_relations.RELATIONS if k not in RELATION_KEYS))
#: descriptors of the final state whose distributions are compared (AD p-values in the note) but
#: do not decide: a winding or a reversal is what multistability changes
DESCRIPTOR_KEYS = ("total_turns", "n_reversals", "lower_length", "lower_friction_use")
VERDICT_CODE = {distributions.WITHIN: 1, distributions.BEYOND: 2, distributions.UNDECIDED: 3}
#: a comparison described but not deciding: no figure the ladder serves reports the quantity
NOT_DECIDING = 4


def _member_values(sim: xr.Dataset) -> dict[str, float | None]:
    """What an ensemble ladder reads from one run: the state, its descriptors, the local relations."""
    sh = ensembles.shape(sim)
    out: dict[str, float | None] = {"F_transmitted": float(sim["F_transmitted"]), "L_z": float(sim["L_z"]),
                                    "total_turns": sh.total_turns, "n_reversals": float(sh.reversals.size)}
    frictional = float(sim.attrs["k_fr"]) > 0
    an = regions.analyse(sim) if frictional else None
    out.update(local_relations.measure(sim, an))
    loose = local_relations.loosely_wound(out)
    out["loosely_wound"] = None if loose is None else float(loose)
    out["lower_length"] = float(regions.summary(sim, an)["lower_length"]) if frictional else None
    # the share of the Coulomb limit the lower region's contacts carry axially (where the frictional
    # l0 ladder's shift of F(L) sits: docs/model.md, "What l0 changes")
    out["lower_friction_use"] = regions.friction_use(sim, "lower", an) if frictional else None
    return out


def state_tolerances(members: Mapping[str, np.ndarray], has: np.ndarray, rungs: tuple[int, ...], dist_tol: float,
                     served: list[Mapping[str, Any]] | None) -> dict[str, tuple[float, str] | None]:
    """Per final-state quantity (STATE_KEYS): (tolerance, where it comes from), or None where it
    does not decide (module docstring, ``serves``). Without served figures every quantity is held
    to ``dist_tol``; with them, a quantity reported by the served figures to the larger of
    ``dist_tol`` and budget_tolerance over the largest served ensemble that reports it, computed
    from the members of each of ``rungs`` (the publication rung and the finest) and the smallest
    taken: a state that some seeds of one rung fall into widens that rung's spread, and the
    tolerance it is held to must not grow with it. For the same reason the ratios to the
    torque-free helix (local_relations.TORQUE_FREE) take their spread from the members that are
    not loosely wound wherever at least two are not: a shift of the loosely wound share moves
    their mean, and the state's own spread must not widen the tolerance that shift is held to."""
    out: dict[str, tuple[float, str] | None] = {}
    for k in STATE_KEYS:
        if not served:
            out[k] = (dist_tol, "")
            continue
        by = [s for s in served if k in s["reports"]]
        if not by:
            out[k] = None
            continue
        figure = max(by, key=lambda s: s["seeds"])
        budgets, tight_used = [], []
        for i in rungs:
            v = members[k][i] if k in members else np.array([])
            ok = (has[i] == 1) & np.isfinite(v) if v.size else np.array([], dtype=bool)
            if k in local_relations.TORQUE_FREE and "loosely_wound" in members:
                # the loosely wound state sets the ratios' spread when it is there: its own share's
                # shift is then what a widened tolerance would hide (module docstring, ``serves``)
                tight = ok & (members["loosely_wound"][i] == 0)
                tight_used.append(bool(tight.sum() >= 2))
                ok = tight if tight_used[-1] else ok
            x = v[ok] if v.size else v
            if x.size >= 2 and x.mean() != 0.0 and figure["seeds"] >= 2:
                budgets.append(distributions.budget_tolerance(x, int(figure["seeds"])))
        budget = min(budgets) if budgets else 0.0
        if budget > dist_tol:
            whose = ("" if not tight_used else
                     "the seeds that are not loosely wound on " if all(tight_used) else
                     "all seeds (fewer than two are not loosely wound) on " if not any(tight_used) else
                     "the seeds that are not loosely wound where at least two are, all seeds elsewhere, on ")
            out[k] = (budget, f" (half the 95 % error of a mean over the {figure['seeds']} seeds "
                              f"{figure['name']} is configured for, from the 95 % lower bound of the smaller "
                              f"relative spread of {whose}the publication and the finest rung)")
        else:
            out[k] = (dist_tol, "")
    return out


#: a passing ladder names the deciding quantities whose distributions the AD test tells apart at this level
AD_ALPHA = 0.05


def ladder_verdict(values: np.ndarray, members: Mapping[str, np.ndarray], has: np.ndarray, ipub: int,
                   tol: float, dist_tol: float, seeds: np.ndarray | None = None,
                   served: list[Mapping[str, Any]] | None = None) -> tuple[str, list[str], dict[str, list]]:
    """(status, notes, table) of a ladder of ensembles ordered coarse to fine. ``members[k]`` is
    (rung, member) with NaN where member k has no value (no regular helix, say). ``seeds`` (rung,
    member): every rung starts a seed from the same rod (sim/perturbation.py), so the shifts are
    estimated from the differences seed by seed over the seeds both rungs have a value for
    (distributions.compare, paired); without it, unpaired.

    Every rung finer than the publication one is compared with it (distributions.compare): the
    local relation (RELATION_KEYS) against ``tol``, the state (STATE_KEYS) against ``dist_tol``; the
    descriptors only by their AD p-value; with ``served`` figures (module docstring) each state
    quantity against its state_tolerances, and the quantities none of them reports are compared
    but do not decide (table flag ``deciding``). fail if a comparison is beyond its tolerance; else
    inconclusive if one is undecided (its note names the seeds per rung that would decide); else
    pass. A relation with fewer than two values on either rung is not compared (said in the notes);
    a ladder with no local relation on its publication rung is inconclusive."""
    finer = list(range(ipub + 1, len(values)))
    table: dict[str, list] = {k: [] for k in ("rung", "quantity", "cmp", "deciding")}
    notes, decisive = [], []
    loose_notes: dict[int, str] = {}     # rung -> the note of a tested loosely wound share
    if "loosely_wound" in members:
        shares = {j: _loose_share(members["loosely_wound"], has, seeds, values, ipub, j) for j in finer}
        notes += [text for text, _ in shares.values()]
        loose_notes = {j: text for j, (text, tested) in shares.items() if tested}
    state_tol = state_tolerances(members, has, (ipub, len(values) - 1), dist_tol, served)
    if not finer:
        return "inconclusive: no rung finer than the publication value", ["no finer rung"], table
    compared_relation = False
    for k in (*RELATION_KEYS, *STATE_KEYS, *DESCRIPTOR_KEYS):
        if k not in members:
            continue
        for j in finer:
            a, b = aligned(members[k], has, seeds, ipub, j)
            where = f"{k} at {values[j]:g}"
            if a.size < 2 or b.size < 2:
                if k in RELATION_KEYS and (a.size or b.size):
                    notes.append(f"{where}: not compared ({a.size} and {b.size} runs with a regular helix)")
                continue
            if k in DESCRIPTOR_KEYS:
                p = distributions.anderson_p(a, b)
                notes.append(f"{where}: {distributions.ad_text(p)} (mean {a.mean():.3g} against {b.mean():.3g}; "
                             "not deciding)")
                continue
            if np.mean(b) == 0.0:
                continue
            limit, origin = (tol, "") if k in RELATION_KEYS else (state_tol[k] or (dist_tol, ""))
            deciding = k in RELATION_KEYS or state_tol[k] is not None
            c = distributions.compare(a, b, limit, paired=seeds is not None)
            compared_relation |= k in RELATION_KEYS
            table["rung"].append(j)
            table["quantity"].append(k)
            table["cmp"].append(c)
            table["deciding"].append(deciding)
            line = (f"{where}: {c.text(tolerance_note=origin)}" if deciding else
                     f"{where} (described, not deciding: no served figure reports it): {c.text()}")
            notes.append(line)
            if deciding and c.verdict != distributions.WITHIN:
                decisive.append((c, line, j, k))
    if not compared_relation:
        return ("inconclusive: no local relation could be compared (no regular helix on the publication rung and a "
                "finer one)"), notes, table
    beyond = [line for c, line, _, _ in decisive if c.verdict == distributions.BEYOND]
    undecided = [(c, line) for c, line, _, _ in decisive if c.verdict == distributions.UNDECIDED]
    if beyond:
        # a ratio to the torque-free helix that moved with the loosely wound share: the share says why
        why = [loose_notes[j] for j in sorted({j for c, _, j, k in decisive if c.verdict == distributions.BEYOND
                                               and k in local_relations.TORQUE_FREE}) if j in loose_notes]
        return "fail: " + "; ".join(beyond + why), notes, table
    if undecided:
        need = max(c.seeds_needed for c, _ in undecided)
        head = ("no finite number of seeds decides" if math.isinf(need)
                else f"about {math.ceil(need)} seeds per rung would decide")
        return f"inconclusive ({head}): " + "; ".join(line for _, line in undecided), notes, table
    largest = {}
    for k, c, deciding in zip(table["quantity"], table["cmp"], table["deciding"]):
        if deciding and abs(c.shift) >= abs(largest.get(k, c).shift):
            largest[k] = c
    summary = ", ".join(f"{k} {100 * c.shift:+.2g} % (resolution {100 * c.resolution:.3g} %"
                        + (f", tolerance {100 * c.tolerance:.3g} %" if k in STATE_KEYS and c.tolerance != dist_tol
                           else "") + ")" for k, c in largest.items())
    states = (f"final states within {100 * dist_tol:g} %" if not served else
              "final states that " + ", ".join(s["name"] for s in served) + " report within their tolerances")
    shape: dict[str, float] = {}      # quantity -> its smallest AD p-value below AD_ALPHA
    for k, c, deciding in zip(table["quantity"], table["cmp"], table["deciding"]):
        if deciding and c.p_ad < AD_ALPHA:
            shape[k] = min(c.p_ad, shape.get(k, 1.0))
    told = ("" if not shape else
            f"; the Anderson-Darling test tells the rungs' distributions apart at {100 * AD_ALPHA:g} % for "
            + ", ".join(f"{k} ({distributions.ad_text(p)})" for k, p in sorted(shape.items(), key=lambda kp: kp[1]))
            + ": a difference in location or shape that the means' tolerance allows")
    return f"pass: local relation within {100 * tol:g} %, {states} (largest shifts: {summary}){told}", notes, table


def _loose_share(loose: np.ndarray, has: np.ndarray, seeds: np.ndarray | None, values: np.ndarray,
                 i: int, j: int) -> tuple[str, bool]:
    """One note: how many members of rungs i and j are loosely wound, and whether the shares
    differ: paired seeds by McNemar's exact test (the seeds loosely wound on one rung only, split
    half and half under equal shares), unpaired by Fisher's exact test; not deciding (the
    wall-force ratio itself is compared as a state quantity). With it, whether a test was made
    (no loosely wound seed on either rung: none)."""
    from scipy.stats import binomtest, fisher_exact

    a, b = aligned(loose, has, seeds, i, j)
    na, nb = int(a.sum()), int(b.sum())
    head = (f"loosely wound at {values[i]:g} against {values[j]:g}: {na} of {a.size} and {nb} of {b.size} seeds "
            f"(wall force below {local_relations.LOOSE_WALL_RATIO:g} of the torque-free helix's)")
    if not na and not nb:
        return head + "; described, not deciding", False
    if seeds is not None:
        only_a, only_b = int(((a == 1) & (b == 0)).sum()), int(((a == 0) & (b == 1)).sum())
        p = binomtest(min(only_a, only_b), only_a + only_b, 0.5).pvalue if only_a + only_b else 1.0
        test = f"McNemar exact p = {p:.2g} ({only_a} and {only_b} seeds loosely wound on one rung only)"
    else:
        p = fisher_exact([[na, a.size - na], [nb, b.size - nb]]).pvalue
        test = f"Fisher exact p = {p:.2g}"
    return f"{head}; {test}; described, not deciding (the means of the ratios it moves are compared)", True


def aligned(v: np.ndarray, has: np.ndarray, seeds: np.ndarray | None, i: int, j: int) -> tuple[np.ndarray, np.ndarray]:
    """The values of rungs i and j: every member with a value (seeds None), or the seeds both
    rungs have a value for, in one order (paired)."""
    ok_i, ok_j = (has[i] == 1) & np.isfinite(v[i]), (has[j] == 1) & np.isfinite(v[j])
    if seeds is None:
        return v[i][ok_i], v[j][ok_j]
    at_i = {int(s): x for s, x in zip(seeds[i][ok_i], v[i][ok_i])}
    at_j = {int(s): x for s, x in zip(seeds[j][ok_j], v[j][ok_j])}
    common = sorted(set(at_i) & set(at_j))
    return np.array([at_i[s] for s in common]), np.array([at_j[s] for s in common])


def _build_ensemble(fig_cfg, sims, groups, publication_value, context=None) -> xr.Dataset:
    """The ladder with a seed ensemble per rung: members, means, standard errors, the local
    relations and the comparisons with the publication rung (ladder_verdict)."""
    param = fig_cfg["parameter"]
    hname, hfun = REFINEMENT[param]
    groups = sorted(groups, key=lambda g: -hfun(float(sims[g[0]].attrs[param])))
    values = np.array([float(sims[g[0]].attrs[param]) for g in groups])
    h = np.array([hfun(v) for v in values])
    if not np.any(np.isclose(values, publication_value, rtol=1e-9)):
        raise ValueError(f"convergence ladder over {param} does not contain the publication value {publication_value}")
    ipub = int(np.flatnonzero(np.isclose(values, publication_value, rtol=1e-9))[0])
    tol = float(fig_cfg["tolerance"])
    dist_tol = float(fig_cfg.get("distribution_tolerance", tol))
    pad = ensembles.Padded(groups, sims)
    has = pad.has
    per_run = {id(d): _member_values(d) for d in sims.values()}
    keys = (*RELATION_KEYS, *STATE_KEYS, *DESCRIPTOR_KEYS, "loosely_wound")
    members = {k: pad.values(lambda d, k=k: _or_nan(per_run[id(d)][k]), fill=math.nan) for k in keys}
    members = {k: v for k, v in members.items() if np.isfinite(v[has == 1]).any()}
    loose = members.get("loosely_wound")
    seeds = pad.values(lambda d: float(d.attrs["seed"]))
    served = list((context or {}).get("served") or [])
    status, notes, table = ladder_verdict(values, members, has, ipub, tol, dist_tol, seeds=seeds.astype(np.int64),
                                          served=served)
    data = {}
    # and, stored but not deciding, the lower region's friction use (where the l0 ladder's F(L) moves)
    shown = [k for k in (*STATE_KEYS, *RELATION_KEYS, "lower_friction_use") if k in members]
    for k in shown:
        v = members[k]
        ok = (has == 1) & np.isfinite(v)
        st = [ensembles.stats(v[i, ok[i]]) if ok[i].sum() else None for i in range(len(groups))]
        means = np.array([s.mean if s else 0.0 for s in st])
        sems = np.array([s.sem if s else 0.0 for s in st])
        data[k] = variable(("rung",), means, k)
        data[f"{k}_sem"] = xr.Variable(("rung",), sems, attrs={**attrs(k), "long_name": "standard error of the "
                                                                 "ensemble mean of " + attrs(k)["long_name"]})
        data[f"{k}_member"] = xr.Variable(("rung", "member"), np.where(ok, v, 0.0),
                                          attrs={**attrs(k), "long_name": attrs(k)["long_name"]
                                                 + " of each ensemble member (0 where it has none)"})
        data[f"{k}_has"] = xr.Variable(("rung", "member"), ok.astype(np.int8),
                                       attrs={"long_name": f"1 where the member has a value of {k}", "units": "1"})
        data[f"{k}_limit"] = xr.Variable((), means[-1], attrs={**attrs(k), "long_name": "ensemble mean at the finest "
                                                                "rung of " + attrs(k)["long_name"]})
    quantities = [k for k in (*RELATION_KEYS, *STATE_KEYS) if k in members]
    shape = (len(groups), len(quantities))
    cmp_vars = {"shift": np.zeros(shape), "shift_se": np.zeros(shape), "resolution": np.zeros(shape),
                "p_ad": np.ones(shape), "verdict_code": np.zeros(shape, dtype=np.int8),
                "seeds_needed": np.zeros(shape), "compared_tolerance": np.zeros(shape), "dof": np.zeros(shape)}
    for j, k, c, deciding in zip(table["rung"], table["quantity"], table["cmp"], table["deciding"]):
        q = quantities.index(k)
        cmp_vars["shift"][j, q], cmp_vars["shift_se"][j, q] = c.shift, c.se
        cmp_vars["resolution"][j, q], cmp_vars["p_ad"][j, q] = c.resolution, c.p_ad
        cmp_vars["verdict_code"][j, q] = VERDICT_CODE[c.verdict] if deciding else NOT_DECIDING
        cmp_vars["seeds_needed"][j, q] = -1.0 if math.isinf(c.seeds_needed) else c.seeds_needed
        cmp_vars["compared_tolerance"][j, q] = c.tolerance
        cmp_vars["dof"][j, q] = -1.0 if math.isinf(c.dof) else c.dof       # -1: the normal limit
    for name, arr in cmp_vars.items():
        data[f"cmp_{name}"] = variable(("rung", "quantity"), arr, name)
    if loose is not None:
        flag = (has == 1) & (loose == 1.0)
        data["loosely_wound_member"] = variable(("rung", "member"), flag.astype(np.int8), "loosely_wound_member")
        data["n_loosely_wound"] = variable(("rung",), flag.sum(axis=1), "n_loosely_wound")
    data["n_turns_member"] = xr.Variable(("rung", "member"), pad.values(n_turns), attrs={
        **attrs("n_turns"), "long_name": attrs("n_turns")["long_name"] + " of each ensemble member"})
    data["has_member"] = variable(("rung", "member"), has, "has_member")
    data["member_seed"] = variable(("rung", "member"), seeds.astype(np.int64), "member_seed")
    data["n_seeds"] = variable(("rung",), has.sum(axis=1), "n_seeds")
    data["converged"] = variable(("rung",), np.int8(pad.values(lambda d: float(d["converged"])).min(
        axis=1, initial=1, where=has == 1)), "converged")
    data["wall_time"] = variable(("rung",), pad.values(lambda d: float(d["wall_time"])).sum(axis=1), "wall_time")
    compared = [k for k in shown if k in (*STATE_KEYS, *RELATION_KEYS)]
    dist = [max([abs(c.shift) for kk, c in zip(table["quantity"], table["cmp"]) if kk == k] or [0.0])
            for k in compared]
    data["observed_order"] = variable(("observable",), np.zeros(len(compared)), "observed_order")
    data["publication_distance"] = variable(("observable",), dist, "publication_distance")
    coords = {"rung": xr.Variable(("rung",), np.array([g[0].rsplit("-s", 1)[0] for g in groups], dtype=object),
                                  attrs=attrs("scene")),
              "value": xr.Variable(("rung",), values, attrs={**attrs("value"), "long_name": f"value of {param}",
                                                              "parameter": param}),
              "h": xr.Variable(("rung",), h, attrs={**attrs("h"), "definition": hname}),
              "member": variable(("member",), np.arange(has.shape[1]), "member"),
              "observable": xr.Variable(("observable",), np.array(compared, dtype=object),
                                        attrs=attrs("observable")),
              "quantity": xr.Variable(("quantity",), np.array(quantities, dtype=object), attrs=attrs("quantity"))}
    # every coarser rung against the finest: where along the rod the transmitted force moves
    splits = [_split_by_region(sims, groups, i, len(groups) - 1) for i in range(len(groups) - 1)]
    if ipub < len(groups) - 1 and splits[ipub] is not None:
        nreg = len(regions.REGIONS) + 1
        shift = np.array([sp[0] if sp else np.zeros(nreg) for sp in splits] + [np.zeros(nreg)])
        se = np.array([sp[1] if sp else np.zeros(nreg) for sp in splits] + [np.zeros(nreg)])
        data["F_shift_split_seeds"] = variable(("rung",), np.array([sp[2] if sp else 0 for sp in splits] + [0]),
                                               "F_shift_split_seeds")
        data["F_shift_split_total"] = variable(("rung",), shift[:, -1], "F_shift_split_total")
        data["F_shift_split_total_se"] = variable(("rung",), se[:, -1], "F_shift_by_region_se")
        data["F_shift_split_total_se"].attrs["long_name"] = ("standard error of F_shift_split_total over the "
                                                             "paired seeds")
        shift, se = shift[:, :-1], se[:, :-1]
        data["F_shift_by_region"] = variable(("rung", "region"), shift, "F_shift_by_region")
        data["F_shift_by_region_se"] = variable(("rung", "region"), se, "F_shift_by_region_se")
        data["F_shift_by_region_has"] = xr.Variable(("rung",), np.array([sp is not None for sp in splits] + [False],
                                                                         dtype=np.int8),
                                                    attrs={"long_name": "1 where the rung's shift against the finest "
                                                           "rung is split by region", "units": "1"})
        nr = len(regions.REGIONS)
        data["F_shift_by_region_cov"] = variable(("rung", "region", "region_b"), np.array(
            [sp[3] if sp else np.zeros((nr, nr)) for sp in splits] + [np.zeros((nr, nr))]), "F_shift_by_region_cov")
        data["F_split_mean"] = variable(("rung",), [sp[4][0] if sp else 0.0 for sp in splits] + [0.0], "F_split_mean")
        data["bulk_part_split_mean"] = variable(("rung",), [sp[4][1] if sp else 0.0 for sp in splits] + [0.0],
                                                "bulk_part_split_mean")
        coords["region"] = xr.Variable(("region",), np.array(regions.REGIONS, dtype=object), attrs=attrs("rod_region"))
        coords["region_b"] = xr.Variable(("region_b",), np.array(regions.REGIONS, dtype=object),
                                         attrs=attrs("rod_region"))
        for i, sp in enumerate(splits):
            if sp is not None:
                notes.append(f"F_transmitted at {values[i]:g} against {values[-1]:g} by region from the loaded end "
                             f"({sp[2]} paired seeds, -F_i(L) F_j(L) times the change of what the region adds to "
                             "1/|F_z| over the mean F_j(L): the regions sum to the shift of the mean): "
                             + ", ".join(f"{r} {100 * a:+.2g} +- {100 * b:.2g} %"
                                         for r, a, b in zip((*regions.REGIONS, "sum"), sp[0], sp[1])))
    ds = xr.Dataset(data, coords=coords)
    ds.attrs.update({"parameter": param, "refinement": hname, "publication_value": publication_value,
                     "tolerance": tol, "distribution_tolerance": dist_tol, "status": status,
                     # the largest shift of a deciding comparison (the table's 'off'; described ones excluded)
                     "worst_distance": max([abs(c.shift) for c, deciding in zip(table["cmp"], table["deciding"])
                                            if deciding] or [0.0]),
                     "notes": "; ".join(notes),
                     "comparisons": "\n".join(notes),
                     "paired": int(bool(fig_cfg.get("paired", False))),
                     "serves": (", ".join(f"{s['name']} ({s['seeds']} seeds configured: {', '.join(s['reports'])})"
                                          for s in served) or "none"),
                     "method": (f"seed ensembles, two questions: the local relation of the regular helix "
                                f"({', '.join(RELATION_KEYS)}; analysis.local_relations) within {100 * tol:g} % and "
                                f"the distribution of final states ({', '.join(STATE_KEYS)}) within "
                                + (f"{100 * dist_tol:g} %" if not served else
                                   f"the larger of {100 * dist_tol:g} % and half the 95 % error of the served "
                                   "figures' means (the quantities they report; the others described)")
                                + " of every finer rung; each shift of the ensemble mean decided "
                                "by its 95 % bound, with the resolution at 95 % power and the Anderson-Darling "
                                "k-sample p-value stated (analysis.distributions)")})
    return ds


def _split_by_region(sims, groups, i: int, j: int) -> tuple | None:
    """Where along the rod the transmitted force of rung i moves against rung j, over the seeds
    that ran with a bulk on both: with X_r what region r adds to 1/|F_z| (regions.force_parts;
    they sum to 1/F(L) - 1/F(0), F(0) the load on both rungs), per seed exactly
    F_i - F_j = -F_i F_j sum_r (X_r,i - X_r,j), so the shift of the ensemble mean,
    sum_s (F_i - F_j) / sum_s F_j, is the sum over the regions of
    mean_s(-F_i F_j dX_r) / mean_s(F_j): each region's share, exact also for a seed that jumped
    to another state (a first-order split, -F_j dX_r, does not close there). Their means with
    standard errors (the spread of the per-seed shares over sqrt(n)) and the number of seeds; the
    fourth column is their sum, the shift of the mean over these seeds; then the covariance of
    the three regions' mean shares, and rung i's mean F(L) and mean bulk part X_bulk over these
    seeds (what the error budget rescales the shares to another rod with). None without friction
    or with fewer than two such seeds."""
    if any(float(d.attrs["k_fr"]) <= 0.0 for d in sims.values()):
        return None

    def by_seed(group):
        out = {}
        for name in group:
            d = sims[name]
            parts = regions.force_parts(d)
            if parts is not None:
                out[int(d.attrs["seed"])] = (parts, float(np.abs(d["F_z"].values[-1])))
        return out

    a, b = by_seed(groups[i]), by_seed(groups[j])
    common = sorted(set(a) & set(b))
    if len(common) < 2:
        return None
    mean_j = float(np.mean([b[s][1] for s in common]))
    d = np.array([[-a[s][1] * b[s][1] * (a[s][0][r] - b[s][0][r]) / mean_j for r in regions.REGIONS]
                  for s in common])
    n = len(common)
    # the covariance of the regions' mean shares (a rescaled sum's error: analysis.error_budget)
    cov = np.cov(d, rowvar=False, ddof=1) / n
    # the regions' sum as a fourth column: the shift of the mean F(L) over these seeds
    d = np.column_stack([d, d.sum(axis=1)])
    # the rod the shares were measured on (rung i): its mean F(L) and what its bulk adds to 1/|F_z|
    at_i = (float(np.mean([a[s][1] for s in common])), float(np.mean([a[s][0]["bulk"] for s in common])))
    return d.mean(axis=0), d.std(axis=0, ddof=1) / math.sqrt(n), n, cov, at_i


def _or_nan(v) -> float:
    return math.nan if v is None else float(v)


def check(ds: xr.Dataset, figure: str, on_inconclusive: str = "fail", on_fail: str = "fail") -> str:
    """Raise ConvergenceError if the check failed (unless the config says a failure warns) or was
    inconclusive (if the config says that fails too); return a one-line summary otherwise."""
    status = ds.attrs["status"]
    if "quantity" in ds.coords:
        line = (f"{figure}: {ds.attrs['parameter']} = {ds.attrs['publication_value']:g}, local relation "
                f"(tolerance {100 * ds.attrs['tolerance']:g} %) and final states (tolerance "
                f"{100 * ds.attrs['distribution_tolerance']:g} %"
                + ("" if ds.attrs.get("serves", "none") == "none" else
                   f", or half the 95 % error of the means of {ds.attrs['serves']} where that is larger")
                + f") against every finer rung: {status}")
    else:
        line = (f"{figure}: {ds.attrs['parameter']} = {ds.attrs['publication_value']:g} is "
                + ", ".join(f"{k} {100 * d:.3g} %" for k, d in zip(ds["observable"].values,
                                                                    ds["publication_distance"].values))
                + f" from the limit ({_limit_sources(ds)}; tolerance {100 * ds.attrs['tolerance']:g} %): {status}")
        if "pitch_theory_deviation" in ds.attrs:
            line += (f"; the pitch is that of the discrete chain's torque-free helix (theory.discrete_helix) "
                     f"within {100 * ds.attrs['pitch_theory_deviation']:.2g} % on every rung")
    word = verdict_word(status)
    if (word == "fail" and on_fail == "fail") or (word == "inconclusive" and on_inconclusive == "fail"):
        raise ConvergenceError(line)
    return line


#: the refinement axis: h on a log scale, ticked at the rungs by the parameter's value
_X_LABEL = {"l0": r"$l_0$ [$R$] (axis: $h = l_0$)", "k_ph": r"$k_{ph}$ [$EI/R^2$] (axis: $h = 1/k_{ph}$)",
            "k_w": r"$k_w$ [$EI/R^3$] (axis: $h = 1/k_w$)", "k_t": r"$k_t$ [$EI/R^3$] (axis: $h = 1/k_t$)",
            "tol": r"tol (axis: $h$ = tol)", "ramp_steps": r"$n_{ramp}$ (axis: $h = 1/n_{ramp}$)",
            "dx_max": r"$dx_{max}$ [$R$] (axis: $h = dx_{max}$)"}


def _extrapolated(ds: xr.Dataset, k: str) -> bool:
    """Whether a single-run ladder's limit of k is Richardson's extrapolation (else the finest rung's value)."""
    return ds[f"{k}_limit"].attrs.get("comment", "").startswith("Richardson")


def _limit_sources(ds: xr.Dataset) -> str:
    """Where a single-run ladder's limits come from, for its check line: Richardson's extrapolation
    from the three finest rungs, or the finest rung's value where its differences are already
    below a tenth of the tolerance (richardson's ``resolved``)."""
    obs = list(ds["observable"].values)
    rich = [k for k in obs if _extrapolated(ds, k)]
    fine = [k for k in obs if k not in rich]
    parts = ([f"Richardson's extrapolation for {', '.join(rich)}"] if rich else []) + (
        [f"the finest rung for {', '.join(fine)}, whose finest differences are below a tenth of the tolerance"]
        if fine else [])
    return "; ".join(parts)


def _seed_lines(ax, ds: xr.Dataset, k: str, h: np.ndarray, has: np.ndarray) -> None:
    """A paired ladder (every rung starts a seed from the same rod): each seed's values joined
    across the rungs, so that a seed that moves to a neighbouring equilibrium shows."""
    seeds, v = ds["member_seed"].values, ds[f"{k}_member"].values
    for s in np.unique(seeds[has]):
        at = [(h[i], v[i, list(seeds[i]).index(s)]) for i in range(len(h)) if s in seeds[i][has[i]]]
        ax.plot(*zip(*at), "-", **P.SEEDS, lw=0.5, zorder=1)


def _rung_ticks(ax, ds: xr.Dataset) -> None:
    """The refinement axis ticked at the rungs, labelled by the parameter's value (a ramp's step
    count, k's value, ...), so that every rung is named; the log axis keeps no other labels."""
    from matplotlib import ticker

    h, values = ds["h"].values, ds["value"].values
    ax.xaxis.set_major_locator(ticker.FixedLocator(h))
    ax.xaxis.set_major_formatter(ticker.FixedFormatter([f"{v:g}" for v in values]))
    ax.xaxis.set_minor_formatter(ticker.NullFormatter())
    if len(h) and max(len(f"{v:g}") for v in values) > 4:
        ax.tick_params(axis="x", labelrotation=30)


def _y_label(k: str) -> str:
    """The quantity's label with its fractions set in display style: a text-style fraction prints
    its numerator and denominator at 70 % of the axis label's size, below 7 pt."""
    return label(k).replace(r"\frac", r"\dfrac")


def loose_counts(ds: xr.Dataset) -> tuple[np.ndarray, np.ndarray] | None:
    """Per rung, the loosely wound seeds and the seeds with a regular helix to tell (the flag is
    read from the wall-force ratio, local_relations.loosely_wound); None if the ladder stores no flag."""
    if "n_loosely_wound" not in ds:
        return None
    n = ds["n_loosely_wound"].values.astype(int)
    told = (ds["wall_force_ratio_has"].values.sum(axis=1) if "wall_force_ratio_has" in ds
            else ds["n_seeds"].values).astype(int)
    return n, told


def _loose_text(ds: xr.Dataset) -> str:
    """One title line, over the decay ratio's panel: how many seeds of every rung are loosely
    wound, out of those with a regular helix ('' if none)."""
    counts = loose_counts(ds)
    if counts is None or not counts[0].sum():
        return ""
    n, total = counts
    v = ds["value"].values
    if np.array_equal(n, total):
        return "every seed loosely wound"
    return (f"loosely wound: {', '.join(f'{n[i]}/{total[i]}' for i in range(n.size))}\n"
            f"at {', '.join(f'{x:g}' for x in v)}")


def plot(ds: xr.Dataset):
    """One panel per quantity against the refinement variable h (log axis). Single runs: the
    rungs, the Richardson limit and the tolerance band about it. Ensembles: the single seeds,
    the means with their 95 % intervals, the tolerance band about the finest rung's mean, and
    per panel the largest shift of the publication rung with its resolution."""
    ensemble = "quantity" in ds.coords
    obs = [k for k in ((*STATE_KEYS, *RELATION_KEYS) if ensemble else OBSERVABLES) if k in ds]
    ncol = min(len(obs), 3)
    nrow = math.ceil(len(obs) / ncol)
    # at most the printed page's height (plotting.MAX_HEIGHT_IN): a taller figure is scaled down
    # when printed, and its smallest text with it, below plotting.MIN_FONT_PT
    height = min(2.9 * nrow + 0.9, P.MAX_HEIGHT_IN - 0.2)
    fig, axes = P.plt.subplots(nrow, ncol, figsize=(7.0, height), squeeze=False, label=ds.attrs["title"])
    h = ds["h"].values
    param = ds.attrs["parameter"]
    pub = np.isclose(ds["value"].values, float(ds.attrs["publication_value"]), rtol=1e-9)
    checked = list(ds["observable"].values)
    for ax, k in zip(axes.flat, obs):
        f = ds[k].values
        if not ensemble and k == "pitch" and not (ds["n_turns"].values >= 1.0).all():
            # a rung that is not a helix has no pitch: its rungs are left out, never drawn as 0
            helical = ds["n_turns"].values >= 1.0
            ax.plot(h[helical], f[helical], "o", ms=4.5, **P.SIM)
            ax.set_title("not checked: rung(s) " + ", ".join(f"{v:g}" for v in ds["value"].values[~helical])
                         + " not helical", fontsize=7.5)
            ax.set_xscale("log")
            _rung_ticks(ax, ds)
            ax.set_xlabel(_X_LABEL[param])
            ax.set_ylabel(_y_label(k))
            continue
        tol = float(ds.attrs["distribution_tolerance"] if ensemble and k in STATE_KEYS else ds.attrs["tolerance"])
        codes_k = ds["cmp_verdict_code"].sel(quantity=k).values if ensemble else np.zeros(0)
        if (codes_k > 0).any():
            # the tolerance the comparisons were decided against (a served figure's: per quantity)
            tol = float(ds["cmp_compared_tolerance"].sel(quantity=k).values.max())
        # a quantity no served figure reports is described, not decided: no tolerance band
        described = bool((codes_k > 0).any() and (codes_k[codes_k > 0] == NOT_DECIDING).all())
        if not ensemble:  # single runs: the rungs joined (an ensemble's means stand alone, beside its seeds' lines)
            ax.plot(h, f, "-", color="0.6", lw=0.7)
        if ensemble:
            has = ds[f"{k}_has"].values == 1
            hm = np.broadcast_to(h[:, None], has.shape)
            ax.plot(hm[has], ds[f"{k}_member"].values[has], ".", ms=3, **P.SEEDS, label="single seeds")
            if ds.attrs.get("paired"):
                _seed_lines(ax, ds, k, h, has)
            if "loosely_wound_member" in ds and (loose := has & (ds["loosely_wound_member"].values == 1)).any():
                ax.plot(hm[loose], ds[f"{k}_member"].values[loose], "v", ms=3.5, mfc="none", mec="tab:orange",
                        mew=0.8, zorder=3, label="loosely wound seeds")
            t95 = [distributions.t_quantiles(n - 1.0)[0] if n > 1 else 0.0 for n in has.sum(axis=1)]
            ax.errorbar(h, f, yerr=np.array(t95) * ds[f"{k}_sem"].values, fmt="none", ecolor="black",
                        elinewidth=0.9, capsize=2.5)
        ax.plot(h, f, "o", ms=4.5, **P.SIM, label="ensemble means, 95 % interval" if ensemble else "rungs")
        ax.plot(h[pub], f[pub], "s", ms=9, mfc="none", mec="tab:green", mew=1.4, label="publication setting")
        if k == "pitch" and "pitch_theory" in ds:
            ax.plot(h, ds["pitch_theory"].values, "x", ms=7, color="tab:red", label="discrete helix (theory)")
        lim = float(ds[f"{k}_limit"]) if f"{k}_limit" in ds else None
        if lim is not None:
            richardson = not ensemble and _extrapolated(ds, k)
            # one legend serves every panel: the Richardson limit dashed, a finest rung dotted
            ax.axhline(lim, **(P.MODEL | ({} if richardson else {"ls": ":"})),
                       label="finest rung's mean" if ensemble else "Richardson limit" if richardson else "finest rung")
            if not described:
                # the band never sets the axes: a tolerance much wider than the rungs' spread would
                # squash them onto one line (a band filling the panel: every rung is inside it);
                # the axes span at least a fifth of the tolerance, so that rungs equal to round-off
                # are drawn as equal, not as an offset scale of their last digits
                y0, y1 = ax.get_ylim()
                ax.axhspan(lim * (1 - tol), lim * (1 + tol), color="tab:blue", alpha=0.12, lw=0,
                           label=rf"{'finest' if ensemble else 'limit'} $\pm$ tolerance")
                lo, hi = sorted((lim * (1 - tol / 5), lim * (1 + tol / 5)))
                ax.set_ylim(min(y0, lo), max(y1, hi))
        if ensemble:
            q = list(ds["quantity"].values).index(k)
            codes = ds["cmp_verdict_code"].values[:, q]
            rows = np.flatnonzero(codes > 0)
            if rows.size:
                j = rows[np.argmax(np.abs(ds["cmp_shift"].values[rows, q]))]
                if described:
                    # the comparison is still made against the tolerance, and said, but not counted
                    dof = float(ds["cmp_dof"].values[j, q]) if "cmp_dof" in ds else -1.0
                    verdict = distributions.decide(float(ds["cmp_shift"].values[j, q]),
                                                   float(ds["cmp_shift_se"].values[j, q]),
                                                   dof if dof > 0 else math.inf, tol)
                    word = f"{verdict} {100 * tol:.3g} % (described)"
                else:
                    word = {1: "within", 2: "beyond", 3: "undecided"}[int(codes[j])] + f" {100 * tol:.3g} %"
                # once, over the decay ratio's panel (the first of the ratios to the torque-free helix)
                first = next((q for q in local_relations.TORQUE_FREE if q in obs), None)
                left = "\n" + _loose_text(ds) if k == first and _loose_text(ds) else ""
                ax.set_title(f"against {ds['value'].values[j]:g}: shift "
                             f"{100 * ds['cmp_shift'].values[j, q]:+.2g} $\\pm$ "
                             f"{100 * ds['cmp_shift_se'].values[j, q]:.2g} %\nresolution "
                             f"{100 * ds['cmp_resolution'].values[j, q]:.3g} %\n{word}{left}", fontsize=7.5)
            else:
                ax.set_title("not compared (fewer than two values)", fontsize=7.5)
        elif k in checked:
            i = checked.index(k)
            order = float(ds.observed_order[i])
            dist = f"{100 * float(ds.publication_distance[i]):.2g} %"
            head = f"$p = {order:.2f}$" if order > 0 else "$p$ not measurable"
            ax.set_title(f"{head}, pub. off by {dist}", fontsize=7.5)
        else:
            ax.set_title("not checked (not every rung is a helix)", fontsize=7.5)
        ax.set_xscale("log")
        _rung_ticks(ax, ds)
        ax.set_xlabel(_X_LABEL[param])
        ax.set_ylabel(_y_label(k))
    for ax in list(axes.flat)[len(obs):]:
        ax.set_visible(False)
    head = f"convergence in {P.param_text(param, float(ds.attrs['publication_value'])).split(' =')[0]}$: "
    lines = _title_lines(head, ds.attrs["status"])
    fig.suptitle("\n".join(lines + [P.params_text(ds, ("L", "load", "k_fr"))]), fontsize=9)
    # three entries a row: six in one row (a single-run ladder with its theory and Richardson
    # limit) are wider than the page, and the figure would be printed smaller than its text allows
    P.bottom_legend(fig, axes[0][0], bottom=0.16 / nrow, ncol=3)
    return fig
