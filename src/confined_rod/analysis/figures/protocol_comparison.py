"""Kind ``protocol_comparison`` (not in the paper): what the loading path does to one rod.

With static friction the equilibrium depends on how it was reached. This kind puts seed
ensembles of one rod side by side that differ in how the load was applied or in a setting
that could change the path: the protocol (the full load at once on a straight rod, the
paper's; a quasi-static ``ramp`` at several step counts, which also checks that the ramp is
fine enough; a start from a one-handed ``helix``), the end conditions, the amplitude of the
random start, the link length. Per variant it stores, for every member and as ensemble
statistics, the transmitted fraction F(L)/F(0), the three regions of the rod
(confined_rod.analysis.regions: tip, bulk helix, lower region), the number of reversals of handedness
of the wall-contact stretch and the bulk decay rate over the corrected local law.

A *ramp ladder* (variants that differ only in ``ramp_steps``) is compared member by member
(same seed): the change of F(L) from each ramp to the next finer one, as the mean paired
relative change with its standard error and the largest single change over the seeds that
keep their final state; seeds whose winding changes by half a turn or so (a neighbouring
equilibrium, ensembles.STATE_TURNS) are counted apart. The convergence check of the ramp
(kind ``convergence``, parameter ramp_steps) makes the same comparison a verdict.
"""
from __future__ import annotations

import numpy as np
import xarray as xr

from ...errors import ConfigError
from .. import ensembles, regions, torque
from .. import plotting as P
from ..figure_quantities import label, variable
from ..measure import defects, n_turns
from ._common import need_scenes, same_except, scene_coord

OPTIONS = {
    "labels": {"type": "object", "additionalProperties": {"type": "string"},
               "description": "scene id -> a short label of the variant for the figure (default: the scene id)"},
    "profiles": {"type": "array", "items": {"type": "string"}, "minItems": 1, "maxItems": 4,
                 "description": "variants whose first seed is drawn along s (force and axial torque); same L and "
                                "l0 (default: the first three variants)"},
}
ENSEMBLES = True
#: the ensemble means this kind reports (F(L)/F0, the bulk decay rate, the bulk's wall force and pitch
#: rate per protocol), named as the convergence ladders compare them: a ladder that ``serves`` one of its
#: scenes decides on these. The figure's K_ratio (bulk mean of K over R F^2/(4EI)) and pitch_w0_ratio
#: (over the lowest-order w0 = sqrt(F/2EI)) are read by the ladders as wall_force_ratio and pitch_ratio
#: (medians over the regular helix, the pitch over the exact torque-free rate w(F)): the denominators are
#: functions of the local force, so a numerical shift of one ratio is the other's to first order
REPORTS = ("F_transmitted", "decay_ratio", "wall_force_ratio", "pitch_ratio")
#: the share of the log axis of panel (h) below its legend that the profiles may fill
LEGEND_FREE = 0.6
#: the settings a variant may change; everything else is the same in every variant
VARIED = ("protocol", "ramp_steps", "ramp_start", "ends", "lower_end", "perturbation", "l0", "seed",
          "snapshot_interval", "snapshot_growth")


def varied(fig_cfg) -> tuple[str, ...]:
    return VARIED


def _variants(built) -> dict[str, list[str]]:
    return ensembles.by_base(list(built), {n: s.seed for n, s in built.items()})


def validate(figure, fig_cfg, built) -> None:
    groups = _variants(built)
    need_scenes(figure, groups, 2, "a comparison of protocols")
    same_except(figure, built, VARIED, f"the variants of a protocol comparison differ only in {', '.join(VARIED)}")
    for key in fig_cfg.get("labels") or {}:
        if key not in groups:
            raise ConfigError(f"figures.{figure}.labels: {key!r} is not one of its scenes ({', '.join(groups)})")
    for key in fig_cfg.get("profiles") or []:
        if key not in groups:
            raise ConfigError(f"figures.{figure}.profiles: {key!r} is not one of its scenes ({', '.join(groups)})")
    shown = [groups[b][0] for b in profile_variants(fig_cfg, groups)]
    if len({(built[m].L, float(built[m].l0)) for m in shown}) > 1:
        raise ConfigError(f"figures.{figure}.profiles: the variants drawn along s need the same L and l0 "
                          f"({', '.join(profile_variants(fig_cfg, groups))})")


