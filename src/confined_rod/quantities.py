"""The one place that defines each quantity's name, symbol and unit.

Internal units: lengths in R, forces in EI/R^2, force per length in EI/R^3,
torques in EI/R, time in beta_ph R^4/EI (cylinder radius R, bending stiffness
EI, physical drag coefficient per unit length beta_ph).  A dataset stores the
values in the units of the scene (a scene with R = 2e-6 m and EI = 1e-21 J m
stores lengths in metres); ``units`` then names the combination of R and EI.
"""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Quantity:
    name: str
    symbol: str  # LaTeX, for figure labels
    long_name: str
    units: str  # CF-style unit string in terms of the scene's R and EI


_Q = [
    Quantity("L", "L", "contour length of the rod", "R"),
    Quantity("R", "R", "radius of the confining cylinder", "R"),
    Quantity("EI", "EI", "bending stiffness of the rod", "EI"),
    Quantity("load", "|F_z(0)|", "compressive axial load on the upper end", "EI R-2"),
    Quantity("k_fr", "k_{fr}", "wall friction coefficient", "1"),
    Quantity("l0", "l_0", "link length", "R"),
    Quantity("k_ph", "k_{ph}", "physical stretching stiffness of the rod (bond constant k = k_ph/l0)", "EI R-2"),
    Quantity("k_w", "k_w", "wall penalty constant per link end", "EI R-3"),
    Quantity("s", "s", "arc length from the loaded (upper) end", "R"),
    Quantity("s_link", "s", "arc length of the link centre from the loaded end", "R"),
    Quantity("s_helix", "s", "arc length of the link centre from the loaded end", "R"),
    Quantity("time", "t", "simulated time", "beta_ph R4 EI-1"),
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
    Quantity("stuck", "", "link in static friction (1) or sliding/free (0)", "1"),
    Quantity("phi", r"\phi", "azimuth of the link centre (unwrapped) along the wall-contact stretch", "rad"),
    Quantity("dphi_ds", r"d\phi/ds", "azimuthal rate along the wall-contact stretch", "rad R-1"),
    Quantity("converged", "", "run reached the residual-based equilibrium criterion", "1"),
    Quantity("escaped", "", "rod left the pore through the open entrance", "1"),
    Quantity("residual_force", r"\epsilon_F", "final normalised force residual max|F_i| L/(l0 load)", "1"),
    Quantity("residual_torque", r"\epsilon_M", "final normalised torque residual max|M_i| L/(l0 load R)", "1"),
    Quantity("t_final", "t_{end}", "simulated time at the end of the run", "beta_ph R4 EI-1"),
    Quantity("n_steps", "", "number of time steps taken", "1"),
    Quantity("has_force", "", "1 if the run produced a transmitted force (F_transmitted is 0 otherwise)", "1"),
    Quantity("wall_time", "t_{wall}", "wall-clock time of the run", "s"),
    # derived (per-figure datasets)
    Quantity("F_abs", "|F_z|", "magnitude of the axial (compressive) force", "EI R-2"),
    Quantity("n_contact", "n_{wall}", "number of links touching the wall", "1"),
    Quantity("n_turns", "n_{turns}", "turns of the wall-contact stretch about the axis |phi_end - phi_start|/(2 pi)",
             "1"),
    Quantity("L_model", "L", "contour length of the rod (analytic curve)", "R"),
    Quantity("F_simple", "|F_z|", "axial force of the simple helix model, corrected: K = R F^2/(4 EI)", "EI R-2"),
    Quantity("F_simple_paper", "|F_z|", "axial force of the simple helix model as printed: K = R F^2/(2 EI)",
             "EI R-2"),
    Quantity("F_fit", "f", "power-law fit A (l0' + s)^c of |F_z(s)|", "EI R-2"),
    Quantity("in_fit", "", "joint inside the fit window (1) or not (0)", "1"),
    Quantity("fit_A", "A", "prefactor A of the fit A (l0' + s)^c", "EI R-2 R-c"),
    Quantity("fit_l0", "l_0'", "offset l0' of the fit A (l0' + s)^c", "R"),
    Quantity("fit_c", "c", "exponent c of the fit A (l0' + s)^c", "1"),
    Quantity("fit_cov", "", "covariance of the fit parameters (A, l0', c)", "mixed"),
    Quantity("fit_rms", "", "rms relative residual of the fit in its window", "1"),
    Quantity("s_h", "s_h", "arc length of the first link touching the wall (start of the helix)", "R"),
    Quantity("s_end", "s_e", "arc length of the last link touching the wall", "R"),
    Quantity("panel_value", "", "value of the parameter that differs between the panels", "1"),
    Quantity("n_fit", "", "number of joints in the fit window", "1"),
    Quantity("scene", "", "scene id in the config", "1"),
    Quantity("panel", "", "panel (scene id in the config)", "1"),
    Quantity("param", "", "fit parameter", "1"),
    Quantity("pitch", "P", "bulk pitch of the helix, 2 pi |dz/dphi| over the middle half of the contact stretch", "R"),
    Quantity("value", "", "value of the refined parameter", "1"),
    Quantity("h", "h", "refinement variable (l0, 1/k_ph, 1/k_w or tol)", "1"),
    Quantity("observable", "", "observable of the convergence check", "1"),
    Quantity("observed_order", "p", "observed order of convergence (Richardson, three finest rungs)", "1"),
    Quantity("publication_distance", "", "relative distance of the publication setting from the limit", "1"),
    Quantity("error", r"\epsilon", "relative error of |F_z(L)| against the reference run", "1"),
    Quantity("solver", "", "time integrator", "1"),
    Quantity("run_l0", "l_0", "link length of the run", "R"),
    Quantity("run_knob", "", "accuracy knob of the run: tol (explicit) or dx_max in R (implicit)", "1"),
    Quantity("snap_x", "x", "x coordinate of the link centre (snapshot)", "R"),
    Quantity("snap_y", "y", "y coordinate of the link centre (snapshot)", "R"),
    Quantity("snap_z", "z", "z coordinate of the link centre (snapshot)", "R"),
]

QUANTITIES: dict[str, Quantity] = {q.name: q for q in _Q}


def attrs(name: str) -> dict[str, str]:
    """CF attributes (units, long_name) of a quantity."""
    q = QUANTITIES[name]
    return {"units": q.units, "long_name": q.long_name}


def error_attrs(name: str) -> dict[str, str]:
    """CF attributes of the standard error of a quantity."""
    q = QUANTITIES[name]
    return {"units": q.units, "long_name": f"standard error of the {q.long_name}"}


def label(name: str, unit_text: str | None = None) -> str:
    """Axis label, e.g. ``$|F_z(L)|$ [$EI/R^2$]`` (for figures)."""
    q = QUANTITIES[name]
    pretty = {"R": "R", "EI R-2": "EI/R^2", "EI R-3": "EI/R^3", "rad R-1": "1/R",
              "beta_ph R4 EI-1": r"\beta_{ph} R^4/EI", "1": "", "rad": "rad", "EI": "EI", "s": "s"}
    u = unit_text if unit_text is not None else pretty.get(q.units, q.units)
    sym = f"${q.symbol}$" if q.symbol else q.long_name
    return f"{sym} [${u}$]" if u else sym
