"""Measures of the axial force along the rod: the power-law exponents on the bulk and the whole
contact stretch, the printed curves, the local decay law, the transmitted fraction and the
regions at the ends (Figs 4, 6, 7)."""
from __future__ import annotations

import math
from typing import Any

import numpy as np
import xarray as xr

from ...analysis import regions
from ...analysis.fits import DEGENERATE_FALL, determined, undetermined
from ...analysis.measure import HELIX_RUN, detached_lengths
from ...analysis.measure import half_reduction_length as half_reduction_length_of
from ...layout import dataset_path
from ..evidence import ClaimError
from ._base import Measured, _combine, _threshold_robust, _two_windows, measure


def _panel_label(ds, i: int) -> str:
    """(a), (b), ... for a figure of several panels; the scene name of a single panel."""
    if ds.sizes.get("panel", 1) > 1 or "panel" not in ds.coords:
        return f"({chr(97 + i)})"
    return str(ds.panel.values[i])


def _panel_value(ds, var: str, i: int, ensemble: str | None = None) -> tuple[float, float]:
    """A panel's value (the ensemble mean where the dataset has one) and its seed s.d. (0 for one run)."""
    if ensemble and f"{ensemble}_mean" in ds:
        return float(ds[f"{ensemble}_mean"].values[i]), float(ds[f"{ensemble}_std"].values[i])
    return float(ds[var].values[i]), 0.0


def _exponent_windows(ds, i: int, fall_min: float = DEGENERATE_FALL) -> dict[str, tuple[float, float, str]]:
    """c over the whole stretch and over the bulk of panel i: (value, nan without a fit; seed
    s.d.; why the window does not determine c, empty if it does: fits.undetermined at fall_min).
    For a seed ensemble the value and s.d. are over the members whose own fit determines c, and
    the window is undetermined only if none does (the text says how many do)."""
    out = {}
    for name, var, has in (("whole", "fit_c", None), ("bulk", "fit_c_bulk", "has_fit_bulk")):
        where = "the whole stretch" if name == "whole" else "the bulk"
        if has and int(ds[has].values[i]) == 0:
            out[name] = (math.nan, 0.0, "no bulk helix")
            continue
        fall_var = f"fall_{name}_member"
        if fall_var in ds and f"{var}_member" in ds:
            c_m, f_m = ds[f"{var}_member"].values[i], ds[fall_var].values[i]
            has_m = ds["has_fit_member" if name == "whole" else "has_fit_bulk_member"].values[i] == 1
            ok = determined(c_m, f_m, has_m, fall_min)
            if not ok.any():
                out[name] = (float(ds[var].values[i]), 0.0, f"|F_z| falls only {f_m[has_m].min():.3g}-"
                             f"{f_m[has_m].max():.3g}x over {where} of the seeds, or the fits reach their bound")
                continue
            count = "" if ok.sum() == has_m.sum() else f" [{int(ok.sum())} of {int(has_m.sum())} seeds determined]"
            out[name] = (float(c_m[ok].mean()), float(c_m[ok].std(ddof=1)) if ok.sum() > 1 else 0.0, "", count)
            continue
        why = undetermined(float(ds[var].values[i]), float(ds[f"fall_{name}"].values[i]), fall_min)
        c, sd = _panel_value(ds, var, i, var)
        out[name] = (c, sd, why and f"{why} over {where}")
    return out


def _compare_exponent(windows, target: float, tol: float) -> tuple[bool | None, float, str]:
    """Does c agree with target within max(tol, seed s.d.) on both windows? Also the largest
    deviation over the windows that determine c (nan if none does: a fit the pipeline calls
    undetermined is reported in the text, never as our value)."""
    oks, texts, worst = [], [], math.nan
    for name in ("whole", "bulk"):
        c, sd, why, *count = windows[name]
        if math.isfinite(c) and not why:
            worst = abs(c - target) if math.isnan(worst) else max(worst, abs(c - target))
        if why:
            oks.append(None)
            texts.append(f"{name}: " + (f"{c:.3f}, " if math.isfinite(c) else "") + f"not determined ({why})")
            continue
        t = max(tol, sd)
        oks.append(abs(c - target) <= t)
        texts.append(f"{name} {c:.3f}" + (f" +- {sd:.2g}" if sd else "") + "".join(count)
                     + f" ({'within' if oks[-1] else 'outside'} {t:.2g})")
    return _two_windows(*oks), worst, ", ".join(texts)