def profile_variants(fig_cfg, groups) -> list[str]:
    """The variants drawn along s: the option ``profiles``, or the first three."""
    return list(fig_cfg.get("profiles") or list(groups)[:3])


def _describe(sc) -> str:
    text = {"straight": "full load at once on a straight rod (the paper's)",
            "ramp": f"quasi-static ramp of {sc.ramp_steps} load steps from {sc.ramp_start:g}x Euler's load",
            "helix": "full load on a one-handed helix on the wall",
            "planar": "planar start", "planar_then_3d": "planar, then 3-D"}[sc.protocol]
    return text


def caption(figure, fig_cfg, built) -> str:
    groups = _variants(built)
    first = built[next(iter(built))]
    parts = []
    for base, members in groups.items():
        sc = built[members[0]]
        extra = [f"{k} = {getattr(sc, k)}" for k in ("ends", "lower_end") if getattr(sc, k) != getattr(first, k)]
        extra += [f"{k} = {float(getattr(sc, k)):g} R" for k in ("perturbation", "l0")
                  if float(getattr(sc, k)) != float(getattr(first, k))]
        parts.append(f"{(fig_cfg.get('labels') or {}).get(base, base)}: {_describe(sc)}"
                     + (f" ({', '.join(extra)})" if extra else "") + f", {len(members)} seeds")
    return (f"How the loading path sets the equilibrium of one rod, L/R = {first.L:g}, load {first.load:g} EI/R^2, "
            f"k_fr = {first.k_fr:g}, l0 = {float(first.l0):g} R unless stated. Variants: " + "; ".join(parts) + ". "
            f"Per variant (rows) the single seeds ({P.words(P.SEEDS)}) and their mean +- standard deviation "
            f"({P.words(P.SIM)}): (a) the "
            "transmitted fraction F(L)/F(0); (b) the length of the lower region, where the wall friction is stuck "
            f"or azimuthal and |F_z| nearly flat ({regions.__name__}); (c) the number of reversals of "
            "handedness "
            "of the wall-contact stretch; (d) the decay rate d(1/|F_z|)/ds in the bulk helix over the corrected "
            f"local law k_fr R/(4EI) ({P.words(P.MODEL)}: 1; the paper's K gives 2, {P.words(P.PAPER)}).")


def _member_values(d: xr.Dataset) -> dict[str, float]:
    a = regions.analyse(d)
    n_rev = len(defects(np.asarray(d["s_helix"].values), np.asarray(d["dphi_ds"].values)))
    b = torque.budget(d)
    bulk = torque.bulk_summary(d, a.regions.of_links(d["s_link"].values) == 1, b) if a.regions.has_bulk else {}
    out = {"fraction": float(d["F_transmitted"]) / float(d.attrs["load"]),
           "lower_length": a.regions.lower_length, "tip_length": a.regions.tip_length,
           "n_reversals": float(n_rev), "decay_ratio": a.bulk.rate / a.model if a.bulk and a.model > 0 else np.nan,
           "torque_closure": b.closure, "converged": float(d["converged"])}
    for key in torque.SUMMARY_KEYS:
        out[key] = bulk[key] if bulk and a.bulk else np.nan
    out.update(_lower_torque(d, a, b))
    return out


def _lower_torque(d: xr.Dataset, a: regions.Analysis, b: torque.Budget) -> dict[str, float]:
    """What the lower region does with the axial torque: the torque it receives from the bulk
    (at its start, signed along the bulk's handedness; absolute and over tau_0), the largest
    torque in the bulk, and on its links on the wall the azimuthal share |f_phi|/|f| of the
    friction (1: friction that only turns), its utilisation |f|/f_max and the stuck share."""
    reg = a.regions.of_links(d["s_link"].values)
    lower = (reg == 2) & (np.asarray(d["contact"].values) > 0) & (np.asarray(d["friction_force"].values) > 0)
    if not a.regions.has_bulk or not a.bulk or not lower.any():
        return dict.fromkeys(LOWER_KEYS, np.nan)
    sgn = torque.handedness(b, reg == 1)
    i = int(np.argmax(reg == 2))
    f = np.asarray(d["friction_force"].values, dtype=float)[lower]
    return {"lower_torque_ratio": sgn * float(b.tau_friction[i] / b.tau0[i]),
            "lower_torque": sgn * float(b.tau_friction[i]),
            "bulk_torque_max": float(np.max(np.abs(b.tau_friction[reg == 1]))),
            "lower_azimuthal_share": float(np.mean(np.abs(np.asarray(d["friction_phi"].values)[lower]) / f)),
            "lower_utilisation": float(np.mean(f / regions.friction_limit(
                d["wall_force"].values, float(d.attrs["k_fr"]), float(d.attrs.get("friction_cap", 0.0)))[lower])),
            "lower_stuck_share": float(np.mean(np.asarray(d["stuck"].values)[lower] > 0))}


