"""Kind ``protocol_comparison`` (not in the paper): what the loading path does to one rod.

With static friction the equilibrium depends on how it was reached. This kind puts seed
ensembles of one rod side by side that differ in how the load was applied or in a setting
that could change the path: the protocol (the full load at once on a straight rod, the
paper's; a quasi-static ``ramp`` at several step counts, which also checks that the ramp is
fine enough; a start from a one-handed ``helix``), the end conditions, the amplitude of the
random start, the link length. Per variant it stores, for every member and as ensemble
statistics, the transmitted fraction F(L)/F(0), the three regions of the rod
(confined_rod.regions: tip, bulk helix, lower region), the number of reversals of handedness
of the wall-contact stretch and the bulk decay rate over the corrected local law.

A *ramp ladder* (variants that differ only in ``ramp_steps``) is compared member by member
(same seed): the change of F(L) from each ramp to the next finer one, as the mean paired
relative change with its standard error, and the largest single change.
"""
from __future__ import annotations

import numpy as np
import xarray as xr

from .. import ensembles, regions
from .. import plotting as P
from ..errors import ConfigError
from ..io import variable
from ..measure import defects
from ._common import need_scenes, same_except, scene_coord

OPTIONS = {
    "labels": {"type": "object", "additionalProperties": {"type": "string"},
               "description": "scene id -> a short label of the variant for the figure (default: the scene id)"},
}
ENSEMBLES = True
#: the settings a variant may change; everything else is the same in every variant
VARIED = ("protocol", "ramp_steps", "ramp_start", "ends", "lower_end", "perturbation", "l0", "seed")


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
            "Per variant (rows) the single seeds (grey) and their mean +- standard deviation (black): (a) the "
            "transmitted fraction F(L)/F(0); (b) the length of the lower region, where the wall friction is stuck "
            "or azimuthal and |F_z| nearly flat (confined_rod.regions); (c) the number of reversals of handedness "
            "of the wall-contact stretch; (d) the decay rate d(1/|F_z|)/ds in the bulk helix over the corrected "
            "local law k_fr R/(4EI) (dashed: 1; the paper's K gives 2).")


def _member_values(d: xr.Dataset) -> dict[str, float]:
    a = regions.analyse(d)
    n_rev = len(defects(np.asarray(d["s_helix"].values), np.asarray(d["dphi_ds"].values)))
    return {"fraction": float(d["F_transmitted"]) / float(d.attrs["load"]),
            "lower_length": a.regions.lower_length, "tip_length": a.regions.tip_length,
            "n_reversals": float(n_rev), "decay_ratio": a.bulk.rate / a.model if a.bulk and a.model > 0 else np.nan,
            "converged": float(d["converged"])}


KEYS = ("fraction", "lower_length", "tip_length", "n_reversals", "decay_ratio")
NAMES = {"fraction": "fraction_member", "lower_length": "lower_length_member", "tip_length": "tip_length_member",
         "n_reversals": "n_reversals_member", "decay_ratio": "decay_ratio_member"}


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
    grid["decay_ratio"] = np.where(has_rate == 1, grid["decay_ratio"], 0.0)
    VM = ("variant", "member")
    data = {NAMES[k]: variable(VM, grid[k], NAMES[k]) for k in KEYS}
    data["has_member"] = variable(VM, has, "has_member")
    data["has_bulk_member"] = variable(VM, has_rate, "has_bulk_member")
    data["member_seed"] = variable(VM, pad.values(lambda d: float(d.attrs["seed"])).astype(np.int64), "member_seed")
    data["converged"] = variable(("variant",), np.int8(np.where(has == 1, grid["converged"], 1).min(axis=1)),
                                 "converged")
    for k in KEYS:
        ok = has_rate if k == "decay_ratio" else has
        st = [ensembles.stats(grid[k][i, ok[i] == 1]) if ok[i].any() else None for i in range(len(names))]
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
    return ds