@measure
def exponents(ev, spec, claim):
    """The fitted exponent c of every panel of the figures (spec figures, optional panels),
    against the paper's printed c of the panel or the value `around`, on the whole wall-contact
    stretch and on the bulk helix (confined_rod.analysis.regions), each within max(tolerance, seed s.d.).
    A window where |F_z| falls by less than 2x does not determine c (checked at FALL_THRESHOLDS).
    Reproduced if every panel agrees on both windows, refuted if a panel disagrees on both, else
    inconclusive. Value: the largest deviation over the windows that determine c (nan: none does)."""
    return _threshold_robust(lambda fall_min: _exponents(ev, spec, claim, fall_min))


def _exponents(ev, spec, claim, fall_min):
    tol = float(spec["tol"])
    parts, notes, devs, files = [], [], [], []
    for fig in spec["figures"]:
        ds = ev.dataset(fig, claim)
        files.append(f"{dataset_path(fig)}")
        for i in range(ds.sizes["panel"]):
            target = float(spec["around"]) if "around" in spec else float(ds.paper_fit_c.values[i])
            ok, dev, text = _compare_exponent(_exponent_windows(ds, i, fall_min), target, tol)
            parts.append(ok)
            devs.append(dev)
            f_printed = float(ds.paper_fit_fraction.values[i]) if "paper_fit_fraction" in ds else 0.0
            printed_fall = 1.0 / f_printed if f_printed > 0 else math.inf
            if printed_fall < fall_min:
                text += f" (the printed fit itself spans a fall of only {printed_fall:.3g}x)"
            notes.append(f"{fig} {_panel_label(ds, i)} vs {target:g}: {text}")
    return Measured(_nanmax(devs), _combine(parts), \
        ", ".join(f + ":fit_c, fit_c_bulk, fall_whole, fall_bulk" for f in files), "; ".join(notes))


def _nanmax(values) -> float:
    """The largest finite value, nan if there is none (no window determined the quantity)."""
    finite = [v for v in values if math.isfinite(v)]
    return max(finite) if finite else math.nan


@measure
def exponent_change_windows(ev, spec, claim):
    """|c(small load) - c(Fig 4(c))| on both windows, within tol + the larger seed s.d.; value:
    the largest change over the windows where both fits are determined (nan: none)."""
    return _threshold_robust(lambda fall_min: _exponent_change(ev, spec, claim, fall_min))


def _exponent_change(ev, spec, claim, fall_min):
    small, large = spec["figures"]
    a, b = ev.dataset(small, claim), ev.dataset(large, claim)
    wa = _exponent_windows(a, a.sizes["panel"] - 1, fall_min)
    wb = _exponent_windows(b, b.sizes["panel"] - 1, fall_min)
    tol, oks, texts, changes = float(spec["tol"]), [], [], []
    for name in ("whole", "bulk"):
        (ca, sa, why_a, *_), (cb, sb, why_b, *_) = wa[name], wb[name]
        change = abs(ca - cb) if math.isfinite(ca) and math.isfinite(cb) else math.nan
        text = f"{name}: c = {ca:.3f} against {cb:.3f}"
        if why_a or why_b:
            oks.append(None)
            texts.append(f"{text}, not determined ({why_a or why_b})")
            continue
        changes.append(change)
        t = tol + max(sa, sb)
        oks.append(change <= t)
        texts.append(f"{text}, |change| {change:.3f} (limit {t:.2g})")
    return Measured(_nanmax(changes), _two_windows(*oks), \
        f"{dataset_path(small)}, {dataset_path(large)}:fit_c, fit_c_bulk", "; ".join(texts))


@measure
def power_law_quality(ev, spec, claim):
    """Largest rms relative residual of our power-law fits, over the whole stretch and over the
    bulk; a window where |F_z| falls by less than 2x cannot test a power law (any smooth curve
    fits it; checked at FALL_THRESHOLDS). Value: the largest residual of a determined window."""
    return _threshold_robust(lambda fall_min: _power_law_quality(ev, spec, claim, fall_min))


