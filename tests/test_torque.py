"""The axial torque budget (confined_rod.analysis.torque) on constructed rods whose torque is known.

A helix of constant radius and pitch rate is given an axial torque profile tau(s) that is zero
at both ends (both ends free to turn) and is not symmetric, so that a budget summed from the
wrong end, or with the wrong sign, gives a different profile. The friction's azimuthal
component is what changes the torque (rho f_phi = -dtau per link), and the axial force is
the one the helix relation gives for that torque, so both measurements must return tau.
"""
from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from confined_rod.analysis import torque

L, L0, EI, RHO, W = 60.0, 0.5, 1.0, 0.9, -0.3
N = int(L / L0)


def tau_profile(s):
    """0 at both ends, rising over the first 40 R and falling over the last 20 R."""
    return np.where(s < 40.0, 0.004 * s / 40.0, 0.004 * (L - s) / 20.0)


def constructed_helix() -> xr.Dataset:
    s = np.arange(N + 1) * L0
    s_link = (np.arange(N) + 0.5) * L0
    tau_joint = tau_profile(s)
    tau_link = tau_profile(s_link)
    # the torque changes across a link by minus the friction's axial torque on it
    f_phi = -(tau_joint[1:] - tau_joint[:-1]) / RHO
    F_joint = torque.helix_force(RHO, W, tau_joint, EI)   # linear in tau: the link mean is exact
    phi = W * s_link
    c = np.sqrt(1 - RHO**2 * W**2)
    return xr.Dataset(
        {"x": (("s_link",), RHO * np.cos(phi)), "y": (("s_link",), RHO * np.sin(phi)),
         "z": (("s_link",), L - c * s_link), "F_z": (("s",), -F_joint),
         "friction_phi": (("s_link",), f_phi), "contact": (("s_link",), np.ones(N, dtype=np.int8)),
         "wall_force": (("s_link",), torque.helix_wall_force(RHO, W, tau_link, EI) * L0),
         "dphi_ds": (("s_helix",), np.full(N, W))},
        coords={"s": (("s",), s), "s_link": (("s_link",), s_link), "s_helix": (("s_helix",), s_link)},
        attrs={"L": L, "l0": L0, "R": 1.0, "EI": EI})


def test_torque_free_helix_relations():
    """tau = 0 gives F = 2 EI w^2 c and K = EI rho w^4, which is rho F^2/(4EI) to O(rho^2 w^2)."""
    w = np.array([0.05, 0.2, -0.3])
    c = np.sqrt(1 - RHO**2 * w**2)
    F = 2 * EI * w**2 * c
    assert np.allclose(torque.helix_torque(RHO, w, F, EI), 0.0, atol=1e-15)
    assert np.allclose(torque.helix_force(RHO, w, 0.0, EI), F)
    K = torque.helix_wall_force(RHO, w, 0.0, EI)
    assert np.allclose(K, EI * RHO * w**4)
    assert np.allclose(K / (RHO * F**2 / (4 * EI)), 1 / c**2)       # -> 1 for a flat helix
    # all of the bending torque carried (no shear force): F = EI w^2 c
    assert np.allclose(torque.helix_force(RHO, w, EI * RHO**2 * w**3, EI), EI * w**2 * c)


def test_helix_relations_invert():
    w, tau = -0.25, np.linspace(-0.01, 0.01, 7)
    F = torque.helix_force(RHO, w, tau, EI)
    assert np.allclose(torque.helix_torque(RHO, w, F, EI), tau, rtol=0, atol=1e-14)


def test_the_wall_force_at_a_given_force_is_the_torque_eliminated_and_peaks_at_the_torque_free_pitch():
    """K(w, F) = rho w^2 (F/c - EI w^2) is helix_wall_force at the torque helix_force needs for F;
    over rho F^2/(4EI) it is x^2 (2 - x^2) to lowest order in rho w (x = w/w0), 1 at x = 1."""
    w, tau = -0.25, np.linspace(-0.01, 0.01, 7)
    F = torque.helix_force(RHO, w, tau, EI)
    assert np.allclose(torque.helix_wall_force_at_force(RHO, w, F, EI), torque.helix_wall_force(RHO, w, tau, EI),
                       rtol=1e-12, atol=0)
    F, rho = 1e-4, 1.0                                  # a flat helix: (rho w)^2 = x^2 F/(2EI) <= 8.5e-5
    x = np.array([0.2, 0.5, 1.0, 1.3])
    K = torque.helix_wall_force_at_force(rho, x * np.sqrt(F / (2 * EI)), F, EI) / (rho * F**2 / (4 * EI))
    # the first term's 1/c - 1 = (rho w)^2/2 relative to x^2 (2 - x^2) is at most 2x^2/(2 - x^2) x 4.2e-5 = 2.7e-4
    assert np.allclose(K, x**2 * (2 - x**2), rtol=5e-4) and not np.allclose(K, 2 * x**2 - x**4 / 2, rtol=5e-4)


