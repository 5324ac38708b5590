"""Helpers shared by the figure-kind modules (validation and dataset building)."""
from __future__ import annotations

from typing import Any, Mapping

import numpy as np
import xarray as xr

from ...errors import ConfigError
from .. import local_relations, regions
from ..figure_quantities import attrs, variable

#: the Scene field that names a scene: never compared by same_except
SCENE_NAME = "name"


def same_except(figure: str, built: Mapping[str, Any], varied: tuple[str, ...], why: str) -> None:
    """Raise ConfigError unless the scenes differ only in ``varied``. A default that follows
    other parameters (k_t follows l0 and k_ph) may differ where they do: they are compared."""
    ref_name, ref = next(iter(built.items()))
    for name, sc in built.items():
        for key in type(sc).field_names():
            if key in varied or key == SCENE_NAME or not (sc.given(key) or ref.given(key)):
                continue
            if getattr(sc, key) != getattr(ref, key):
                raise ConfigError(f"figures.{figure}.scenes.{name}: {key} = {getattr(sc, key)!r} differs from "
                                  f"{getattr(ref, key)!r} in scene {ref_name!r}; {why}")


def need_scenes(figure: str, built: Mapping[str, Any], n: int, what: str) -> None:
    if len(built) < n:
        raise ConfigError(f"figures.{figure}.scenes: {what} needs at least {n} scene(s), got {len(built)}")


def scene_coord(dim: str, names) -> xr.Variable:
    return xr.Variable((dim,), np.array(list(names), dtype=object), attrs=attrs("scene"))


def per_scene(dim: str, sims: Mapping[str, xr.Dataset], names, name: str, fn) -> xr.Variable:
    return variable((dim,), [fn(sims[n]) for n in names], name)


def check_scene_keys(figure: str, option: str, mapping: Mapping[str, Any] | None, built: Mapping[str, Any]) -> None:
    """A per-scene option (e.g. paper_fits) must name scenes of the figure."""
    for key in mapping or {}:
        if key not in built:
            raise ConfigError(f"figures.{figure}.{option}: {key!r} is not one of its scenes ({', '.join(built)})")


def tol_effective(sim: xr.Dataset) -> float:
    """The equilibrium tolerance a run was tested at: its round-off floor where that exceeds tol
    (limits.equilibrium_tol, stored as ``tol_effective``), else tol."""
    return float(sim.attrs.get("tol_effective", sim.attrs["tol"]))


def loosely_wound(sim: xr.Dataset, analysis) -> bool:
    """Whether the run's bulk helix is loosely wound (analysis.local_relations.loosely_wound; False
    without a wall force ratio to read): a locked torque, under which the torque-free decay law does
    not hold; the figures store it per member. ``analysis``: the run's regions.analyse."""
    if "wall_force_density" not in sim:
        return False
    return bool(local_relations.loosely_wound(local_relations.measure(sim, analysis)))


def bulk_part(sim: xr.Dataset, analysis) -> float:
    """What the run's bulk helix adds to 1/|F_z| (regions.force_parts), 0 without a bulk."""
    parts = regions.force_parts(sim, analysis)
    return float(parts["bulk"]) if parts else 0.0


def rod_parts(F: np.ndarray, part: np.ndarray, has_bulk: np.ndarray) -> tuple[float, float] | None:
    """(mean |F_z(L)|, mean bulk part of 1/|F_z|) over the members with a bulk: the rod an error
    budget rescales a ladder's split by region to (analysis.error_budget.rescaled); None without
    a bulk."""
    ok = np.asarray(has_bulk) == 1
    if not ok.any():
        return None
    return float(np.mean(np.asarray(F)[ok])), float(np.mean(np.asarray(part)[ok]))