def _power_law_quality(ev, spec, claim, fall_min):
    tol = float(spec["tol"])
    parts, notes, worst = [], [], math.nan
    for fig in spec["figures"]:
        ds = ev.dataset(fig, claim)
        for i in range(ds.sizes["panel"]):
            oks, texts = [], []
            for name, rms, fall, has in (("whole", "fit_rms", "fall_whole", None),
                                         ("bulk", "fit_rms_bulk", "fall_bulk", "has_fit_bulk")):
                if has and int(ds[has].values[i]) == 0:
                    oks.append(None)
                    texts.append(f"{name}: no fit")
                    continue
                r, f = float(ds[rms].values[i]), float(ds[fall].values[i])
                if f >= fall_min:
                    worst = _nanmax([worst, r])
                oks.append(r <= tol if f >= fall_min else None)
                texts.append(f"{name} {100 * r:.2g} %" + ("" if f >= fall_min else f" (falls only {f:.3g}x)"))
            parts.append(_two_windows(*oks))
            notes.append(f"{fig} {_panel_label(ds, i)}: " + ", ".join(texts))
    files = ", ".join(f"{dataset_path(f)}:fit_rms, fit_rms_bulk" for f in spec["figures"])
    return Measured(worst, _combine(parts), files, \
        "; ".join(notes))


@measure
def printed_curves(ev, spec, claim):
    """The paper's printed fits A (l0' + s)^c against our profiles: the rms of ln(f_paper/|F_z|)
    over the whole stretch and over the bulk, within `max_rms` on both windows for every panel
    (one finding per figure: the printed A, l0', c and the transmitted fractions are evidence).
    spec['readings'] (label -> figure, optional: read where the config builds it): the same
    panels run under another reading of what the paper leaves open (its printed bending constant,
    the loading path); a verdict that one of them changes is inconclusive, with each reading's
    answer in the note."""
    tol = float(spec["max_rms"])
    worst, holds, notes, _ = _printed_curve(ev, spec["figure"], tol, claim)
    files = [f"{dataset_path(spec['figure'])}"]
    answers = []
    for label, fig in (spec.get("readings") or {}).items():
        if fig not in ev.datasets or not int(ev.datasets[fig].has_paper_fit.values.sum()):
            # optional: a config may not build that reading's runs, or not with the printed fits
            notes.append(f"{label}: not built by this config" if fig not in ev.datasets else
                         f"{label} ({fig}): no printed fit in this config")
            continue
        w, h, _, per_panel = _printed_curve(ev, fig, tol, claim)
        files.append(f"{dataset_path(fig)}")
        answers.append((label, fig, h, per_panel))
    note = "; ".join(notes)
    if answers:
        note += "; under other readings: " + "; ".join(
            f"{label} ({fig}): {per_panel}" for label, fig, h, per_panel in answers)
        if any(h != holds for _, _, h, _ in answers):
            holds = None
            note += "; the verdict depends on the reading"
    return Measured(worst, holds, ", ".join(f + ":paper_rms_log_ratio, paper_rms_log_ratio_bulk" for f in files) + \
        ", fit_A, fit_l0, fit_c, paper_fit_*", note)


def _described_from(ds, i: int, tol: float) -> float | None:
    """The smallest s of the fit window of panel i from which on the printed curve stays within
    tol of our |F_z| in |ln ratio| to the end of the window (None: not even at its last point)."""
    s = np.asarray(ds.s.values, dtype=float)
    w = np.asarray(ds.in_fit.values[i]) == 1
    F, f = np.asarray(ds.F_abs.values[i], dtype=float), np.asarray(ds.F_paper_fit.values[i], dtype=float)
    ok = np.abs(np.log(f[w] / F[w])) <= tol
    if not ok.size or not ok[-1]:
        return None
    bad = np.flatnonzero(~ok)
    return float(s[w][bad[-1] + 1] if bad.size else s[w][0])