LOWER_KEYS = ("lower_torque_ratio", "lower_torque", "bulk_torque_max", "lower_azimuthal_share", "lower_utilisation",
              "lower_stuck_share")
#: per member, measured in the bulk (torque.bulk_summary) and at the lower region (_lower_torque);
#: NaN (has_bulk_member = 0) without a bulk
BULK_KEYS = ("decay_ratio",) + torque.SUMMARY_KEYS + LOWER_KEYS
KEYS = ("fraction", "lower_length", "tip_length", "n_reversals", "torque_closure") + BULK_KEYS
NAMES = {k: f"{k}_member" for k in KEYS}


def build(fig_cfg, sims, context=None) -> xr.Dataset:
    groups = ensembles.by_base(list(sims), {n: int(sims[n].attrs.get("seed", 0)) for n in sims})
    names = list(groups)
    pad = ensembles.Padded(list(groups.values()), sims)
    has = pad.has
    vals = {m: _member_values(sims[m]) for g in groups.values() for m in g}
    grid = {k: np.zeros(has.shape) for k in KEYS + ("converged",)}
    for i, g in enumerate(groups.values()):
        for j, m in enumerate(g):
            for k in grid:
                grid[k][i, j] = vals[m][k]
    has_rate = (np.isfinite(grid["decay_ratio"]) & (has == 1)).astype(np.int8)
    # a member counts for a bulk quantity where it has a bulk and the quantity is defined
    # (the lower region's torque needs a lower region on the wall)
    ok_of = {k: (has_rate == 1) & np.isfinite(grid[k]) if k in BULK_KEYS else has == 1 for k in KEYS}
    has_lower = ok_of["lower_torque_ratio"].astype(np.int8)
    for k in BULK_KEYS:
        grid[k] = np.where(ok_of[k], grid[k], 0.0)
    VM = ("variant", "member")
    data = {NAMES[k]: variable(VM, grid[k], NAMES[k]) for k in KEYS}
    data["has_member"] = variable(VM, has, "has_member")
    data["has_bulk_member"] = variable(VM, has_rate, "has_bulk_member")
    data["has_lower_member"] = variable(VM, has_lower, "has_lower_member")
    data["member_seed"] = variable(VM, pad.values(lambda d: float(d.attrs["seed"])).astype(np.int64), "member_seed")
    data["converged_member"] = variable(VM, np.int8(np.where(has == 1, grid["converged"], 0)), "converged_member")
    data["converged"] = variable(("variant",), np.int8(np.where(has == 1, grid["converged"], 1).min(axis=1)),
                                 "converged")
    for k in KEYS:
        ok = ok_of[k]
        st = [ensembles.stats(grid[k][i, ok[i]]) if ok[i].any() else None for i in range(len(names))]
        data[f"{k}_mean"] = variable(("variant",), [x.mean if x else 0.0 for x in st], f"{k}_mean")
        data[f"{k}_std"] = variable(("variant",), [x.std if x else 0.0 for x in st], f"{k}_std")
    labels = fig_cfg.get("labels") or {}
    first = [sims[g[0]] for g in groups.values()]
    for key in ("protocol", "ends"):
        data[f"variant_{key}"] = xr.Variable(("variant",), np.array([str(d.attrs[key]) for d in first], dtype=object),
                                             attrs={"long_name": f"{key} of the variant", "units": "1"})
    for key in ("ramp_steps", "perturbation", "l0"):
        data[f"variant_{key}"] = xr.Variable(("variant",), np.array([float(d.attrs[key]) for d in first]),
                                             attrs={"long_name": f"{key} of the variant",
                                                    "units": "1" if key == "ramp_steps" else "R"})
    coords = {"variant": scene_coord("variant", names),
              "variant_label": xr.Variable(("variant",), np.array([labels.get(n, n) for n in names], dtype=object),
                                           attrs={"long_name": "label of the variant in the figure", "units": "1"}),
              "member": variable(("member",), np.arange(has.shape[1]), "member")}
    ds = xr.Dataset(data, coords=coords)
    _ramp_ladder(ds, groups, sims)
    return _add_profiles(_add_formation(ds, groups, sims), fig_cfg, groups, sims)


