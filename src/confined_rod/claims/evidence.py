"""What the claims read: the datasets (by figure) and the scene simulations (by 'figure/scene')
of a build, with what each claim has touched (so that a claim resting on a run that is not at
equilibrium is not decided), and a number picked out of a dataset (``test: {method: value}``)."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Mapping

import numpy as np
import xarray as xr

from ..analysis import ensembles
from ..errors import ConfigError
from ..layout import dataset_path, sim_key_path, sims_folder


class ClaimError(ConfigError):
    """A claim that is malformed, or whose evidence is missing."""


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
        from ..analysis import run_checks

        runs: list[str] = []
        for what, key in sorted(self.touched):
            if what == "dataset":
                runs += run_checks.flagged(self.datasets[key].attrs.get("not_at_equilibrium"))
            else:
                runs += run_checks.not_at_equilibrium({key: self.sims[key]})
        return list(dict.fromkeys(runs))

    def protocols(self) -> list[str]:
        """The loading protocols of what has been read: of each simulation read, and of the runs
        behind each dataset read (its attribute ``protocols``)."""
        found: set[str] = set()
        for what, key in self.touched:
            if what == "dataset":
                found.update(p for p in str(self.datasets[key].attrs.get("protocols", "none")).split(", ")
                             if p != "none")
            elif "protocol" in self.sims[key].attrs:
                found.add(str(self.sims[key].attrs["protocol"]))
        return sorted(found)

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
        return self.ensemble(figure, ensembles.base_name(key.split("/", 1)[1], int(first.attrs.get("seed", 0))),
                             claim)

    def ensemble(self, figure: str, base: str, claim: str) -> list[tuple[str, xr.Dataset]]:
        """Every member of the scene the config names `base` in a figure (its seeds, or the one run
        of a scene without seeds), by seed."""
        names = [k.split("/", 1)[1] for k in self.sims if k.startswith(figure + "/")]
        groups = ensembles.by_base(names, {n: int(self.sims[f"{figure}/{n}"].attrs.get("seed", 0)) for n in names})
        if base not in groups:
            raise ClaimError(f"claim {claim!r} needs the runs of scene {base!r} of figure {figure!r} "
                             f"({sims_folder(figure)})")
        keys = [f"{figure}/{n}" for n in groups[base]]
        self.touched.update(("sim", k) for k in keys)
        return [(k, self.sims[k]) for k in keys]


def _by_length(sims, figure, names):
    return sorted(names, key=lambda n: float(sims[f"{figure}/{n}"].attrs.get("L", 0.0)))


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