def printed_panel(ds, i: int, tol: float) -> dict[str, Any]:
    """Whether the printed fit of panel i describes our profile (_printed_curve): 'holds' (True,
    False, None where the windows disagree), 'answer' in words, the rms of ln(f/|F_z|) over the
    whole stretch and the bulk (of a seed ensemble: the mean over the seeds of each seed's rms,
    'seeds' their range), our transmitted fraction (ensemble mean, 'sd'), the printed
    fraction over the load and over the curve's own f(0), 'start' (_described_from) and 'flips'
    (the f(0) normalisation would give another answer)."""
    rw, rb = float(ds.paper_rms_log_ratio.values[i]), float(ds.paper_rms_log_ratio_bulk.values[i])
    seeds = ""
    if "paper_rms_log_ratio_member" in ds:
        # a seed ensemble: the mean over the seeds of each seed's rms (the shown member's alone is one draw)
        on = ds.has_member.values[i] == 1
        w_m, b_m = ds.paper_rms_log_ratio_member.values[i][on], ds.paper_rms_log_ratio_bulk_member.values[i][on]
        rw, rb = float(w_m.mean()), float(b_m.mean())
        seeds = (f"mean rms over {int(on.sum())} seeds, whole {w_m.min():.2g}-{w_m.max():.2g}, "
                 f"bulk {b_m.min():.2g}-{b_m.max():.2g}")
    frac, sd = _panel_value(ds, "transmitted_fraction", i)
    if "fraction_std" in ds:
        sd = float(ds.fraction_std.values[i])
    f0, by_f0 = float(ds.paper_fit_F0.values[i]), float(ds.paper_fit_fraction.values[i])
    by_load = by_f0 * f0 / float(ds.attrs["load"])
    d_load, d_f0 = abs(math.log(by_load / frac)), abs(math.log(by_f0 / frac))
    windows = _two_windows(rw <= tol, rb <= tol)
    holds = windows and d_load <= tol
    answer = {True: "described", False: "not described",
              None: ("described over the bulk only" if rb <= tol else "described over the whole stretch only")
              if d_load <= tol else "not described"}[holds]
    return {"label": _panel_label(ds, i), "holds": holds, "answer": answer, "rms_whole": rw, "rms_bulk": rb,
            "fraction": frac, "sd": sd, "f0": f0, "by_load": by_load, "by_f0": by_f0, "d_load": d_load,
            "d_f0": d_f0, "start": _described_from(ds, i, tol), "flips": (windows and d_f0 <= tol) != holds,
            "seeds": seeds}


def _printed_curve(ev, figure: str, tol: float, claim) -> tuple[float, bool | None, list[str], str]:
    """(worst rms over the bulk, verdict, a note per panel, the per-panel answers in short) of
    the printed fits of one figure. A printed curve describes a panel if its rms of ln(f/|F_z|)
    on both windows and |ln| of the transmitted fraction it implies over ours are all within tol:
    where a profile falls by less than 2x, the rms alone cannot tell a decaying curve from a flat
    one (Fig 7's does), the transmitted fraction can. The printed curve's fraction is f(L) over
    the load, the force at s = 0 by the boundary condition: a curve whose own f(0) is not the
    load does not pass through the loaded end, which the rms over the whole stretch tests; f(L)/f(0)
    is given too, with the panels whose answer it would change. Where the windows disagree the
    panel is described over the bulk only (or the whole stretch only), undecided as a whole."""
    ds = ev.dataset(figure, claim)
    load = float(ds.attrs["load"])
    parts, notes, worst, short, flips = [], [], 0.0, [], []
    for i in range(ds.sizes["panel"]):
        if int(ds.has_paper_fit.values[i]) == 0:
            continue
        r = printed_panel(ds, i, tol)
        worst = max(worst, r["rms_bulk"])
        parts.append(r["holds"])
        if r["flips"]:
            flips.append(r["label"])
        start = r["start"]
        short.append(f"{r['label']} {r['answer']} (rms {r['rms_whole']:.2g} whole, {r['rms_bulk']:.2g} bulk; "
                     f"fraction {r['fraction']:.3g} against {r['by_load']:.3g}"
                     + (f"; within {tol:g} from s = {start:.3g} R on" if start is not None else "") + ")")
        why = undetermined(float(ds.fit_c.values[i]), float(ds.fall_whole.values[i]))
        fit = (float(ds.fit_A.values[i]), float(ds.fit_l0.values[i]), float(ds.fit_c.values[i]))
        ours = f"ours not determined ({why} over the whole stretch)" if why else \
            f"ours {fit[0]:.3g}, {fit[1]:.3g}, {fit[2]:.3f}"
        A, l0p, c = (float(ds[f"paper_fit_{k}"].values[i]) for k in ("A", "l0", "c"))
        notes.append(f"{r['label']}: {r['answer']}: rms ln ratio {r['rms_whole']:.2g} (whole), {r['rms_bulk']:.2g} "
                     f"(bulk); printed A = {A:g}, l0' = {l0p:g}, c = {c:g} (f(0) = {r['f0']:.3g} against the load "
                     f"{load:g}) against {ours}; F(L)/F(0) ours {r['fraction']:.3g}"
                     + (f" +- {r['sd']:.2g}" if r["sd"] else "")
                     + f", printed f(L)/load {r['by_load']:.3g} (|ln ratio| {r['d_load']:.2g}), printed f(L)/f(0) "
                       f"{r['by_f0']:.3g} (|ln ratio| {r['d_f0']:.2g})"
                     + (f"; {r['seeds']}" if r["seeds"] else "")
                     + (f"; the printed curve is within {tol:g} of the shown member's profile from s = {start:.3g} R "
                        "to the end of the stretch" if start is not None else ""))
    if not parts:
        raise ClaimError(f"claim {claim!r}: {dataset_path(figure)} has no printed fit")
    if flips:
        notes.append("normalised by its own f(0) instead of the load, the printed fraction would change the answer "
                     f"for {', '.join(flips)}")
    return worst, _combine(parts), notes, "; ".join(short)


