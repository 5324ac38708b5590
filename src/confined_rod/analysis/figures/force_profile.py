"""Kind ``force_profile`` (paper Figs 4 and 7): |F_z(s)| along the rod, fitted with A (l0' + s)^c.

One panel per scene; the scenes differ at most in ``panel_parameter`` (the reading of
the paper's Fig 4 panels). Each panel holds the profile, our fit over the wall-contact
stretch, the simple model from the first wall contact (corrected 4EI and printed 2EI)
and, where the config gives them (``paper_fits``), the paper's printed fit parameters
and curve, with the deviation between the paper's curve and ours stored in the dataset:
the rms of ln(f_paper/|F_z|) over the contact stretch, and the transmitted fraction
F(L)/F(0) from our data, from our fit and from the printed fit.

A panel may be a seed ensemble (``seeds:``; confined_rod.analysis.ensembles). Its profile, fit and
shape variables are then those of the member with the lowest seed (``shown_seed``), the
member that a single-seed config runs; the transmitted force and fraction are the ensemble
means, with every member's fraction, fitted exponent and final state, the statistics, and
the range of |F_z(s)| over the members.
"""
from __future__ import annotations

import re

import numpy as np
import xarray as xr

from ... import theory
from ...errors import ConfigError
from .. import ensembles, regions
from .. import plotting as P
from ..error_budget import Headline
from ..figure_quantities import attrs, error_attrs, label, variable
from ..fits import PARAMS, FitError, determined, fit_power_law, power_law, undetermined
from ..measure import HELIX_RUN, contact_range, euler_ratio, n_turns
from ._common import bulk_part, check_scene_keys, loosely_wound, rod_parts, same_except, tol_effective

_PAPER_FIT = {"type": "object", "additionalProperties": False, "required": ["A", "l0", "c"],
              "properties": {"A": {"type": "number", "exclusiveMinimum": 0},
                             "l0": {"type": "number", "exclusiveMinimum": 0}, "c": {"type": "number"}}}
OPTIONS = {
    "panel_parameter": {"type": "string", "description": "the one Scene field whose value differs between the "
                        "panels (the reading of the paper's Fig 4 panels (a)-(c))"},
    "fit_trim": {"type": "number", "minimum": 0, "description": "length (R) cut from each end of the "
                 "wall-contact stretch before the fit"},
    "paper_fits": {"type": "object", "additionalProperties": _PAPER_FIT,
                   "description": "scene id -> the paper's printed fit {A, l0 (the paper's l0'), c}, drawn "
                                  "beside ours and compared in the dataset"},
    "paper_euler_ratio": {"type": "number", "exclusiveMinimum": 0,
                          "description": "the load / Euler force ratio printed in the paper's caption"},
}


MIN_CONTACT = 5  # links on the wall below which a profile is not a wall-contact helix
ENSEMBLES = True
#: the ensemble means this kind reports (F(L)/F0 and the bulk decay rate over the corrected law,
#: per panel), named as the convergence ladders compare them: a ladder that ``serves`` one of its
#: scenes decides on these
REPORTS = ("F_transmitted", "decay_ratio")


#: numerics of the loading path a panel may set for itself, each decided by the ladder that
#: serves the panel (Fig 4(b)'s ramp needs more steps than (a) and (c): conv_ramp_steps_b); the
#: dataset then stores them per panel and the caption names them
PANEL_NUMERICS = ("ramp_steps",)


def varied(fig_cfg) -> tuple[str, ...]:
    p = fig_cfg.get("panel_parameter")
    scenes = [sc for sc in (fig_cfg.get("scenes") or {}).values() if isinstance(sc, dict)]
    return ((p,) if p else ()) + tuple(k for k in PANEL_NUMERICS if k != p and any(k in sc for sc in scenes))


def validate(figure, fig_cfg, built) -> None:
    p = fig_cfg.get("panel_parameter")
    sc = next(iter(built.values()))
    if p is not None and p not in type(sc).field_names():
        raise ConfigError(f"figures.{figure}.panel_parameter: {p!r} is not a Scene field")
    panels = _panels(built)
    same_except(figure, panels, varied(fig_cfg), f"the panels of a force-profile figure differ only in "
                                                 f"panel_parameter ({p!r}) and the path's numerics "
                                                 f"({', '.join(PANEL_NUMERICS)})")
    if p and len({getattr(s, p) for s in panels.values()}) != len(panels):
        raise ConfigError(f"figures.{figure}.scenes: two panels have the same {p} value")
    for members in ensembles.by_base(list(built), {n: s.seed for n, s in built.items()}).values():
        same_except(figure, {m: built[m] for m in members}, ("seed",),
                    "the members of a panel's seed ensemble differ only in the seed")
    check_scene_keys(figure, "paper_fits", fig_cfg.get("paper_fits"), panels)


def _panels(built) -> dict:
    """Panel name (the config's scene name) -> the Scene of its shown member (lowest seed)."""
    groups = ensembles.by_base(list(built), {n: s.seed for n, s in built.items()})
    return {b: built[m[0]] for b, m in groups.items()}


