"""Kind ``convergence``: a ladder of scenes refining one numerical parameter, its
Richardson limit and the check of the publication setting (rule ``convergence_check``).

  The scenes differ in one numerical parameter
(l0, k_ph, k_w, k_t, tol or ramp_steps).  Its refinement variable h -> 0 is l0,
1/k_ph, 1/k_w, 1/k_t, tol or 1/ramp_steps.  From the three finest rungs h1 > h2 > h3 (ratio r = h1/h2 = h2/h3) and an
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

Seed ensembles per rung (:func:`statistical_verdict`): the publication rung's mean is
compared with every finer rung's mean. The check passes only when every difference plus
two combined standard errors is below the tolerance and fails when a difference minus two
standard errors is above it. In between (a difference within the tolerance whose errors
reach beyond it, or one beyond it that only the error allowance brings back) the ensembles
cannot decide: the verdict is *inconclusive*, and its note gives the difference, the
tolerance, the combined standard error and the seeds per rung that would decide.

Paired ladders (option ``paired``; :func:`paired_verdict`). When every rung starts a seed from
the same state and only the path to equilibrium differs (the number of steps of a load ramp),
the rungs are compared seed by seed, which removes the spread between seeds. With friction a
finer path can end in a neighbouring equilibrium (half a turn more or less of the helix), which
is a change of final state, not a refinement of the same one. The verdict is decided on all
seeds (the mean paired change plus its 95 % Student-t bound within the tolerance: how much a
finer path moves the ensemble), and the note splits the change into the seeds that keep their
state and those that changed it, each listed.
"""
from __future__ import annotations

import math
import re
import textwrap
from typing import Any, Mapping

import numpy as np
import xarray as xr

from ... import layout
from ...errors import ConfigError
from .. import ensembles, run_checks
from .. import plotting as P
from ..figure_quantities import attrs, label, variable
from ..measure import bulk_pitch, n_turns
from ._common import same_except

REFINEMENT = {"l0": ("h = l0", lambda v: v), "tol": ("h = tol", lambda v: v),
              "k_ph": ("h = 1/k_ph", lambda v: 1.0 / v), "k_w": ("h = 1/k_w", lambda v: 1.0 / v),
              "k_t": ("h = 1/k_t", lambda v: 1.0 / v), "ramp_steps": ("h = 1/n_ramp", lambda v: 1.0 / v)}
OBSERVABLES = ("F_transmitted", "L_z", "pitch")
OPTIONS = {
    "parameter": {"enum": list(REFINEMENT), "description": "the numerical parameter the rungs differ in"},
    "tolerance": {"type": "number", "exclusiveMinimum": 0, "description": "largest relative distance of the "
                  "publication setting from the extrapolated limit (of F_transmitted, L_z and the bulk pitch) "
                  "before the build fails"},
    "on_inconclusive": {"enum": ["fail", "warn"], "description": "what an inconclusive check (rungs in different "
                        "equilibrium states, non-monotone differences) does to the build: fail, or warn and go on"},
    "paired": {"type": "boolean", "description": "compare the rungs seed by seed (paired_verdict): for ladders whose "
               "rungs start every seed from the same state (ramp_steps); default false"},
    "publication_value": {"type": "number", "description": "the value the figures use when it is not a scene default "
                          "(e.g. the ramp_steps of the ramped figures); default: scene_defaults or the Scene default"},
}


ENSEMBLES = True
Z_AGREE = 2.0   # rungs agree within the tolerance plus this many combined standard errors


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


#: an ensemble ladder draws (and checks) the pitch only where it is defined on every rung it reads
PITCH_PANEL = ("the bulk pitch (a panel only where every rung the verdict reads is a helix of at least one turn; "
               "else the pitch is not checked and not drawn)")