def _part_runs(ev, fig: str, ds, dim: str, i: int, claim: str) -> frozenset[str] | None:
    """The files of the runs behind part i (a panel or a length) of a figure, so that a part made of
    the runs of another (Fig 4(c) and Fig 6 at the same L share them) is counted once; None where
    the build's simulations of the figure are not at hand (a dataset alone)."""
    if not any(k.startswith(fig + "/") for k in ev.sims):
        return None
    runs = ev.ensemble(fig, str(ds.panel.values[i]), claim) if dim == "panel" else ev.members(fig, i, claim)
    return frozenset(ev.file(k) for k, _ in runs)


@measure
def local_decay_law(ev, spec, claim):
    """The local decay law in the bulk helix, d(1/|F_z|)/ds against k_fr R/(4EI) (law: corrected)
    or k_fr R/(2EI) (law: paper), for every panel and length of the figures that has a bulk, a
    part made of the same runs as an earlier one counted once: the ratio r (ensemble mean where
    there are seeds) and its uncertainty u = max(window effect, seed s.d.)/law. A part holds if
    |r - 1| <= tol, fails if |r - 1| - 2u > tol, else is undecided; value: the mean ratio over the
    parts. The note gives the spread over the single rods (every seed of every part) too."""
    law, tol = spec["law"], float(spec["tol"])
    parts, notes, ratios, errs, files, skipped, seen, rods = [], [], [], [], [], 0, {}, []
    named: list[str] = []
    for fig in spec["figures"]:
        ds = ev.dataset(fig, claim)
        files.append(f"{dataset_path(fig)}")
        dim = "panel" if "panel" in ds.dims else "L"
        for i in range(ds.sizes[dim]):
            if int(ds.has_bulk.values[i]) == 0:
                skipped += 1
                continue
            where = f"{fig} " + (_panel_label(ds, i) if dim == "panel" else f"L/R = {float(ds.L.values[i]):g}")
            runs = _part_runs(ev, fig, ds, dim, i, claim)
            if runs is not None and runs in seen:
                notes.append(f"{where}: the runs of {seen[runs]}, counted once")
                continue
            if runs is not None:
                seen[runs] = where
            ref = float(ds["decay_rate_model" if law == "corrected" else "decay_rate_paper"].values[i])
            rate, sd = _panel_value(ds, "bulk_decay_rate", i, "bulk_decay_rate")
            u = max(float(ds.bulk_decay_rate_err.values[i]), sd) / ref
            r = rate / ref
            ratios.append(r)
            errs.append(u)
            if "bulk_decay_rate_member" in ds:
                ok = ds.has_bulk_member.values[i] == 1
                rods += list(ds.bulk_decay_rate_member.values[i][ok] / ref)
            else:
                rods.append(r)
            parts.append(True if abs(r - 1) <= tol else (False if abs(r - 1) - 2 * u > tol else None))
            notes.append(f"{where}: {r:.3f} +- {u:.2g}")
            named.append(_part_words(ds, dim, i) + f", {r:.2f} +- {u:.2f}")
    if not ratios:
        raise ClaimError(f"claim {claim!r}: no bulk helix in {files}")
    rods_a = np.asarray(rods, dtype=float)
    off = int(np.sum(np.abs(rods_a - 1) > tol))
    note = (f"mean over {len(ratios)} parts (panels and lengths, each the mean over its seeds) of "
            f"measured/({'k_fr R/(4EI)' if law == 'corrected' else 'k_fr R/(2EI)'}): " + "; ".join(notes)
            + f"; single rods: {rods_a.size}, from {rods_a.min():.3f} to {rods_a.max():.3f}, {off} of them "
              f"outside +-{tol:g}")
    if skipped:
        note += f"; {skipped} runs without a bulk helix (short rods) not counted"
    # the error of the mean over the parts from each part's own (independent ensembles)
    err = float(np.sqrt(np.sum(np.square(errs)))) / len(errs)
    holds = _combine(parts)
    undecided = [n for n, p in zip(named, parts) if p is None]
    # inconclusive means every part holds or is undecided (_combine): say which are undecided
    why = (f"within {100 * tol:g} % at {len(parts) - len(undecided)} of {len(parts)} panels and lengths, "
           f"undecided at {'; '.join(undecided)}") if holds is None else ""
    return Measured(float(np.mean(ratios)), holds, \
        ", ".join(f + ":bulk_decay_rate, bulk_decay_rate_err, decay_rate_model" for f in files), note, part=why,
        error=err)