def caption(figure, fig_cfg, built) -> str:
    p = fig_cfg.get("panel_parameter")
    n_members = len(built)
    built = _panels(built)
    sc = next(iter(built.values()))
    body = f"Axial force |F_z(s)| along the rod (s from the loaded end), L/R = {sc.L:g}"
    own = [k for k in varied(fig_cfg) if k != p]
    if p:
        body += ". Panels: " + "; ".join(f"({chr(97 + i)}) {p} = {getattr(s, p):g}"
                                         + "".join(f", {k} = {getattr(s, k):g}" for k in own)
                                         for i, s in enumerate(built.values())) + "."
    else:
        body += f", k_fr = {sc.k_fr:g}."
    sim, fit, model, paper = (P.words(x) for x in (P.SIM, P.FIT, P.MODEL, P.PAPER))
    region = {k: P.words(v) for k, v in P.REGIONS.items()}
    body += (f" {sim.capitalize()}: simulation; {fit}: fit A (l0' + s)^c over the wall-contact stretch "
             f"({P.words(P.CONTACT)} band; not drawn, and c 'not determined', where |F_z| falls by less than 2x "
             f"over it or c reaches the fit's bound; trimmed by {fig_cfg.get('fit_trim', 0):g} R at each end; "
             f"values and standard errors in the panel and the dataset); {model}: simple model "
             "(1/|F_z(s_h)| + k_fr R (s - s_h)/(4EI))^-1 from the start of the helix on the wall s_h (the first "
             f"run of at least {HELIX_RUN} links on the wall; a detached tip's isolated contacts are not part of "
             f"it); {paper}: the same with the paper's 2EI.")
    body += (" Lower row: 1/|F_z| against s, with the three regions of the rod found from the data "
             f"({regions.__name__}): the tip at the loaded end ({region['tip']}), the bulk helix where "
             f"the wall friction is axial and at its Coulomb limit ({region['bulk']}), and the lower region where "
             f"it is stuck or azimuthal ({region['lower']}). In the bulk the simple model's argument holds locally "
             f"if d(1/|F_z|)/ds = k_fr R/(4EI) ({model}, from the start of the bulk); the paper's K = R F^2/(2EI) "
             f"gives twice that ({paper}). The number is the fitted bulk slope over k_fr R/(4EI), its uncertainty "
             "the difference between the bulk's halves.")
    if n_members > len(built):
        n = n_members / len(built)
        body += (f" Each panel is a seed ensemble of {n:g} runs: the {sim} profile and the fit are those of the "
                 f"lowest seed, the {P.words(P.ENSEMBLE_BAND)} band the range of |F_z(s)| over the seeds, and "
                 "F(L)/F(0) and c are "
                 "given as the ensemble mean +- standard deviation (every member in the dataset).")
    if fig_cfg.get("paper_fits"):
        body += (f" {P.words(P.PAPER_FIT).capitalize()}: the paper's printed fit (its A, l0', c in the panel); "
                 "F(L)/F(0) is the "
                 "transmitted fraction of our rod, f(L)/|F_z(0)| that of the printed fit, its value at the support "
                 "over the load (its own f(0) is not always the load). The difference is a result, "
                 "not a tuning target (docs/model.md, 'Where the paper's fits disagree with ours').")
    if sc.bending_constant == "paper":
        body += (" Run AS PRINTED: the paper's bending constant C = EI/l0^2 (effective stiffness "
                 f"EI R/l0 = {sc.EI * sc.R / sc.l0:g} EI at l0 = {sc.l0:g} R), not the corrected C = EI/l0.")
    return body


def build(fig_cfg, sims, context=None) -> xr.Dataset:
    panels = ensembles.by_base(list(sims), {n: int(sims[n].attrs.get("seed", 0)) for n in sims})
    ds = _build(fig_cfg, {b: sims[m[0]] for b, m in panels.items()})
    if any(len(m) > 1 for m in panels.values()):
        ds = _add_ensemble(ds, fig_cfg, panels, sims)
    return ds


def _fit_window(d: xr.Dataset, trim: float):
    """The wall-contact stretch (s_h, s_e), the fit window (joints) and |F_z| at s_h."""
    s = d["s"].values
    L = float(d.attrs["L"])
    F = np.abs(d["F_z"].values)
    s_h, s_e = contact_range(d)
    tiny = 1e-9 * L  # s_h, s_e are joints: include them despite rounding
    window = (s >= s_h + trim - tiny) & (s <= s_e - trim + tiny)
    return s_h, s_e, window, float(np.interp(s_h, s, F))


def _fit(d: xr.Dataset, trim: float):
    """Our fit A (l0' + s)^c of |F_z(s)| over the wall-contact stretch of one run."""
    R, EI, k_fr = (float(d.attrs[k]) for k in ("R", "EI", "k_fr"))
    s = d["s"].values
    F = np.abs(d["F_z"].values)
    s_h, _, window, F_h = _fit_window(d, trim)
    guess_A = 4 * EI / (k_fr * R) if k_fr > 0 else F_h
    guess_l0 = max(4 * EI / (k_fr * R * F_h) - s_h, 1.0) if k_fr > 0 else 1.0
    return fit_power_law(s[window], F[window], guess=(guess_A, guess_l0, -1.0))


REGION_KEYS = regions.SUMMARY_KEYS


def _bulk_fit(d: xr.Dataset, a: regions.Analysis):
    """Our fit A (l0' + s)^c over the bulk helix only (None without a bulk or a fit), and the
    factors by which |F_z| falls over the whole stretch and over the bulk."""
    s, F = d["s"].values, np.abs(d["F_z"].values)
    s_h, s_e, _, _ = _fit_window(d, 0.0)
    fall_whole = float(np.interp(s_h, s, F) / np.interp(s_e, s, F))
    if not a.regions.has_bulk:
        return None, fall_whole, 0.0
    lo, hi = a.regions.s_bulk_start, a.regions.s_bulk_end
    fall_bulk = float(np.interp(lo, s, F) / np.interp(hi, s, F))
    w = (s >= lo) & (s <= hi)
    R, EI, k_fr = (float(d.attrs[k]) for k in ("R", "EI", "k_fr"))
    F_b = float(np.interp(lo, s, F))
    try:
        f = fit_power_law(s[w], F[w], guess=(4 * EI / (k_fr * R), max(4 * EI / (k_fr * R * F_b) - lo, 1.0), -1.0))
    except FitError:
        f = None
    return f, fall_whole, fall_bulk