def caption(figure, fig_cfg, built, publication_value=None) -> str:
    p = fig_cfg["parameter"]
    sc = next(iter(built.values()))
    values = sorted({getattr(s, p) for s in built.values()}, reverse=True)
    vals = ", ".join(f"{v:g}" for v in values)
    n = len(built) / len(values)
    if n > 1 and fig_cfg.get("paired"):
        what = "a quasi-static load ramp of n_ramp steps" if p == "ramp_steps" else p
        return (f"Convergence in the path to equilibrium: {what}, {p} = {vals} (L/R = {sc.L:g}, load = "
                f"{sc.load:g} EI/R^2, k_fr = {sc.k_fr:g}), each rung the same {n:g} seeds (a seed not at a stable "
                f"equilibrium at some rung, capped or on a saddle, is left out at every rung and named in the "
                f"verdict): ensemble means of the "
                f"transmitted force, L_z and {PITCH_PANEL} against the refinement variable (error bars two standard "
                f"errors), {P.words(P.SEEDS)} dots and lines the single seeds, {P.words(P.MARK)} circles the seeds "
                f"that end in another final "
                f"state than at the publication value (winding by at least {ensembles.STATE_TURNS:g} turn); the band "
                f"of +-{100 * float(fig_cfg['tolerance']):g} % about the finest rung's mean. The rungs are compared "
                f"seed by seed: the publication value {p} = {publication_value:g} passes when the mean paired change "
                "to every finer rung over all seeds, plus its 95 % Student-t bound, is within the tolerance; the seeds "
                "that change state (a finer path may select a neighbouring equilibrium) are listed apart in the "
                f"verdict ({layout.CHECKS}).")
    if n > 1:
        return (f"Convergence in {p} = {vals} (L/R = {sc.L:g}, k_fr = {sc.k_fr:g}), each rung a seed ensemble of "
                f"{n:g} runs: ensemble means of the transmitted force, L_z and {PITCH_PANEL} against the refinement "
                f"variable, error bars two standard errors, {P.words(P.SEEDS)} dots the single seeds; the band of "
                f"+-{100 * float(fig_cfg['tolerance']):g} % about the finest rung's mean. The publication value "
                f"{p} = {publication_value:g} passes when its difference from every finer rung plus two combined "
                "standard errors is within the tolerance and fails when the difference minus two standard errors "
                "exceeds it; otherwise the ensembles are too small to decide and the verdict is inconclusive, with "
                "the seeds per rung that would decide it.")
    return (f"Convergence in {p} = {vals} (L/R = {sc.L:g}, k_fr = {sc.k_fr:g}): transmitted force, L_z and "
            f"bulk pitch against the refinement variable, with the Richardson limit from the three finest "
            f"rungs and the band of +-{100 * float(fig_cfg['tolerance']):g} % about it that the publication "
            f"value {p} = {publication_value:g} must lie in.")


def richardson(h: np.ndarray, f: np.ndarray, resolved: float = 0.0) -> tuple[float, float, str]:
    """(observed order, limit, note) from the three finest rungs (h descending).

    ``resolved``: differences below this (absolute) are taken as converged: the
    finest value is the limit and the order is not measurable (reported as 0).
    Without it, noise at the level of the equilibrium tolerance would make a
    converged ladder look non-monotone."""
    h1, h2, h3 = h[-3:]
    f1, f2, f3 = f[-3:]
    r = h1 / h2
    if not math.isclose(h2 / h3, r, rel_tol=0.02):
        return 0.0, float(f3), "ladder not geometric; limit = finest value"
    d1, d2 = f1 - f2, f2 - f3
    if d2 == 0.0:
        return 0.0, float(f3), "converged to round-off"
    if max(abs(d1), abs(d2)) <= resolved:
        return 0.0, float(f3), "finest differences below a tenth of the tolerance (converged)"
    q = d1 / d2
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
        return _build_ensemble(fig_cfg, sims, groups, float((context or {})["publication_value"]))
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
    for k, lim in zip(checked, limit):  # one variable per observable: they carry different units
        data[f"{k}_limit"] = xr.Variable((), lim, attrs={**attrs(k), "long_name": "extrapolated limit h -> 0 of the "
                                                          + attrs(k)["long_name"]})
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
    return ds


def agree(m1: float, e1: float, m2: float, e2: float, tol: float) -> bool:
    """Two ensemble means agree: |m1 - m2| <= tol |m2| + Z_AGREE sqrt(e1^2 + e2^2) (m2 the finer rung)."""
    return abs(m1 - m2) <= tol * abs(m2) + Z_AGREE * math.hypot(e1, e2)