def _part_words(ds, dim: str, i: int) -> str:
    """A part of the local decay law in words: 'Fig. 4(c)', 'Fig. 7', 'Fig. 6 at L/R = 640' (the
    figure's paper number where it has one)."""
    fig = str(ds.attrs.get("paper_figure", "none"))
    name = f"Fig. {fig}" if fig != "none" else str(ds.attrs.get("figure", "the figure"))
    if dim == "L":
        return f"{name} at L/R = {float(ds.L.values[i]):g}"
    return name + (_panel_label(ds, i) if ds.sizes.get("panel", 1) > 1 else "")


def _printed_rates(ev, figures, claim) -> list[dict]:
    """Per panel with a printed fit: the decay rate d(1/f)/ds the printed curve implies over our
    bulk window, our measured bulk rate with its relative seed spread, and the panel's k_fr, l0, EI, R."""
    rows = []
    for fig in figures:
        ds = ev.dataset(fig, claim)
        for i in range(ds.sizes["panel"]):
            if int(ds.has_paper_fit.values[i]) == 0 or int(ds.has_bulk.values[i]) == 0:
                continue
            k_fr = (float(ds.panel_value.values[i]) if ds.attrs.get("panel_parameter") == "k_fr"
                    else float(ds.attrs["k_fr"]))
            ours, sd = _panel_value(ds, "bulk_decay_rate", i, "bulk_decay_rate")
            rows.append({"where": f"{fig} {_panel_label(ds, i)}", "printed": float(ds.paper_fit_decay_rate.values[i]),
                         "ours": ours, "spread": max(sd, float(ds.bulk_decay_rate_err.values[i])) / ours,
                         "k_fr": k_fr, "l0": float(ds.attrs["l0"]), "EI": float(ds.attrs["EI"]),
                         "R": float(ds.attrs["R"]), "L": float(ds.attrs.get("L", 0.0)),
                         "load": float(ds.attrs.get("load", 0.0))})
    return rows


#: readings of the paper's numerics, each a prediction of the local decay rate d(1/|F_z|)/ds
READINGS = {
    "corrected": ("C = EI/l0, the physics of our model: k_fr R/(4EI)", lambda r: r["k_fr"] * r["R"] / (4 * r["EI"])),
    "paper_K": ("the paper's K = R F^2/(2EI): k_fr R/(2EI)", lambda r: r["k_fr"] * r["R"] / (2 * r["EI"])),
    "printed_C": ("the printed C = EI/l0^2 at our l0 (a rod of stiffness EI R/l0): k_fr l0/(4EI)",
                  lambda r: r["k_fr"] * r["l0"] / (4 * r["EI"])),
}


def _ramp_reading(ev, spec, claim, rows, tol, notes) -> bool:
    """The loading path as a reading: the printed rate of each panel against the bulk rate our
    rods reach when the same panel is loaded by a quasi-static ramp (spec['ramp']: figure ->
    its ramped copy, same panels). Agrees if every panel is within max(tol, 2 x the ramp's
    relative spread)."""
    ramped = {}
    for fig, rfig in spec["ramp"].items():
        for r in _printed_rates(ev, [rfig], claim):
            ramped[(fig, r["where"].split(" ", 1)[1])] = r
    parts, ok_all = [], True
    for r in rows:
        fig, panel = r["where"].split(" ", 1)
        rr = ramped.get((fig, panel))
        if rr is None:
            ok_all = False
            parts.append(f"{r['where']}: no ramped run with a bulk")
            continue
        q = r["printed"] / rr["ours"]
        ok = abs(q - 1) <= max(tol, 2 * rr["spread"])
        ok_all &= ok
        parts.append(f"{r['where']} {q:.2f} (ramp rate {rr['ours'] / READINGS['corrected'][1](rr):.2f} +- "
                     f"{rr['spread'] * rr['ours'] / READINGS['corrected'][1](rr):.2f} of the corrected law)"
                     + (" agrees" if ok else ""))
    notes.append("the loading path, a quasi-static ramp (" + ", ".join(spec["ramp"].values())
                 + "): printed/ramp rate = " + "; ".join(parts) + (" (agrees)" if ok_all else ""))
    return ok_all