def _log_rms(curve: np.ndarray, F: np.ndarray, mask: np.ndarray) -> float:
    """rms of ln(curve/F) over the points of mask (0 over none): a printed curve against a profile."""
    return float(np.sqrt(np.mean(np.log(curve[mask] / F[mask]) ** 2))) if mask.any() else 0.0


def _add_ensemble(ds: xr.Dataset, fig_cfg, panels: dict[str, list[str]], sims) -> xr.Dataset:
    """The ensemble of each panel: members' transmitted fraction, exponent and final state,
    their statistics, and the range of the profiles; the panel's transmitted force and
    fraction become ensemble means (those of the shown member are kept)."""
    trim = float(fig_cfg.get("fit_trim", 0.0))
    pad = ensembles.Padded(list(panels.values()), sims)
    has = pad.has
    frac = pad.values(lambda d: float(d["F_transmitted"]) / float(d.attrs["load"]))
    force = pad.values(lambda d: float(d["F_transmitted"]))
    cls = pad.values(lambda d: float(ensembles.CLASSES.index(ensembles.final_class(d))))

    def exponent(d):
        if int(d["contact"].sum()) < MIN_CONTACT:
            return np.nan          # no wall-contact stretch to fit: flagged by has_fit_member
        try:
            return float(_fit(d, trim).c)
        except FitError:
            return np.nan
    c = pad.values(exponent)
    has_fit = (np.isfinite(c) & (has == 1)).astype(np.int8)
    printed = fig_cfg.get("paper_fits") or {}

    def printed_rms(d, a, pf) -> tuple[float, float]:
        """rms of ln(f_paper/|F_z|) over the member's own fit window and bulk (as _build's)."""
        if not pf:
            return 0.0, 0.0
        s_ = d["s"].values
        F_ = np.abs(d["F_z"].values)
        window = _fit_window(d, trim)[2]
        curve = power_law(s_, pf["A"], pf["l0"], pf["c"])
        in_bulk = (s_ >= a.regions.s_bulk_start) & (s_ <= a.regions.s_bulk_end)
        return _log_rms(curve, F_, window), _log_rms(curve, F_, in_bulk)

    per_member, paper_rms = {}, {}
    for name, members in panels.items():
        for m in members:
            a = regions.analyse(sims[m])
            paper_rms[m] = printed_rms(sims[m], a, printed.get(name))
            fb, fall_w, fall_b = _bulk_fit(sims[m], a)
            per_member[m] = (a.bulk.rate if a.bulk else np.nan, fb.c if fb else np.nan,
                             a.regions.tip_length, a.regions.lower_length, fall_w, fall_b,
                             float(a.bulk is not None and loosely_wound(sims[m], a)), bulk_part(sims[m], a))
    grid = np.zeros(has.shape + (8,))
    rms_grid = np.zeros(has.shape + (2,))
    for i, members in enumerate(panels.values()):
        for j, m in enumerate(members):
            grid[i, j] = per_member[m]
            rms_grid[i, j] = paper_rms[m]
    rate, cb, tip_len, low_len, fall_w, fall_b, loose, bpart = (grid[..., k] for k in range(8))
    has_rate = (np.isfinite(rate) & (has == 1)).astype(np.int8)
    loose = ((loose == 1.0) & (has_rate == 1)).astype(np.int8)
    rate = np.where(has_rate == 1, rate, 0.0)
    has_cb = (np.isfinite(cb) & (has == 1)).astype(np.int8)
    cb = np.where(has_cb == 1, cb, 0.0)
    c = np.where(has_fit == 1, c, 0.0)
    st = [ensembles.stats(frac[i, has[i] == 1]) for i in range(len(panels))]
    # the statistics of an exponent are over the members whose fit determines it
    sure = determined(c, fall_w, has_fit)
    cst = [ensembles.stats(c[i, sure[i]]) if sure[i].any() else None for i in range(len(panels))]
    profiles = [np.abs(np.stack([sims[m]["F_z"].values for m in members])) for members in panels.values()]

    P = ("panel",)
    ds["transmitted_fraction_shown"] = variable(P, ds["transmitted_fraction"].values, "transmitted_fraction_shown")
    ds["transmitted_fraction"] = variable(P, [x.mean for x in st], "transmitted_fraction")
    ds["transmitted_fraction"].attrs["long_name"] += " (ensemble mean)"
    ds["F_transmitted"] = variable(P, [float(np.mean(force[i, has[i] == 1])) for i in range(len(panels))],
                                   "F_transmitted")
    ds["F_transmitted"].attrs["long_name"] += " (ensemble mean)"
    ds["converged"] = variable(P, np.int8(pad.values(lambda d: float(d["converged"]), 1.0).min(axis=1)), "converged")
    ds["shown_seed"] = variable(P, [int(sims[m[0]].attrs.get("seed", 0)) for m in panels.values()], "shown_seed")
    ds["n_seeds"] = variable(P, [x.n for x in st], "n_seeds")
    for name, field in (("fraction_std", "std"), ("fraction_sem", "sem"), ("fraction_min", "min"),
                        ("fraction_max", "max")):
        ds[name] = variable(P, [getattr(x, field) for x in st], name)
    ds["fit_c_mean"] = variable(P, [x.mean if x else 0.0 for x in cst], "fit_c_mean")
    ds["fit_c_std"] = variable(P, [x.std if x else 0.0 for x in cst], "fit_c_std")
    PM = ("panel", "member")
    ds["fraction_member"] = variable(PM, frac, "fraction_member")
    ds["fit_c_member"] = variable(PM, c, "fit_c_member")
    ds["has_fit_member"] = variable(PM, has_fit, "has_fit_member")
    ds["member_seed"] = variable(PM, pad.values(lambda d: float(d.attrs["seed"])).astype(np.int64), "member_seed")
    ds["has_member"] = variable(PM, has, "has_member")
    ds["bulk_decay_rate_member"] = variable(PM, rate, "bulk_decay_rate_member")
    ds["has_bulk_member"] = variable(PM, has_rate, "has_bulk_member")
    ds["fit_c_bulk_member"] = variable(PM, cb, "fit_c_bulk_member")
    ds["has_fit_bulk_member"] = variable(PM, has_cb, "has_fit_bulk_member")
    ds["tip_length_member"] = variable(PM, tip_len, "tip_length_member")
    ds["lower_length_member"] = variable(PM, low_len, "lower_length_member")
    ds["fall_whole_member"] = variable(PM, np.where(has == 1, fall_w, 0.0), "fall_whole_member")
    ds["fall_bulk_member"] = variable(PM, np.where(has_cb == 1, fall_b, 0.0), "fall_bulk_member")
    ds["loosely_wound_member"] = variable(PM, loose, "loosely_wound_member")
    ds["bulk_part_member"] = variable(PM, np.where(has == 1, bpart, 0.0), "bulk_part_member")
    ds["paper_rms_log_ratio_member"] = variable(PM, rms_grid[..., 0], "paper_rms_log_ratio_member")
    ds["paper_rms_log_ratio_bulk_member"] = variable(PM, rms_grid[..., 1], "paper_rms_log_ratio_bulk_member")
    sure_bulk = determined(cb, fall_b, has_cb)
    for name, vals, ok in (("bulk_decay_rate", rate, has_rate == 1), ("fit_c_bulk", cb, sure_bulk)):
        st_ = [ensembles.stats(vals[i, ok[i]]) if ok[i].any() else None for i in range(len(panels))]
        ds[f"{name}_mean"] = variable(P, [x.mean if x else 0.0 for x in st_], f"{name}_mean")
        ds[f"{name}_std"] = variable(P, [x.std if x else 0.0 for x in st_], f"{name}_std")
    ds["member_class"] = variable(PM, cls.astype(np.int8), "member_class")
    ds["member_class"].attrs.update({"flag_values": np.arange(len(ensembles.CLASSES), dtype=np.int8),
                                     "flag_meanings": " ".join(ensembles.CLASSES)})
    ds["n_class"] = variable(("panel", "state_class_name"),
                             [[int(((cls[i] == k) & (has[i] == 1)).sum()) for k in range(len(ensembles.CLASSES))]
                              for i in range(len(panels))], "n_class")
    ds["F_abs_min"] = variable(("panel", "s"), [f.min(axis=0) for f in profiles], "F_abs_min")
    ds["F_abs_max"] = variable(("panel", "s"), [f.max(axis=0) for f in profiles], "F_abs_max")
    ds = ds.assign_coords(member=variable(("member",), np.arange(has.shape[1]), "member"),
                          state_class_name=variable(("state_class_name",), np.array(ensembles.CLASSES, dtype=object),
                                                    "state_class_name"))
    ds.attrs["ensemble"] = ("profile, fit and shape variables: the member with the lowest seed (shown_seed); "
                            "F_transmitted, transmitted_fraction: ensemble means; converged: all members")
    return ds