def seeds_to_decide(n: float, se: float, dist: float, tol: float) -> float:
    """Seeds per rung that make Z_AGREE combined standard errors smaller than the margin
    |tol - dist| (all relative), so that the comparison with the tolerance is decided: the
    standard errors shrink as 1/sqrt(n), so n (Z_AGREE se / margin)^2. inf at dist = tol."""
    margin = abs(tol - dist)
    return math.inf if margin == 0.0 else n * (Z_AGREE * se / margin) ** 2


def statistical_verdict(values: np.ndarray, means: np.ndarray, sems: np.ndarray, ipub: int,
                        tol: float, n: np.ndarray | None = None) -> tuple[str, float, str]:
    """(status, distance, note) of one observable over rungs ordered coarse to fine.

    For every rung finer than the publication one, with d the relative difference of the
    means and e their combined relative standard error: decided within the tolerance if
    d + Z_AGREE e <= tol, decided beyond it if d - Z_AGREE e > tol, undecided otherwise.
    pass: every finer rung decided within; fail: one decided beyond; inconclusive: the finer
    rungs disagree among themselves beyond tolerance and errors, or a comparison is
    undecided. An undecided comparison is not a pass, also when the point difference is
    above the tolerance and only the errors reach it: its note gives d, the tolerance, e
    and the seeds per rung (``n``: the seeds of each rung) that would decide it
    (:func:`seeds_to_decide`). The distance is the largest d."""
    finer = list(range(ipub + 1, len(values)))
    if not finer:
        return "inconclusive", 0.0, "no rung finer than the publication value"
    for a in finer:
        for b in finer:
            if a < b and not agree(means[a], sems[a], means[b], sems[b], tol):
                return ("inconclusive", 0.0,
                        f"the finer ensembles disagree beyond their errors: {values[a]:g}: {means[a]:.5g} +- "
                        f"{sems[a]:.2g}, {values[b]:g}: {means[b]:.5g} +- {sems[b]:.2g} (difference "
                        f"{abs(means[a] - means[b]) / math.hypot(sems[a], sems[b]):.1f} combined s.e.)")
    rel = {j: (abs(means[ipub] - means[j]) / abs(means[j]), math.hypot(sems[ipub], sems[j]) / abs(means[j]))
           for j in finer}
    worst = max(finer, key=lambda j: rel[j][0])
    dist = rel[worst][0]
    beyond = [j for j in finer if rel[j][0] - Z_AGREE * rel[j][1] > tol]
    undecided = [j for j in finer if j not in beyond and rel[j][0] + Z_AGREE * rel[j][1] > tol]

    def numbers(j):
        d, e = rel[j]
        return (f"{values[j]:g}: difference {100 * d:.2g} %, tolerance {100 * tol:g} %, combined s.e. "
                f"{100 * e:.2g} % ({d / e if e > 0 else math.inf:.1f} s.e.)")

    if beyond:
        j = max(beyond, key=lambda j: rel[j][0])
        return ("fail", dist, "the publication rung differs from the finer rungs beyond tolerance and errors: "
                + numbers(j))
    if undecided:
        parts = []
        for j in undecided:
            d, e = rel[j]
            nj = max(float(n[ipub]), float(n[j])) if n is not None else None
            need = seeds_to_decide(nj if nj is not None else 1.0, e, d, tol)
            what = ("exclude the tolerance" if d > tol else "confirm the tolerance")
            if n is None:
                seeds = f"{need:.3g} times the seeds per rung"
            elif math.isinf(need):
                seeds = "no finite number of seeds (the difference equals the tolerance)"
            else:
                seeds = f"about {math.ceil(need)} seeds per rung (now {nj:g})"
            parts.append(f"{numbers(j)}: {Z_AGREE:g} s.e. exceed the margin {100 * abs(tol - d):.2g} %; to "
                         f"{what} needs {seeds}")
        return "inconclusive", dist, "undecided at the tolerance: " + "; ".join(parts)
    return "pass", dist, "ok, largest " + numbers(worst)