@measure
def printed_decay_readings(ev, spec, claim):
    """The decay rates the printed fits imply in the bulk, against each reading of the paper's
    numerics (READINGS; the panels' k_fr as the config reads them), and the link length the
    printed C = EI/l0^2 would need for each panel (one l0 for all, or none). A reading agrees if
    every panel is within max(tol, 2 x our relative seed spread); value: the printed rate over
    the corrected law, averaged over the panels. Nothing is tuned: each reading is a hypothesis
    with a number attached."""
    rows = _printed_rates(ev, spec["figures"], claim)
    if not rows:
        raise ClaimError(f"claim {claim!r}: no panel with a printed fit and a bulk helix in {spec['figures']}")
    tol = float(spec["tol"])
    notes, agree = [], []
    for key, (text, law) in READINGS.items():
        ratios = [r["printed"] / law(r) for r in rows]
        ok = all(abs(q - 1) <= max(tol, 2 * r["spread"]) for q, r in zip(ratios, rows))
        agree.append(ok)
        notes.append(f"{text}: printed/predicted = " + ", ".join(f"{q:.2f}" for q in ratios)
                     + (" (agrees)" if ok else ""))
    l0_needed = [4 * r["EI"] * r["printed"] / r["k_fr"] for r in rows]
    one_l0 = max(l0_needed) / min(l0_needed) - 1 <= 2 * tol
    notes.append("printed C = EI/l0^2 with l0 free: each panel needs l0 = " + ", ".join(f"{x:.3g}" for x in l0_needed)
                 + " R" + (" (one l0 fits all)" if one_l0 else " (no single l0)"))
    if "k_fr_all" in spec:
        k = float(spec["k_fr_all"])
        notes.append(f"printed C with k_fr = {k:g} in every panel (the panels varying l0 instead): l0 = "
                     + ", ".join(f"{4 * r['EI'] * r['printed'] / k:.3g}" for r in rows) + " R")
    notes.append("panels: " + ", ".join(f"{r['where']} (k_fr = {r['k_fr']:g}, printed {r['printed']:.3g}, ours "
                                        f"{r['ours']:.3g} R/EI)" for r in rows))
    value = float(np.mean([r["printed"] / READINGS["corrected"][1](r) for r in rows]))
    if "ramp" in spec:
        agree.append(_ramp_reading(ev, spec, claim, rows, tol, notes))
    holds = any(agree) or one_l0
    return Measured(value, holds, ", ".join(f"{dataset_path(f)}:paper_fit_decay_rate, bulk_decay_rate"
                                                  for f in spec["figures"]), "; ".join(notes))


def _last_panel(ev, figure, var, claim):
    return float(np.asarray(ev.dataset(figure, claim)[var].values).ravel()[-1])


@measure
def small_load_transmits_more(ev, spec, claim):
    small, large = spec["figures"]
    f7 = _last_panel(ev, small, "transmitted_fraction", claim)
    f4 = _last_panel(ev, large, "transmitted_fraction", claim)
    return Measured(f7 / f4, f7 > f4, (f"{dataset_path(small)}:transmitted_fraction, "
                              f"{dataset_path(large)}:transmitted_fraction[last panel]"), \
        f"F(L)/F(0) = {f7:.3g} against {f4:.3g}")


def _boundary_regions(sim: xr.Dataset) -> tuple[float, float]:
    """(tip, lower region) lengths of the force profile (regions.analyse)."""
    r = regions.analyse(sim).regions
    return r.tip_length, r.lower_length