def _build(fig_cfg, sims) -> xr.Dataset:
    p = fig_cfg.get("panel_parameter")
    trim = float(fig_cfg.get("fit_trim", 0.0))
    printed = fig_cfg.get("paper_fits") or {}
    names = list(sims)
    s = sims[names[0]]["s"].values
    rows = {k: [] for k in ("F_abs", "F_fit", "in_fit", "F_simple", "F_simple_paper", "F_paper_fit")}
    link_rows = {"region": [], "q_axial": []}
    reg = {k: [] for k in REGION_KEYS + ("fit_c_bulk", "fit_c_bulk_err", "fit_rms_bulk", "has_fit_bulk", "fall_whole",
                                          "fall_bulk", "paper_rms_log_ratio_bulk", "paper_fit_decay_rate")}
    scal = {k: [] for k in ("fit_A", "fit_l0", "fit_c", "fit_cov", "fit_rms", "s_h", "s_end", "n_fit",
                            "fit_fraction", "paper_fit_A", "paper_fit_l0", "paper_fit_c", "has_paper_fit",
                            "paper_fit_fraction", "paper_fit_F0", "paper_rms_log_ratio")}
    err = {k: [] for k in ("fit_A", "fit_l0", "fit_c")}
    for name in names:
        d = sims[name]
        if d["s"].size != s.size or not np.allclose(d["s"].values, s):
            raise ValueError(f"scene {name!r}: the panels of a force-profile figure must share the rod discretisation")
        R, EI, k_fr, L = (float(d.attrs[k]) for k in ("R", "EI", "k_fr", "L"))
        F = np.abs(d["F_z"].values)
        if int(d["contact"].sum()) < MIN_CONTACT:
            raise ValueError(f"scene {name!r}: {int(d['contact'].sum())} links touch the wall (converged = "
                             f"{int(d['converged'])}, tol_effective = {d.attrs.get('tol_effective', '?')}): not a "
                             "helix on the wall but the straight or planar saddle the run stopped on (docs/model.md, "
                             "'Caveat: saddles'); raise its perturbation or lower tol")
        s_h, s_e, window, F_h = _fit_window(d, trim)
        try:
            f = _fit(d, trim)
        except FitError as e:
            raise FitError(f"scene {name!r}: {e}") from e
        a = regions.analyse(d)
        link_rows["region"].append(a.regions.of_links(d["s_link"].values))
        link_rows["q_axial"].append(a.q_smooth)
        for k, v in regions.summary(d, a).items():
            reg[k].append(v)
        fb, fall_whole, fall_bulk = _bulk_fit(d, a)
        reg["fit_c_bulk"].append(fb.c if fb else 0.0)
        reg["fit_c_bulk_err"].append(fb.errors[2] if fb else 0.0)
        reg["fit_rms_bulk"].append(fb.rms_relative_residual if fb else 0.0)
        in_bulk = (s >= a.regions.s_bulk_start) & (s <= a.regions.s_bulk_end)
        reg["has_fit_bulk"].append(int(fb is not None))
        reg["fall_whole"].append(fall_whole)
        reg["fall_bulk"].append(fall_bulk)
        rows["F_abs"].append(F)
        rows["F_fit"].append(f(s))
        rows["in_fit"].append(window.astype(np.int8))
        rows["F_simple"].append(theory.force_decay(np.maximum(s - s_h, 0.0), F_h, k_fr, R, EI))
        rows["F_simple_paper"].append(theory.force_decay(np.maximum(s - s_h, 0.0), F_h, k_fr, R, EI, paper=True))
        for k, v, e in zip(("fit_A", "fit_l0", "fit_c"), (f.A, f.l0_fit, f.c), f.errors):
            scal[k].append(v)
            err[k].append(e)
        scal["fit_cov"].append(f.covariance)
        scal["fit_rms"].append(f.rms_relative_residual)
        scal["s_h"].append(s_h)
        scal["s_end"].append(s_e)
        scal["n_fit"].append(f.n_points)
        scal["fit_fraction"].append(float(f(L) / f(0.0)))
        pf = printed.get(name)
        if pf:
            curve = power_law(s, pf["A"], pf["l0"], pf["c"])
            scal["paper_rms_log_ratio"].append(_log_rms(curve, F, window))
            reg["paper_rms_log_ratio_bulk"].append(_log_rms(curve, F, in_bulk))
            # the local decay rate the printed curve implies over the same bulk window as ours
            pr = regions.decay_rate(s, curve, a.regions.s_bulk_start, a.regions.s_bulk_end) if a.bulk else None
            reg["paper_fit_decay_rate"].append(pr.rate if pr else 0.0)
            scal["paper_fit_fraction"].append(float(curve[-1] / curve[0]))
            scal["paper_fit_F0"].append(float(curve[0]))
            vals = (pf["A"], pf["l0"], pf["c"], 1)
        else:
            curve = np.zeros_like(s)
            scal["paper_rms_log_ratio"].append(0.0)
            reg["paper_rms_log_ratio_bulk"].append(0.0)
            reg["paper_fit_decay_rate"].append(0.0)
            scal["paper_fit_fraction"].append(0.0)
            scal["paper_fit_F0"].append(0.0)
            vals = (0.0, 0.0, 0.0, 0)
        rows["F_paper_fit"].append(curve)
        for k, v in zip(("paper_fit_A", "paper_fit_l0", "paper_fit_c", "has_paper_fit"), vals):
            scal[k].append(v)

    PJ = ("panel", "s")
    data = {k: variable(PJ, v, k) for k, v in rows.items()}
    data["region"] = variable(("panel", "s_link"), np.array(link_rows["region"], dtype=np.int8), "region")
    data["region"].attrs.update(flag_values=np.arange(len(regions.REGIONS), dtype=np.int8),
                                flag_meanings=" ".join(regions.REGIONS))
    data["q_axial"] = variable(("panel", "s_link"), link_rows["q_axial"], "q_axial")
    for k, v in reg.items():
        data[k] = variable(("panel",), np.int8(v) if k.startswith("has_") else v, k)
    for k in ("has_bulk", "has_fit_bulk"):
        data[k].attrs.update(flag_values=np.array([0, 1], dtype=np.int8), flag_meanings="false true")
    data["fit_cov"] = variable(("panel", "param", "param_"), scal.pop("fit_cov"), "fit_cov")
    for k, v in scal.items():
        data[k] = variable(("panel",), np.int8(v) if k == "has_paper_fit" else v, k)
    for k in ("fit_A", "fit_l0", "fit_c"):
        data[k + "_err"] = xr.Variable(("panel",), np.array(err[k]), attrs=error_attrs(k))
    data.update({
        "F_transmitted": variable(("panel",), [float(sims[n]["F_transmitted"]) for n in names], "F_transmitted"),
        "transmitted_fraction": variable(("panel",), [float(sims[n]["F_transmitted"]) / float(sims[n].attrs["load"])
                                                      for n in names], "transmitted_fraction"),
        "converged": variable(("panel",), [np.int8(sims[n]["converged"]) for n in names], "converged"),
        "n_contact": variable(("panel",), [int(sims[n]["contact"].sum()) for n in names], "n_contact"),
        "n_turns": variable(("panel",), [n_turns(sims[n]) for n in names], "n_turns"),
        "euler_ratio": variable(("panel",), [euler_ratio(sims[n]) for n in names], "euler_ratio"),
        "tol_effective": variable(("panel",), [tol_effective(sims[n]) for n in names], "tol_effective"),
    })
    data["has_paper_fit"].attrs.update(flag_values=np.array([0, 1], dtype=np.int8), flag_meanings="false true")
    coords = {
        "s": variable(("s",), s, "s"),
        "s_link": variable(("s_link",), sims[names[0]]["s_link"].values, "s_link"),
        "panel": xr.Variable(("panel",), np.array(names, dtype=object), attrs=attrs("panel")),
        "param": xr.Variable(("param",), np.array(PARAMS, dtype=object), attrs=attrs("param")),
        "param_": xr.Variable(("param_",), np.array(PARAMS, dtype=object), attrs=attrs("param")),
    }
    if p:
        pv = [float(sims[n].attrs[p]) for n in names]
        coords["panel_value"] = xr.Variable(("panel",), np.array(pv), attrs={**attrs("panel_value"),
                                            "long_name": f"value of {p} in the panel", "parameter": p})
    for k in set(varied(fig_cfg)) & set(PANEL_NUMERICS):
        data[f"panel_{k}"] = variable(("panel",), np.array([int(sims[n].attrs[k]) for n in names], dtype=np.int64),
                                      f"panel_{k}")
    ds = xr.Dataset(data, coords=coords)
    ds.attrs.update({"panel_parameter": p or "none", "fit_trim": trim,
                     "fit_method": "scipy.optimize.curve_fit, relative residuals (sigma = |F_z|), A > 0, l0' > 0",
                     "fit_window": "joints of the wall-contact stretch (from the first to the last run of at least "
                                   f"{HELIX_RUN} links on the wall: measure.contact_range), trimmed by fit_trim",
                     "regions": (f"{regions.__name__}: bulk = longest stretch where the axial friction utilisation, "
                                 f"averaged over {regions.WINDOW_R:g} R, is >= {regions.Q_BULK:g}; tip before it, "
                                 "lower region after it; decay rates are slopes of 1/|F_z| against s, uncertainty "
                                 "max(s.e., half the difference of the two halves)"),
                     "paper_euler_ratio": float(fig_cfg.get("paper_euler_ratio", 0.0)),
                     "paper_reference": "D. Svensek and R. Podgornik, Confined nanorods: jamming due to helical "
                                        "buckling; printed fit parameters as given in the config (paper_fits)"})
    return ds




