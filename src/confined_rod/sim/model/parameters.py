"""Discrete constants from continuum ones (derivation in docs/model.md).

Bending:   E_b = (EI/2) int |dt/ds|^2 ds  ->  sum_joints C (1 - t_i.t_{i+1}),
           with |t_{i+1}-t_i|^2 = 2(1 - t_i.t_{i+1}) and dt/ds ~ (t_{i+1}-t_i)/l0:
           C = EI / l0          (a torque; the paper's C = EI/l0^2 is a force)
           bending_constant='paper' reproduces the paper's formula in its units R = 1:
           C = EI R / l0^2, the corrected constant of a rod of stiffness EI R/l0
Bonds:     E_s = (k_ph/2) int eps^2 ds, gap = eps l0 per link:  k = k_ph / l0
Drag:      translation  beta  = beta_ph l0
           rotation     gamma_r = beta_ph l0^3 / 12   ("rigid_link": a straight
           segment turning about its centre in a fluid of drag beta_ph per length)
           or gamma_r = beta_ph l0 R^2 ("paper": the paper's Eq. (rot) uses beta
           for both; R^2 restores the dimension of a rotational drag).
Equilibria do not depend on beta or gamma_r; only the path does.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

BETA_PH = 1.0  # physical drag per unit length: the unit of time


@dataclass(frozen=True)
class DiscreteConstants:
    N: int  # number of links
    C: float  # bending couple constant [EI/R]
    k: float  # bond constant [EI/R^3]
    k_support: float  # stiffness of the z support / lateral pins [EI/R^3]
    beta: float  # translational drag per link
    gamma_r: float  # rotational drag per link
    dt_stable: float  # estimated explicit-Euler stability limit


def discrete_constants(L: float, R: float, EI: float, l0: float, k_ph: float, k_w: float,
                       rotational_drag: str = "paper", bending_constant: str = "corrected",
                       k_t_ends: float = 0.0) -> DiscreteConstants:
    N = int(round(L / l0))
    C = EI / l0 if bending_constant == "corrected" else EI * R / l0**2
    k = k_ph / l0
    beta = BETA_PH * l0
    if rotational_drag == "rigid_link":
        gamma_r = BETA_PH * l0**3 / 12.0
    else:
        gamma_r = BETA_PH * l0 * R * R
    # Gershgorin bound on the largest eigenvalue of (mobility x Hessian) about a
    # straight rod pressed against the wall (docs/model.md, "time step"):
    #   translation row: (4 k + 2 k_w)/beta + k l0/sqrt(beta gamma_r)
    #   rotation row:    (k l0^2 + 4 C + k_w l0^2/2)/gamma_r + k l0/sqrt(beta gamma_r)
    # and, with friction at the link ends (k_t_ends > 0: a stick spring at each end, arm l0/2),
    #   translation row: + 2 k_t/beta + (k_t l0/2)/sqrt(beta gamma_r)   (one end stuck: no cancelling)
    #   rotation row:    + (k_t l0^2/2)/gamma_r + (k_t l0/2)/sqrt(beta gamma_r)
    cross = (k * l0 + 0.5 * k_t_ends * l0) / math.sqrt(beta * gamma_r)
    lam_t = (4.0 * k + 2.0 * k_w + 2.0 * k_t_ends) / beta + cross
    lam_r = (k * l0**2 + 4.0 * C + 0.5 * k_w * l0**2 + 0.5 * k_t_ends * l0**2) / gamma_r + cross
    lam = max(lam_t, lam_r)
    return DiscreteConstants(N=N, C=C, k=k, k_support=k, beta=beta, gamma_r=gamma_r,
                             dt_stable=2.0 / lam)
