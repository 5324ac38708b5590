"""Numerical studies over ladders of scenes: convergence in a numerical parameter,
and run time against error.  Pure functions of the scene datasets; the pipeline
calls them through postprocess.build.

Convergence (kind ``convergence``).  The scenes differ in one numerical parameter
(l0, k_ph, k_w or tol).  Its refinement variable h -> 0 is l0, 1/k_ph, 1/k_w or
tol.  From the three finest rungs h1 > h2 > h3 (ratio r = h1/h2 = h2/h3) and an
observable f, Richardson extrapolation gives

    observed order  p = ln((f1 - f2)/(f2 - f3)) / ln r
    limit           f_inf = f3 + (f3 - f2)/(r^p - 1),

valid when the differences have one sign (monotone convergence); differences
below a tenth of the tolerance count as converged (limit = finest value).  The check
compares the value at the publication setting with f_inf: |f_pub - f_inf| /
|f_inf| must not exceed the tolerance in config.

Like with like.  With friction a coarse and a fine rod started alike may settle
in different equilibria (a jammed near-planar state and a helix).  Extrapolating
across them is meaningless, so every rung is classified (helical: the contact
stretch winds at least one turn) and the check is declared *inconclusive* when
the classes or the winding numbers (to within half a turn) differ, or when the
differences change sign.  An inconclusive check says why; whether it fails the
build is the config's choice (``on_inconclusive``).
"""
from __future__ import annotations

import math
from typing import Any, Mapping

import numpy as np
import xarray as xr

from .io import variable
from .quantities import attrs

REFINEMENT = {"l0": ("h = l0", lambda v: v), "tol": ("h = tol", lambda v: v),
              "k_ph": ("h = 1/k_ph", lambda v: 1.0 / v), "k_w": ("h = 1/k_w", lambda v: 1.0 / v)}
OBSERVABLES = ("F_transmitted", "L_z", "pitch")


class ConvergenceError(RuntimeError):
    """The publication settings are further from the extrapolated limit than the tolerance."""


def n_turns(sim: xr.Dataset) -> float:
    phi = sim["phi"].values
    return float(abs(phi[-1] - phi[0]) / (2 * np.pi)) if phi.size >= 2 else 0.0