def headlines(figure: str, ds: xr.Dataset) -> list[Headline]:
    """The error budget's numbers of each panel: the transmitted fraction and the bulk decay rate
    over the simple model's k_fr R/(4EI), ensemble means with their standard errors. A figure run
    with the paper's printed bending constant tests that constant and has none."""
    if ds.attrs.get("bending_constant") == "paper" or "n_seeds" not in ds:
        return []
    out = []
    protocol = str(ds.attrs.get("protocol", "straight"))
    p = str(ds.attrs.get("panel_parameter", "none"))
    where = "ramp, " if protocol == "ramp" else ""
    for i, panel in enumerate(ds["panel"].values):
        def par(k, i=i):
            if p == k and "panel_value" in ds.coords:
                return float(ds["panel_value"].values[i])
            return float(ds.attrs[k]) if k in ds.attrs else float(ds[k].values[i])
        L, load, k_fr = par("L"), par("load"), par("k_fr")
        n = int(ds["n_seeds"].values[i])
        numerics = {"tol": float(ds["tol_effective"].values[i])} if "tol_effective" in ds else {}
        tag = f"{where}panel {panel}" if ds.sizes["panel"] > 1 else f"{where}L/R = {L:g}".rstrip(", ")
        out.append(Headline(f"{figure}.fraction.{panel}", figure, f"F(L)/F0, {tag}",
                            float(ds["transmitted_fraction"].values[i]),
                            float(ds["fraction_sem"].values[i]) if n > 1 else None, n, "F_transmitted", L, load, k_fr,
                            protocol, note="ensemble mean over seeds; statistical error sd/sqrt(n)",
                            numerics=numerics,
                            force_parts=rod_parts(ds["fraction_member"].values[i] * load,
                                                  ds["bulk_part_member"].values[i], ds["has_bulk_member"].values[i])
                            if "bulk_part_member" in ds else None))
        nb = int(ds["has_bulk_member"].values[i].sum())
        n_loose = int(ds["loosely_wound_member"].values[i].sum()) if "loosely_wound_member" in ds else 0
        model = float(ds["decay_rate_model"].values[i])
        if nb and k_fr > 0 and model > 0:
            out.append(Headline(f"{figure}.decay_ratio.{panel}", figure,
                                f"bulk decay rate / (k_fr R/4EI), {tag}",
                                float(ds["bulk_decay_rate_mean"].values[i]) / model,
                                float(ds["bulk_decay_rate_std"].values[i]) / model / np.sqrt(nb) if nb > 1 else None,
                                nb, "decay_ratio", L, load, k_fr, protocol,
                                note="mean over the seeds with a bulk helix"
                                     + (f" ({n_loose} of them loosely wound)" if n_loose else "")
                                     + "; statistical error sd/sqrt(n)",
                                numerics=numerics))
    return out