def _add_profiles(ds: xr.Dataset, fig_cfg, groups, sims) -> xr.Dataset:
    """Along s, for the first seed of each variant drawn (``profiles``): |F_z| at the joints,
    the axial torque the friction left in the rod and the one its helix carries (torque.py),
    signed so that positive is along the handedness of the bulk, and the region of each link."""
    shown = profile_variants(fig_cfg, groups)
    first = [sims[groups[b][0]] for b in shown]
    tau_fr, tau_hx, on, reg, F, tau0 = [], [], [], [], [], []
    for d in first:
        b = torque.budget(d)
        a = regions.analyse(d)
        r = a.regions.of_links(d["s_link"].values)
        sgn = torque.handedness(b, r == 1 if a.regions.has_bulk else np.ones(r.size, dtype=bool))
        tau_fr.append(sgn * b.tau_friction)
        tau_hx.append(sgn * b.tau_helix)
        on.append(b.on_helix.astype(np.int8))
        reg.append(r)
        F.append(np.abs(np.asarray(d["F_z"].values, dtype=float)))
        tau0.append(b.tau0)
    PL, PJ = ("profile", "s_link"), ("profile", "s")
    ds = ds.assign({
        "profile_F_abs": variable(PJ, np.array(F), "F_abs"),
        "profile_torque_friction": variable(PL, np.array(tau_fr), "torque_friction"),
        "profile_torque_helix": variable(PL, np.array(tau_hx), "torque_helix"),
        "profile_torque_scale": variable(PL, np.array(tau0), "torque_scale"),
        "profile_on_helix": variable(PL, np.array(on), "on_helix"),
        "profile_region": variable(PL, np.array(reg), "region"),
    })
    return ds.assign_coords(profile=scene_coord("profile", shown),
                            s=variable(("s",), np.asarray(first[0]["s"].values), "s"),
                            s_link=variable(("s_link",), np.asarray(first[0]["s_link"].values), "s_link"))


SETTLED = 0.05  # a profile has formed where it stays within 5 % of its final value


def settle_time(t: np.ndarray, F: np.ndarray, rel: float) -> float:
    """The first snapshot time from which |F| (snapshot, position) stays within ``rel`` of
    its final value at every position."""
    dev = np.max(np.abs(F / F[-1] - 1.0), axis=1)
    late = np.flatnonzero(dev > rel)
    return float(t[late[-1] + 1]) if late.size else float(t[0])


def _add_formation(ds: xr.Dataset, groups, sims) -> xr.Dataset:
    """|F_z| along s at the stored snapshot times of the first seed of the first variant that
    stores snapshots (scene parameters snapshot_interval, snapshot_growth): how the equilibrium
    and its lower region form during the run; attributes formation_settled_quarter and
    formation_settled_end: the times from which |F_z| over the upper quarter of the rod, and at
    its lower end, stays within SETTLED of its final value."""
    for base, members in groups.items():
        d = sims[members[0]]
        if "snap_F_z" in d:
            F_abs = np.abs(np.asarray(d["snap_F_z"].values, dtype=float))
            ds = ds.assign({"formation_F_abs": variable(("t", "formation_joint"), F_abs, "F_abs")})
            ds = ds.assign_coords(t=variable(("t",), np.asarray(d["t"].values, dtype=float), "t"),
                                  formation_s=variable(("formation_joint",), np.asarray(d["s"].values), "s"))
            ds.attrs["formation_variant"] = base
            ds.attrs["formation_seed"] = int(d.attrs["seed"])
            t, F = ds["t"].values, ds["formation_F_abs"].values
            s = ds["formation_s"].values
            for where, sel in (("quarter", s <= 0.25 * s[-1]), ("end", s >= s[-1])):
                ds.attrs[f"formation_settled_{where}"] = settle_time(t, F[:, sel], SETTLED)
            return ds
    return ds


