"""Helpers shared by the figure-kind modules (validation and dataset building)."""
from __future__ import annotations

from typing import Any, Mapping

import numpy as np
import xarray as xr

from ...errors import ConfigError
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