@measure
def boundary_wider(ev, spec, claim):
    """The boundary regions of the small-load rod against the large-load one (Fig 7 against
    Fig 4(c)), at each end (s = 0 is the loaded end), in two readings: the detached lengths
    (measure.detached_lengths) and the regions of the force profile (regions.analyse: the tip
    and the lower region). An end is wider (narrower) if in both readings every seed of the
    small load lies above (below) every seed of the large one, else undecided. The paper's
    "boundary regions" are both ends: holds if both are wider, partly (at the wider end) if one
    is wider and the other narrower, refuted if one is narrower and the other not wider, else
    inconclusive. Value: the loaded end's detached length, ratio of the ensemble means."""
    small, large = spec["figures"]
    m7, m4 = ev.members(small, -1, claim), ev.members(large, -1, claim)
    if float(m4[0][1].attrs["k_fr"]) < float(m7[0][1].attrs["k_fr"]):
        raise ClaimError(f"claim {claim!r}: the longest-L scene of {large} is not its panel (c)")
    readings = {"detached": detached_lengths, "region": _boundary_regions}
    ends, texts = [], []
    for j, end in enumerate(("the loaded end", "the support")):
        calls, parts = [], []
        for name, read in readings.items():
            a = np.array([read(d)[j] for _, d in m7])
            b = np.array([read(d)[j] for _, d in m4])
            calls.append("wider" if a.min() > b.max() else ("narrower" if a.max() < b.min() else "overlapping"))
            parts.append(f"{name} {a.mean():.3g} R ({a.min():.3g}-{a.max():.3g}) against {b.mean():.3g} R "
                         f"({b.min():.3g}-{b.max():.3g}), ratio {a.mean() / max(b.mean(), 1e-300):.2f}")
        ends.append(calls[0] if len(set(calls)) == 1 and calls[0] != "overlapping" else None)
        texts.append(f"at {end} {ends[-1] or 'undecided'}: " + ", ".join(parts))
    holds = True if all(e == "wider" for e in ends) else (False if "narrower" in ends else None)
    # one end wider, the other narrower: the claim holds at one end only (partly reproduced)
    part = ("at the loaded end" if ends[0] == "wider" else "at the support") if holds is False and "wider" in ends \
        else ""
    note = ("; ".join(texts) + f" (means and seed ranges over {len(m7)} and {len(m4)} seeds; "
            f"detached: to the first or from the last run of {HELIX_RUN} or more links on the wall, shorter "
            "clusters of contacts inside it not counted; region: the tip and the lower region of the force profile)")
    if part:
        note = f"holds {part} only, refuted at the other end: " + note
    top7 = np.mean([detached_lengths(d)[0] for _, d in m7])
    top4 = np.mean([detached_lengths(d)[0] for _, d in m4])
    return Measured(top7 / max(top4, 1e-300), holds, \
        f"{ev.file(m7[0][0])}, {ev.file(m4[0][0])} (and their seeds):contact, s_link, F_z, friction_z", note, part)


@measure
def transmitted_decays(ev, spec, claim):
    ds = ev.dataset(spec["figure"], claim)
    L = np.asarray(ds.L.values, dtype=float)
    F = np.asarray(ds.F_transmitted.values, dtype=float)
    frac = F / float(ds.attrs["load"])
    slope = float(np.log(F[-1] / F[-2]) / np.log(L[-1] / L[-2]))
    holds = bool(np.all(np.diff(F) < 0) and slope < -0.5)
    seeds = int(ds["n_seeds"].values[-1]) if "n_seeds" in ds else 1
    err = float(ds["F_sem"].values[-1]) / float(ds.attrs["load"]) if seeds > 1 else None
    return Measured(float(frac[-1]), holds, f"{dataset_path(spec['figure'])}:F_transmitted, F_sem", \
        f"F(L)/F(0) = {frac[-1]:.3g} at L/R = {L[-1]:g} (mean over {seeds} seeds); slope of the last two "
        f"lengths {slope:.2f}", error=err)


@measure
def half_reduction_length(ev, spec, claim):
    """The rod length at which |F_z(L)|/|F_z(0)| first falls below 1/2 (the value), and below the
    other `thresholds` of a "significant reduction" (default 1/2 and 1/4): reproduced if every
    threshold's length lies in [lo, hi], refuted if none does, inconclusive if the answer depends
    on the threshold."""
    ds = ev.dataset(spec["figure"], claim)
    L = np.asarray(ds.L.values, dtype=float)
    frac = np.asarray(ds.F_transmitted.values, dtype=float) / float(ds.attrs["load"])
    lo, hi = float(spec["lo"]), float(spec["hi"])
    oks, texts, value = [], [], None
    for t in spec.get("thresholds", [0.5, 0.25]):
        x, how = half_reduction_length_of(L, frac, float(t))
        value = x if value is None else value
        ok = how == "interpolated" and lo <= x <= hi
        if how == "upper bound" and x < lo:
            ok = False
        elif how == "lower bound" and x > hi:
            ok = False
        elif how != "interpolated" and lo <= x <= hi:
            ok = None                      # a bound inside the range decides nothing
        oks.append(ok)
        texts.append(f"below {t:g} at L/R {'<=' if how == 'upper bound' else '>=' if how == 'lower bound' else '='} "
                     f"{x:.3g}")
    holds = True if all(o is True for o in oks) else False if all(o is False for o in oks) else None
    return Measured(float(value), holds, f"{dataset_path(spec['figure'])}:F_transmitted", \
        "; ".join(texts) + f" (range {lo:g}-{hi:g}); F(L)/F(0) = " + ", ".join(f"{f:.2f}" for f in frac))
