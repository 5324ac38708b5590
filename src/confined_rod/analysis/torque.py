"""The axial torque budget along a confined rod, and what it does to the helix.

The rod has no twist stiffness, so its internal moment is the bending moment
m = EI t x t' (t the unit tangent, ' = d/ds). Cut the rod at s: the part above the cut (the
loaded end, s' < s) is held by the internal force n(s) and moment m(s) exerted on it by the
part below. About the cylinder axis (z) its only other torques are those of the wall
friction: the wall's normal force is radial and the load acts along z, so neither has an
axial torque. The axial torque carried through the rod at s is therefore

    tau(s) = [r x n + m]_z (s) = - Gamma(s),   Gamma(s) = sum over links above s of rho f_phi,

with rho the distance of a link centre from the axis and f_phi the azimuthal component of
the friction on it (quantities.py: friction_phi). With both ends free to turn about the axis
(no torque from the loaded end's piston or the lower support), Gamma(L) = 0 in equilibrium:
the budget closes over the whole rod (``closure`` below measures it).

A helix of constant pitch rate w = dphi/ds on a cylinder of radius rho (c = dz/ds =
sqrt(1 - rho^2 w^2)) under the axial force |F_z| = F carries, from the Kirchhoff equations
m' + t x n = 0, n' + f_wall = 0 with n = F e_z + S e_phi (derived in docs/model.md, "The axial
torque budget"):

    tau = EI rho^2 w^3 + rho S                       (bending + the shear force's lever arm)
    F   = c (2 EI w^2 - tau / (rho^2 w))              (the helix relation with torque)
    K   = (EI rho^2 w^4 - w tau) / rho               (its wall force per length)

With tau = 0 (a torque-free helix) these are the relations of docs/model.md, F = 2 EI w^2 c and
K = EI rho w^4 ~ rho F^2/(4EI) (the corrected simple model). The helix's own torque,
``helix_torque`` = rho^2 w (2 EI w^2 - F/c), read from its local pitch and force, and the torque
the friction left in the rod, -Gamma(s), are two independent measurements of the same tau: where
they agree the budget closes locally, and tau says how far the helix is from torque-free, i.e.
why its pitch and wall force, and with them the decay rate of the force, differ from the
simple model's.

Eliminating tau, K = R w^2 (F/c - EI w^2): at a given force the wall force is largest, R F^2/(4EI)
to lowest order, at w^2 = F/(2EI), the torque-free helix; a torque of either sign moves the pitch
off that optimum and lowers the wall force, and with it the decay rate of the force.

Scale: tau_0 = EI R^2 w0^3 with w0 = sqrt(F/(2EI)), the bending torque of a torque-free helix
at the local force; tau sign(w)/tau_0 is 0 for a torque-free helix, (2/c)^(3/2) ~ 2.8 for a helix
that carries all of its bending torque (no shear force: F = EI w^2 c, and K = 0 to this order),
and negative when the torque opposes the handedness (the helix wound against its own sense). The
relation between F and w is double-valued for tau sign(w) < 0: the torque does not fix the pitch;
the loading path selects the branch.

Post-processing: reads datasets only and never imports the simulator; every function works
on plain arrays (tests/test_torque.py), links ordered from the loaded end (s = 0).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import xarray as xr

W_MAX = np.sqrt(2.0 / 3.0)  # R |w| of the steepest helix on the wall (pitch_profile.W_MAX)


def carried_torque(rho: np.ndarray, f_phi: np.ndarray) -> np.ndarray:
    """tau = -Gamma at the link centres (links from the loaded end): minus the axial torque
    of the friction on every link above, and half of the link's own."""
    tq = np.asarray(rho, dtype=float) * np.asarray(f_phi, dtype=float)
    return -(np.cumsum(tq) - 0.5 * tq)


