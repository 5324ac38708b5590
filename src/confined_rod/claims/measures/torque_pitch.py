"""Measures of the axial torque budget, the loading path's torque and the pitch along the helix."""
from __future__ import annotations

import math

import numpy as np
import xarray as xr

from ...layout import dataset_path
from ..evidence import ClaimError
from ._base import Measured, _threshold_robust, _two_windows, measure


@measure
def torque_budget_closes(ev, spec, claim):
    """The axial torque budget (confined_rod.analysis.torque) in every member of the protocol comparisons
    with both ends free: the friction's total axial torque vanishes (closure <= `max_closure`),
    and in the bulk the torque the friction left in the rod equals the one the local helix
    carries, link by link: the median over the bulk of |difference| / (tau_0 + |tau|) is at
    most `tol` in every run (torque.bulk_summary; compared link by link, so that a reversal of
    handedness inside the bulk, where the uniform helix's torque does not hold, is outvoted, not
    mixed into two separate medians). Value: the largest over the runs."""
    worst_c, worst_d, parts, files = 0.0, 0.0, [], []
    for fig in spec["figures"]:
        ds = ev.dataset(fig, claim)
        files.append(f"{dataset_path(fig)}:torque_closure_member, torque_budget_residual_member, "
                     "torque_friction_ratio_member")
        free = (ds["variant_ends"].values == "free")[:, None] & (ds["has_member"].values == 1)
        # away from equilibrium the budget need not close: those runs are no evidence
        off = free & (ds["converged_member"].values == 0)
        if off.any():
            parts.append(f"{fig}: {int(off.sum())} runs not at equilibrium left out (" + ", ".join(
                f"{ds.variant.values[i]} member {j}" for i, j in zip(*np.nonzero(off))) + ")")
        has = free & ~off
        bulk = has & (ds["has_bulk_member"].values == 1)
        c = ds["torque_closure_member"].values[has]
        fr = ds["torque_friction_ratio_member"].values[bulk]
        d = ds["torque_budget_residual_member"].values[bulk]
        worst_c, worst_d = max(worst_c, float(c.max(initial=0))), max(worst_d, float(d.max(initial=0)))
        parts.append(f"{fig}: {int(has.sum())} runs, closure <= {float(c.max(initial=0)):.1e}, bulk torque from "
                     f"friction and from the helix differ link by link by a median <= {float(d.max(initial=0)):.3f} "
                     f"(tau_0 + |tau|) over {int(bulk.sum())} runs; bulk tau/tau_0 from "
                     f"{float(fr.min(initial=0)):.2f} to {float(fr.max(initial=0)):.2f}")
    holds = worst_c <= float(spec["max_closure"]) and worst_d <= float(spec["tol"])
    return Measured(worst_d, holds, ", ".join(files), "; ".join(parts))


def _variant(ds, name: str, claim: str) -> int:
    names = [str(v) for v in ds.variant.values]
    if name not in names:
        raise ClaimError(f"claim {claim!r}: no variant {name!r} in the protocol comparison ({', '.join(names)})")
    return names.index(name)


def _mean_sd(ds, key: str, i: int) -> tuple[float, float]:
    return float(ds[f"{key}_mean"].values[i]), float(ds[f"{key}_std"].values[i])


@measure
def loading_path_torque(ev, spec, claim):
    """The loading path selects the bulk helix: the bulk pitch over the torque-free one and the
    bulk tau/tau_0 of `variants` (ensemble means) differ pairwise by more than twice the larger
    s.d., and the variant whose pitch is nearest the torque-free one (smallest |w/w0 - 1|) has the
    largest wall force over R F^2/(4EI) and the largest decay rate (at a given force
    K = R w^2 (F/c - EI w^2) peaks at the torque-free pitch; torque.py). The size of the torque does
    not order them: the relation is double-valued for a torque against the handedness. The note
    gives every number. Value: that variant's wall force over R F^2/(4EI)."""
    ds = ev.dataset(spec["figure"], claim)
    rows = []
    for v in spec["variants"]:
        i = _variant(ds, v, claim)
        if not ds["has_bulk_member"].values[i].any():
            return Measured(0.0, None, f"{dataset_path(spec['figure'])}:has_bulk_member", \
                f"no run of variant {v!r} has a bulk helix (L/R = {float(ds.attrs.get('L', 0)):g}): nothing to compare")
        rows.append((v, {k: _mean_sd(ds, k, i) for k in ("torque_friction_ratio", "pitch_w0_ratio", "K_ratio",
                                                           "K_ratio_from_torque", "decay_ratio", "fraction")}))

    def apart(key):
        return all(abs(a[1][key][0] - b[1][key][0]) > 2 * max(a[1][key][1], b[1][key][1])
                   for k, a in enumerate(rows) for b in rows[k + 1:])

    nearest = min(rows, key=lambda r: abs(r[1]["pitch_w0_ratio"][0] - 1.0))
    top_K = max(rows, key=lambda r: r[1]["K_ratio"][0])
    top_rate = max(rows, key=lambda r: r[1]["decay_ratio"][0])
    holds = apart("pitch_w0_ratio") and apart("torque_friction_ratio") and nearest is top_K and nearest is top_rate
    note = "; ".join(f"{v}: tau/tau_0 {d['torque_friction_ratio'][0]:.2f} +- {d['torque_friction_ratio'][1]:.2f}, "
                     f"pitch {d['pitch_w0_ratio'][0]:.2f} +- {d['pitch_w0_ratio'][1]:.2f} of the lowest-order "
                     "torque-free w0, K "
                     f"{d['K_ratio'][0]:.2f} of R F^2/(4EI) (from pitch and torque {d['K_ratio_from_torque'][0]:.2f}), "
                     f"decay rate {d['decay_ratio'][0]:.2f} +- {d['decay_ratio'][1]:.2f} of the corrected law, "
                     f"F(L)/F(0) {d['fraction'][0]:.2f}" for v, d in rows)
    note += (f"; pitch nearest the torque-free one: {nearest[0]}, largest K: {top_K[0]}, largest decay rate: "
             f"{top_rate[0]}")
    return Measured(nearest[1]["K_ratio"][0], holds, \
        f"{dataset_path(spec['figure'])}:torque_friction_ratio_mean, pitch_w0_ratio_mean, K_ratio_mean, " \
        "decay_ratio_mean", note)


