"""Stopping rules (escape, time cap, divergence) and the protocols.

Thresholds here are qualitative on purpose: an escape happens within a few
time units of bending relaxation of a 2 R piece (EI q^4 ~ 6), far below 100;
a planar state touching the wall has |x| = R up to the penalty penetration."""
import re

import numpy as np
import pytest

from confined_rod import DivergenceError, Scene, simulate
from confined_rod.errors import SceneError
from confined_rod.sim.solvers import base, explicit


def test_escape_stops_the_run():
    # the top 2 R of the rod stand out of the pore; a load of 2 EI/R^2 (8x the
    # Euler load of a 2 R free-standing piece) throws it sideways out of the pore
    ds = simulate(Scene(L=10.0, pore_length=8.0, load=2.0, t_max=2000.0, tol=1e-4), progress=False)
    assert int(ds.escaped) == 1 and int(ds.converged) == 0
    assert float(ds.t_final) < 100.0


def test_time_cap_flags_not_converged():
    ds = simulate(Scene(L=10.0, load=0.5, t_max=5.0), progress=False)
    assert int(ds.converged) == 0 and int(ds.escaped) == 0
    assert float(ds.t_final) == pytest.approx(5.0, rel=1e-3)
    assert float(ds.residual_force) > ds.attrs["tol"]


@pytest.mark.parametrize("cap", [{"t_max": 5.0}, {"max_steps": 30}])
def test_a_ramp_stage_that_uses_up_the_cap_ends_the_run_and_is_named(cap):
    """The time cap and the step budget belong to the run: a ramp stage that uses them up ends it
    there, unconverged, with the stage and its load in the reason, and no later stage is tried
    (each would take one step at a load the rod never relaxed under)."""
    sc = Scene(L=10.0, load=0.5, protocol="ramp", ramp_steps=4, **cap)
    ds = simulate(sc, progress=False)
    assert ds.attrs["status"] in ("time_cap", "step_cap") and int(ds.converged) == 0
    assert f"ramp stage 1 of 4 (load {sc.ramp_loads()[0]:.3g} EI/R^2" in ds.attrs["status_reason"]
    assert list(np.atleast_1d(ds.attrs["stage_converged"])) == [0]


@pytest.mark.parametrize("solver", ["explicit", "implicit"])
def test_a_step_budget_ends_the_run_as_step_cap_and_is_refused_when_negative(solver):
    """max_steps is a work budget: the run stops once it has taken exactly that many
    steps, unconverged, with the reason."""
    from confined_rod.sim.probe import STATUS, probe
    from confined_rod.sim.scenes import SceneError

    ds = simulate(Scene(L=10.0, load=0.5, solver=solver, max_steps=30), progress=False)
    assert ds.attrs["status"] == "step_cap" and int(ds.converged) == 0
    assert int(ds.n_steps) == 30
    assert "max_steps = 30" in ds.attrs["status_reason"]
    p = probe({"L": 10.0, "load": 0.5, "solver": solver, "max_steps": 30})
    assert STATUS[int(p.status)] == "step_cap" and int(p.has_force) == 1
    with pytest.raises(SceneError, match="'max_steps': -1"):
        Scene(max_steps=-1)


def test_bonds_tearing_apart_is_reported_as_divergence(monkeypatch):
    # k_ph = 0.5: the load 1 compresses each bond by load l0/k_ph = l0, > l0/2; refused
    # up front (limits.MAX_STRAIN), and caught during the run if let through
    from confined_rod import limits
    from confined_rod.errors import SceneError

    with pytest.raises(SceneError, match=r"scene 'soft'.*'k_ph'.*take k_ph >= 20"):
        Scene(L=4.0, load=1.0, k_ph=0.5, name="soft")
    monkeypatch.setattr(limits, "MAX_STRAIN", float("inf"))
    with pytest.raises(DivergenceError, match=r"scene 'soft'.*step \d+.*bond gap"):
        simulate(Scene(L=4.0, load=1.0, k_ph=0.5, name="soft"), progress=False)


def test_unstable_time_step_is_reported_as_divergence(monkeypatch):
    monkeypatch.setattr(Scene, "dt", lambda self: 50 * self.constants().dt_stable)
    with pytest.raises(DivergenceError, match=r"scene 'big-step'.*diverged at step \d+ \(t = "):
        simulate(Scene(L=4.0, load=0.5, name="big-step", solver="explicit"), progress=False)


@pytest.mark.parametrize("solver", ["implicit", "explicit"])
def test_planar_protocol_stays_planar_and_touches_the_wall(solver):
    ds = simulate(Scene(L=20.0, load=0.25, k_fr=0.8, protocol="planar", tol=1e-4, solver=solver), progress=False)
    assert int(ds.converged) == 1
    assert np.all(ds.y.values == 0.0)  # exact: every force stays in the x-z plane
    assert int(ds.contact.sum()) >= 2
    assert np.abs(ds.x).max() > 0.9


def test_planar_then_3d_leaves_the_plane_and_records_both_stages():
    sc = Scene(L=12.0, load=0.5, k_fr=0.0, protocol="planar_then_3d", tol=1e-4, snapshot_interval=20.0)
    st = explicit.run(sc, progress=False)
    assert len(st.stage_converged) == 2
    assert st.stage_converged[0]
    assert np.all(st.snapshot_r[0][:, 1] == 0.0)
    assert np.abs(st.r[:, 1]).max() > 0.5  # the final state is three-dimensional


