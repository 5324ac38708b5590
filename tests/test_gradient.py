"""Forces and torques of the kernels are minus the gradient of the total energy.

The energy twin (model.reference) is plain numpy written separately from the
kernels.  Central differences with step h have truncation error ~h^2 |U'''| and
round-off ~eps |U|/h; with h = 1e-6 and |U|, |U'''| = O(1e3) both are < 1e-8 of
the typical force (O(10) here), so a relative error < 1e-6 tests the kernels,
not the differencing.
"""
import dataclasses

import numpy as np
import pytest

from confined_rod import Scene
from confined_rod.sim.model import kernels as K
from confined_rod.sim.model.forces import Workspace
from confined_rod.sim.model.reference import total_energy

from .conftest import random_state

H = 1e-6


def rotate(v, axis, angle):
    axis = axis / np.linalg.norm(axis)
    return (v * np.cos(angle) + np.cross(axis, v) * np.sin(angle)
            + axis * np.dot(axis, v) * (1 - np.cos(angle)))


def minus_energy_gradient(r, t, par):
    """-dU/dr_i of the numpy twin by central differences (step H)."""
    grad = np.zeros_like(r)
    for i in range(r.shape[0]):
        for c in range(3):
            rp, rm = r.copy(), r.copy()
            rp[i, c] += H
            rm[i, c] -= H
            grad[i, c] = -(total_energy(rp, t, par) - total_energy(rm, t, par)) / (2 * H)
    return grad


@pytest.mark.parametrize("ends", ["free", "pinned"])
@pytest.mark.parametrize("lower_end", ["held", "free"])
def test_forces_and_torques_are_minus_energy_gradient(rng, ends, lower_end):
    scene = Scene(L=6.0, l0=0.5, k_ph=50.0, k_w=80.0, load=0.3, ends=ends, lower_end=lower_end,
                  body_force=(0.05, -0.02, 0.01), pore_length=6.0)
    r, t = random_state(scene, rng)
    r[:, 2] -= 0.6  # push the lowest link ends through the floor (lower piston)
    par = scene.params()
    ws = Workspace.for_links(scene.N)
    e, _, f_floor = K.conservative_loads(r, t, par, ws.Fm, ws.Fp, ws.F, ws.M, ws.Nw)
    assert e == pytest.approx(total_energy(r, t, par), rel=1e-12)
    assert np.count_nonzero(ws.Nw) >= 3, "the state must press some link ends into the wall"
    assert f_floor > 0, "the state must press some link ends into the floor"

    err_F = np.abs(minus_energy_gradient(r, t, par) - ws.F).max() / np.abs(ws.F).max()
    assert err_F < 1e-6, err_F

    # torque: U(t_i rotated by angle a about axis n) -> dU/da = -M_i . n for n perpendicular to t_i
    for i in range(scene.N):
        a1 = np.cross(t[i], [1.0, 0.0, 0.0])
        a1 /= np.linalg.norm(a1)
        a2 = np.cross(t[i], a1)
        for axis in (a1, a2):
            tp, tm = t.copy(), t.copy()
            tp[i] = rotate(t[i], axis, H)
            tm[i] = rotate(t[i], axis, -H)
            num = -(total_energy(r, tp, par) - total_energy(r, tm, par)) / (2 * H)
            ana = ws.M[i] @ axis
            assert abs(num - ana) < 1e-6 * np.abs(ws.M).max(), (i, num, ana)


def test_friction_never_exceeds_coulomb_or_cap(rng):
    """|f_i| <= min(k_fr N_i, cap) on every link, with equality for sliding links."""
    # k_fr and the cap are large so that this strongly strained state has links
    # in all three regimes: stuck, sliding at k_fr N, sliding at the cap
    scene = Scene(L=6.0, l0=0.5, k_fr=5.0, friction_cap=500.0, pore_length=6.0)
    r, t = random_state(scene, rng)
    par = scene.params()
    ws = Workspace.for_links(scene.N)
    K.conservative_loads(r, t, par, ws.Fm, ws.Fp, ws.F, ws.M, ws.Nw)
    F_cons = ws.F.copy()
    K.coulomb_friction(r, par, ws.Nw, ws.F, ws.Ff, ws.stuck)
    f = np.linalg.norm(ws.Ff, axis=1)
    limit = np.minimum(scene.k_fr * ws.Nw, scene.friction_cap)
    assert np.all(f <= limit * (1 + 1e-12))
    sliding = (ws.Nw > 0) & (ws.stuck == 0)
    capped = sliding & (scene.k_fr * ws.Nw > scene.friction_cap)
    assert (ws.stuck == 1).any() and (sliding & ~capped).any() and capped.any(), "all regimes must occur"
    np.testing.assert_allclose(f[sliding], limit[sliding], rtol=1e-12)
    # friction is tangent to the wall: no radial component at the link centre
    n = r[:, :2] / np.linalg.norm(r[:, :2], axis=1)[:, None]
    assert np.abs(np.einsum("ij,ij->i", ws.Ff[:, :2], n)).max() < 1e-12
    # stuck links: the tangential net force vanishes exactly
    stuck = ws.stuck == 1
    Fn = np.einsum("ij,ij->i", F_cons[:, :2], n)
    tang = ws.F.copy()
    tang[:, :2] -= (np.einsum("ij,ij->i", ws.F[:, :2], n))[:, None] * n
    assert np.abs(tang[stuck]).max(initial=0.0) < 1e-12 * max(1.0, np.abs(Fn).max())


def test_the_pore_entrance_and_guided_end_are_conservative(rng):
    """Around the pore entrance a link end inside the solid is
    pushed out along the nearer face, the wall rho = R or the block's top face
    z = z_top, so the energy is continuous across the rim; the guided loaded end
    meets the wall above the entrance too.  The state puts ends in all three places."""
    base = Scene(L=6.0, l0=0.5, k_ph=50.0, k_w=80.0, load=0.3, ends="guided")
    r, t = random_state(base, rng, lateral=1.05)
    r[-1, :2] = (1.2 * base.R, 0.0)  # the loaded end presses its guide
    h = 0.5 * base.l0
    pts = np.concatenate([r - h * t, r + h * t])
    over = np.hypot(pts[:, 0], pts[:, 1]) - base.R
    # the entrance just above an end that is outside R by more than its depth under it
    k = max((j for j in range(len(pts) - 1) if 3.0 < pts[j, 2] < 5.0), key=lambda j: over[j])
    scene = dataclasses.replace(base, pore_length=float(pts[k, 2] + 0.5 * over[k]))
    par = scene.params()
    face = [K._face_point(*p, par, False) > 0 for p in pts[:-1]]
    radial = [K._wall_point(*p, par, False)[0] > 0 for p in pts[:-1]]
    assert sum(face) >= 1 and sum(radial) >= 3, "ends must press both the top face and the wall"
    assert pts[-1, 2] > scene.pore_length, "the loaded end is above the entrance"
    ws = Workspace.for_links(scene.N)
    e, _, _ = K.conservative_loads(r, t, par, ws.Fm, ws.Fp, ws.F, ws.M, ws.Nw)
    assert e == pytest.approx(total_energy(r, t, par), rel=1e-12)
    assert np.abs(minus_energy_gradient(r, t, par) - ws.F).max() / np.abs(ws.F).max() < 1e-6
    # without the guide the loaded end above the entrance is free
    par[K.GUIDED] = 0.0
    assert total_energy(r, t, par) < e