@measure
def lower_region_torque(ev, spec, claim):
    """The lower region of `variant` in each of `figures`: the axial torque it receives from the
    bulk (at its start; the torque vanishes at the free lower end), and the mean azimuthal share
    |f_phi|/|f| of its friction. Its friction turns the rod more than it holds it axially where
    the share exceeds `min_share` (1/sqrt 2: azimuthal above axial) and the received torque is
    nonzero by more than twice its s.d. Holds if that is so at every length, refuted if at none,
    inconclusive otherwise. Value: the share at the first figure's length."""
    parts, results, files, value = [], [], [], None
    for fig in spec["figures"]:
        ds = ev.dataset(fig, claim)
        i = _variant(ds, spec["variant"], claim)
        files.append(f"{dataset_path(fig)}:lower_torque_mean, lower_azimuthal_share_mean")
        if not ds["has_lower_member"].values[i].any():
            parts.append(f"{fig}: no run of {spec['variant']!r} has a bulk and a lower region")
            continue
        tq, tq_sd = _mean_sd(ds, "lower_torque", i)
        peak = _mean_sd(ds, "bulk_torque_max", i)[0]
        share, share_sd = _mean_sd(ds, "lower_azimuthal_share", i)
        used, stuck = _mean_sd(ds, "lower_utilisation", i)[0], _mean_sd(ds, "lower_stuck_share", i)[0]
        ok = abs(tq) > 2 * tq_sd and share > float(spec["min_share"])
        results.append(ok)
        value = share if value is None else value
        parts.append(f"{fig} (L/R = {float(ds.attrs.get('L', 0)):g}): lower region "
                     f"{_mean_sd(ds, 'lower_length', i)[0]:.0f} R receives tau = {tq:.2g} +- {tq_sd:.2g} EI/R "
                     f"(the bulk carries up to {peak:.2g}; {_mean_sd(ds, 'lower_torque_ratio', i)[0]:.2f} tau_0 at the "
                     f"local force), azimuthal share of its friction {share:.2f} +- {share_sd:.2f}, friction at "
                     f"{used:.2f} of its limit, {100 * stuck:.0f} % of its links on the wall stuck"
                     + ("" if ok else " (not above the threshold)"))
    if not results:
        return Measured(0.0, None, ", ".join(files), "; ".join(parts))
    holds = True if all(results) else (False if not any(results) else None)
    return Measured(value, holds, ", ".join(files), "; ".join(parts))


def _pitch_rods(ev, spec, claim) -> list[tuple[str, xr.Dataset]]:
    """The runs of the rod of spec['figure'] (its shown member) and, with `seeds_from`, every seed
    of the same rod (same L, load, k_fr) in that figure; a run shared by both figures (one file)
    counts once."""
    key, rod = ev.sim(spec["figure"], -1, claim)
    runs = {ev.file(key): (key, rod)}
    if "seeds_from" in spec:
        for k, d in ev.sims.items():
            if k.startswith(spec["seeds_from"] + "/") and all(float(d.attrs[a]) == float(rod.attrs[a])
                                                              for a in ("L", "load", "k_fr")):
                runs.setdefault(ev.file(k), (k, d))
                ev.touched.add(("sim", k))
    return list(runs.values())