def _ramp_ladder(ds: xr.Dataset, groups: dict[str, list[str]], sims) -> None:
    """Each ramp variant against the next finer one that differs only in ramp_steps, seed by
    seed (ensembles.paired_changes): the mean relative change of F(L) over the seeds that keep
    their final state, its standard error, the largest such change, the seeds that changed
    state and the change of the ensemble mean; stored as attributes ramp_ladder_*."""
    ramps = sorted(((b, float(sims[m[0]].attrs["ramp_steps"])) for b, m in groups.items()
                    if sims[m[0]].attrs.get("protocol") == "ramp"), key=lambda x: x[1])
    rows = []
    for (b0, n0), (b1, n1) in zip(ramps[:-1], ramps[1:]):
        pad = ensembles.Padded([groups[b0], groups[b1]], sims)
        seeds = pad.values(lambda d: float(d.attrs["seed"]))
        F = pad.values(lambda d: float(d["F_transmitted"]))
        common, rel, moved = ensembles.paired_changes(seeds, F, pad.values(n_turns), pad.has, 0, 1)
        if common.size == 0:
            continue
        kept = rel[~moved]
        st = ensembles.stats(kept) if kept.size else ensembles.Stats(0, 0.0, 0.0, 0.0, 0.0, 0.0)
        mean0, mean1 = (float(np.mean(F[i][pad.has[i] == 1])) for i in (0, 1))
        rows.append((n0, n1, st.mean, st.sem, float(np.max(np.abs(kept))) if kept.size else 0.0,
                     mean1 / mean0 - 1.0, kept.size, int(moved.sum()),
                     ", ".join(f"seed {s} {100 * r:+.2g} %" for s, r in zip(common[moved], rel[moved]))))
    if rows:
        ds.attrs["ramp_ladder_steps"] = np.array([[r[0], r[1]] for r in rows]).ravel()
        ds.attrs["ramp_ladder_paired_change"] = np.array([r[2] for r in rows])
        ds.attrs["ramp_ladder_paired_sem"] = np.array([r[3] for r in rows])
        ds.attrs["ramp_ladder_max_change"] = np.array([r[4] for r in rows])
        ds.attrs["ramp_ladder_mean_change"] = np.array([r[5] for r in rows])
        ds.attrs["ramp_ladder_same_state"] = np.array([r[6] for r in rows])
        ds.attrs["ramp_ladder_state_changes"] = np.array([r[7] for r in rows])
        ds.attrs["ramp_ladder"] = "; ".join(_ladder_text(r) for r in rows)


def _ladder_text(r) -> str:
    n0, n1, change, sem, largest, mean_change, kept, moved, which = r
    same = (f"paired change of F(L) {100 * change:+.2f} +- {100 * sem:.2f} % (s.e., {kept} seeds in the same final "
            f"state, largest {100 * largest:.1f} %)" if kept >= 2 else
            f"the one seed in the same final state changed F(L) by {100 * change:+.2f} %" if kept == 1 else
            "no seed kept its final state")
    return (f"{n0:g} -> {n1:g} steps: {same}, {moved} seeds changed their final state (winding by >= "
            f"{ensembles.STATE_TURNS:g} turn){': ' + which if moved else ''}; change of the mean "
            f"{100 * mean_change:+.2f} %")


PANELS = (("fraction", r"$|F_z(L)|/|F_z(0)|$"), ("lower_length", r"lower region $L - s_l$ [$R$]"),
          ("n_reversals", "reversals"), ("decay_ratio", "bulk decay rate\nover $k_{fr}R/(4EI)$"),
          ("torque_friction_ratio", "bulk axial torque\n" + r"$\tau\,\mathrm{sgn}\,w\,/\,\tau_0$"))
PROFILE_COLORS = ("black", "tab:red", "tab:blue", "tab:green")