def _ramp_ladder(ds: xr.Dataset, groups: dict[str, list[str]], sims) -> None:
    """Paired (same seed) relative change of F(L) from each ramp variant to the next finer one
    that differs only in ramp_steps; stored as attributes ramp_ladder_* (text and numbers)."""
    ramps = [(b, float(sims[m[0]].attrs["ramp_steps"])) for b, m in groups.items()
             if sims[m[0]].attrs.get("protocol") == "ramp"]
    ramps.sort(key=lambda x: x[1])
    rows = []
    for (b0, n0), (b1, n1) in zip(ramps[:-1], ramps[1:]):
        seeds0 = {int(sims[m].attrs["seed"]): float(sims[m]["F_transmitted"]) for m in groups[b0]}
        seeds1 = {int(sims[m].attrs["seed"]): float(sims[m]["F_transmitted"]) for m in groups[b1]}
        common = sorted(set(seeds0) & set(seeds1))
        if not common:
            continue
        rel = np.array([seeds1[s] / seeds0[s] - 1.0 for s in common])
        st = ensembles.stats(rel)
        mean0, mean1 = np.mean([seeds0[s] for s in common]), np.mean([seeds1[s] for s in common])
        rows.append((n0, n1, st.mean, st.sem, float(np.max(np.abs(rel))), float(mean1 / mean0 - 1.0), len(common)))
    if rows:
        ds.attrs["ramp_ladder_steps"] = np.array([[r[0], r[1]] for r in rows]).ravel()
        ds.attrs["ramp_ladder_paired_change"] = np.array([r[2] for r in rows])
        ds.attrs["ramp_ladder_paired_sem"] = np.array([r[3] for r in rows])
        ds.attrs["ramp_ladder_max_change"] = np.array([r[4] for r in rows])
        ds.attrs["ramp_ladder_mean_change"] = np.array([r[5] for r in rows])
        ds.attrs["ramp_ladder"] = "; ".join(
            f"{r[0]:g} -> {r[1]:g} steps: paired change of F(L) {100 * r[2]:+.2f} +- {100 * r[3]:.2f} % (s.e.), "
            f"largest single {100 * r[4]:.1f} %, change of the mean {100 * r[5]:+.2f} % ({r[6]} seeds)" for r in rows)


def plot(ds: xr.Dataset):
    n = ds.sizes["variant"]
    fig, axes = P.plt.subplots(1, 4, figsize=(7.0, 0.9 + 0.32 * n), sharey=True, label=ds.attrs["title"])
    y = np.arange(n)[::-1]
    has = ds["has_member"].values == 1
    panels = (("fraction", r"$|F_z(L)|/|F_z(0)|$", has), ("lower_length", r"lower region $L - s_l$ [$R$]", has),
              ("n_reversals", "reversals", has),
              ("decay_ratio", "bulk decay rate\nover $k_{fr}R/(4EI)$", ds["has_bulk_member"].values == 1))
    for k, (ax, (key, xlabel, ok)) in enumerate(zip(axes, panels)):
        vals = ds[NAMES[key]].values
        for i in range(n):
            jitter = np.linspace(-0.12, 0.12, vals.shape[1])
            m = ok[i]
            ax.plot(vals[i][m], (y[i] + jitter)[m], ".", ms=3.5, color="0.55",
                    label="single seeds" if i == 0 else None)
            if m.any():
                ax.errorbar(float(ds[f"{key}_mean"].values[i]), y[i], xerr=float(ds[f"{key}_std"].values[i]),
                            fmt="o", ms=4, color="black", capsize=2, label="mean $\\pm$ s.d." if i == 0 else None)
        if key == "decay_ratio":
            ax.axvline(1.0, **P.MODEL)
            ax.axvline(2.0, **P.PAPER)
            ax.set_xlim(0, 2.3)
        ax.set_xlabel(xlabel, fontsize=8)
        ax.set_title(f"({chr(97 + k)})", fontsize=9, loc="left")
        ax.tick_params(labelsize=7.5)
        ax.set_ylim(-0.6, n - 0.4)
    axes[0].set_yticks(y)
    axes[0].set_yticklabels([str(v) for v in ds["variant_label"].values], fontsize=7.5)
    axes[0].legend(loc="lower right", fontsize=7, handletextpad=0.2)
    fig.tight_layout(w_pad=0.6)
    return fig