def _plot_local_law(ax, d, s) -> None:
    """1/|F_z| against s with the three regions shaded and the local laws k_fr R/(4EI)
    (corrected) and k_fr R/(2EI) (paper) drawn from the start of the bulk."""
    inv = 1.0 / d["F_abs"].values
    if int(d.has_bulk):
        for name, lo, hi in (("tip", 0.0, float(d.s_bulk_start)), ("bulk", float(d.s_bulk_start), float(d.s_bulk_end)),
                             ("lower", float(d.s_bulk_end), float(s[-1]))):
            ax.axvspan(lo, hi, **P.REGIONS[name], lw=0, zorder=0, label=f"{name} region")
        s_b = float(d.s_bulk_start)
        inv_b = float(np.interp(s_b, s, inv))
        x = np.linspace(s_b, float(s[-1]), 50)
        ax.plot(x, inv_b + float(d.decay_rate_model) * (x - s_b), **P.MODEL, label=r"simple model, $K = RF^2/(4EI)$")
        ax.plot(x, inv_b + float(d.decay_rate_paper) * (x - s_b), **P.PAPER, label=r"paper's form, $K = RF^2/(2EI)$")
        rate, err = float(d.bulk_decay_rate), float(d.bulk_decay_rate_err)
        ratio = rate / float(d.decay_rate_model)
        text = f"bulk: ${ratio:.2f} \\pm {err / float(d.decay_rate_model):.2f}$\n" + r"$\times\,k_{fr}R/(4EI)$"
        if "bulk_decay_rate_mean" in d:
            text += (f"\nseeds: ${float(d.bulk_decay_rate_mean) / float(d.decay_rate_model):.2f} \\pm "
                     f"{float(d.bulk_decay_rate_std) / float(d.decay_rate_model):.2f}$")
        ax.text(0.97, 0.04, text, transform=ax.transAxes, ha="right", va="bottom", fontsize=7.5,
                bbox=dict(fc="white", ec="none", alpha=0.8, pad=1.5))
    ax.plot(s, inv, lw=1.6, **P.SIM)
    ax.set_ylim(0, 1.08 * float(np.max(inv)))
    ax.set_xlim(0, s[-1])
    ax.set_xlabel(label("s"))