def plot(ds: xr.Dataset):
    n = ds.sizes["variant"]
    top = 0.9 + 0.3 * n
    fig = P.plt.figure(figsize=(6.85, min(top + 2.3, P.MAX_HEIGHT_IN)), label=ds.attrs["title"])
    gs = fig.add_gridspec(2, 1, height_ratios=[top, 2.3], hspace=0.5)
    row1 = gs[0].subgridspec(1, len(PANELS), wspace=0.12)
    axes = [fig.add_subplot(row1[0, 0])]
    axes += [fig.add_subplot(row1[0, k], sharey=axes[0]) for k in range(1, len(PANELS))]
    _plot_variants(ds, axes)
    n_bottom = 3 if "formation_F_abs" in ds else 2
    row2 = gs[1].subgridspec(1, n_bottom, wspace=0.38)
    bottom = [fig.add_subplot(row2[0, k]) for k in range(n_bottom)]
    _plot_profiles(ds, bottom[0], bottom[1])
    if n_bottom == 3:
        _plot_formation(ds, bottom[2])
    for k, ax in enumerate(bottom):
        ax.set_title(f"({chr(97 + len(PANELS) + k)})", fontsize=9, loc="left")
        ax.tick_params(labelsize=7.5)
    fig.subplots_adjust(left=0.17, right=0.985, top=0.96, bottom=0.1)
    return fig


def _plot_variants(ds: xr.Dataset, axes) -> None:
    n = ds.sizes["variant"]
    y = np.arange(n)[::-1]
    has = ds["has_member"].values == 1
    has_bulk = ds["has_bulk_member"].values == 1
    for k, (ax, (key, xlabel)) in enumerate(zip(axes, PANELS)):
        ok = has_bulk if key in BULK_KEYS else has
        vals = ds[NAMES[key]].values
        for i in range(n):
            jitter = np.linspace(-0.12, 0.12, vals.shape[1])
            m = ok[i]
            ax.plot(vals[i][m], (y[i] + jitter)[m], ".", ms=3.5, **P.SEEDS,
                    label="single seeds" if i == 0 else None)
            if m.any():
                ax.errorbar(float(ds[f"{key}_mean"].values[i]), y[i], xerr=float(ds[f"{key}_std"].values[i]),
                            fmt="o", ms=4, **P.SIM, capsize=2, label="mean $\\pm$ s.d." if i == 0 else None)
        shown = vals[ok]
        if key == "fraction" and shown.size and shown.min() > 0 and shown.max() / shown.min() > 10:
            ax.set_xscale("log")        # fractions over a decade and more: the small ones stay apart
            P.plain_log_ticks(ax.xaxis)
        if key == "decay_ratio":
            ax.axvline(1.0, **P.MODEL)
            ax.axvline(2.0, **P.PAPER)
            ax.set_xlim(0, 2.3)
        if key == "torque_friction_ratio":
            ax.axvline(0.0, color="tab:blue", ls="--", lw=1.0)
        ax.set_xlabel(xlabel, fontsize=7.5)
        ax.set_title(f"({chr(97 + k)})", fontsize=9, loc="left", pad=2)
        ax.tick_params(labelsize=7.5)
        ax.set_ylim(-0.6, n - 0.4)
        if k:
            ax.tick_params(labelleft=False)
    axes[0].set_yticks(y)
    axes[0].set_yticklabels([str(v) for v in ds["variant_label"].values], fontsize=7.5)
    # above the variants' labels, left of panel (a): clear of every row of data and of the panel letters
    axes[0].legend(loc="lower right", bbox_to_anchor=(-0.04, 0.98), fontsize=7, handletextpad=0.2, frameon=False,
                   borderaxespad=0.0)


def _label(ds: xr.Dataset, base: str) -> str:
    names = [str(v) for v in ds["variant"].values]
    return str(ds["variant_label"].values[names.index(base)]) if base in names else base


