"""The claims of the original paper (``paper/claims.yaml``), evaluated on the datasets.

Each claim names how it is tested (see the header of ``paper/claims.yaml``): a symbolic
derivation (:mod:`confined_rod.claims.derivations`), a number from a dataset compared with the
paper's within a tolerance, a named measure (:data:`MEASURES`),
or a reason why it cannot be tested. :func:`evaluate` returns one :class:`Verdict` per
claim; the verdict is computed here, never typed, and a claim whose evidence (dataset,
variable, simulation) is missing raises :class:`ClaimError`, so the build fails.

Post-processing: reads datasets only and never imports the simulator.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Mapping

import numpy as np
import xarray as xr

from ..analysis import ensembles, regions
from ..analysis.fits import DEGENERATE_FALL, determined, undetermined
from ..analysis.measure import HELIX_RUN, detached_lengths, force_at_links
from ..analysis.measure import half_reduction_length as half_reduction_length_of
from ..errors import ConfigError
from ..io import read_yaml
from ..layout import dataset_path, sim_key_path, sims_folder

VERDICTS = ("reproduced", "reproduced under reading", "refuted", "inconclusive", "not testable")
METHODS = ("derivation", "value", "measure", "not_testable")
KEYS = {"id", "where", "claim", "paper", "paper_from", "test", "tolerance", "reading", "why", "format", "finding"}


class ClaimError(ConfigError):
    """A claim that is malformed, or whose evidence is missing."""


@dataclass
class Verdict:
    id: str
    where: str
    claim: str
    paper: str                  # the paper's value as text
    paper_value: float | None   # ... as a number, where it is one
    ours: str
    ours_value: float | None
    tolerance: str
    verdict: str
    evidence: str
    reading: str = ""
    note: str = ""
    finding: str = ""           # the independent finding it belongs to (claims.yaml `finding`, default its id)


@dataclass
class Evidence:
    """The datasets (by figure) and scene simulations (by 'figure/scene') a build has."""
    datasets: Mapping[str, xr.Dataset]
    sims: Mapping[str, xr.Dataset] = field(default_factory=dict)
    #: 'figure/scene' -> the file it was read from (a run shared by several figures is one file)
    files: Mapping[str, str] = field(default_factory=dict)
    #: what the claim being evaluated has read: ("dataset", figure) and ("sim", 'figure/scene')
    touched: set = field(default_factory=set)

    def unsettled(self) -> list[str]:
        """The runs behind what has been read that are not at equilibrium: 'figure/scene (status)'."""
        from ..analysis import evidence

        runs: list[str] = []
        for what, key in sorted(self.touched):
            if what == "dataset":
                runs += evidence.flagged(self.datasets[key].attrs.get("not_at_equilibrium"))
            else:
                runs += evidence.not_at_equilibrium({key: self.sims[key]})
        return list(dict.fromkeys(runs))

    def file(self, key: str) -> str:
        """The path of the simulation 'figure/scene' as the build has it (evidence strings)."""
        return self.files.get(key, sim_key_path(key))

    def dataset(self, figure: str, claim: str) -> xr.Dataset:
        if figure not in self.datasets:
            raise ClaimError(f"claim {claim!r} needs the dataset of figure {figure!r} "
                             f"({dataset_path(figure)}), which this config does not build")
        self.touched.add(("dataset", figure))
        return self.datasets[figure]

    def sim(self, figure: str, scene: str | int, claim: str) -> tuple[str, xr.Dataset]:
        names = sorted(k.split("/", 1)[1] for k in self.sims if k.startswith(figure + "/"))
        if not names:
            raise ClaimError(f"claim {claim!r} needs the simulations of figure {figure!r} ({sims_folder(figure)})")
        if isinstance(scene, int):      # the scene's place by length; an ensemble counts once, by its lowest seed
            shown = [m[0] for m in ensembles.by_base(
                names, {n: int(self.sims[f"{figure}/{n}"].attrs.get("seed", 0)) for n in names}).values()]
            key = f"{figure}/{_by_length(self.sims, figure, shown)[scene]}"
        else:
            key = f"{figure}/{scene}"
        if key not in self.sims:
            raise ClaimError(f"claim {claim!r} needs {sim_key_path(key)}")
        self.touched.add(("sim", key))
        return key, self.sims[key]


    def members(self, figure: str, scene: str | int, claim: str) -> list[tuple[str, xr.Dataset]]:
        """Every member of the seed ensemble of a scene (or the one run of a scene without
        seeds), by seed: the scene as in :meth:`sim` (a name or a place by length)."""
        key, first = self.sim(figure, scene, claim)
        names = [k.split("/", 1)[1] for k in self.sims if k.startswith(figure + "/")]
        seeds = {n: int(self.sims[f"{figure}/{n}"].attrs.get("seed", 0)) for n in names}
        base = ensembles.base_name(key.split("/", 1)[1], int(first.attrs.get("seed", 0)))
        keys = [f"{figure}/{n}" for n in ensembles.by_base(names, seeds)[base]]
        self.touched.update(("sim", k) for k in keys)
        return [(k, self.sims[k]) for k in keys]


def _by_length(sims, figure, names):
    return sorted(names, key=lambda n: float(sims[f"{figure}/{n}"].attrs.get("L", 0.0)))


def _derivations():
    from .derivations import DERIVATIONS

    return DERIVATIONS


# -- reading claims.yaml -----------------------------------------------------------------------
def finding_titles(path: str | Path) -> dict[str, str]:
    """The titles of the findings that several claims share (claims.yaml `findings`)."""
    data = read_yaml(path, what="claims file", error=ClaimError)
    titles = data.get("findings") or {}
    if not isinstance(titles, dict) or not all(isinstance(v, str) and v for v in titles.values()):
        raise ClaimError(f"claims file {str(path)!r}: 'findings' must map finding names to non-empty titles")
    return {str(k): v for k, v in titles.items()}


def load(path: str | Path) -> list[dict[str, Any]]:
    data = read_yaml(path, what="claims file", error=ClaimError)
    if not isinstance(data, dict) or not isinstance(data.get("claims"), list):
        raise ClaimError(f"claims file {str(path)!r}: needs a list 'claims' at the top level")
    titles = finding_titles(path)
    claims, seen = data["claims"], set()
    for i, c in enumerate(claims):
        where = f"claims file {str(path)!r}, claim {i + 1}"
        if not isinstance(c, dict):
            raise ClaimError(f"{where}: must be a mapping")
        unknown = set(c) - KEYS
        if unknown:
            raise ClaimError(f"{where} ({c.get('id')!r}): unknown keys {sorted(unknown)}")
        for key in ("id", "where", "claim", "test"):
            if key not in c:
                raise ClaimError(f"{where}: missing {key!r}")
        if c["id"] in seen:
            raise ClaimError(f"{where}: duplicate id {c['id']!r}")
        if "finding" in c and c["finding"] not in titles:
            raise ClaimError(f"{where} ({c['id']!r}): finding {c['finding']!r} has no title in the file's 'findings' "
                             f"({', '.join(titles) or 'none'})")
        seen.add(c["id"])
        method = c["test"].get("method")
        if method not in METHODS:
            raise ClaimError(f"{where} ({c['id']!r}): test.method = {method!r}, expected one of {METHODS}")
        if "paper" not in c and "paper_from" not in c:
            raise ClaimError(f"{where} ({c['id']!r}): needs 'paper' or 'paper_from'")
        if method == "value" and "tolerance" not in c:
            raise ClaimError(f"{where} ({c['id']!r}): a value comparison needs 'tolerance' (rel or abs)")
        if method == "derivation" and c["test"].get("name") not in _derivations():
            raise ClaimError(f"{where} ({c['id']!r}): test.name = {c['test'].get('name')!r} is not a derivation of "
                             f"confined_rod.claims.derivations ({', '.join(_derivations())})")
        if method == "measure" and c["test"].get("name") not in MEASURES:
            raise ClaimError(f"{where} ({c['id']!r}): test.name = {c['test'].get('name')!r} is not a measure of "
                             f"confined_rod.claims.verdicts.MEASURES ({', '.join(MEASURES)})")
        paper = c.get("paper")
        numeric = "paper_from" in c or (isinstance(paper, (int, float)) and not isinstance(paper, bool))
        if "tolerance" in c and not numeric:
            raise ClaimError(f"{where} ({c['id']!r}): a tolerance needs a numeric paper value, got {c.get('paper')!r}")
        tol = c.get("tolerance")
        if tol is not None and (not isinstance(tol, dict) or set(tol) - {"rel", "abs"} or len(tol) != 1
                                or not float(next(iter(tol.values()))) > 0):
            raise ClaimError(f"{where} ({c['id']!r}): tolerance = {tol!r}, expected {{rel: x}} or {{abs: x}}, x > 0")
    return claims


# -- picking a number out of a dataset ------------------------------------------------------------
def pick(ev: Evidence, spec: Mapping[str, Any], claim: str) -> tuple[float, str]:
    """A number from a dataset: variable `var` (with `sel`, `isel`, `reduce`) or attribute `attr`."""
    ds = ev.dataset(spec["figure"], claim)
    where = f"{dataset_path(spec['figure'])}"
    if "attr" in spec:
        if spec["attr"] not in ds.attrs:
            raise ClaimError(f"claim {claim!r}: {where} has no attribute {spec['attr']!r}")
        return float(np.asarray(ds.attrs[spec["attr"]]).ravel()[0]), f"{where}:{spec['attr']}"
    var = spec["var"]
    if var not in ds:
        raise ClaimError(f"claim {claim!r}: {where} has no variable {var!r}")
    da = ds[var]
    if spec.get("sel"):
        da = da.sel(spec["sel"])
    if spec.get("isel"):
        da = da.isel(spec["isel"])
    if spec.get("require"):                      # a flag variable that must be 1 where we read
        flag = ds[spec["require"]]
        flag = flag.sel(spec["sel"]) if spec.get("sel") else flag
        flag = flag.isel(spec["isel"]) if spec.get("isel") else flag
        if not np.all(np.asarray(flag.values) == 1):
            raise ClaimError(f"claim {claim!r}: {where}:{spec['require']} is 0 where {var} is read "
                             "(the config gives no value there)")
    reduce = spec.get("reduce")
    values = np.asarray(da.values, dtype=float).ravel()
    if reduce:
        value = {"max": np.max, "min": np.min, "mean": np.mean}[reduce](values)
    elif values.size != 1:
        raise ClaimError(f"claim {claim!r}: {where}:{var} selects {values.size} values; give sel/isel or reduce")
    else:
        value = values[0]
    if not math.isfinite(value):
        raise ClaimError(f"claim {claim!r}: {where}:{var} is not finite")
    sel = ", ".join(f"{k}={v}" for k, v in {**spec.get("sel", {}), **spec.get("isel", {})}.items())
    return float(value), f"{where}:{var}" + (f"[{sel}]" if sel else "") + (f" ({reduce})" if reduce else "")


# -- named measures: (value, holds, evidence, note) ------------------------------------------------
# holds is True, False, or None: "inconclusive", when the answer flips with an analysis choice (a
# fit window, a threshold) or the data cannot decide; the note then says why.
Measure = Callable[[Evidence, Mapping[str, Any], str], tuple[float, bool, str, str]]
MEASURES: dict[str, Measure] = {}


def measure(fn: Measure) -> Measure:
    MEASURES[fn.__name__] = fn
    return fn


def _bulk(mask: np.ndarray, frac: float = 0.25) -> np.ndarray:
    """Links of the contact stretch away from its ends (middle 1 - 2 frac)."""
    idx = np.flatnonzero(mask)
    if idx.size < 8:
        return np.zeros(0, dtype=int)
    lo, hi = idx[0], idx[-1]
    n = hi - lo
    return np.arange(lo + int(frac * n), hi - int(frac * n) + 1)


@measure
def wall_force_coefficient(ev, spec, claim):
    """K EI/(R F_z^2) in the bulk (middle half of the contact stretch) of the longest
    frictionless rod of the figure, against the paper's 1/2 (the tolerance), and in the note
    against the lowest order 1/4 and the exact constant-pitch value 1/(4(1 - R^2 w^2)) with the
    measured pitch rate w = dphi/ds of each link (docs/model.md, "The paper's simple model")."""
    key, sim = ev.sim(spec["figure"], -1, claim)
    if float(sim.attrs["k_fr"]) != 0.0:
        raise ClaimError(f"claim {claim!r}: {ev.file(key)} has k_fr = {sim.attrs['k_fr']}, needs 0")
    R, EI = float(sim.attrs["R"]), float(sim.attrs["EI"])
    K = np.asarray(sim.wall_force_density.values)
    F = force_at_links(sim)
    bulk = _bulk(np.asarray(sim.contact.values) > 0)
    if bulk.size == 0:
        raise ClaimError(f"claim {claim!r}: {ev.file(key)} has no helix on the wall")
    s_link = np.asarray(sim.s_link.values)[bulk]
    w = np.interp(s_link, np.asarray(sim.s_helix.values), np.abs(np.asarray(sim.dphi_ds.values)))
    value = float(np.median(K[bulk] * EI / (R * F[bulk] ** 2)))
    exact = float(np.median(1.0 / (4.0 * (1.0 - (R * w) ** 2))))
    dev_exact, dev_lowest = value / exact - 1.0, value / 0.25 - 1.0
    confirmed = ("the exact constant-pitch relation" if abs(dev_exact) < abs(dev_lowest)
                 else "the lowest order")
    note = (f"exact constant pitch 1/(4(1 - R^2 w^2)) = {exact:.4g} (median R w = {float(np.median(R * w)):.3g}): "
            f"{100 * dev_exact:+.2f} %; lowest order 1/4: {100 * dev_lowest:+.3g} %; the paper's 1/2: "
            f"{100 * (value / 0.5 - 1):+.3g} %. The data confirm {confirmed}")
    return value, True, (f"{ev.file(key)}:wall_force_density, F_z, dphi_ds "
                         "(medians over the middle half of the contact)"), note


@measure
def capped_fraction(ev, spec, claim):
    """Fraction of the links on the wall where the friction cap is below k_fr N."""
    key, sim = ev.sim(spec["figure"], spec["scene"], claim)
    k_fr, cap, l0 = (float(sim.attrs[k]) for k in ("k_fr", "friction_cap", "l0"))
    N = np.asarray(sim.wall_force.values)
    on = N > 0
    capped = on & (cap > 0) & (k_fr * N > cap * l0)
    value = float(capped.sum() / max(on.sum(), 1))
    return value, value <= float(spec["max"]), f"{ev.file(key)}:wall_force, attrs k_fr, friction_cap", \
        f"{int(capped.sum())} of {int(on.sum())} links"


def _aspect_R(ds, i):
    """R of threshold row i: from L^2/EI and L/R (Fig. 3) or the stored R (Fig. 8)."""
    if "aspect_R" in ds:
        return float(ds.aspect_R.values[i])
    L = math.sqrt(float(ds.L2_over_EI.values[i]) * float(ds.attrs["EI"]))
    return L / float(ds.aspect.values[i])


@measure
def threshold_R_dependence(ev, spec, claim):
    """Largest relative difference, R = 2 against R = 1 at equal L/R (and equal kind of
    threshold), of the threshold midpoints in units of EI/R^2."""
    worst, n, files = 0.0, 0, []
    for fig in spec["figures"]:
        ds = ev.dataset(fig, claim)
        files.append(f"{dataset_path(fig)}")
        names = [str(s) for s in ds.aspect_scene.values]
        mid = 0.5 * (np.asarray(ds.threshold_lo.values) + np.asarray(ds.threshold_hi.values))
        mid = mid.reshape(len(names), -1)
        for i, name in enumerate(names):
            R = _aspect_R(ds, i)
            if abs(R - 1.0) < 1e-12:
                continue
            base = name.rsplit("_R", 1)[0]
            if base not in names:
                continue
            j = names.index(base)
            EI = float(ds.attrs.get("EI", 1.0))
            worst = max(worst, float(np.max(np.abs(mid[i] * R**2 / EI - mid[j] * _aspect_R(ds, j)**2 / EI)
                                            / (mid[j] * _aspect_R(ds, j)**2 / EI))))
            n += 1
    if n == 0:
        raise ClaimError(f"claim {claim!r}: no threshold at R != 1 with an R = 1 partner in {files}")
    return worst, True, ", ".join(f + ":threshold_lo, threshold_hi" for f in files), f"{n} pairs"


@measure
def first_threshold_over_estimate(ev, spec, claim):
    ds = ev.dataset(spec["figure"], claim)
    i = int(ds.attrs["main_index"])
    lo, hi = (float(ds[v].values[i, 0]) for v in ("threshold_lo", "threshold_hi"))
    est = float(ds.threshold_estimate.values[i, 0])
    return 0.5 * (lo + hi) / est, True, (f"{dataset_path(spec['figure'])}:threshold_lo, threshold_hi, "
                                         "threshold_estimate[first]"), \
        f"bracket [{lo:.6g}, {hi:.6g}], estimate {est:.6g} EI/R^2 at L/R = {float(ds.aspect.values[i]):g}"


@measure
def two_thresholds(ev, spec, claim):
    ds = ev.dataset(spec["figure"], claim)
    i = int(ds.attrs["main_index"])
    lo, hi = np.asarray(ds.threshold_lo.values[i]), np.asarray(ds.threshold_hi.values[i])
    holds = bool(hi[0] < lo[1])
    return float(lo[1] / hi[0]), holds, f"{dataset_path(spec['figure'])}:threshold_lo, threshold_hi", \
        f"second/first = {lo[1] / hi[0]:.3g}"


def _straight_points(ds, claim) -> tuple[np.ndarray, np.ndarray]:
    """(load, L_z) of every straight state (class 'straight') on the frictionless sweeps with
    protocol 'straight' (up and down), by load."""
    classes = ds.state_class.attrs["flag_meanings"].split()
    k = classes.index("straight")
    F, Lz = [], []
    for i, (p, kf) in enumerate(zip(ds.branch_protocol.values, ds.branch_k_fr.values)):
        if str(p) == "straight" and float(kf) == 0:
            m = (np.asarray(ds.state_class.values[i]) == k) & (np.asarray(ds.converged.values[i]) == 1)
            F += list(np.asarray(ds["load"].values)[m])
            Lz += list(np.asarray(ds.L_z.values[i])[m])
    if not F:
        raise ClaimError(f"claim {claim!r}: the bifurcation figure has no straight state on a frictionless sweep")
    order = np.argsort(F)
    return np.asarray(F)[order], np.asarray(Lz)[order]


@measure
def straight_branch_compliance(ev, spec, claim):
    """dL_z/dF on the straight branch (linear fit over its loads) over -L/k_ph, the compliance
    of the bonds alone (for the tilted rod, L_z = sqrt(L'^2 - 4R^2) with L' = L(1 - T/k_ph) and
    the tension T = F L/L_z along it: dL_z/dF = -(L/k_ph)(L/L_z)^2, 1 % more at L/R = 20)."""
    ds = ev.dataset(spec["figure"], claim)
    i = int(ds.attrs["main_index"])
    L, R = float(ds.aspect.values[i]) * _aspect_R(ds, i), _aspect_R(ds, i)
    k_ph = float(ds.attrs["k_ph"])
    F, Lz = _straight_points(ds, claim)
    loads = np.unique(F)
    if loads.size < 2:
        return 0.0, None, f"{dataset_path(spec['figure'])}:L_z, state_class", \
            f"only {loads.size} load on the straight branch: no slope"
    slope = float(np.polyfit(F, Lz, 1)[0])
    tilt = L**2 / (L**2 - 4 * R**2)
    return slope / (-L / k_ph), True, \
        f"{dataset_path(spec['figure'])}:L_z[straight states of the frictionless straight-protocol sweeps]", \
        (f"dL_z/dF = {slope:.4g} R^3/EI over {loads.size} loads ({loads.min():.3g}-{loads.max():.3g} EI/R^2); "
         f"-L/k_ph = {-L / k_ph:.4g}; the tilted rod's -(L/k_ph) L^2/L_z^2 = {-L / k_ph * tilt:.4g}")


@measure
def straight_branch_tilt(ev, spec, claim):
    """Our finding: with both ends free sideways the straight rod lies diagonally across the pore;
    the offset L - L_z extrapolated to zero load over L - sqrt(L^2 - 4R^2) (1 for the tilted rod,
    0 for a rod on the axis)."""
    ds = ev.dataset(spec["figure"], claim)
    i = int(ds.attrs["main_index"])
    L, R = float(ds.aspect.values[i]) * _aspect_R(ds, i), _aspect_R(ds, i)
    F, Lz = _straight_points(ds, claim)
    Lz0 = float(np.polyval(np.polyfit(F, Lz, 1), 0.0)) if np.unique(F).size >= 2 else float(Lz[0])
    ratio = (L - Lz0) / (L - math.sqrt(L**2 - 4 * R**2))
    return ratio, abs(ratio - 1) <= float(spec["rel"]), \
        f"{dataset_path(spec['figure'])}:L_z[straight states]", \
        f"L - L_z(F -> 0) = {L - Lz0:.4g} R; tilted rod L - sqrt(L^2 - 4R^2) = {L - math.sqrt(L**2 - 4 * R**2):.4g} R"


def _classes(ds, protocol: str, frictional: bool, claim: str) -> np.ndarray:
    """State classes along the first branch (config order) run with this protocol, with or
    without friction."""
    for i, (p, k) in enumerate(zip(ds.branch_protocol.values, ds.branch_k_fr.values)):
        if str(p) == protocol and (float(k) > 0) == frictional:
            return np.asarray(ds.state_class.values[i])
    raise ClaimError(f"claim {claim!r}: the bifurcation figure has no {'frictional' if frictional else 'frictionless'} "
                     f"sweep with protocol {protocol!r} (branches: {', '.join(map(str, ds.branch.values))})")


@measure
def planar_unstable(ev, spec, claim):
    """Above the second threshold: the planar-only sweep stays planar (the state exists),
    the fresh runs with an out-of-plane perturbation end 3-D (it is unstable)."""
    ds = ev.dataset(spec["figure"], claim)
    i = int(ds.attrs["main_index"])
    loads = np.asarray(ds["load"].values)
    above = loads > float(ds.threshold_hi.values[i, 1])
    if not above.any():
        raise ClaimError(f"claim {claim!r}: no load above the second threshold in {dataset_path(spec['figure'])}")
    planar = float(np.mean(_classes(ds, "planar", False, claim)[above] == 1))
    three_d = float(np.mean(_classes(ds, "planar_then_3d", False, claim)[above] == 2))
    return three_d, planar >= 0.8 and three_d >= 0.8, \
        f"{dataset_path(spec['figure'])}:state_class[protocol planar, planar_then_3d]", \
        f"above the second threshold: {planar:.0%} of planar-only runs planar, {three_d:.0%} of fresh runs 3-D"


@measure
def friction_keeps_planar(ev, spec, claim):
    ds = ev.dataset(spec["figure"], claim)
    loads = np.asarray(ds["load"].values)
    both = (_classes(ds, "straight", False, claim) == 2) & (_classes(ds, "straight", True, claim) == 1)
    span = f"{loads[both].min():.3g}-{loads[both].max():.3g} EI/R^2" if both.any() else "none"
    return float(both.sum()), bool(both.any()), \
        f"{dataset_path(spec['figure'])}:state_class[protocol straight, k_fr = 0 and > 0]", \
        f"loads where the frictionless sweep is 3-D and the frictional one planar: {span}"


@measure
def ends_detach(ev, spec, claim):
    ds = ev.dataset(spec["figure"], claim)
    top = float(np.min(ds.detached_top.values))
    force = float(np.min(ds.end_contact_force.values))
    return top, top > 0 and force > 0, f"{dataset_path(spec['figure'])}:detached_top, end_contact_force", \
        f"tip wall force {force:.3g} EI/R^2"


@measure
def final_out_of_plane(ev, spec, claim):
    ds = ev.dataset(spec["figure"], claim)
    oop = np.asarray(ds.frame_out_of_plane.values)
    return float(oop[-1]), bool(oop[-1] > 0.05 and oop[-1] > oop[0]), \
        f"{dataset_path(spec['figure'])}:frame_out_of_plane", f"planar frame {oop[0]:.2g} R"


@measure
def defect_fraction(ev, spec, claim):
    ds = ev.dataset(spec["figure"], claim)
    n, of = int(ds.attrs["seeds_with_defects"]), int(ds.attrs["seeds"])
    return n / of, n > 0, f"{dataset_path(spec['figure'])}:attrs seeds_with_defects, seeds", f"{n} of {of} seeds"


@measure
def defects_after_unloading(ev, spec, claim):
    ds = ev.dataset(spec["figure"], claim)
    per_state = np.asarray(ds.attrs["seeds_with_defects_per_state"]).ravel()
    loads = np.asarray(ds.state_load.values)
    converged = bool(np.all(ds.final_converged.values))
    holds = converged and per_state[0] > 0 and per_state[-1] < per_state[0]
    text = ", ".join(f"{int(n)} at {load:g}" for n, load in zip(per_state, loads))
    return float(per_state[-1]), holds, \
        f"{dataset_path(spec['figure'])}:attrs seeds_with_defects_per_state, state_load", \
        f"seeds with a defect: {text} EI/R^2"


# -- window-aware verdicts: the bulk helix and the whole wall-contact stretch ----------------------
#: the threshold and a factor sqrt(2) either side: a verdict that changes among them rests on the
#: choice of the threshold, not on the data, and is inconclusive
FALL_THRESHOLDS = (DEGENERATE_FALL / math.sqrt(2), DEGENERATE_FALL, DEGENERATE_FALL * math.sqrt(2))
_WORD = {True: "holds", False: "fails", None: "undecided"}


def _threshold_robust(test: Callable[[float], tuple[float, bool | None, str, str]]):
    """test(fall_min) at DEGENERATE_FALL, its verdict kept only if the same at every threshold
    of FALL_THRESHOLDS (else inconclusive, the note saying how it changes)."""
    results = {fm: test(fm) for fm in FALL_THRESHOLDS}
    value, holds, evidence, note = results[DEGENERATE_FALL]
    if len({r[1] for r in results.values()}) > 1:
        holds = None
        note += ("; the verdict depends on the fall below which a window does not determine a fit: "
                 + ", ".join(f"{_WORD[r[1]]} at {fm:.3g}x" for fm, r in results.items()))
    return value, holds, evidence, note


def _combine(parts: list[bool | None]) -> bool | None:
    """One verdict from several independent parts (panels, lengths): refuted if any part is,
    reproduced if every part is, else inconclusive."""
    if any(p is False for p in parts):
        return False
    return True if parts and all(p is True for p in parts) else None


def _two_windows(ok_whole: bool | None, ok_bulk: bool | None) -> bool | None:
    """A statement tested on the whole stretch and on the bulk: decided only if both agree."""
    return ok_whole if ok_whole == ok_bulk else None


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
    return _nanmax(devs), _combine(parts), \
        ", ".join(f + ":fit_c, fit_c_bulk, fall_whole, fall_bulk" for f in files), "; ".join(notes)


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
    return _nanmax(changes), _two_windows(*oks), \
        f"{dataset_path(small)}, {dataset_path(large)}:fit_c, fit_c_bulk", "; ".join(texts)


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
    return worst, _combine(parts), files, \
        "; ".join(notes)


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
            f"{label} ({fig}): {'describes' if h else 'does not describe' if h is False else 'undecided for'} "
            f"our profiles ({per_panel})" for label, fig, h, per_panel in answers)
        if any(h != holds for _, _, h, _ in answers):
            holds = None
            note += "; the verdict depends on the reading"
    return worst, holds, ", ".join(f + ":paper_rms_log_ratio, paper_rms_log_ratio_bulk" for f in files) + \
        ", fit_A, fit_l0, fit_c, paper_fit_*", note


def _printed_curve(ev, figure: str, tol: float, claim) -> tuple[float, bool | None, list[str], str]:
    """(worst rms over the bulk, verdict, a note per panel, the per-panel numbers in short) of
    the printed fits of one figure. A printed curve describes a panel if its rms of
    ln(f/|F_z|) on both windows and |ln| of its transmitted fraction f(L)/f(0) over ours are all
    within tol: where a profile falls by less than 2x, the rms alone cannot tell a decaying
    curve from a flat one (Fig 7's does), the transmitted fraction can."""
    ds = ev.dataset(figure, claim)
    parts, notes, worst, short = [], [], 0.0, []
    for i in range(ds.sizes["panel"]):
        if int(ds.has_paper_fit.values[i]) == 0:
            continue
        rw, rb = float(ds.paper_rms_log_ratio.values[i]), float(ds.paper_rms_log_ratio_bulk.values[i])
        worst = max(worst, rb)
        frac, sd = _panel_value(ds, "transmitted_fraction", i)
        if "fraction_std" in ds:
            sd = float(ds.fraction_std.values[i])
        d_frac = abs(math.log(float(ds.paper_fit_fraction.values[i]) / frac))
        parts.append(_two_windows(rw <= tol, rb <= tol) and d_frac <= tol)
        short.append(f"{_panel_label(ds, i)} rms {max(rw, rb):.2g}, fraction {frac:.3g}")
        why = undetermined(float(ds.fit_c.values[i]), float(ds.fall_whole.values[i]))
        fit = (float(ds.fit_A.values[i]), float(ds.fit_l0.values[i]), float(ds.fit_c.values[i]))
        ours = f"ours not determined ({why} over the whole stretch)" if why else \
            f"ours {fit[0]:.3g}, {fit[1]:.3g}, {fit[2]:.3f}"
        A, l0p, c = (float(ds[f"paper_fit_{k}"].values[i]) for k in ("A", "l0", "c"))
        notes.append(f"{_panel_label(ds, i)}: rms ln ratio {rw:.2g} (whole), {rb:.2g} (bulk); printed A = "
                     f"{A:g}, l0' = {l0p:g}, c = {c:g} (f(0) = {A * l0p ** c:.3g} against the load "
                     f"{float(ds.attrs['load']):g}) against {ours}; F(L)/F(0) printed "
                     f"{float(ds.paper_fit_fraction.values[i]):.3g}, ours {frac:.3g}" + (f" +- {sd:.2g}" if sd else "")
                     + f" (|ln ratio| {d_frac:.2g})")
    if not parts:
        raise ClaimError(f"claim {claim!r}: {dataset_path(figure)} has no printed fit")
    return worst, _combine(parts), notes, ", ".join(short)


@measure
def local_decay_law(ev, spec, claim):
    """The local decay law in the bulk helix, d(1/|F_z|)/ds against k_fr R/(4EI) (law: corrected)
    or k_fr R/(2EI) (law: paper), for every panel and length of the figures that has a bulk:
    the ratio r (ensemble mean where there are seeds) and its uncertainty u = max(window effect,
    seed s.d.)/law. A part holds if |r - 1| <= tol, fails if |r - 1| - 2u > tol, else is
    undecided; value: the mean ratio."""
    law, tol = spec["law"], float(spec["tol"])
    parts, notes, ratios, files, skipped = [], [], [], [], 0
    for fig in spec["figures"]:
        ds = ev.dataset(fig, claim)
        files.append(f"{dataset_path(fig)}")
        dim = "panel" if "panel" in ds.dims else "L"
        for i in range(ds.sizes[dim]):
            if int(ds.has_bulk.values[i]) == 0:
                skipped += 1
                continue
            ref = float(ds["decay_rate_model" if law == "corrected" else "decay_rate_paper"].values[i])
            rate, sd = _panel_value(ds, "bulk_decay_rate", i, "bulk_decay_rate")
            u = max(float(ds.bulk_decay_rate_err.values[i]), sd) / ref
            r = rate / ref
            ratios.append(r)
            parts.append(True if abs(r - 1) <= tol else (False if abs(r - 1) - 2 * u > tol else None))
            where = _panel_label(ds, i) if dim == "panel" else f"L/R = {float(ds.L.values[i]):g}"
            notes.append(f"{fig} {where}: {r:.3f} +- {u:.2g}")
    if not ratios:
        raise ClaimError(f"claim {claim!r}: no bulk helix in {files}")
    note = f"measured/({'k_fr R/(4EI)' if law == 'corrected' else 'k_fr R/(2EI)'}): " + "; ".join(notes)
    if skipped:
        note += f"; {skipped} runs without a bulk helix (short rods) not counted"
    return float(np.mean(ratios)), _combine(parts), \
        ", ".join(f + ":bulk_decay_rate, bulk_decay_rate_err, decay_rate_model" for f in files), note


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
    return value, holds, ", ".join(f"{dataset_path(f)}:paper_fit_decay_rate, bulk_decay_rate"
                                                  for f in spec["figures"]), "; ".join(notes)


@measure
def torque_budget_closes(ev, spec, claim):
    """The axial torque budget (confined_rod.analysis.torque) in every member of the protocol comparisons
    with both ends free: the friction's total axial torque vanishes (closure <= `max_closure`),
    and in the bulk the torque the friction left in the rod equals the one the local helix
    carries, |difference| <= `tol` (1 + |tau|/tau_0) in units of tau_0. Value: the largest
    difference over tau_0."""
    worst_c, worst_d, parts, files = 0.0, 0.0, [], []
    for fig in spec["figures"]:
        ds = ev.dataset(fig, claim)
        files.append(f"{dataset_path(fig)}:torque_closure_member, torque_friction_ratio_member, "
                     "torque_helix_ratio_member")
        free = (ds["variant_ends"].values == "free")[:, None] & (ds["has_member"].values == 1)
        # away from equilibrium the budget need not close: those runs are no evidence
        off = free & (ds["converged_member"].values == 0)
        if off.any():
            parts.append(f"{fig}: {int(off.sum())} runs not at equilibrium left out (" + ", ".join(
                f"{ds.variant.values[i]} member {j}" for i, j in zip(*np.nonzero(off))) + ")")
        has = free & ~off
        bulk = has & (ds["has_bulk_member"].values == 1)
        c = ds["torque_closure_member"].values[has]
        fr, hx = ds["torque_friction_ratio_member"].values[bulk], ds["torque_helix_ratio_member"].values[bulk]
        d = np.abs(fr - hx) / (1 + np.abs(fr))
        worst_c, worst_d = max(worst_c, float(c.max(initial=0))), max(worst_d, float(d.max(initial=0)))
        parts.append(f"{fig}: {int(has.sum())} runs, closure <= {float(c.max(initial=0)):.1e}, bulk torque from "
                     f"friction and from the helix differ by <= {float(d.max(initial=0)):.3f} (1 + |tau|/tau_0) "
                     f"tau_0 over {int(bulk.sum())} runs; bulk tau/tau_0 from {float(fr.min(initial=0)):.2f} to "
                     f"{float(fr.max(initial=0)):.2f}")
    holds = worst_c <= float(spec["max_closure"]) and worst_d <= float(spec["tol"])
    return worst_d, holds, ", ".join(files), "; ".join(parts)


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
            return 0.0, None, f"{dataset_path(spec['figure'])}:has_bulk_member", \
                f"no run of variant {v!r} has a bulk helix (L/R = {float(ds.attrs.get('L', 0)):g}): nothing to compare"
        rows.append((v, {k: _mean_sd(ds, k, i) for k in ("torque_friction_ratio", "pitch_ratio", "K_ratio",
                                                           "K_ratio_from_torque", "decay_ratio", "fraction")}))

    def apart(key):
        return all(abs(a[1][key][0] - b[1][key][0]) > 2 * max(a[1][key][1], b[1][key][1])
                   for k, a in enumerate(rows) for b in rows[k + 1:])

    nearest = min(rows, key=lambda r: abs(r[1]["pitch_ratio"][0] - 1.0))
    top_K = max(rows, key=lambda r: r[1]["K_ratio"][0])
    top_rate = max(rows, key=lambda r: r[1]["decay_ratio"][0])
    holds = apart("pitch_ratio") and apart("torque_friction_ratio") and nearest is top_K and nearest is top_rate
    note = "; ".join(f"{v}: tau/tau_0 {d['torque_friction_ratio'][0]:.2f} +- {d['torque_friction_ratio'][1]:.2f}, "
                     f"pitch {d['pitch_ratio'][0]:.2f} +- {d['pitch_ratio'][1]:.2f} of torque-free, K "
                     f"{d['K_ratio'][0]:.2f} of R F^2/(4EI) (from pitch and torque {d['K_ratio_from_torque'][0]:.2f}), "
                     f"decay rate {d['decay_ratio'][0]:.2f} +- {d['decay_ratio'][1]:.2f} of the corrected law, "
                     f"F(L)/F(0) {d['fraction'][0]:.2f}" for v, d in rows)
    note += (f"; pitch nearest the torque-free one: {nearest[0]}, largest K: {top_K[0]}, largest decay rate: "
             f"{top_rate[0]}")
    return nearest[1]["K_ratio"][0], holds, \
        f"{dataset_path(spec['figure'])}:torque_friction_ratio_mean, pitch_ratio_mean, K_ratio_mean, " \
        "decay_ratio_mean", note


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
        return 0.0, None, ", ".join(files), "; ".join(parts)
    holds = True if all(results) else (False if not any(results) else None)
    return value, holds, ", ".join(files), "; ".join(parts)


@measure
def pitch_exponent(ev, spec, claim):
    """d ln|dphi/ds| / d ln|F_z| on the whole defined stretch and on the bulk helix against
    `expected` within `tol`; a window over which |F_z| falls by less than 2x does not
    determine a slope (checked at FALL_THRESHOLDS); value: the bulk slope (nan if not determined)."""
    ds = ev.dataset(spec["figure"], claim)
    target, tol = float(spec["expected"]), float(spec["tol"])

    def windows(fall_min):
        oks, texts = [], []
        for name in ("whole", "bulk"):
            e, fall = float(ds[f"exponent_omega_F_{name}"]), float(ds[f"fall_{name}"])
            if fall < fall_min:
                oks.append(None)
                texts.append(f"{name}: {e:.3f}, not determined (|F_z| falls only {fall:.3g}x)")
                continue
            oks.append(abs(e - target) <= tol)
            texts.append(f"{name}: {e:.3f}")
        value = float(ds["exponent_omega_F_bulk"]) if oks[1] is not None else math.nan
        return value, _two_windows(*oks), "", "; ".join(texts)

    value, holds, _, note = _threshold_robust(windows)
    texts = [note]
    if "seeds_from" in spec and holds is not None:
        # the same slope on every seed of an ensemble of the same rod (same L, load, k_fr) in another
        # figure: a verdict that a seed flips is luck
        from ..analysis.figures import pitch_profile
        _, rod = ev.sim(spec["figure"], -1, claim)
        same = [(k, d) for k, d in ev.sims.items() if k.startswith(spec["seeds_from"] + "/")
                and all(float(d.attrs[a]) == float(rod.attrs[a]) for a in ("L", "load", "k_fr"))]
        ev.touched.update(("sim", k) for k, _ in same)
        per = [float(pitch_profile.build({}, {k: d})["exponent_omega_F_bulk"]) for k, d in same]
        if per:
            ok = [abs(e - target) <= tol for e in per]
            texts.append(f"bulk slope over {len(per)} seeds of the same rod in {spec['seeds_from']}: "
                         + ", ".join(f"{e:.3f}" for e in per))
            if any(ok) and not all(ok):
                holds = None
                texts.append(f"{sum(ok)} of {len(ok)} seeds within the tolerance: the verdict depends on the seed")
    return value, holds, \
        f"{dataset_path(spec['figure'])}:exponent_omega_F_whole, exponent_omega_F_bulk", \
        "; ".join(texts) + f" (expected {target:g} +- {tol:g})"


@measure
def pitch_falls_less(ev, spec, claim):
    ds = ev.dataset(spec["figure"], claim)
    d_omega, d_F = float(ds.drop_omega), float(ds.drop_F)
    return d_omega, 0 < d_omega < d_F, f"{dataset_path(spec['figure'])}:drop_omega, drop_F", \
        f"|dphi/ds| falls by {d_omega:.0%}, |F_z| by {d_F:.0%}"


def _last_panel(ev, figure, var, claim):
    return float(np.asarray(ev.dataset(figure, claim)[var].values).ravel()[-1])


@measure
def small_load_transmits_more(ev, spec, claim):
    small, large = spec["figures"]
    f7 = _last_panel(ev, small, "transmitted_fraction", claim)
    f4 = _last_panel(ev, large, "transmitted_fraction", claim)
    return f7 / f4, f7 > f4, (f"{dataset_path(small)}:transmitted_fraction, "
                              f"{dataset_path(large)}:transmitted_fraction[last panel]"), \
        f"F(L)/F(0) = {f7:.3g} against {f4:.3g}"


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
    "boundary regions" are both ends: holds if both are wider, refuted if one is narrower, else
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
    note = ("; ".join(texts) + f" (means and seed ranges over {len(m7)} and {len(m4)} seeds; "
            f"detached: to the first or from the last run of {HELIX_RUN} or more links on the wall, shorter "
            "clusters of contacts inside it not counted; region: the tip and the lower region of the force profile)")
    if holds is False and "wider" in ends:
        note = "refuted as stated, holds at " + ("the loaded end" if ends[0] == "wider" else "the support") + \
            " only: " + note
    top7 = np.mean([detached_lengths(d)[0] for _, d in m7])
    top4 = np.mean([detached_lengths(d)[0] for _, d in m4])
    return top7 / max(top4, 1e-300), holds, \
        f"{ev.file(m7[0][0])}, {ev.file(m4[0][0])} (and their seeds):contact, s_link, F_z, friction_z", note


@measure
def transmitted_decays(ev, spec, claim):
    ds = ev.dataset(spec["figure"], claim)
    L = np.asarray(ds.L.values, dtype=float)
    F = np.asarray(ds.F_transmitted.values, dtype=float)
    frac = F / float(ds.attrs["load"])
    slope = float(np.log(F[-1] / F[-2]) / np.log(L[-1] / L[-2]))
    holds = bool(np.all(np.diff(F) < 0) and slope < -0.5)
    return float(frac[-1]), holds, f"{dataset_path(spec['figure'])}:F_transmitted", \
        f"F(L)/F(0) = {frac[-1]:.3g} at L/R = {L[-1]:g}; slope of the last two lengths {slope:.2f}"


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
    return float(value), holds, f"{dataset_path(spec['figure'])}:F_transmitted", \
        "; ".join(texts) + f" (range {lo:g}-{hi:g}); F(L)/F(0) = " + ", ".join(f"{f:.2f}" for f in frac)


@measure
def fold_threshold_exists(ev, spec, claim):
    ds = ev.dataset(spec["figure"], claim)
    lo, hi = (float(v) for v in np.asarray(ds.attrs["fold_threshold_range"]).ravel()[:2])
    limit = float(ds.attrs["helix_limit"])
    return 0.5 * (lo + hi), hi < limit, \
        f"{dataset_path(spec['figure'])}:attrs fold_threshold_range, helix_limit", \
        f"fold thresholds {lo:.3g}-{hi:.3g} EI/R^2, helix limit {limit:.3g}"


@measure
def event_escapes(ev, spec, claim):
    ds = ev.dataset(spec["figure"], claim)
    esc = int(ds.attrs["event_escaped"])
    return float(esc), esc == 1, f"{dataset_path(spec['figure'])}:attrs event_escaped", \
        f"L/R = {float(ds.attrs['event_L']) / float(ds.attrs['event_R']):g}, load {float(ds.attrs['event_load']):g}"


@measure
def escape_at_stated_conditions(ev, spec, claim):
    """At the paper's conditions (the rod in the pore from its top, the entrance closed above it):
    the paper's load lies below every measured fold threshold, so the rod coils instead of
    folding or escaping. Value: the paper's load over the smallest fold threshold."""
    ds = ev.dataset(spec["figure"], claim)
    lo, hi = (float(v) for v in np.asarray(ds.attrs["fold_threshold_range"]).ravel()[:2])
    load = float(ds.attrs["paper_load"])
    below = int(ds.attrs["paper_load_below_fold_thresholds"]) == 1
    escaped_open = int(ds.attrs.get("event_escaped", 0)) == 1
    # the paper does not describe its entrance: closed, the rod coils; open, it can escape
    holds = (None if escaped_open else False) if below else True
    return load / lo, holds, \
        (f"{dataset_path(spec['figure'])}:attrs paper_load, fold_threshold_range, "
         "paper_load_below_fold_thresholds"), \
        (f"load {load:g} EI/R^2 against fold thresholds {lo:.3g}-{hi:.3g} EI/R^2 (closed entrance): "
         + ("below them, the rod coils into a helix" if below else "above the smallest")
         + ("; with an open entrance and a free span of "
            f"{float(ds.attrs.get('event_free_span', 0)):g} R (not stated in the paper) the rod escapes at this load: "
            "the answer depends on the entrance" if escaped_open and below else ""))


# material numbers of the paper's conclusions (SI units)
NANOTUBE = {"L": 100e-6, "E": 1e12, "R": 1e-6, "load": 0.25, "F_range": (1e-9, 10e-9),
            "plausible_radius": (1e-9, 50e-9)}
DNA = {"persistence_length": 50e-9, "diameter": 2e-9, "aspect_ratio": 100.0}


@measure
def nanotube_radius(ev, spec, claim):
    """Tube radius r (solid section, I = pi r^4/4) for which load EI/R^2 lies in the nN range."""
    p = NANOTUBE
    r = [(4 * F * p["R"] ** 2 / (p["load"] * math.pi * p["E"])) ** 0.25 for F in p["F_range"]]
    ok = p["L"] / p["R"] >= 100 and p["plausible_radius"][0] <= r[0] and r[1] <= p["plausible_radius"][1]
    return r[0] * 1e9, ok, "confined_rod.claims.verdicts.NANOTUBE (computed)", \
        f"L/R = {p['L'] / p['R']:g}; tube radius {r[0] * 1e9:.3g}-{r[1] * 1e9:.3g} nm for 1-10 nN"


@measure
def dna_pore_radius(ev, spec, claim):
    p = DNA
    R = p["persistence_length"] / p["aspect_ratio"]
    return R * 1e9, R < p["diameter"] / 2, "confined_rod.claims.verdicts.DNA (computed)", \
        f"pore radius {R * 1e9:.2g} nm against the DNA radius {p['diameter'] / 2 * 1e9:.2g} nm"


# measures that read scene simulations (results/sims/), from the test's figure or figures
SIM_MEASURES = {"wall_force_coefficient", "capped_fraction", "boundary_wider", "pitch_exponent"}


def required_figures(claims: list[Mapping[str, Any]]) -> dict[str, list[str]]:
    """figure -> the claims that read its dataset or simulations."""
    out: dict[str, list[str]] = {}
    for c in claims:
        for spec in (c["test"], c.get("paper_from") or {}):
            for f in ([spec["figure"]] if "figure" in spec else []) + list(spec.get("figures", [])) + \
                    ([spec["protocols"]] if "protocols" in spec else []) + list((spec.get("ramp") or {}).values()):
                out.setdefault(f, []).append(c["id"])
    return out


def sim_figures(claims: list[Mapping[str, Any]]) -> list[str]:
    """The figures whose scene simulations the claims read."""
    out: list[str] = []
    for c in claims:
        t = c["test"]
        if t.get("method") == "measure" and t.get("name") in SIM_MEASURES:
            figs = ([t["figure"]] if "figure" in t else list(t.get("figures", [])))
            figs += [t["seeds_from"]] if "seeds_from" in t else []
            out += [f for f in figs if f not in out]
    return out


# -- evaluation --------------------------------------------------------------------------------
def fmt(value: float, spec: str | None = None) -> str:
    """Plain-text number: the claim's format, else 3 significant digits without exponent
    where that is readable."""
    if spec:
        return format(value, spec)
    if value != 0 and (abs(value) >= 1e5 or abs(value) < 1e-3):
        return format(value, ".2e")
    return format(value, ".3g")


def _tolerance_text(tol):
    if not tol:
        return ""
    (kind, x), = tol.items()
    return f"{'relative' if kind == 'rel' else 'absolute'} {x:g}"


def _within(ours, paper, tol):
    (kind, x), = tol.items()
    if kind == "rel":
        return abs(ours - paper) <= x * abs(paper)
    return abs(ours - paper) <= x


#: our value where no window of the data determines it (an inconclusive verdict says why)
NOT_DETERMINED = "not determined"


def evaluate_one(c: Mapping[str, Any], ev: Evidence) -> Verdict:
    """A claim's verdict; if anything it read comes from a run that is not at equilibrium, the
    verdict is 'not testable' and the note names those runs (the measure is not trusted, and
    may not even complete, on such evidence)."""
    ev.touched.clear()
    try:
        verdict = _evaluate_one(c, ev)
    except (ClaimError, ValueError, KeyError, IndexError, ZeroDivisionError):
        if not ev.unsettled():
            raise
        verdict = None
    off = ev.unsettled()
    if off:
        return unsettled_verdict(c, off)
    return verdict


def unsettled_verdict(c: Mapping[str, Any], runs: list[str]) -> Verdict:
    shown = "; ".join(runs[:4]) + (f"; and {len(runs) - 4} more" if len(runs) > 4 else "")
    paper = c.get("paper", "-")
    return Verdict(c["id"], c["where"], c["claim"], str(paper if "paper_from" not in c else "-"),
                   float(paper) if isinstance(paper, (int, float)) and not isinstance(paper, bool) else None,
                   "-", None, "", "not testable", "-", str(c.get("reading", "")),
                   f"evidence not at equilibrium ({shown})", str(c.get("finding", c["id"])))


def _evaluate_one(c: Mapping[str, Any], ev: Evidence) -> Verdict:
    from . import derivations

    test, cid = c["test"], c["id"]
    method = test["method"]
    reading = str(c.get("reading", ""))
    tol = c.get("tolerance")
    paper_value, paper_src = None, ""
    if "paper_from" in c:
        paper_value, paper_src = pick(ev, c["paper_from"], cid)
        paper_text = fmt(paper_value, c.get("format"))
    else:
        paper_text = str(c["paper"])
        if isinstance(c["paper"], (int, float)) and not isinstance(c["paper"], bool):
            paper_value = float(c["paper"])
    ours_value, note = None, ""
    if method == "not_testable":
        return Verdict(cid, c["where"], c["claim"], paper_text, paper_value, "-", None, "", "not testable",
                       "-", reading, str(test.get("reason", "")), str(c.get("finding", cid)))
    if method == "derivation":
        d = derivations.DERIVATIONS[test["name"]]()
        ours, holds, evidence, note = d.ours, d.agrees, f"confined_rod.claims.derivations.{test['name']}", d.detail
    else:
        if method == "value":
            ours_value, evidence = pick(ev, test, cid)
            holds = True
        else:
            ours_value, holds, evidence, note = MEASURES[test["name"]](ev, test, cid)
        if math.isnan(ours_value) and holds is None:
            # the measure found no window that determines the quantity (the note says why): no value
            ours, ours_value = NOT_DETERMINED, None
        elif not math.isfinite(ours_value):
            raise ClaimError(f"claim {cid!r}: the measured value is not finite ({evidence})")
        else:
            ours = fmt(ours_value, c.get("format"))
        if tol and holds is not None:
            holds = holds and _within(ours_value, paper_value, tol)
    if paper_src:
        evidence += f"; paper value from {paper_src}"
    if holds is None:       # the measure found the answer to depend on an analysis choice (note: why)
        verdict = "inconclusive"
    else:
        verdict = ("reproduced under reading" if reading else "reproduced") if holds else "refuted"
    return Verdict(cid, c["where"], c["claim"], paper_text, paper_value, ours, ours_value, _tolerance_text(tol),
                   verdict, evidence, reading, note, str(c.get("finding", cid)))


def evaluate(claims: list[Mapping[str, Any]], ev: Evidence) -> list[Verdict]:
    return [evaluate_one(c, ev) for c in claims]


COLUMNS = ("id", "where", "claim", "paper", "ours", "verdict", "tolerance", "reading", "evidence", "note", "finding")


#: a finding's verdict from its claims' (the paper's claims only: claims of ours, whose `where`
#: says "our finding", do not decide it): the first of these that occurs
FINDING_ORDER = ("refuted", "inconclusive", "reproduced under reading", "reproduced", "not testable")


def ours_only(v: Verdict) -> bool:
    return "our finding" in v.where


def findings(verdicts: list[Verdict]) -> dict[str, tuple[str, list[str]]]:
    """Independent findings: name -> (verdict, ids of its claims), in the order of first
    appearance; a finding whose claims are all ours gets their verdict."""
    groups: dict[str, list[Verdict]] = {}
    for v in verdicts:
        groups.setdefault(v.finding or v.id, []).append(v)
    out = {}
    for name, vs in groups.items():
        deciding = [v for v in vs if not ours_only(v)] or vs
        verdict = next(o for o in FINDING_ORDER if any(v.verdict == o for v in deciding))
        out[name] = (verdict, [v.id for v in vs])
    return out


def split_findings(verdicts: list[Verdict]) -> tuple[dict, dict]:
    """(the findings about the paper's claims, the findings of our own): a finding all of whose
    claims are ours ("our finding" in where) is ours; counts and the abstract keep them apart."""
    found = findings(verdicts)
    mine = {v.id for v in verdicts if ours_only(v)}
    own = {n: f for n, f in found.items() if set(f[1]) <= mine}
    return {n: f for n, f in found.items() if n not in own}, own


VARIABLE = {"claim": "statement"}   # the claim's text (the dimension is called claim)


def to_dataset(verdicts: list[Verdict], titles: Mapping[str, str] | None = None) -> xr.Dataset:
    """The verdicts as a CF-style dataset: text variables, and the numbers with a flag where
    a claim has one (no NaN)."""
    from ..io import finalize

    def text(name, long_name):
        return xr.Variable("claim", np.array([str(getattr(v, name)) for v in verdicts], dtype=object),
                           {"long_name": long_name, "units": "1"})

    def number(name, long_name):
        vals = [getattr(v, name) for v in verdicts]
        return (xr.Variable("claim", np.array([x if x is not None else 0.0 for x in vals], dtype=float),
                            {"long_name": long_name + " (0 where has_" + name + " is 0)", "units": "1"}),
                xr.Variable("claim", np.array([x is not None for x in vals], dtype=np.int8),
                            {"long_name": "1 where the claim has " + long_name, "units": "1"}))

    data = {VARIABLE.get(name, name): text(name, long) for name, long in (
        ("where", "section, equation or figure of the original"), ("claim", "what the paper says"),
        ("paper", "the paper's value as printed"), ("ours", "our value"),
        ("verdict", "reproduced, reproduced under reading, refuted or not testable"),
        ("tolerance", "tolerance deciding the verdict"), ("reading", "interpretation the verdict needs"),
        ("evidence", "dataset and variable, or derivation, behind our value"), ("note", "how it was decided"),
        ("finding", "the independent finding the claim belongs to"))}
    for name, long in (("paper_value", "the paper's value"), ("ours_value", "our value")):
        data[name], data["has_" + name] = number(name, long)
    ds = xr.Dataset(data, coords={"claim": ("claim", np.array([v.id for v in verdicts], dtype=object),
                                            {"long_name": "claim id (paper/claims.yaml)", "units": "1"})})
    paper_claims = [v for v in verdicts if not ours_only(v)]
    for verdict in VERDICTS:
        ds.attrs["n_" + verdict.replace(" ", "_")] = sum(v.verdict == verdict for v in paper_claims)
    ds.attrs["n_own_claims"] = len(verdicts) - len(paper_claims)
    found, own = split_findings(verdicts)
    ds.attrs["n_findings"] = len(found)
    for verdict in VERDICTS:
        ds.attrs["n_findings_" + verdict.replace(" ", "_")] = sum(f[0] == verdict for f in found.values())
    ds.attrs["n_own_findings"] = len(own)
    ds.attrs["finding_titles"] = json.dumps(dict(titles or {}))
    return finalize(ds, "Claims of Svensek & Podgornik, evaluated on this build's datasets", {})


def to_csv(verdicts: list[Verdict]) -> str:
    import csv
    import io

    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(COLUMNS)
    for v in verdicts:
        w.writerow([getattr(v, c) for c in COLUMNS])
    return buf.getvalue()