def helix_torque(rho: np.ndarray, w: np.ndarray, F: np.ndarray, EI: float) -> np.ndarray:
    """tau of a helix of local radius rho, pitch rate w and axial force F = |F_z|:
    rho^2 w (2 EI w^2 - F/c), c = sqrt(1 - rho^2 w^2) (0 where rho |w| >= 1)."""
    rho, w, F = (np.asarray(v, dtype=float) for v in (rho, w, F))
    c2 = 1.0 - rho**2 * w**2
    c = np.sqrt(np.where(c2 > 0, c2, 1.0))
    return np.where(c2 > 0, rho**2 * w * (2.0 * EI * w**2 - F / c), 0.0)


def helix_force(rho, w, tau, EI: float):
    """F = c (2 EI w^2 - tau/(rho^2 w)): the axial force a helix with torque tau carries."""
    rho, w, tau = (np.asarray(v, dtype=float) for v in (rho, w, tau))
    return np.sqrt(1.0 - rho**2 * w**2) * (2.0 * EI * w**2 - tau / (rho**2 * w))


def helix_wall_force(rho, w, tau, EI: float):
    """K = (EI rho^2 w^4 - w tau)/rho: wall force per length of a helix with torque tau."""
    rho, w, tau = (np.asarray(v, dtype=float) for v in (rho, w, tau))
    return (EI * rho**2 * w**4 - w * tau) / rho


def helix_wall_force_at_force(rho, w, F, EI: float):
    """K = rho w^2 (F/c - EI w^2), c = sqrt(1 - rho^2 w^2): the wall force per length of a helix
    of pitch rate w carrying the axial force F, whatever its torque (helix_force solved for tau and
    put into helix_wall_force; derivations.helix_with_torque). To lowest order in rho w, with
    x = w/w0, w0^2 = F/(2EI): K/(rho F^2/(4EI)) = x^2 (2 - x^2), largest (1) at the torque-free
    pitch x = 1 (derivations.wall_force_pitch_relation)."""
    rho, w, F = (np.asarray(v, dtype=float) for v in (rho, w, F))
    return rho * w**2 * (F / np.sqrt(1.0 - rho**2 * w**2) - EI * w**2)


def torque_scale(F, R: float, EI: float):
    """tau_0 = EI R^2 w0^3, w0 = sqrt(F/(2EI)): the bending torque of a torque-free helix."""
    return EI * R**2 * (np.asarray(F, dtype=float) / (2.0 * EI)) ** 1.5


#: the scalars of bulk_summary (quantities.py names)
SUMMARY_KEYS = ("torque_friction_ratio", "torque_helix_ratio", "torque_budget_residual", "pitch_w0_ratio", "K_ratio",
                "K_ratio_from_torque", "K_ratio_from_pitch")


@dataclass(frozen=True)
class Budget:
    """The axial torque along one rod (link centres from the loaded end)."""
    tau_friction: np.ndarray    # -Gamma(s): torque the wall friction left in the rod
    tau_helix: np.ndarray       # the torque the local helix carries (0 off the helix)
    on_helix: np.ndarray        # links where the helix's torque is defined
    tau0: np.ndarray            # EI R^2 w0^3 at the local force
    w: np.ndarray               # pitch rate dphi/ds (0 off the contact stretch)
    closure: float              # |Gamma(L)| / sum |rho f_phi| (0: the budget closes)


def link_values(sim: xr.Dataset) -> dict[str, np.ndarray]:
    """Per link from the loaded end: rho, |F_z| (mean of the two joints), w (0 off the
    contact stretch) and f_phi."""
    x, y = np.asarray(sim["x"].values, dtype=float), np.asarray(sim["y"].values, dtype=float)
    Fz = np.abs(np.asarray(sim["F_z"].values, dtype=float))
    s_link = np.asarray(sim["s_link"].values, dtype=float)
    w = np.zeros(s_link.size)
    s_h = np.asarray(sim["s_helix"].values, dtype=float)
    if s_h.size:
        w[np.searchsorted(s_link, s_h)] = np.asarray(sim["dphi_ds"].values, dtype=float)
    return {"rho": np.hypot(x, y), "F": 0.5 * (Fz[1:] + Fz[:-1]), "w": w,
            "f_phi": np.asarray(sim["friction_phi"].values, dtype=float)}