def t_factor(n: int) -> float:
    """Two-sided 95 % Student-t factor for the mean of n values (n - 1 degrees of freedom): the
    bound a paired ladder uses instead of Z_AGREE, since its ensembles can be as small as 3
    (t = 4.30 there, 2.13 for 16 seeds)."""
    from scipy.stats import t

    return float(t.ppf(0.975, n - 1))


def paired_seeds_to_decide(n: int, se: float, dist: float, tol: float, n_max: int = 100_000) -> float:
    """Seeds that make the 95 % Student bound t(m) s/sqrt(m) smaller than the margin |tol - dist|,
    with s = se sqrt(n) the spread of the paired changes seen with n seeds; inf if none up to n_max."""
    margin, spread = abs(tol - dist), se * math.sqrt(n)
    if margin == 0.0:
        return math.inf
    m = max(n + 1, 2, math.ceil((1.96 * spread / margin) ** 2))    # the large-m bound is a lower limit
    while m <= n_max:
        if t_factor(m) * spread / math.sqrt(m) < margin:
            return float(m)
        m += max(1, m // 50)
    return math.inf


def paired_verdict(values: np.ndarray, v: np.ndarray, seeds: np.ndarray, turns: np.ndarray, has: np.ndarray,
                   ipub: int, tol: float) -> tuple[str, float, str]:
    """(status, distance, note) of one observable over rungs ordered coarse to fine, each finer
    rung compared with the publication rung seed by seed (:func:`confined_rod.analysis.ensembles.paired_changes`).

    Over all seeds both rungs have, d = |mean relative change| and e its standard error, with
    t the 95 % Student factor (:func:`t_factor`): within the tolerance if d + t e <= tol, beyond it
    if d - t e > tol, undecided otherwise (the note gives the seeds that would decide). A seed
    that ends in another final state counts like any other: the question is how much a finer
    path changes the ensemble. The note splits the change: over the seeds that keep their state
    (a refinement of one equilibrium) and the seeds that changed it (another equilibrium), each
    listed. The distance is the largest d."""
    finer = list(range(ipub + 1, len(values)))
    if not finer:
        return "inconclusive", 0.0, "no rung finer than the publication value"
    verdicts, dist, parts = [], 0.0, []
    for j in finer:
        common, rel, changed = ensembles.paired_changes(seeds, v, turns, has, ipub, j)
        if rel.size < 2:
            verdicts.append("inconclusive")
            parts.append(f"{values[j]:g}: fewer than two seeds on both rungs")
            continue
        st, kept = ensembles.stats(rel), rel[~changed]
        d, e, t = abs(st.mean), st.sem, t_factor(rel.size)
        dist = max(dist, d)
        ks = ensembles.stats(kept) if kept.size >= 2 else None
        same = (f"; over the {ks.n} seeds that keep their final state {100 * ks.mean:+.2g} +- {100 * ks.sem:.2g} % "
                f"(largest {100 * max(abs(ks.min), abs(ks.max)):.2g} %)" if ks else "")
        switched = (f"; {int(changed.sum())} of {rel.size} seeds changed their final state (winding by >= "
                    f"{ensembles.STATE_TURNS:g} turn): " + ", ".join(f"seed {s} {100 * r:+.2g} %" for s, r in
                                                          zip(common[changed], rel[changed]))
                    if changed.any() else f"; none of {rel.size} seeds changed its final state")
        head = (f"{values[j]:g}: paired change {100 * st.mean:+.2g} +- {100 * e:.2g} % (s.e., {rel.size} seeds, "
                f"95 % bound {100 * (d + t * e):.2g} %), tolerance {100 * tol:g} %")
        if d - t * e > tol:
            verdicts.append("fail")
            parts.append(head + ": beyond" + same + switched)
        elif d + t * e > tol:
            verdicts.append("inconclusive")
            need = paired_seeds_to_decide(rel.size, e, d, tol)
            parts.append(head + (f": undecided, about {math.ceil(need)} seeds would decide" if math.isfinite(need)
                                 else ": undecided") + same + switched)
        else:
            verdicts.append("pass")
            parts.append(head + ": within" + same + switched)
    status = "fail" if "fail" in verdicts else "inconclusive" if "inconclusive" in verdicts else "pass"
    return status, dist, "paired by seed: " + "; ".join(parts)


TITLE_WIDTH, TITLE_LINES = 95, 2


def _first_clause(part: str) -> str:
    """'F_transmitted: paired by seed: 256: paired change +3.7 +- 2.8 % (s.e., 16 seeds, 95 % bound
    9.7 %), tolerance 1 %: undecided, about 69 seeds would decide; ...' -> 'F_transmitted: paired
    +3.7 +- 2.8 % (95 % bound 9.7 % > 1 %)': the observable and the last label of its headline,
    cut before the first parenthesis or comma; for an undecided ensemble its mean change and the
    95 % bound that exceeds the tolerance."""
    name, sep, rest = part.partition(": ") if part.split(": ")[0] in OBSERVABLES else ("", "", part)
    head = re.split(r" \(|, ", rest, maxsplit=1)[0].rsplit(": ", 1)[-1]
    # why an ensemble does not decide: its 95 % bound against the tolerance, and the seeds it would take
    bound = re.search(r"95 % bound ([^)]*?%)\), tolerance ([^:]*?%): undecided", rest)
    change = re.search(r"[+-]?[\d.]+ \+- [\d.]+ %", head)
    if bound and change:
        head = f"{change[0]} (95 % bound {bound[1]} > {bound[2]})"
    return name + sep + head


def brief_status(status: str) -> str:
    """A verdict by its headlines: per observable that decides it ("F_transmitted: ...;
    pitch: ..."; an observable that converged is left out) the first clause of its reason
    (_first_clause). The full text is in results/checks."""
    word, _, reasons = status.partition(": ")
    if not reasons:
        return status
    # one part per observable ("F_transmitted: ...; pitch: ..."; a part may hold "; " itself)
    starts = "|".join(re.escape(k) for k in OBSERVABLES)
    parts = re.split(rf"; (?=(?:{starts}): )", reasons)
    # an observable that converged is not why the verdict is what it is
    parts = [_first_clause(part) for part in parts if not part.endswith("(converged)")] or [_first_clause(parts[0])]
    return f"{word}: " + "; ".join(parts)


def _title_lines(head: str, status: str) -> list[str]:
    """The verdict as a figure title of at most TITLE_LINES lines: whole if it fits; else its
    headlines (brief_status) with a pointer to the full text; only then cut at a word."""
    def wrap(text):
        return textwrap.wrap(head + text.replace(" +- ", " $\\pm$ "), width=TITLE_WIDTH)
    for text in (status, brief_status(status) + f" (full verdict: {layout.CHECKS})"):
        lines = wrap(text)
        if len(lines) <= TITLE_LINES:
            return lines
    return textwrap.wrap(head + status.replace(" +- ", " $\\pm$ "), width=TITLE_WIDTH, max_lines=TITLE_LINES,
                         placeholder=f" ... (full verdict: {layout.CHECKS})")


def winding_shift(values: np.ndarray, turns: np.ndarray, has: np.ndarray, ipub: int) -> str:
    """Finer rungs whose helices settle in another state than the publication rung's: the mean
    winding of their helical members (at least one turn) differs by ensembles.STATE_TURNS or more,
    the project's measure of another final state. A difference of ensemble means across such
    rungs compares different equilibria, not a discretisation error (conv_l0, publication build
    of 2026-12-02: 3.28 turns at l0 = 0.5 against 3.77 at 0.125, so its 5.6 % difference in
    |F_z(L)| decided nothing about l0)."""
    hel = (has == 1) & (turns >= 1.0)

    def mean(i):
        return float(turns[i, hel[i]].mean()) if hel[i].any() else math.nan

    a = mean(ipub)
    apart = [f"{mean(j):.2f} at {values[j]:g}" for j in range(ipub + 1, len(values))
             if math.isfinite(a) and math.isfinite(mean(j)) and abs(mean(j) - a) >= ensembles.STATE_TURNS]
    if not apart:
        return ""
    return (f"mean winding of the helical members {a:.2f} turns at {values[ipub]:g} against "
            + " and ".join(apart) + f": apart by {ensembles.STATE_TURNS:g} turn or more")


def _build_ensemble(fig_cfg, sims, groups, publication_value) -> xr.Dataset:
    """The ladder with a seed ensemble per rung: members, means, standard errors and the
    statistical verdict (statistical_verdict)."""
    param = fig_cfg["parameter"]
    hname, hfun = REFINEMENT[param]
    groups = sorted(groups, key=lambda g: -hfun(float(sims[g[0]].attrs[param])))
    values = np.array([float(sims[g[0]].attrs[param]) for g in groups])
    h = np.array([hfun(v) for v in values])
    if not np.any(np.isclose(values, publication_value, rtol=1e-9)):
        raise ValueError(f"convergence ladder over {param} does not contain the publication value {publication_value}")
    ipub = int(np.flatnonzero(np.isclose(values, publication_value, rtol=1e-9))[0])
    tol = float(fig_cfg["tolerance"])
    pad = ensembles.Padded(groups, sims)
    members, has = pad.values, pad.has
    turns = members(n_turns)
    helical = (turns >= 1.0) | (has == 0)
    paired = bool(fig_cfg.get("paired", False))
    obs = {"F_transmitted": members(lambda d: float(d["F_transmitted"])), "L_z": members(lambda d: float(d["L_z"]))}
    # the pitch needs a helix on every rung the verdict reads: all of them, or for a paired
    # ladder the publication rung and the finer ones (a coarser rung's seeds that jammed with
    # less than a turn are then left out of its pitch statistics)
    if helical[ipub if paired else 0:].all():
        obs["pitch"] = members(bulk_pitch)
    seeds = members(lambda d: float(d.attrs["seed"]))
    data, dist, notes, statuses = {}, [], [], []
    for k, v in obs.items():
        use = (has == 1) & (helical if k == "pitch" else True)
        st = [ensembles.stats(v[i, use[i]]) for i in range(len(groups))]
        means, sems = np.array([s.mean for s in st]), np.array([s.sem for s in st])
        data[k] = variable(("rung",), means, k)
        data[f"{k}_sem"] = xr.Variable(("rung",), sems, attrs={**attrs(k), "long_name": "standard error of the "
                                                                 "ensemble mean of " + attrs(k)["long_name"]})
        data[f"{k}_member"] = xr.Variable(("rung", "member"), v, attrs={**attrs(k), "long_name": attrs(k)["long_name"]
                                                                         + " of each ensemble member"})
        data[f"{k}_limit"] = xr.Variable((), means[-1], attrs={**attrs(k), "long_name": "ensemble mean at the finest "
                                                                "rung of " + attrs(k)["long_name"]})
        if paired:
            status, d, note = paired_verdict(values, v, seeds, turns, has, ipub, tol)
        else:
            status, d, note = statistical_verdict(values, means, sems, ipub, tol, n=has.sum(axis=1))
        statuses.append(status)
        dist.append(d)
        notes.append(note)
    checked = list(obs)
    bad = [f"{k}: {n}" for k, s, n in zip(checked, statuses, notes) if s == "inconclusive"]
    moved = "" if paired else winding_shift(values, turns, has, ipub)
    if moved:
        status = "inconclusive: the rungs settle in different states (" + moved + ")"
    elif bad:
        status = "inconclusive: " + "; ".join(bad)
    elif "fail" in statuses:
        status = "fail"
    else:
        status = "pass"
    data["n_turns"] = variable(("rung",), pad.mean(n_turns), "n_turns")
    data["n_turns_member"] = xr.Variable(("rung", "member"), turns, attrs={**attrs("n_turns"), "long_name":
                                         attrs("n_turns")["long_name"] + " of each ensemble member"})
    data["has_member"] = variable(("rung", "member"), has, "has_member")
    data["member_seed"] = variable(("rung", "member"), seeds.astype(np.int64), "member_seed")
    if paired:
        changed = np.zeros(has.shape, dtype=np.int8)
        for j in (j for j in range(len(groups)) if j != ipub):
            common, _, moved = ensembles.paired_changes(seeds, np.ones_like(turns), turns, has, ipub, j)
            for s, m in zip(common, moved):
                changed[j, list(seeds[j]).index(s)] = int(m)
        data["state_changed_member"] = xr.Variable(
            ("rung", "member"), changed, attrs={"long_name": "1 where the seed's final state differs from its state at "
                                                f"the publication rung (winding by >= {ensembles.STATE_TURNS:g} turn)",
                                                "units": "1"})
    data["n_seeds"] = variable(("rung",), has.sum(axis=1), "n_seeds")
    data["converged"] = variable(("rung",), np.int8(members(lambda d: float(d["converged"])).min(axis=1, initial=1,
                                                                                                   where=has == 1)),
                                 "converged")
    data["wall_time"] = variable(("rung",), members(lambda d: float(d["wall_time"])).sum(axis=1), "wall_time")
    data["observed_order"] = variable(("observable",), np.zeros(len(checked)), "observed_order")
    data["publication_distance"] = variable(("observable",), dist, "publication_distance")
    coords = {"rung": xr.Variable(("rung",), np.array([g[0].rsplit("-s", 1)[0] for g in groups], dtype=object),
                                  attrs=attrs("scene")),
              "value": xr.Variable(("rung",), values, attrs={**attrs("value"), "long_name": f"value of {param}",
                                                              "parameter": param}),
              "h": xr.Variable(("rung",), h, attrs={**attrs("h"), "definition": hname}),
              "member": variable(("member",), np.arange(has.shape[1]), "member"),
              "observable": xr.Variable(("observable",), np.array(checked, dtype=object), attrs=attrs("observable"))}
    ds = xr.Dataset(data, coords=coords)
    ds.attrs.update({"parameter": param, "refinement": hname, "publication_value": publication_value,
                     "tolerance": tol, "status": status, "worst_distance": max(dist),
                     "notes": "; ".join(f"{k}: {n}" for k, n in zip(checked, notes)),
                     "paired": int(paired),
                     "method": ("seed ensembles paired by seed: the mean relative change over all seeds plus its 95 "
                                "% Student-t bound within the tolerance; the seeds that changed their final state are "
                                "listed apart" if paired
                                else f"seed ensembles: rungs agree when their means differ by at most the tolerance "
                                f"plus {Z_AGREE:g} combined standard errors")})
    return ds


def check(ds: xr.Dataset, figure: str, on_inconclusive: str = "fail") -> str:
    """Raise ConvergenceError if the check failed (or was inconclusive and the
    config says that fails too); return a one-line summary otherwise."""
    status = ds.attrs["status"]
    line = (f"{figure}: {ds.attrs['parameter']} = {ds.attrs['publication_value']:g} is "
            + ", ".join(f"{k} {100 * d:.3g} %" for k, d in zip(ds["observable"].values,
                                                                ds["publication_distance"].values))
            + (" mean change seed by seed to the finer rungs (tolerance " if ds.attrs.get("paired") else
               " from the finest rung's ensemble mean (tolerance " if "has_member" in ds else
               " from the extrapolated limit (tolerance ")
            + f"{100 * ds.attrs['tolerance']:g} %"
            + (" + the 95 % bound)" if ds.attrs.get("paired") else f" + {Z_AGREE:g} combined s.e.)"
               if "has_member" in ds else ")")
            + f": {status}")
    if status == "fail" or (status.startswith("inconclusive") and on_inconclusive == "fail"):
        raise ConvergenceError(line)
    return line



_H_LABEL = {"l0": r"$h = l_0$ [$R$]", "k_ph": r"$h = 1/k_{ph}$ [$R^2/EI$]", "k_w": r"$h = 1/k_w$ [$R^3/EI$]",
            "k_t": r"$h = 1/k_t$ [$R^3/EI$]", "tol": r"$h = \mathrm{tol}$", "ramp_steps": r"$h = 1/n_{ramp}$"}


def _seed_lines(ax, ds: xr.Dataset, k: str, h: np.ndarray, has: np.ndarray) -> None:
    """A paired ladder: each seed's values joined across the rungs; seeds whose final state
    differs from the publication rung's circled."""
    seeds, v = ds["member_seed"].values, ds[f"{k}_member"].values
    for s in np.unique(seeds[has]):
        at = [(h[i], v[i, list(seeds[i]).index(s)]) for i in range(len(h)) if s in seeds[i][has[i]]]
        ax.plot(*zip(*at), "-", **P.SEEDS, lw=0.5, zorder=1)
    moved = (ds["state_changed_member"].values == 1) & has
    if moved.any():
        ax.plot(np.broadcast_to(h[:, None], has.shape)[moved], v[moved], "o", ms=6, mfc="none", mec=P.MARK["color"],
                mew=0.9, label="seed in another final state")


def plot(ds: xr.Dataset):
    """One panel per observable against the refinement variable h (log axis): the
    rungs, the Richardson limit, the tolerance band about it and the publication rung."""
    obs = [k for k in OBSERVABLES if k in ds]
    fig, axes = P.plt.subplots(1, len(obs), figsize=(min(7.0, 2.2 * len(obs) + 0.4), 3.0), squeeze=False,
                               label=ds.attrs["title"])
    h = ds["h"].values
    param = ds.attrs["parameter"]
    pub = np.isclose(ds["value"].values, float(ds.attrs["publication_value"]), rtol=1e-9)
    tol = float(ds.attrs["tolerance"])
    checked = list(ds["observable"].values)
    ensemble = "has_member" in ds
    for ax, k in zip(axes[0], obs):
        f = ds[k].values
        ax.plot(h, f, "-", color="0.6", lw=0.7)
        if ensemble:
            has = ds["has_member"].values == 1
            hm = np.broadcast_to(h[:, None], has.shape)
            if k == "pitch":        # a member with less than a turn has no pitch (0)
                has = has & (ds[f"{k}_member"].values > 0)
            ax.plot(hm[has], ds[f"{k}_member"].values[has], ".", ms=3, **P.SEEDS, label="single seeds")
            if "state_changed_member" in ds:
                _seed_lines(ax, ds, k, h, has)
            ax.errorbar(h, f, yerr=Z_AGREE * ds[f"{k}_sem"].values, fmt="none", ecolor="black", elinewidth=0.9,
                        capsize=2.5)
        ax.plot(h, f, "o", ms=4.5, **P.SIM, label="ensemble means $\\pm$ 2 s.e." if ensemble else "rungs")
        ax.plot(h[pub], f[pub], "s", ms=9, mfc="none", mec="tab:green", mew=1.4, label="publication setting")
        if k in checked:
            i = checked.index(k)
            lim = float(ds[f"{k}_limit"])
            ax.axhline(lim, **P.MODEL, label="finest rung's mean" if ensemble else "Richardson limit")
            ax.axhspan(lim * (1 - tol), lim * (1 + tol), color="tab:blue", alpha=0.12, lw=0,
                       label=rf"{'finest' if ensemble else 'limit'} $\pm$ {100 * tol:g} %")
            order = float(ds.observed_order[i])
            dist = f"{100 * float(ds.publication_distance[i]):.2g} %"
            if ds.attrs.get("paired"):       # short: three panels side by side
                ax.set_title(f"mean paired change {dist}", fontsize=7.5)
            else:
                head = ("ensembles" if ensemble else f"$p = {order:.2f}$" if order > 0 else "$p$ not measurable")
                ax.set_title(f"{head}, pub. off by {dist}", fontsize=7.5)
        else:
            ax.set_title("not checked (not every rung is a helix)", fontsize=7.5)
        ax.set_xscale("log")
        P.plain_log_ticks(ax.xaxis)
        ax.set_xlabel(_H_LABEL[param])
        ax.set_ylabel(label(k))
    head = f"convergence in {P.param_text(param, float(ds.attrs['publication_value'])).split(' =')[0]}$: "
    lines = _title_lines(head, ds.attrs["status"])
    fig.suptitle("\n".join(lines + [P.params_text(ds, ("L", "load", "k_fr"))]), fontsize=9)
    if ensemble:        # five entries: two rows
        P.bottom_legend(fig, axes[0][0], bottom=0.16, ncol=3)
    else:
        P.bottom_legend(fig, axes[0][0], bottom=0.08)
    return fig