def test_budget_reads_the_known_torque_from_the_loaded_end():
    ds = constructed_helix()
    b = torque.budget(ds)
    want = tau_profile(ds["s_link"].values)
    assert b.closure < 1e-12                          # zero torque at both ends
    assert np.all(b.on_helix)
    # the friction's budget is exact up to the half-link midpoint rule (tau is linear per link)
    assert np.allclose(b.tau_friction, want, rtol=0, atol=1e-12)
    assert np.allclose(b.tau_helix, want, rtol=0, atol=1e-12)
    # summed from the support instead, or with the opposite sign, the profile would be -tau
    assert np.max(np.abs(b.tau_friction + want)) > 0.007


def test_bulk_summary_of_the_constructed_helix():
    ds = constructed_helix()
    s = ds["s_link"].values
    bulk = (s > 10) & (s < 35)
    out = torque.bulk_summary(ds, bulk)
    F = torque.helix_force(RHO, W, tau_profile(s[bulk]), EI)
    tau0 = torque.torque_scale(F, 1.0, EI)
    assert out["torque_friction_ratio"] == pytest.approx(np.median(-tau_profile(s[bulk]) / tau0), rel=1e-9)
    assert out["torque_helix_ratio"] == pytest.approx(out["torque_friction_ratio"], rel=1e-4)
    assert out["torque_budget_residual"] < 1e-6
    assert out["K_ratio"] == pytest.approx(out["K_ratio_from_torque"], rel=1e-3)
    assert out["K_ratio"] == pytest.approx(out["K_ratio_from_pitch"], rel=1e-3)
    assert out["pitch_w0_ratio"] == pytest.approx(np.median(abs(W) / np.sqrt(F / 2)), rel=1e-9)
    assert torque.bulk_summary(ds, np.zeros(N, dtype=bool))["K_ratio"] == 0.0


def test_the_simulated_friction_closes_the_torque_budget():
    """A frictional rod in equilibrium with both ends free to turn: the wall friction's total
    axial torque vanishes to the equilibrium tolerance, and in the bulk helix the torque it leaves
    in the rod equals the one the local helix carries."""
    from confined_rod import Scene, simulate
    from confined_rod.analysis import regions

    d = simulate(Scene(L=60.0, load=0.25, k_fr=0.8, seed=2, tol=1e-6), progress=False)
    assert d.attrs["status"] == "converged"
    b = torque.budget(d)
    assert b.closure < 1e-4
    a = regions.analyse(d)
    assert a.regions.has_bulk
    bulk = (a.regions.of_links(d["s_link"].values) == 1) & b.on_helix
    diff = np.abs(b.tau_friction[bulk] - b.tau_helix[bulk]) / (b.tau0[bulk] + np.abs(b.tau_friction[bulk]))
    assert np.median(diff) < 0.05


def test_the_budget_residual_is_read_link_by_link():
    """A defect inside the bulk (here the pitch rate of 30 % of its links off by 40 %, so that the
    helix's torque there is wrong) moves the median of the helix's torque away from the
    friction's, but the median of the per-link difference stays at the closed budget's: the
    measure compares where the uniform helix holds, and a majority of defects would show."""
    ds = constructed_helix()
    s = ds["s_link"].values
    bulk = (s > 10) & (s < 35)
    defect = bulk & (s < 17.5)                         # 15 of the bulk's 50 links
    w = ds["dphi_ds"].values.copy()
    w[defect] *= 1.4
    ds["dphi_ds"] = (("s_helix",), w)
    out = torque.bulk_summary(ds, bulk)
    b = torque.budget(ds)
    per_link = np.abs(b.tau_friction - b.tau_helix) / (b.tau0 + np.abs(b.tau_friction))
    assert per_link[defect].min() > 0.05                # the defect's links are far off
    assert out["torque_budget_residual"] < 1e-6         # 35 of 50 links close the budget
    w[bulk & (s < 25)] = 1.4 * W                        # a defect over 30 of the 50 links
    ds["dphi_ds"] = (("s_helix",), w)
    assert torque.bulk_summary(ds, bulk)["torque_budget_residual"] > 0.05
