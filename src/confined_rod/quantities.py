"""The one place that defines each quantity's name, symbol and unit: the scene parameters and the
variables of the scene files (simulations, probes, load paths) here; the quantities that
post-processing derives (figure datasets) in :mod:`confined_rod.analysis.figure_quantities`, which
extends this table (so a new figure quantity re-runs no simulation).

Internal units: lengths in R, forces in EI/R^2, force per length in EI/R^3,
torques in EI/R, time in beta_ph R^4/EI (cylinder radius R, bending stiffness
EI, physical drag coefficient per unit length beta_ph).  A dataset stores the
values in the units of the scene.  Each quantity declares its unit in these reduced
units (``Quantity.units``, e.g. ``"EI R-2"``); what a dataset's CF ``units`` attribute says
follows from the scene's ``unit_system`` (:func:`cf_units`):

- ``reduced`` (default): the numbers are multiples of the reduced unit, so ``units`` is
  dimensionless, ``"1"`` (``"rad"`` for an angle, ``"rad"`` for an angle per reduced length), and
  the reduced unit is named in ``units_reduced``;
- ``SI``: the scene's numbers are SI (R in m, EI in J m, load in N, with the drag per length
  beta_ph = 1 Pa s): ``units`` is the SI unit (``"N"``, ``"m"``, ``"s"``, ``"N m-1"``), and
  ``units_reduced`` still names the combination of R and EI.

No reduced symbol ever reaches ``units``: UDUNITS would read ``R`` as the roentgen.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Any, Iterable

import numpy as np
import xarray as xr

from . import limits


@dataclass(frozen=True)
class Quantity:
    name: str
    symbol: str  # LaTeX, for figure labels
    long_name: str
    units: str  # CF-style unit string in terms of the scene's R and EI
    #: scene parameters only: the JSON-schema type of a config value (the config schema's
    #: scene section is generated from it: python -m confined_rod schema)
    schema: dict[str, Any] | None = field(default=None, compare=False)

    @property
    def choices(self) -> tuple[str, ...]:
        """Allowed values of a categorical scene parameter."""
        return tuple(self.schema["enum"]) if self.schema and "enum" in self.schema else ()


_POS = {"type": "number", "exclusiveMinimum": 0}
_NONNEG = {"type": "number", "minimum": 0}
_POS_OR_DEFAULT = {"type": ["number", "null"], "exclusiveMinimum": 0}  # null: the resolved default
_NONNEG_OR_DEFAULT = {"type": ["number", "null"], "minimum": 0}


#: how a run ends: a simulation's ``status`` (its flag values in this order; ``status_reason`` says why)
RUN_STATUS = ("converged", "time_cap", "escaped", "model_violated", "step_cap")
#: how a stability-map probe ends: its run's status, or "diverged" (the run blew up) or "invalid"
#: (the scene was refused); its flag values in this order
PROBE_STATUS = RUN_STATUS[:3] + ("diverged", "invalid") + RUN_STATUS[3:]


def _param(name, symbol, long_name, units, schema):
    return Quantity(name, symbol, long_name, units, schema)


#: Every field of confined_rod.Scene but its name, declared once: description, symbol,
#: unit and config type. The schema's scene section, the dataset attributes and the
#: parameter symbols of figure titles are derived from this list (tests/test_figures.py
#: checks that they agree with Scene).
SCENE_PARAMETERS = [
    _param("L", "L", "contour length of the rod", "R", _POS),
    _param("R", "R", "radius of the confining cylinder", "R", _POS),
    _param("EI", "EI", "bending stiffness of the rod", "EI", _POS),
    _param("load", "|F_z(0)|", "compressive axial load on the upper end", "EI R-2", _POS),
    _param("k_fr", "k_{fr}", "wall friction coefficient", "1", {**_NONNEG, "maximum": limits.K_FR_MAX}),
    _param("friction_cap", "f_{cap}", "cap on the wall friction force on one link (0 = none)", "EI R-2",
           _NONNEG_OR_DEFAULT),
    _param("body_force", r"\mathbf{f}_{ext}", "external force per unit length (fx, fy, fz) on every link", "EI R-3",
           {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3}),
    _param("pore_length", "z_{entr}", "height of the open pore entrance (default L)", "R", _POS_OR_DEFAULT),
    _param("ends", "", "lateral end condition: free (paper), pinned on the axis, or guided "
           "(free, the loaded end kept within R above the entrance)", "1",
           {"enum": ["free", "pinned", "guided"]}),
    _param("lower_end", "", "lower end held in z (paper) or free", "1", {"enum": ["held", "free"]}),
    _param("floor", "", "the lower piston at z = 0 is a wall for the whole rod", "1", {"type": "boolean"}),
    _param("protocol", "", "start and loading: straight rod + 3-D perturbation at the full load, planar, planar "
           "then 3-D, a quasi-static load ramp (ramp), or a one-handed helix on the wall (helix)", "1",
           {"enum": ["straight", "planar", "planar_then_3d", "ramp", "helix"]}),
    _param("perturbation", "a", "amplitude of the random lateral displacement of the start", "R",
           _NONNEG_OR_DEFAULT),
    _param("kick", "a_{3D}", "out-of-plane perturbation of the second stage of planar_then_3d", "R",
           _NONNEG_OR_DEFAULT),
    _param("ramp_steps", "n_{ramp}", "protocol ramp: number of load steps, geometric from ramp_start times "
           "Euler's load to the load, each relaxed from the last", "1", {"type": "integer", "minimum": 1}),
    _param("ramp_start", "F_1/F_E", "protocol ramp: first load of the ramp over Euler's load pi^2 EI/L^2", "1",
           {"type": "number", "exclusiveMinimum": 1}),
    _param("seed", r"\mathrm{seed}", "random seed of the perturbation", "1",
           {"type": "integer", "minimum": 0, "maximum": limits.SEED_MAX}),
    _param("saddle_kicks", "n_{kick}", "how often a run that stops on a known saddle is kicked by `kick` and relaxed "
           "again; 0: it ends there, flagged", "1", {"type": "integer", "minimum": 0}),
    _param("l0", "l_0", "link length", "R", _POS_OR_DEFAULT),
    _param("k_ph", "k_{ph}", "physical stretching stiffness of the rod (bond constant k = k_ph/l0)", "EI R-2",
           _POS_OR_DEFAULT),
    _param("k_w", "k_w", "wall penalty constant per link end", "EI R-3", _POS_OR_DEFAULT),
    _param("k_t", "k_t", "stick stiffness of the wall friction (a stuck link or link end is held by a tangential "
           "spring to its anchor, rigid stick as k_t -> inf; default k_w/10 with friction at the centre, k_ph/l0 at "
           "the ends)", "EI R-3", _POS_OR_DEFAULT),
    _param("solver", "", "time integrator: implicit (fast default) or explicit (the paper's, reference)", "1",
           {"enum": ["implicit", "explicit"]}),
    _param("dx_max", "dx_{max}", "implicit solver: largest displacement of a link end per step", "R",
           _POS_OR_DEFAULT),
    _param("dt_factor", r"\Delta t/\Delta t_{stab}", "explicit solver: step over the estimated stability limit",
           "1", {"type": "number", "minimum": limits.MIN_DT_FACTOR, "maximum": limits.MAX_DT_FACTOR}),
    _param("tol", r"\mathrm{tol}", "equilibrium tolerance on the normalised force and torque residuals", "1",
           {**_POS, "maximum": limits.TOL_MAX}),
    _param("t_max", "t_{max}", "cap on the simulated time", "beta_ph R4 EI-1", _POS_OR_DEFAULT),
    _param("max_steps", "n_{max}", "cap on the number of time steps (a work budget, the same on every machine); "
           "0: none", "1", {"type": "integer", "minimum": 0}),
    _param("rotational_drag", "", "rotational drag: paper (beta_ph l0 R^2) or rigid_link (beta_ph l0^3/12)", "1",
           {"enum": ["paper", "rigid_link"]}),
    _param("friction_at", "", "where a wall contact's friction acts: ends (each link end on the wall, with its own "
           "normal force and stick anchor; the default) or centre (the link centre, with the link's summed normal "
           "force)", "1",
           {"enum": ["centre", "ends"]}),
    _param("bending_constant", "",
           "joint bending constant: corrected (C = EI/l0) or paper (the printed C = EI/l0^2, i.e. EI R/l0^2)", "1",
           {"enum": ["corrected", "paper"]}),
    _param("snapshot_interval", r"\Delta t_{snap}", "simulated time between stored shapes (0 = none)",
           "beta_ph R4 EI-1", _NONNEG),
    _param("snapshot_growth", "g_{snap}", "growth factor of the snapshot times (1: a fixed interval; g > 1: at 0, "
           "snapshot_interval, then each time the simulated time grows by g)", "1", {"type": "number", "minimum": 1}),
    _param("unit_system", "", "how the scene's numbers are meant, and so the datasets' CF units: reduced (multiples "
           "of the scene's R, EI and beta_ph; units '1', the combination in 'units_reduced') or SI (R in m, EI in J m, "
           "load in N, drag per length beta_ph = 1 Pa s; units 'm', 'N', 's', ...); the computation is the same", "1",
           {"enum": ["reduced", "SI"]}),
]

#: what the scene files (simulations, probes, load paths) store
SIMULATION_VARIABLES = [
    Quantity("s", "s", "arc length from the loaded (upper) end", "R"),
    Quantity("s_link", "s", "arc length of the link centre from the loaded end", "R"),
    Quantity("s_helix", "s", "arc length of the link centre from the loaded end, on the wall-contact stretch", "R"),
    Quantity("t", "t", "simulated time", "beta_ph R4 EI-1"),
    Quantity("x", "x", "x coordinate of the link centre", "R"),
    Quantity("y", "y", "y coordinate of the link centre", "R"),
    Quantity("z", "z", "z coordinate (cylinder axis) of the link centre", "R"),
    Quantity("tx", "t_x", "x component of the unit tangent", "1"),
    Quantity("ty", "t_y", "y component of the unit tangent", "1"),
    Quantity("tz", "t_z", "z component of the unit tangent", "1"),
    Quantity("F_z", "F_z", "axial force transmitted through the joint (negative = compression)", "EI R-2"),
    Quantity("F_transmitted", "|F_z(L)|",
             "compressive force transmitted to the lower piston (support of the lower end + floor contacts)",
             "EI R-2"),
    Quantity("L_z", "L_z", "projection of the rod on the cylinder axis", "R"),
    Quantity("wall_force", "N", "magnitude of the wall normal force on the link", "EI R-2"),
    Quantity("wall_force_density", "K", "wall normal force per unit length (N/l0)", "EI R-3"),
    Quantity("contact", "", "link touches the wall (1) or not (0)", "1"),
    Quantity("friction_force", "f", "magnitude of the wall friction force on the link", "EI R-2"),
    Quantity("friction_z", "f_z", "axial component of the wall friction force on the link", "EI R-2"),
    Quantity("saddle", "", "the converged state is a known saddle (unstable equilibrium): straight above Euler's "
             "load, or planar and frictionless above the second threshold", "1"),
    Quantity("face_force", "f_{top}", "z force of the block's top face around the pore entrance on the link "
             "(a rod bent out of an open entrance rests on it)", "EI R-2"),
    Quantity("body_force_z", "F_{body,z}", "z component of the body force on the whole rod (body_force_z L)",
             "EI R-2"),
    Quantity("axial_balance", r"\Delta F_z", "axial force balance of the rod: load - F_transmitted - sum f_z - sum "
             "f_top - F_body,z (all z forces up positive; 0 at equilibrium, up to the residual)", "EI R-2"),
    Quantity("friction_phi", r"f_\varphi", "azimuthal wall friction on the link: its axial torque about the pore "
             "axis over the link centre's distance rho from it (the azimuthal component along e_z x r with "
             "friction at the centre; positive counter-clockwise seen from the loaded end's side, +z)", "EI R-2"),
    Quantity("stuck", "", "link in static friction (1) or sliding/free (0)", "1"),
    Quantity("phi", r"\phi", "azimuth of the link centre (unwrapped) along the wall-contact stretch", "rad"),
    Quantity("dphi_ds", r"d\phi/ds", "azimuthal rate along the wall-contact stretch", "rad R-1"),
    Quantity("converged", "", "run reached the residual-based equilibrium criterion", "1"),
    Quantity("escaped", "", "rod left the pore through the open entrance", "1"),
    Quantity("status", "", f"how the run ended: {', '.join(RUN_STATUS[:-1])} or {RUN_STATUS[-1]} (reason in the "
             "attribute 'reason')", "1"),
    Quantity("residual_force", r"\epsilon_F", "final normalised force residual max|F_i| L/(l0 load)", "1"),
    Quantity("residual_torque", r"\epsilon_M", "final normalised torque residual max|M_i| L/(l0 load R)", "1"),
    Quantity("t_final", "t_{end}", "simulated time at the end of the run", "beta_ph R4 EI-1"),
    Quantity("n_steps", "", "number of time steps taken", "1"),
    Quantity("has_force", "", "1 if the run produced a transmitted force (F_transmitted is 0 otherwise)", "1"),
    Quantity("wall_time", "t_{wall}", "wall-clock time of the run", "s"),
    Quantity("n_contact", "n_{wall}", "number of links touching the wall", "1"),
    Quantity("scene", "", "scene id in the config", "1"),
    Quantity("tol_effective", r"\mathrm{tol}_{eff}", "equilibrium tolerance used (tol or the round-off floor)", "1"),
    # load paths and thresholds (Fig 3)
    Quantity("deflection", r"\delta", "largest distance of a link centre from the chord through the end centres",
             "R"),
    Quantity("out_of_plane", r"\delta_\perp", "rms distance of the link centres from their best-fitting plane",
             "R"),
    Quantity("state_class", "", "shape of the equilibrium: straight, planar (buckled in a plane) or three_d", "1"),
    Quantity("threshold", "", "threshold: first (straight to buckled) or second (planar to 3-D)", "1"),
    Quantity("threshold_lo", "F_{lo}", "largest load found below the threshold (bisection)", "EI R-2"),
    Quantity("threshold_hi", "F_{hi}", "smallest load found above the threshold (bisection)", "EI R-2"),
    Quantity("threshold_runs", "", "runs the bisection took", "1"),
    Quantity("run", "", "how the sweep was run: up or down (continuation from the previous load) or fresh", "1"),
    Quantity("snap_stage", "", "stage of the protocol the snapshot belongs to (0 planar, 1 three-dimensional)", "1"),
    Quantity("state", "", "state of a transition run: final, or after reducing the load (reduced_<fraction>)", "1"),
    Quantity("in_stretch", "", "link lies on the wall-contact stretch (first to last link touching the wall)", "1"),
    # Fig 8: fold and escape
    Quantity("escaped_above", "", "the run just above the threshold left the pore (1) or folded inside it (0)", "1"),
    Quantity("outside_radius", r"\rho_{out}", "largest distance from the axis of a link end above the pore "
             "entrance (0 if none; beyond R the rod has left the pore)", "R"),
    Quantity("free_span", "g", "free span: length of rod above the pore entrance at the start, between the "
             "guided loaded end and the entrance", "R"),
    Quantity("snap_x", "x", "x coordinate of the link centre (snapshot)", "R"),
    Quantity("snap_y", "y", "y coordinate of the link centre (snapshot)", "R"),
    Quantity("snap_z", "z", "z coordinate of the link centre (snapshot)", "R"),
    Quantity("snap_F_z", "F_z", "axial force transmitted through the joint (snapshot)", "EI R-2"),
    Quantity("snap_wall_force", "N", "magnitude of the wall normal force on the link (snapshot)", "EI R-2"),
    Quantity("snap_friction_z", "f_z", "axial component of the wall friction force on the link (snapshot)",
             "EI R-2"),
    Quantity("snap_friction_phi", r"f_\varphi", "azimuthal wall friction on the link, as friction_phi "
             "(snapshot)", "EI R-2"),
]


_PRETTY_UNITS = {"R": "R", "EI R-2": "EI/R^2", "EI R-3": "EI/R^3", "rad R-1": "1/R", "R-1": "1/R",
                 "beta_ph R4 EI-1": r"\beta_{ph} R^4/EI", "R EI-1": "R/EI", "1": "", "rad": "rad", "EI": "EI", "s": "s"}


def pretty_unit(units: str) -> str:
    """LaTeX form of a CF unit string of this package ('EI R-2' -> 'EI/R^2')."""
    return _PRETTY_UNITS.get(units, units)


#: how a scene's numbers are meant (Scene.unit_system): reduced (R = EI = beta_ph = 1 units of the
#: scene's own R and EI) or SI (R in m, EI in J m, load in N, beta_ph = 1 Pa s)
UNIT_SYSTEMS = ("reduced", "SI")
#: the reduced units' symbols, as SI base-unit exponents (kg, m, s): R a length, EI = J m, beta_ph = Pa s
_REDUCED_BASES = {"R": (0, 1, 0), "EI": (1, 3, -2), "beta_ph": (1, -1, -1)}
#: SI names of the dimensions (kg, m, s exponents) the package's quantities have
_SI_NAMES = {(0, 0, 0): "1", (0, 1, 0): "m", (0, -1, 0): "m-1", (0, 0, 1): "s", (1, 1, -2): "N",
             (1, 0, -2): "N m-1", (1, -1, -2): "N m-2", (1, 2, -2): "N m", (1, 3, -2): "J m",
             (-1, -1, 2): "N-1", (-1, -2, 2): "N-1 m-1"}
_TOKEN = re.compile(r"([A-Za-z_]+?|1)(-?\d+|-[a-z]+)?")
#: a unit with no fixed dimension: the covariance of parameters of different units
MIXED = "mixed"


def _tokens(units: str) -> list[tuple[str, int | str]]:
    out: list[tuple[str, int | str]] = []
    for tok in units.split():
        m = _TOKEN.fullmatch(tok)
        if m is None:
            raise ValueError(f"unit {units!r}: cannot read {tok!r}")
        exp = m.group(2) or "1"
        out.append((m.group(1), int(exp) if exp.lstrip("-").isdigit() else exp))
    return out


def is_reduced(units: str) -> bool:
    """True if a unit string names a reduced unit (a combination of R, EI, beta_ph, or 'mixed')."""
    return units == MIXED or any(base in _REDUCED_BASES for base, _ in _tokens(units))


def cf_units(units: str, system: str = "reduced") -> str:
    """The CF (UDUNITS) unit of a quantity whose reduced unit is ``units``, in a scene of
    ``system``: ``cf_units("EI R-2") == "1"``, ``cf_units("EI R-2", "SI") == "N"``,
    ``cf_units("rad R-1") == "rad"``, ``cf_units("rad R-1", "SI") == "rad m-1"``; units with no
    reduced symbol ("1", "rad", "s" of a wall time) are returned as they are.  A unit with a
    symbolic exponent (the fit prefactor A of A (l0' + s)^c: "EI R-2 R-c") or 'mixed' (a
    covariance of parameters of different units) has no CF unit: "1", with the reduced unit
    kept in ``units_reduced``."""
    if system not in UNIT_SYSTEMS:
        raise ValueError(f"unit system {system!r}: must be one of {', '.join(UNIT_SYSTEMS)}")
    if units == MIXED:
        return "1"
    tokens = _tokens(units)
    if not any(base in _REDUCED_BASES for base, _ in tokens):
        return units
    if any(isinstance(e, str) for _, e in tokens):
        return "1"
    rest = [b if e == 1 else f"{b}{e}" for b, e in tokens if b not in _REDUCED_BASES and b != "1"]
    if system == "reduced":
        return " ".join(rest) or "1"
    dims = np.zeros(3, dtype=int)
    for base, exp in tokens:
        if base in _REDUCED_BASES:
            dims += int(exp) * np.array(_REDUCED_BASES[base])
    key = tuple(int(d) for d in dims)
    si = _SI_NAMES.get(key) or " ".join(f"{b}{e if e != 1 else ''}" for b, e in zip(("kg", "m", "s"), key) if e)
    return " ".join(([] if si == "1" else [si]) + rest) or "1"


def cf_attrs(units: str, system: str = "reduced") -> dict[str, str]:
    """The CF unit attributes of a variable whose reduced unit is ``units``: ``units`` and, when
    it differs, ``units_reduced`` (the combination of R, EI and beta_ph)."""
    cf = cf_units(units, system)
    return {"units": cf} if cf == units else {"units": cf, "units_reduced": units}


def apply_unit_system(ds: xr.Dataset, system: str = "reduced") -> xr.Dataset:
    """Give every variable of ``ds`` whose ``units`` is still a reduced unit (as the tables and
    the figure kinds write them) its CF units for ``system`` (in place; returns ``ds``)."""
    for var in ds.variables.values():
        units = var.attrs.get("units")
        if isinstance(units, str) and "units_reduced" not in var.attrs and is_reduced(units):
            var.attrs.update(cf_attrs(units, system))
    return ds


class Table(dict):
    """Quantities by name, with what the datasets and figures take from them."""

    def __init__(self, quantities: Iterable[Quantity]):
        quantities = list(quantities)
        super().__init__((q.name, q) for q in quantities)
        if len(self) != len(quantities):
            seen: set[str] = set()
            twice = [q.name for q in quantities if q.name in seen or seen.add(q.name)]
            raise ValueError(f"quantities declared twice: {', '.join(twice)}")

    def extended(self, quantities: Iterable[Quantity]) -> "Table":
        """This table and more quantities (none of them already declared)."""
        return Table([*self.values(), *quantities])

    def attrs(self, name: str) -> dict[str, str]:
        """CF attributes (units, long_name) of a quantity."""
        q = self[name]
        return {"units": q.units, "long_name": q.long_name}

    def error_attrs(self, name: str) -> dict[str, str]:
        """CF attributes of the standard error of a quantity."""
        q = self[name]
        return {"units": q.units, "long_name": f"standard error of the {q.long_name}"}

    def variable(self, dims, data, name: str) -> xr.Variable:
        """A dataset variable with the quantity's CF attributes."""
        return xr.Variable(dims, np.asarray(data), attrs=self.attrs(name))

    def label(self, name: str, unit_text: str | None = None) -> str:
        """Axis label, e.g. ``$|F_z(L)|$ [$EI/R^2$]`` (for figures)."""
        q = self[name]
        u = unit_text if unit_text is not None else pretty_unit(q.units)
        sym = f"${q.symbol}$" if q.symbol else q.long_name
        return f"{sym} [${u}$]" if u else sym

    def param_text(self, name: str, value: float) -> str:
        """'$k_{fr} = 0.8$', '$L = 320\\,R$': a parameter value for a figure title."""
        q = self[name]
        u = pretty_unit(q.units)
        sym = q.symbol or q.name.replace("_", r"\_")
        return f"${sym} = {value:g}" + (rf"\,{u}$" if u else "$")


#: the scene parameters and the scene files' variables (the figure datasets' quantities:
#: confined_rod.analysis.figure_quantities.QUANTITIES)
QUANTITIES = Table(SCENE_PARAMETERS + SIMULATION_VARIABLES)
attrs, error_attrs, variable = QUANTITIES.attrs, QUANTITIES.error_attrs, QUANTITIES.variable
label, param_text = QUANTITIES.label, QUANTITIES.param_text