def budget(sim: xr.Dataset) -> Budget:
    """The torque budget of one scene dataset (results/sims/...)."""
    a = sim.attrs
    R, EI = float(a["R"]), float(a["EI"])
    v = link_values(sim)
    rho, w = v["rho"], v["w"]
    on = (np.asarray(sim["contact"].values) > 0) & (w != 0) & (R * np.abs(w) < W_MAX)
    tq = rho * v["f_phi"]
    total = float(np.abs(tq).sum())
    return Budget(tau_friction=carried_torque(rho, v["f_phi"]),
                  tau_helix=np.where(on, helix_torque(rho, w, v["F"], EI), 0.0), on_helix=on,
                  tau0=torque_scale(v["F"], R, EI), w=w,
                  closure=abs(float(tq.sum())) / total if total > 0 else 0.0)


def handedness(b: Budget, where: np.ndarray) -> float:
    """+1 or -1: the sign of the median pitch rate of the links on the helix within ``where``
    (a boolean mask over links), +1 if there are none."""
    w = b.w[np.asarray(where, dtype=bool) & b.on_helix]
    return float(np.sign(np.median(w))) if w.size and np.median(w) != 0 else 1.0


def bulk_summary(sim: xr.Dataset, bulk: np.ndarray, b: Budget | None = None) -> dict[str, float]:
    """Medians over the links of the bulk (a boolean mask over links) that are on the helix:
    the carried torque from the friction and from the helix over tau_0 (signed with the
    handedness), the pitch rate over the torque-free w0, and the wall force per length over
    the corrected simple model's R F^2/(4EI) (measured, and predicted from the local pitch
    and the friction's torque); and the two torques compared link by link,
    |tau_friction - tau_helix| / (tau_0 + |tau_friction|) (its median: a reversal of handedness
    or another defect inside the bulk, where the uniform helix's torque does not hold, moves
    the two medians apart but not this one). Zeros if no bulk link is on the helix."""
    b = b or budget(sim)
    keys = SUMMARY_KEYS
    m = np.asarray(bulk, dtype=bool) & b.on_helix & (b.tau0 > 0)
    if m.sum() < 3:
        return dict.fromkeys(keys, 0.0)
    a = sim.attrs
    R, EI, l0 = float(a["R"]), float(a["EI"]), float(a["l0"])
    v = link_values(sim)
    rho, w, F = v["rho"][m], b.w[m], v["F"][m]
    sgn = np.sign(w)
    bulk = np.asarray(bulk, dtype=bool)
    K_model = R * v["F"][bulk] ** 2 / (4.0 * EI)     # over the whole bulk, on the wall or not
    K_meas = np.asarray(sim["wall_force"].values, dtype=float)[bulk] / l0
    K_pred = helix_wall_force(rho, w, b.tau_friction[m], EI)
    return {"torque_friction_ratio": float(np.median(sgn * b.tau_friction[m] / b.tau0[m])),
            "torque_helix_ratio": float(np.median(sgn * b.tau_helix[m] / b.tau0[m])),
            "torque_budget_residual": float(np.median(np.abs(b.tau_friction[m] - b.tau_helix[m])
                                                      / (b.tau0[m] + np.abs(b.tau_friction[m])))),
            "pitch_w0_ratio": float(np.median(np.abs(w) / np.sqrt(F / (2.0 * EI)))),
            "K_ratio": float(np.mean(K_meas) / np.mean(K_model)),
            "K_ratio_from_torque": float(np.mean(K_pred) / np.mean(R * F**2 / (4.0 * EI))),
            "K_ratio_from_pitch": float(np.mean(helix_wall_force_at_force(rho, w, F, EI))
                                        / np.mean(R * F**2 / (4.0 * EI)))}