def _plot_profiles(ds: xr.Dataset, ax_f, ax_t) -> None:
    """|F_z|/|F_z(0)| and the axial torque over tau_0 along s for the first seed of the variants
    drawn, the start of the lower region of each marked by a triangle; the helix's own torque
    is drawn beyond the tip (in the tip the contacts are isolated: no helix)."""
    s, s_link = ds["s"].values, ds["s_link"].values
    for i, base in enumerate(ds["profile"].values):
        color = PROFILE_COLORS[i % len(PROFILE_COLORS)]
        F = ds["profile_F_abs"].values[i]
        ax_f.plot(s, F / F[0], color=color, lw=1.2, label=_label(ds, str(base)))
        reg = ds["profile_region"].values[i]
        if (reg == 2).any():
            s_l = float(s_link[np.argmax(reg == 2)])
            ax_f.plot([s_l], [float(np.interp(s_l, s, F / F[0]))], "v", color=color, ms=5)
        tau0 = ds["profile_torque_scale"].values[i]
        ax_t.plot(s_link, ds["profile_torque_friction"].values[i] / tau0, color=color, lw=1.2)
        on = (ds["profile_on_helix"].values[i] == 1) & (reg > 0)
        ax_t.plot(s_link[on][::8], (ds["profile_torque_helix"].values[i] / tau0)[on][::8], "o", ms=2.2, mfc="none",
                  mec=color, mew=0.6)
    ax_f.set_yscale("log")
    P.plain_log_ticks(ax_f.yaxis)
    ax_f.set_xlabel(label("s"), fontsize=8)
    ax_f.set_ylabel(r"$|F_z(s)|/|F_z(0)|$", fontsize=8)
    ax_f.set_ylim(top=3.0)      # room above the profiles (all start at 1) for the legend
    ax_f.legend(fontsize=7, loc="upper right", handlelength=1.4, framealpha=0.9)
    ax_t.axhline(0.0, color="tab:blue", ls="--", lw=1.0)
    ax_t.plot([], [], color="0.3", lw=1.2, label=r"friction, $-\Gamma(s)$")
    ax_t.plot([], [], "o", ms=2.5, mfc="none", mec="0.3", label="local helix")
    ax_t.set_xlabel(label("s"), fontsize=8)
    ax_t.set_ylabel(r"axial torque $\tau\,\mathrm{sgn}\,w\,/\,\tau_0(s)$", fontsize=8)
    ax_t.plot([], [], " ", label="colours as in (f)")
    lo, hi = ax_t.get_ylim()
    # headroom above the curves for the key (three rows), so that it covers no data
    ax_t.set_ylim(lo, hi + 0.75 * (hi - lo))
    ax_t.legend(fontsize=7, loc="upper left", handlelength=1.0, handletextpad=0.4, borderaxespad=0.3,
                framealpha=0.9)


def _plot_formation(ds: xr.Dataset, ax) -> None:
    t = ds["t"].values
    F = ds["formation_F_abs"].values
    s = ds["formation_s"].values
    keep = [k for k in range(t.size) if t[k] > 0]
    cmap = P.plt.get_cmap("viridis")
    lo, hi = np.log10(t[keep[0]]), np.log10(t[keep[-1]])
    marked = {keep[0], keep[len(keep) // 2], keep[-1]}
    for k in keep:
        frac = (np.log10(t[k]) - lo) / max(hi - lo, 1e-12)
        last = k == keep[-1]
        ax.plot(s, F[k] / F[k][0], color="black" if last else cmap(0.9 * frac), lw=1.5 if last else 0.9,
                label=(("final, " if last else "") + f"$t = {P.sci(t[k])}$") if k in marked else None,
                zorder=3 if last else 2)
    ax.set_yscale("log")
    P.plain_log_ticks(ax.yaxis)
    ax.set_xlabel(label("s"), fontsize=8)
    ax.set_ylabel(r"$|F_z(s)|/|F_z(0)|$ while forming", fontsize=8)
    # room above the profiles for the legend (four lines at the top right): the curves, which may
    # rise above 1 near the support while the helix forms, fill at most the lower LEGEND_FREE of
    # the log axis
    lo = ax.get_ylim()[0]
    peak = max(float(np.nanmax(F[k] / F[k][0])) for k in keep)
    ax.set_ylim(lo, max(6.0, 10 ** (np.log10(lo) + (np.log10(peak) - np.log10(lo)) / LEGEND_FREE)))
    ax.legend(fontsize=7, loc="upper right", handlelength=1.0, framealpha=0.9,
              title=f"seed {ds.attrs['formation_seed']}, " + r"$t$ in $\beta_{ph}R^4/EI$", title_fontsize=7)