def bulk_pitch(sim: xr.Dataset) -> float:
    """Axial length of one turn, 2 pi |dz/dphi|, fitted over the middle half of the
    wall-contact stretch; 0 if the stretch winds less than one turn."""
    if n_turns(sim) < 1.0:
        return 0.0
    phi = sim["phi"].values
    z = sim["z"].sel(s_link=sim["s_helix"].values).values
    n = phi.size
    mid = slice(n // 4, n - n // 4)
    slope = np.polyfit(phi[mid], z[mid], 1)[0]
    return float(2 * np.pi * abs(slope))


def richardson(h: np.ndarray, f: np.ndarray, resolved: float = 0.0) -> tuple[float, float, str]:
    """(observed order, limit, note) from the three finest rungs (h descending).

    ``resolved``: differences below this (absolute) are taken as converged: the
    finest value is the limit and the order is not measurable (reported as 0).
    Without it, noise at the level of the equilibrium tolerance would make a
    converged ladder look non-monotone."""
    h1, h2, h3 = h[-3:]
    f1, f2, f3 = f[-3:]
    r = h1 / h2
    if not math.isclose(h2 / h3, r, rel_tol=0.02):
        return 0.0, float(f3), "ladder not geometric; limit = finest value"
    d1, d2 = f1 - f2, f2 - f3
    if d2 == 0.0:
        return 0.0, float(f3), "converged to round-off"
    if max(abs(d1), abs(d2)) <= resolved:
        return 0.0, float(f3), "finest differences below a tenth of the tolerance (converged)"
    q = d1 / d2
    if q <= 1.0:
        return 0.0, float(f3), "differences do not shrink monotonically (no asymptotic range)"
    p = math.log(q) / math.log(r)
    return p, float(f3 + (f3 - f2) / (r**p - 1.0)), ""


def convergence(fig_cfg: Mapping[str, Any], sims: Mapping[str, xr.Dataset],
                publication_value: float) -> xr.Dataset:
    param = fig_cfg["parameter"]
    hname, hfun = REFINEMENT[param]
    items = sorted(sims.items(), key=lambda kv: -hfun(float(kv[1].attrs[param])))
    values = np.array([float(d.attrs[param]) for _, d in items])
    h = np.array([hfun(v) for v in values])
    turns = np.array([n_turns(d) for _, d in items])
    helical = turns >= 1.0
    obs = {"F_transmitted": np.array([float(d["F_transmitted"]) for _, d in items]),
           "L_z": np.array([float(d["L_z"]) for _, d in items]),
           "pitch": np.array([bulk_pitch(d) for _, d in items])}
    tol = float(fig_cfg["tolerance"])
    reasons = []
    if helical.any() and not helical.all():
        reasons.append("the rungs settle in different states (helical: "
                       + ", ".join(f"{v:g}" for v in values[helical]) + "; not helical: "
                       + ", ".join(f"{v:g}" for v in values[~helical]) + ")")
    elif np.ptp(turns) > 0.5:
        reasons.append(f"the winding differs between rungs ({turns.min():.2f} to {turns.max():.2f} turns)")
    if not np.any(np.isclose(values, publication_value, rtol=1e-9)):
        raise ValueError(f"convergence ladder over {param} does not contain the publication value {publication_value}")
    ipub = int(np.flatnonzero(np.isclose(values, publication_value, rtol=1e-9))[0])
    checked = [k for k in OBSERVABLES if k != "pitch" or helical.all()]
    data, order, limit, dist, notes = {}, [], [], [], []
    for k in OBSERVABLES:
        data[k] = variable(("rung",), obs[k], k)
    for k in checked:
        p, lim, note = richardson(h, obs[k], resolved=0.1 * tol * abs(obs[k][-1]))
        order.append(p)
        limit.append(lim)
        dist.append(abs(obs[k][ipub] - lim) / abs(lim) if lim != 0 else abs(obs[k][ipub]))
        notes.append(note or "ok")
    if not reasons and any(n.startswith("differences") or n.startswith("ladder") for n in notes):
        reasons.append("; ".join(f"{k}: {n}" for k, n in zip(checked, notes) if n != "ok"))
    worst = max(dist)
    if reasons:
        status = "inconclusive: " + "; ".join(reasons)
    elif worst > tol:
        status = "fail"
    else:
        status = "pass"
    data["n_turns"] = variable(("rung",), turns, "n_turns")
    data["converged"] = variable(("rung",), [np.int8(d["converged"]) for _, d in items], "converged")
    data["wall_time"] = variable(("rung",), [float(d["wall_time"]) for _, d in items], "wall_time")
    data["observed_order"] = variable(("observable",), order, "observed_order")
    data["publication_distance"] = variable(("observable",), dist, "publication_distance")
    for k, lim in zip(checked, limit):  # one variable per observable: they carry different units
        data[f"{k}_limit"] = xr.Variable((), lim, attrs={**attrs(k), "long_name": "extrapolated limit h -> 0 of the "
                                                          + attrs(k)["long_name"]})
    coords = {"rung": xr.Variable(("rung",), np.array([k for k, _ in items], dtype=object), attrs=attrs("scene")),
              "value": xr.Variable(("rung",), values, attrs={**attrs("value"), "long_name": f"value of {param}",
                                                              "parameter": param}),
              "h": xr.Variable(("rung",), h, attrs={**attrs("h"), "definition": hname}),
              "observable": xr.Variable(("observable",), np.array(checked, dtype=object), attrs=attrs("observable"))}
    ds = xr.Dataset(data, coords=coords)
    ds.attrs.update({"parameter": param, "refinement": hname, "publication_value": publication_value,
                     "tolerance": tol, "status": status, "worst_distance": worst,
                     "notes": "; ".join(f"{k}: {n}" for k, n in zip(checked, notes)),
                     "method": "Richardson extrapolation from the three finest rungs"})
    return ds


def check(ds: xr.Dataset, figure: str, on_inconclusive: str = "fail") -> str:
    """Raise ConvergenceError if the check failed (or was inconclusive and the
    config says that fails too); return a one-line summary otherwise."""
    status = ds.attrs["status"]
    line = (f"{figure}: {ds.attrs['parameter']} = {ds.attrs['publication_value']:g} is "
            + ", ".join(f"{k} {100 * d:.3g} %" for k, d in zip(ds["observable"].values,
                                                                ds["publication_distance"].values))
            + f" from the extrapolated limit (tolerance {100 * ds.attrs['tolerance']:g} %): {status}")
    if status == "fail" or (status.startswith("inconclusive") and on_inconclusive == "fail"):
        raise ConvergenceError(line)
    return line


def time_vs_error(fig_cfg: Mapping[str, Any], sims: Mapping[str, xr.Dataset]) -> xr.Dataset:
    """Wall time and error of every scene against the reference scene's |F_z(L)|."""
    ref_name = fig_cfg["reference"]
    ref = sims[ref_name]
    F_ref = float(ref["F_transmitted"])
    names = [n for n in sims if n != ref_name]
    F = np.array([float(sims[n]["F_transmitted"]) for n in names])
    data = {
        "wall_time": variable(("run",), [float(sims[n]["wall_time"]) for n in names], "wall_time"),
        "F_transmitted": variable(("run",), F, "F_transmitted"),
        "error": variable(("run",), np.maximum(np.abs(F - F_ref) / F_ref, 1e-16), "error"),
        "converged": variable(("run",), [np.int8(sims[n]["converged"]) for n in names], "converged"),
        "n_contact": variable(("run",), [int(sims[n]["contact"].sum()) for n in names], "n_contact"),
    }
    knob = {"explicit": "tol", "implicit": "dx_max"}  # each solver's accuracy knob (explicit: dt is pinned)
    coords = {
        "run": xr.Variable(("run",), np.array(names, dtype=object), attrs=attrs("scene")),
        "solver": xr.Variable(("run",), np.array([sims[n].attrs["solver"] for n in names], dtype=object),
                              attrs=attrs("solver")),
        "run_l0": variable(("run",), [float(sims[n].attrs["l0"]) for n in names], "run_l0"),
        "run_knob": xr.Variable(("run",), np.array([float(sims[n].attrs[knob[sims[n].attrs["solver"]]])
                                                    for n in names]), attrs=attrs("run_knob")),
    }
    ds = xr.Dataset(data, coords=coords)
    ds.attrs.update({"reference": ref_name, "F_reference": F_ref, "reference_wall_time": float(ref["wall_time"]),
                     "reference_solver": ref.attrs["solver"], "reference_l0": float(ref.attrs["l0"]),
                     "reference_knob": f"{knob[ref.attrs['solver']]} = {float(ref.attrs[knob[ref.attrs['solver']]]):g}",
                     "error_definition": "|F_z(L) - F_ref| / F_ref, F_ref from the reference scene: the same rod "
                                         "with the finest numerics of the ladder (see reference_*)",
                     "timing": "wall time of each simulate job, one core per job"})
    return ds