@measure
def pitch_exponent(ev, spec, claim):
    """The slope d ln|dphi/ds| / d ln|F_z| against `expected` within `tol`, on the whole defined
    stretch and on the bulk helix, decided on the mean over the seeds of the rod (_pitch_rods), as
    the local decay law is: per window the mean m over the seeds whose window determines a slope
    (|F_z| falls by at least fall_min over it, checked at FALL_THRESHOLDS) and its standard error
    u; a window holds if |m - expected| <= tol, fails if |m - expected| - 2u > tol, else is
    undecided; the claim is decided only if both windows agree. Value: the bulk's mean slope
    (nan if not determined)."""
    from ...analysis.figures import pitch_profile

    target, tol = float(spec["expected"]), float(spec["tol"])
    rods = _pitch_rods(ev, spec, claim)
    per = [pitch_profile.build({}, {k: d}) for k, d in rods]

    def windows(fall_min):
        oks, texts, value, err = [], [], math.nan, None
        for name in ("whole", "bulk"):
            e = np.array([float(p[f"exponent_omega_F_{name}"]) for p in per])
            ok = np.array([float(p[f"fall_{name}"]) >= fall_min for p in per]) & np.isfinite(e)
            if not ok.any():
                oks.append(None)
                texts.append(f"{name}: not determined (|F_z| falls by less than {fall_min:.3g}x on every seed)")
                continue
            m = float(e[ok].mean())
            u = float(e[ok].std(ddof=1) / math.sqrt(ok.sum())) if ok.sum() > 1 else 0.0
            oks.append(True if abs(m - target) <= tol else (False if abs(m - target) - 2 * u > tol else None))
            texts.append(f"{name}: mean {m:.3f} +- {u:.2g} (s.e.) over {int(ok.sum())} seeds, per seed "
                         + ", ".join(f"{x:.3f}" for x in e[ok]))
            if name == "bulk":
                value, err = m, (u if ok.sum() > 1 else None)
        return Measured(value, _two_windows(*oks), "", "; ".join(texts), error=err)

    value, holds, _, note, _, err = _threshold_robust(windows)
    return Measured(value, holds, \
        ", ".join(ev.file(k) for k, _ in rods) + ":dphi_ds, F_z", \
        note + f" (expected {target:g} +- {tol:g}: holds within it, fails beyond it by more than twice the "
               "standard error of the mean)", error=err if math.isfinite(value) else None)


@measure
def wall_force_pitch_law(ev, spec, claim):
    """The relation that organises the bulk helix (derivations.wall_force_pitch_relation): per
    rod (every member with a bulk of the protocol comparisons), the measured wall force per length
    K_ratio = <K>/<R F^2/(4EI)> against K_ratio_from_pitch, the constant-pitch helix's
    rho w^2 (F/c - EI w^2) at the local pitch and force (torque.bulk_summary). Per loading path
    (a variant of a comparison): holds if every rod agrees within `tol` (relative), fails if the
    median rod misses by more than twice it, else is undecided. The claim ("whatever its loading
    path") holds if every path holds and fails if one fails (the paths that hold are named in the
    note; those near the torque-free pitch, where K is stationary in x, do not test the pitch
    dependence), else is undecided. Value: the largest relative difference over the
    rods. The note gives per path the range of x = |w|/w0 and of K/(R F^2/(4EI))."""
    tol = float(spec["tol"])
    diffs, parts, files, held, failed = [], [], [], [], []
    for fig in spec["figures"]:
        ds = ev.dataset(fig, claim)
        files.append(f"{dataset_path(fig)}:K_ratio_member, K_ratio_from_pitch_member, pitch_w0_ratio_member")
        for i, v in enumerate(ds.variant.values):
            ok = ds.has_bulk_member.values[i] == 1
            if not ok.any():
                continue
            K, Kw = ds.K_ratio_member.values[i][ok], ds.K_ratio_from_pitch_member.values[i][ok]
            x = ds.pitch_w0_ratio_member.values[i][ok]
            d = np.abs(K / Kw - 1.0)
            diffs += list(d)
            word = "holds" if d.max() <= tol else ("fails" if np.median(d) > 2 * tol else "undecided")
            (held if word == "holds" else failed if word == "fails" else []).append(f"{fig} {v}")
            parts.append(f"{fig} {v} ({int(ok.sum())} rods, {word}): x {x.min():.2f}-{x.max():.2f}, K/(R F^2/(4EI)) "
                         f"{K.min():.3g}-{K.max():.3g}, from the pitch {Kw.min():.3g}-{Kw.max():.3g}, largest "
                         f"difference {d.max():.2%}")
    if not diffs:
        raise ClaimError(f"claim {claim!r}: no rod with a bulk helix in {', '.join(spec['figures'])}")
    d = np.asarray(diffs)
    n_paths = len(parts)
    holds = True if len(held) == n_paths else (False if failed else None)
    return Measured(float(d.max()), holds, "; ".join(files),
                    f"{d.size} rods on {n_paths} loading paths, {int(np.sum(d > tol))} rods beyond {tol:.0%}; paths "
                    f"that hold: {len(held)}, fail: {len(failed)}: " + "; ".join(parts))


@measure
def pitch_falls_less(ev, spec, claim):
    ds = ev.dataset(spec["figure"], claim)
    d_omega, d_F = float(ds.drop_omega), float(ds.drop_F)
    return Measured(d_omega, 0 < d_omega < d_F, f"{dataset_path(spec['figure'])}:drop_omega, drop_F", \
        f"|dphi/ds| falls by {d_omega:.0%}, |F_z| by {d_F:.0%}")