#: curves of the upper row: the data (and the fits to it), then the models; the scale follows
#: the data, the free corners and the log range all of them
DATA_CURVES = ("F_abs", "F_fit", "F_paper_fit", "F_abs_min", "F_abs_max")
CURVES = DATA_CURVES + ("F_simple", "F_simple_paper")
LOG_SPAN = 5.0      # data spanning more than this factor are drawn on a log axis
TEXT_ROOM = 0.46    # share of the panel height two stacked text blocks take (six lines at 7.5 pt)
LINE_ROOM = TEXT_ROOM / 6


#: the text blocks stand over the part of a panel from this share of its length on
TEXT_FROM = 0.3


def _drawn(ds: xr.Dataset, keys, s_from: float = 0.0) -> np.ndarray:
    """The positive values of the curves `keys` as the panels draw them (from s_from times the
    rod's length on): our fit only over its window and only where it determines c, the paper's
    fit only where the panel has one."""
    out = []
    s = ds["s"].values
    part = s >= s_from * s[-1]
    for i in range(ds.sizes["panel"]):
        d = ds.isel(panel=i)
        for k in keys:
            if k not in d or (k == "F_paper_fit" and not int(d.has_paper_fit)):
                continue
            v = np.ravel(d[k].values)
            keep = part.copy()
            if k == "F_fit":
                if undetermined(float(d.fit_c), float(d.fall_whole)):
                    continue
                keep &= np.ravel(d["in_fit"].values) == 1
            out.append(v[keep])
    v = np.concatenate(out) if out else np.array([1.0])
    return v[np.isfinite(v) & (v > 0)]


def _y_range(ax, ds: xr.Dataset, room: float = TEXT_ROOM) -> tuple[float, float]:
    """One y range for every panel: linear from 0 where the data span less than LOG_SPAN (a log
    axis would leave most of the panel empty), else logarithmic over every drawn
    curve, with the lowest curve `room` (the share of the height the text blocks take, and a
    margin) above the bottom, so that the text below the curves covers none. Returns the limits
    set."""
    data, every = _drawn(ds, DATA_CURVES), _drawn(ds, CURVES)
    if float(data.max()) / float(data.min()) < LOG_SPAN:
        # room above the curves where the text blocks stand
        ax.set_ylim(0.0, max(1.12 * float(every.max()), float(_drawn(ds, CURVES, TEXT_FROM).max()) / (0.97 - room)))
    else:
        ax.set_yscale("log")
        hi, low = 1.3 * float(every.max()), float(every.min())
        r = min(room + 0.04, 0.7)
        ax.set_ylim(low * (low / hi) ** (r / (1.0 - r)), hi)
        P.plain_log_ticks(ax.yaxis)
    return ax.get_ylim()


def _free_corner(d: xr.Dataset, s: np.ndarray, ylim: tuple[float, float], room: float) -> str:
    """'top' or 'bottom': where on the right half of a linear panel its curves leave `room`
    (a share of the height) free; else the freer of the two."""
    right = s >= TEXT_FROM * s[-1]
    vals = np.concatenate([d[k].values[right] for k in CURVES if k in d])
    vals = vals[np.isfinite(vals)]
    lo, hi = ylim
    top, bottom = (hi - float(vals.max())) / (hi - lo), (float(vals.min()) - lo) / (hi - lo)
    if top >= room:
        return "top"
    return "bottom" if bottom >= room or bottom > top else "top"


def _math(text: str) -> str:
    """A plain-text note in mathtext: |F_z|, negative numbers and the 'x' of a factor."""
    text = re.sub(r"(?<=\d)x", r"$\\times$", text.replace("|F_z|", "$|F_z|$"))
    return re.sub(r"(?<![\w$])-(\d+(\.\d+)?)", r"$-\1$", text)


def _determined_seeds(d: xr.Dataset) -> tuple[int, int]:
    """(members whose fit determines c, members with a fit) of one panel of an ensemble."""
    has = d["has_fit_member"].values
    if "fall_whole_member" not in d:
        return int(has.sum()), int(has.sum())
    return int(determined(d["fit_c_member"].values, d["fall_whole_member"].values, has).sum()), int(has.sum())


def _text_room(ds: xr.Dataset, wide: bool) -> float:
    """The share of a panel's height its text blocks take: ours (up to four lines with seeds)
    and the paper's (three), stacked in narrow panels, side by side in a wide one."""
    ours = 4 if "shown_seed" in ds else 3
    paper = 3 if int(ds["has_paper_fit"].values.max()) else 0
    return LINE_ROOM * (max(ours, paper) if wide else ours + paper)