def test_snapshots_only_when_asked():
    plain = simulate(Scene(L=6.0, load=0.5, t_max=20.0), progress=False)
    assert "t" not in plain.dims and "snap_x" not in plain
    snap = simulate(Scene(L=6.0, load=0.5, t_max=20.0, snapshot_interval=2.0), progress=False)
    times = snap.t.values
    # one snapshot every 2 time units (to within a step), plus the final state
    n_regular = int(np.floor(float(snap.t_final) / 2.0)) + 1
    assert snap.sizes["t"] in (n_regular, n_regular + 1)
    np.testing.assert_allclose(times[:n_regular], 2.0 * np.arange(n_regular), atol=2 * snap.attrs["dt"])
    np.testing.assert_allclose(snap.snap_x.isel(t=-1), snap.x)


def test_progress_is_reported_on_stderr(monkeypatch, capsys):
    monkeypatch.setattr(base, "PROGRESS_AFTER_S", 0.0)
    monkeypatch.setattr(base, "PROGRESS_EVERY_S", 0.0)
    simulate(Scene(L=6.0, load=0.5, t_max=20.0, name="chatty"), progress=True)
    err = capsys.readouterr().err
    # the fraction of the residual decades covered, and the time left (here bounded by the time cap)
    assert re.search(r"\[chatty\] +\d+ % of [\d.]+ residual decades \(eps = .*t = .*elapsed, (~.* left|at most "
                     r".* left \(time cap t_max = 20\))", err), err
    simulate(Scene(L=6.0, load=0.5, t_max=20.0, name="quiet"), progress=False)
    assert capsys.readouterr().err == ""


def test_the_equilibrium_tolerance_is_lifted_only_to_the_round_off_floor():
    """The floor 2 x 4 eps (k L + k_w R + load) / (l0 load / L) grows as L^2 k_ph / l0^2:
    far below tol for the rods of the tests, 1.2e-4 > tol = 1e-5 at the publication's
    L/R = 640 (k_ph = 1e4, l0 = 0.5 R)."""
    from confined_rod.sim.solvers.base import equilibrium_tol

    assert equilibrium_tol(Scene(L=20, load=0.25, l0=0.5, tol=1e-5)) == 1e-5
    long = Scene(L=640, load=0.25, l0=0.5, k_ph=1e4, tol=1e-5)
    eps = np.finfo(float).eps
    expected = 2 * 4 * eps * (1e4 / 0.5 * 640 + long.k_w + 0.25) * 640 / (0.5 * 0.25)
    assert equilibrium_tol(long) == pytest.approx(expected, rel=1e-12)
    assert 1e-4 < equilibrium_tol(long) < 1.5e-4
    half = Scene(L=320, load=0.25, l0=0.5, k_ph=1e4, tol=1e-6)
    assert equilibrium_tol(half) == pytest.approx(equilibrium_tol(long) / 4, rel=0.01)


def test_snapshots_at_growing_times_store_the_force_along_the_rod():
    """snapshot_growth g: t = 0, dt, dt g, dt g^2, ... and the final state, each with |F_z| along s
    evaluated on the stored state (the loaded end carries the load at every time)."""
    sc = Scene(L=10.0, load=0.5, k_fr=0.8, t_max=200.0, snapshot_interval=5.0, snapshot_growth=2.0)
    d = simulate(sc, progress=False)
    times = d.t.values
    n = int(np.floor(np.log2(float(d.t_final) / 5.0))) + 1      # 5, 10, 20, ... below t_final
    np.testing.assert_allclose(times[1:n + 1], 5.0 * 2.0 ** np.arange(n), atol=2 * d.attrs["dt"])
    assert times[0] == 0.0 and times[-1] == pytest.approx(float(d.t_final))
    np.testing.assert_allclose(d.snap_F_z.values[:, 0], -0.5)
    np.testing.assert_allclose(d.snap_F_z.isel(t=-1), d.F_z, atol=1e-12)
    np.testing.assert_allclose(d.snap_friction_phi.isel(t=-1), d.friction_phi, atol=1e-12)
    with pytest.raises(SceneError, match="snapshot_growth"):
        Scene(L=10.0, snapshot_interval=5.0, snapshot_growth=0.5)


def test_the_escape_radius_reaches_the_kernel_through_the_parameter_vector():
    """A link end above the open entrance has left the pore beyond limits.ESCAPE_RADIUS (one
    source: the scene puts it into the kernels' parameter vector, which a cached kernel cannot
    freeze as it would a global)."""
    import numpy as np

    from confined_rod import limits
    from confined_rod.sim.model import kernels as K
    from confined_rod.sim.scenes import Scene

    sc = Scene(L=10.0, R=2.0, pore_length=8.0, l0=1.0)
    par = sc.params()
    assert par[K.R_ESCAPE] == limits.ESCAPE_RADIUS * sc.R
    t = np.tile([0.0, 0.0, 1.0], (1, 1))
    inside = np.array([[0.99 * par[K.R_ESCAPE], 0.0, 9.0]])
    outside = np.array([[1.01 * par[K.R_ESCAPE], 0.0, 9.0]])
    below = np.array([[1.01 * par[K.R_ESCAPE], 0.0, 6.0]])   # below the entrance the wall holds it
    assert not K.escaped(inside, t, par) and K.escaped(outside, t, par) and not K.escaped(below, t, par)
