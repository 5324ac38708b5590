"""Kind ``pitch_profile`` (paper Fig 5): dphi/ds along the wall-contact stretch of one rod,
and the local helix relation between the pitch and the axial force.

The paper's claim (caption of Fig 5): dphi/dl falls along the rod as |F_z| falls, but
relatively less, "as hinted by F_z ~ (dphi/dl)^2" (its Eq. dotphi). This module measures
both on the data. With w = |dphi/ds| of the link centres on the wall, a torque-free helix on
the wall carries |F_z| = 2 EI w^2 sqrt(1 - R^2 w^2) (docs/model.md, "The paper's simple model,
rederived"); the dataset stores that force, the pitch rate the local |F_z| would give such a
helix, their ratio, the slope of ln w against ln |F_z| (1/2 for F ~ w^2) and the relative
decrease of both along the bulk of the stretch. Reversals of handedness (sign changes of
dphi/ds) are detected, stored and marked, not drawn as spikes.

Where the pitch is defined: links touching the wall with R|dphi/ds| below sqrt(2/3) (the
largest pitch rate of a helix on the wall). The bulk is the middle 80 % of the stretch (the
transition zones at its ends are not a helix of slowly varying pitch); the decreases compare
the medians of the first and last tenth of the bulk.
"""
from __future__ import annotations

import numpy as np
import xarray as xr

from ... import theory
from ...errors import ConfigError
from .. import plotting as P
from .. import regions
from ..figure_quantities import label, variable
from ..measure import contact_range, force_at_links, handedness_reversals

OPTIONS: dict = {}
BULK = (0.1, 0.9)  # fraction of the contact stretch that is the bulk helix
W_MAX = np.sqrt(2.0 / 3.0)  # R |w| of the steepest helix on the wall


def validate(figure, fig_cfg, built) -> None:
    if len(built) != 1:
        raise ConfigError(f"figures.{figure}.scenes: a pitch profile shows one rod, got {len(built)} scenes")


def caption(figure, fig_cfg, built) -> str:
    sc = next(iter(built.values()))
    return (f"Pitch rate dphi/ds (the inverse of the helical pitch, q0 = 2 pi/(dphi/ds)) along the wall-contact "
            f"stretch of the rod of L/R = {sc.L:g}, k_fr = {sc.k_fr:g} (the rod of Fig 4(c), same simulation). "
            f"(a) |dphi/ds| of the link centres on the wall ({P.words(P.SIM)}; links off the wall inside the "
            f"stretch omitted), reversals of handedness marked by {P.words(P.MARK)} triangles; "
            f"{P.words(P.MODEL)}: the pitch rate a torque-free helix carrying the local |F_z| would have, "
            "2 EI omega^2 sqrt(1 - R^2 omega^2) = |F_z| with omega = |dphi/ds|; "
            f"{P.words(P.PAPER)}: its lowest order sqrt(|F_z|/2EI) (paper's Eq. dotphi). (b) |F_z(s)| "
            f"({P.words(P.SIM)}) against the same relation evaluated with the measured pitch ({P.words(P.MARK)}), "
            "and their ratio in the dataset. The bulk (middle 80 % of the stretch, between the "
            f"{P.words(P.GUIDE)} lines) gives the slope of ln|dphi/ds| against ln|F_z| and the relative "
            "decreases that test the paper's claim.")