def _profile_texts(ax, d: xr.Dataset, seeds: bool, wide: bool, ylim) -> None:
    """Our fit and transmitted fraction (red) and the paper's printed numbers (orange) in the
    corner of the right half that the curves leave free; a wide single panel holds the two
    blocks side by side, narrow panels stack them. The full fit parameters are in the dataset
    and the claims."""
    s = d["s"].values
    log = ax.get_yscale() == "log"
    # three lines of 7.5 pt a block: side by side they take TEXT_ROOM / 2 of the height
    corner = "bottom" if log else _free_corner(d, s, ylim, TEXT_ROOM / (2 if wide else 1))  # _y_range left room
    va, y0, step = ("top", 0.97, -0.23) if corner == "top" else ("bottom", 0.03, 0.23)
    why = undetermined(float(d.fit_c), float(d.fall_whole))
    lines = [f"$c = {float(d.fit_c):.3f}$"] if not why else ["$c$ not determined", "(" + _math(why) + ")"]
    if seeds:
        k, n = _determined_seeds(d)
        lines.append("(no seed determines $c$)" if k == 0 else f"(1 of {n} seeds determines $c$)" if k == 1 < n else
                     f"(seeds ${float(d.fit_c_mean):.2f} \\pm {float(d.fit_c_std):.2f}$"
                     + ("" if k == n else f", {k} of {n}") + ")")
        lines.append(f"$F(L)/F(0) = {float(d.transmitted_fraction):.3f} \\pm {float(d.fraction_std):.3f}$")
    else:
        lines.append(f"$F(L)/F(0) = {float(d.transmitted_fraction):.3f}$")
    blocks = [("\n".join(lines), P.FIT["color"])]
    if int(d.has_paper_fit):
        f_load = float(d.paper_fit_fraction * d.paper_fit_F0) / float(d.attrs["load"])
        blocks.insert(0, (f"paper: $c = {float(d.paper_fit_c):g}$\n$l_0' = {float(d.paper_fit_l0):g}\\,R$\n"
                          f"$f(L)/|F_z(0)| = {f_load:.3f}$", P.PAPER_FIT["color"]))
    x0 = 0.97 if not log else 0.03
    ha = "right" if not log else "left"
    for k, (text, color) in enumerate(blocks if corner == "top" else blocks[::-1]):
        x, y = (x0 - 0.45 * k * (1 if ha == "right" else -1), y0) if wide else (x0, y0 + k * step)
        ax.text(x, y, text, transform=ax.transAxes, ha=ha, va=va, fontsize=7.5, color=color,
                bbox=dict(fc="white", ec="none", alpha=0.7, pad=1.0))


def plot(ds: xr.Dataset):
    n = ds.sizes["panel"]
    width = 6.8 if n > 1 else 4.6
    local = "bulk_decay_rate" in ds
    rows = 2 if local else 1
    fig, all_axes = P.plt.subplots(rows, n, figsize=(width, 3.3 + 2.2 * (rows - 1)), squeeze=False,
                                   label=ds.attrs["title"], gridspec_kw={"height_ratios": [3, 2][:rows]})
    axes = all_axes[:1]
    for ax in axes[0][1:]:
        ax.sharey(axes[0][0])
    s = ds["s"].values
    p = ds.attrs.get("panel_parameter", "none")
    for i, ax in enumerate(axes[0]):
        d = ds.isel(panel=i)
        w = d["in_fit"].values == 1
        ax.axvspan(float(d.s_h), float(d.s_end), **P.CONTACT, zorder=0, lw=0, label="wall contact")
        if "F_abs_min" in ds:
            ax.fill_between(s, d["F_abs_min"], d["F_abs_max"], **P.ENSEMBLE_BAND, lw=0, zorder=1,
                            label=f"range over {int(d.n_seeds)} seeds")
        ax.plot(s, d["F_abs"], lw=2.2, **P.SIM,
                label="simulation" if "shown_seed" not in ds else "simulation, lowest seed")
        if not undetermined(float(d.fit_c), float(d.fall_whole)):     # a curve of degenerate parameters: none
            ax.plot(s[w], d["F_fit"].values[w], **P.FIT, label=r"our fit $A\,(l_0'+s)^c$")
        ax.plot(s, d["F_simple"], **P.MODEL, label=r"simple model, $K = RF^2/(4EI)$")
        ax.plot(s, d["F_simple_paper"], **P.PAPER, label=r"paper's form, $K = RF^2/(2EI)$")
        if int(d.has_paper_fit):
            ax.plot(s, d["F_paper_fit"], **P.PAPER_FIT, label="paper's printed fit")
        _profile_texts(ax, d, "shown_seed" in ds, n == 1, _y_range(ax, ds, _text_room(ds, n == 1)))
        ax.set_xlabel(label("s"))
        title = f"({chr(97 + i)})" if n > 1 else ""
        if p != "none":
            title += " " + P.param_text(p, float(d.panel_value))
        ax.set_title(title, fontsize=9, loc="left")
        ax.set_xlim(0, s[-1])
    axes[0][0].set_ylabel(label("F_abs"))
    if local:
        for i, ax in enumerate(all_axes[1]):
            _plot_local_law(ax, ds.isel(panel=i), s)
            ax.set_title((f"({chr(97 + n + i)})" if n > 1 else "") + " local decay law", fontsize=9, loc="left")
        all_axes[1][0].set_ylabel(r"$1/|F_z|$ [$R^2/EI$]")
    head = P.params_text(ds, ("L", "load", "k_fr", "l0"))
    if ds.attrs.get("bending_constant") == "paper":
        head += r"; AS PRINTED: $C = EI/l_0^2$"
    fig.suptitle(head, fontsize=9)
    handles, labels = P.legend_entries(list(axes[0]) + (list(all_axes[1]) if local else []))
    ncol = min(len(labels), 4 if n > 1 else 2)
    fig.legend(handles, labels, loc="lower center", ncol=ncol, bbox_to_anchor=(0.5, -0.01))
    legend_rows = -(-len(labels) // ncol)
    fig.tight_layout(rect=(0, (0.17 * legend_rows + 0.05) / fig.get_figheight(), 1, 1))
    return fig