def build(fig_cfg, sims, context=None) -> xr.Dataset:
    (name, d), = sims.items()
    R, EI = float(d.attrs["R"]), float(d.attrs["EI"])
    s_h = d["s_helix"].values
    w = d["dphi_ds"].values
    if s_h.size < 10:
        raise ValueError(f"scene {name!r}: the wall-contact stretch has {s_h.size} links; no pitch profile")
    link = np.searchsorted(d["s_link"].values, s_h)
    F = force_at_links(d)[link]
    on_wall = d["contact"].values[link] == 1
    rev = np.zeros(s_h.size, dtype=np.int8)
    irev = handedness_reversals(w)
    rev[irev] = 1
    near_rev = np.zeros(s_h.size, dtype=bool)
    for i in irev:  # the pitch passes through 0 (infinite pitch) at a reversal: 2 links either side
        near_rev[max(i - 2, 0):i + 4] = True
    defined = on_wall & (R * np.abs(w) < W_MAX) & ~near_rev
    s_rev = 0.5 * (s_h[irev] + s_h[irev + 1])
    F_helix = np.where(defined, theory.helix_force(np.abs(w), R, EI), 0.0)
    ratio = np.where(defined & (F_helix > 0), F / np.where(F_helix > 0, F_helix, 1.0), 0.0)
    F_ok = np.minimum(F, theory.HELIX_F_MAX * EI / R**2)
    w_helix = theory.helix_pitch_rate(F_ok, R, EI)
    w_low = np.sqrt(F / (2.0 * EI))

    # the stretch from the first to the last run of links on the wall (a detached tip's
    # isolated contacts are not part of the helix)
    lo, hi = contact_range(d)
    stretch = (s_h >= lo) & (s_h <= hi)
    span = hi - lo
    bulk = (s_h >= lo + BULK[0] * span) & (s_h <= lo + BULK[1] * span) & defined
    fit = bulk & (np.abs(w) > 0)
    slope = float(np.polyfit(np.log(F[fit]), np.log(np.abs(w[fit])), 1)[0]) if fit.sum() >= 5 else 0.0
    # the same slope over the whole defined stretch and over the bulk helix of confined_rod.analysis.regions
    reg = regions.analyse(d).regions
    in_region = (s_h >= reg.s_bulk_start) & (s_h <= reg.s_bulk_end) & defined & (np.abs(w) > 0)
    slopes = {}
    for key, m in (("whole", defined & stretch & (np.abs(w) > 0)), ("bulk", in_region)):
        slopes[key] = float(np.polyfit(np.log(F[m]), np.log(np.abs(w[m])), 1)[0]) if m.sum() >= 5 else 0.0
        slopes[key + "_fall"] = float(F[m].max() / F[m].min()) if m.sum() >= 5 else 1.0
    sb = s_h[bulk]
    tenth = 0.1 * (sb[-1] - sb[0]) if sb.size else 0.0
    first, last = bulk & (s_h <= sb[0] + tenth), bulk & (s_h >= sb[-1] - tenth)
    drop_w = float(1.0 - np.median(np.abs(w[last])) / np.median(np.abs(w[first])))
    drop_F = float(1.0 - np.median(F[last]) / np.median(F[first]))
    claim = bool(0 < drop_w < drop_F)

    H = ("s_helix",)
    data = {
        "omega": variable(H, w, "omega"),
        "F_link": variable(H, F, "F_link"),
        "omega_helix": variable(H, w_helix, "omega_helix"),
        "omega_lowest": variable(H, w_low, "omega_lowest"),
        "F_helix": variable(H, F_helix, "F_helix"),
        "helix_ratio": variable(H, ratio, "helix_ratio"),
        "reversal": variable(H, rev, "reversal"),
        "contact": variable(H, on_wall.astype(np.int8), "contact"),
        "pitch_defined": xr.Variable(H, defined.astype(np.int8), attrs={
            "long_name": "pitch defined: link on the wall with R|dphi/ds| < sqrt(2/3), not within 2 links of a "
                         "reversal of handedness", "units": "1",
            "flag_values": np.array([0, 1], dtype=np.int8), "flag_meanings": "false true"}),
        "in_bulk": xr.Variable(H, bulk.astype(np.int8), attrs={
            "long_name": "in the bulk (middle 80 % of the contact stretch) and defined", "units": "1"}),
        "s_reversal": variable(("reversal_index",), s_rev, "s_reversal"),
        "exponent_omega_F": variable((), slope, "exponent_omega_F"),
        "exponent_omega_F_whole": variable((), slopes["whole"], "exponent_omega_F_whole"),
        "exponent_omega_F_bulk": variable((), slopes["bulk"], "exponent_omega_F_bulk"),
        "fall_whole": variable((), slopes["whole_fall"], "fall_whole"),
        "fall_bulk": variable((), slopes["bulk_fall"], "fall_bulk"),
        "drop_omega": variable((), drop_w, "drop_omega"),
        "drop_F": variable((), drop_F, "drop_F"),
        "helix_ratio_median": xr.Variable((), float(np.median(ratio[bulk])) if bulk.any() else 0.0, attrs={
            "long_name": "median over the bulk of |F_z| / (2 EI w^2 sqrt(1 - R^2 w^2))", "units": "1"}),
    }
    for k in ("reversal", "contact"):
        data[k].attrs.update(flag_values=np.array([0, 1], dtype=np.int8), flag_meanings="false true")
    ds = xr.Dataset(data, coords={"s_helix": variable(H, s_h, "s_helix")})
    ds.attrs.update({
        "scene": name, "n_reversals": int(irev.size),
        "claim": "dphi/dl falls along the rod, relatively less than |F_z| (paper, caption of Fig 5)",
        "claim_holds": int(claim),
        "claim_test": "0 < drop_omega < drop_F over the bulk (middle 80 % of the contact stretch)",
        "helix_relation": "|F_z| = 2 EI w^2 sqrt(1 - R^2 w^2), torque-free helix on the wall (docs/model.md)",
    })
    return ds


def plot(ds: xr.Dataset):
    fig, (a, b) = P.plt.subplots(2, 1, figsize=(5.0, 5.6), sharex=True, label=ds.attrs["title"])
    s = ds["s_helix"].values
    w = np.abs(ds["omega"].values)
    ok = ds["pitch_defined"].values == 1
    bulk = s[ds["in_bulk"].values == 1]
    # NaN here only breaks the drawn line where the pitch is not defined (links off the wall);
    # it is never stored, and no NaN is drawn
    w_line = np.where(ok, w, np.nan)
    a.plot(s, w_line, **P.SIM, lw=1.6, label=r"simulation $|d\phi/ds|$")
    a.plot(s, np.where(ok, ds["omega_helix"].values, np.nan), **P.MODEL,
           label=r"helix with the local $|F_z|$: $2EI\omega^2\sqrt{1-R^2\omega^2}=|F_z|$")
    a.plot(s, np.where(ok, ds["omega_lowest"].values, np.nan), **P.PAPER,
           label=r"lowest order $\sqrt{|F_z|/2EI}$ (paper's Eq. dotphi)")
    if ds.sizes.get("reversal_index", 0):
        top = float(np.nanmax(w_line)) * 1.08
        a.plot(ds["s_reversal"], np.full(ds.sizes["reversal_index"], top), "v", **P.MARK, ms=6,
               label="reversal of handedness")
    a.set_ylabel(r"$|d\phi/ds|$ [$1/R$]")
    a.set_ylim(0, None)
    a.legend(loc="upper right", fontsize=7)
    a.set_title("(a) pitch rate along the wall-contact stretch", fontsize=9, loc="left")
    a.text(0.02, 0.04, f"bulk: $|d\\phi/ds|$ falls by {100 * float(ds.drop_omega):.0f} %, $|F_z|$ by "
           f"{100 * float(ds.drop_F):.0f} %;\nslope $d\\ln|d\\phi/ds| / d\\ln|F_z|$ = {float(ds.exponent_omega_F):.2f} "
           "(simple model: 0.5)", transform=a.transAxes, fontsize=7.5, va="bottom")
    F_line = np.where(ok, ds["F_helix"].values, np.nan)
    b.plot(s, ds["F_link"], **P.SIM, lw=1.6, label=r"$|F_z(s)|$, simulation")
    b.plot(s, F_line, **P.MARK, lw=1.0, label=r"$2EI\omega^2\sqrt{1-R^2\omega^2}$, measured $\omega$")
    b.set_yscale("log")
    P.plain_log_ticks(b.yaxis)
    b.set_ylabel(label("F_abs"))
    b.set_xlabel(label("s_helix"))
    b.legend(loc="upper right", fontsize=7)
    b.text(0.02, 0.04, f"median ratio $|F_z|/F_{{helix}}$ in the bulk = {float(ds.helix_ratio_median):.2f}",
           transform=b.transAxes, fontsize=7.5)
    b.set_title("(b) axial force against the local helix relation", fontsize=9, loc="left")
    for ax in (a, b):
        if bulk.size:
            ax.axvline(bulk[0], **P.GUIDE)
            ax.axvline(bulk[-1], **P.GUIDE)
    fig.suptitle(P.params_text(ds, ("L", "load", "k_fr", "l0")), fontsize=9)
    fig.tight_layout()
    return fig
