"""Load paths and thresholds (groundwork of Fig 3).

The straight branch: with both ends free sideways, a straight rod under an axial load
is neutral to tilting only without a wall; the couple F L sin(theta) of the load and
the support tilts it until both ends touch the wall, so the straight rod lies
diagonally across the pore, L_z = sqrt(L^2 - 4 R^2) (less the compression F L/k_ph).

The first threshold: the diagonal rod is compressed along its own axis by the load
and the wall forces at its ends, N = F tan(theta), together F/cos(theta).  It buckles
when that reaches Euler's load for free-free (= pinned-pinned) lateral conditions,
pi^2 EI/L^2, i.e. at F_1 = (pi^2 EI/L^2) cos(theta), cos(theta) = sqrt(1 - 4R^2/L^2);
for the discrete rod (C = EI/l0) pi^2/L^2 becomes (4/l0^2) sin^2(pi l0/(2L)).
"""
import math

import numpy as np
import pytest
import xarray as xr

from confined_rod.sim import load_paths as paths
from confined_rod.sim import observables as obs
from confined_rod.sim.scenes import Scene

L, L0 = 10.0, 0.5
COS = np.sqrt(1 - 4.0 / L**2)
F1_DISCRETE = 4.0 / L0**2 * np.sin(np.pi * L0 / (2 * L)) ** 2 * COS  # EI = R = 1


def base(**kw):
    return Scene(**{"L": L, "l0": L0, "k_fr": 0.0, "protocol": "planar", "k_ph": 1e4, "tol": 1e-8, "seed": 1,
                    "name": "path", **kw})


def test_shape_measures_tell_straight_planar_and_helical_apart():
    s = np.linspace(0, 10, 21)
    line = np.stack([0.2 * s - 1, 0 * s, s], 1)  # straight, tilted
    assert obs.shape_measures(line, 1.0) == pytest.approx((0.0, 0.0), abs=1e-12)
    wave = np.stack([0.7 * np.sin(np.pi * s / 10), 0 * s, s], 1)  # planar arc of amplitude 0.7
    d, o = obs.shape_measures(wave, 1.0)
    assert d == pytest.approx(0.7, rel=1e-9) and o == pytest.approx(0.0, abs=1e-12)
    helix = np.stack([np.cos(s), np.sin(s), s], 1)  # 1.6 turns of radius 1
    d, o = obs.shape_measures(helix, 1.0)
    assert o > 0.3 and paths.classify(d, o) == "three_d"
    assert paths.classify(*obs.shape_measures(wave, 1.0)) == "planar"


def test_the_straight_branch_lies_diagonally_across_the_pore():
    ds = paths.load_path(base(), [0.02, 0.05, 0.08])
    assert list(ds.state_class.values) == [paths.CLASSES.index("straight")] * 3
    assert np.all(ds.converged.values == 1)
    # compression F L/k_ph <= 1e-4 here; L_z falls with F at that rate
    np.testing.assert_allclose(ds.L_z.values, np.sqrt(L**2 - 4.0) * (1 - ds["load"].values / 1e4), atol=2e-5)


def test_first_threshold_is_eulers_load_of_the_tilted_rod():
    lo, hi, n = paths.bisect_threshold(base(), paths.buckled, 0.05, 0.2, 1e-3)
    assert hi - lo <= 1e-3 * hi and n < 20
    # resolution of fresh runs at tol 1e-8, perturbation 1e-3 R: ~tol L/(a pi^2) = 1e-5 relative
    assert lo - 2e-5 * F1_DISCRETE <= F1_DISCRETE <= hi + 2e-5 * F1_DISCRETE
    assert hi < F1_DISCRETE / COS  # the tilt correction (2 %) is resolved, not just Euler's load


def test_continuation_down_from_the_buckled_branch_returns_straight():
    """Frictionless, the first transition has no hysteresis: sweeping the load down from
    a buckled state straightens the rod again below the threshold."""
    loads = [0.2, 0.15, 0.12, 0.9 * F1_DISCRETE, 0.5 * F1_DISCRETE]
    ds = paths.load_path(base(), loads, mode="continuation")
    classes = [paths.CLASSES[c] for c in ds.state_class.values]
    assert classes[:3] == ["planar"] * 3 and classes[-1] == "straight"
    assert np.all(np.diff(ds.L_z.values) > 0)  # the rod lengthens along the axis as the load falls


@pytest.mark.parametrize("aspect, lo_ratio", [(20.0, 3.8), (40.0, 3.9)])
def test_second_threshold_is_the_second_euler_mode(aspect, lo_ratio):
    """Planar to 3-D (planar_then_3d, frictionless): once the buckled arc rests on the
    wall at mid-span its two halves are columns of length L/2, which buckle again (out
    of the plane) at pi^2 EI/(L/2)^2 = 4 F_E.  Measured: 3.69, 3.93, 3.98 F_E at
    L/R = 10, 20, 40 (the tilt and the arc's own excursion lower it at small L/R); it
    depends on R only through L/R (F_2 R^2/EI the same for R = 1 and 2)."""
    def f2(R):
        sc = Scene(L=aspect * R, R=R, k_fr=0.0, protocol="planar_then_3d", tol=1e-7, seed=1, k_ph=1e4 / R**2)
        guess = 4 * np.pi**2 / (aspect * R) ** 2
        lo, hi, _ = paths.bisect_threshold(sc, paths.three_dimensional, 0.6 * guess, 1.2 * guess, 1e-2)
        return 0.5 * (lo + hi), hi - lo

    F2, width = f2(1.0)
    F_E = np.pi**2 / aspect**2
    assert lo_ratio * F_E < F2 < 4.0 * F_E + width
    if aspect == 20.0:
        F2_R2, _ = f2(2.0)
        assert F2_R2 * 4 == pytest.approx(F2, rel=1e-2)  # F_2 R^2/EI depends only on L/R


def test_a_defect_is_found_in_a_helix_with_one_reversal_and_none_in_a_clean_one():
    """Helices on the wall built link by link: phi(s) winds one way, then (with a
    defect at s = 12.25) the other; the contact-stretch rate dphi/ds as the simulator
    computes it (np.gradient of the unwrapped azimuth)."""
    from confined_rod.analysis.measure import defects

    s = (np.arange(60) + 0.5) * 0.5
    omega = 0.7
    clean = omega * s
    rng = np.random.default_rng(3)
    noisy = clean + rng.normal(scale=0.02, size=s.size)  # wobble of the link centres
    assert defects(s, np.gradient(np.unwrap(clean), s)).size == 0
    assert defects(s, np.gradient(np.unwrap(noisy), s)).size == 0
    kinked = np.where(s < 12.25, omega * s, omega * (24.5 - s))
    d = defects(s, np.gradient(kinked, s))
    assert d.size == 1 and abs(d[0] - 12.25) <= 0.5  # located to a link length
    # a one-link flicker of the sense is not a defect
    flicker = np.gradient(clean, s)
    flicker[30] *= -1
    assert defects(s, flicker).size == 0


# -- the figure kind (Fig 3) ------------------------------------------------------------------
FIG3 = {"kind": "bifurcation", "loads": {"min": 0.05, "max": 0.5, "n": 5}, "precision": 0.05,
        "defaults": {"L": 10, "k_fr": 0.0, "k_ph": 100.0, "tol": 1e-7, "perturbation": 0.01, "seed": 1},
        "scenes": {"up": {"protocol": "straight"}, "fresh": {"protocol": "planar_then_3d"}, "thr": {}},
        "runs": {"up": "up", "fresh": "fresh", "thr": "thresholds"}}


def test_bifurcation_config_is_checked_before_any_work():
    import copy

    from confined_rod import pipeline
    from confined_rod.errors import ConfigError

    def check(fig):
        pipeline.validate({"figures": {"fig3": fig}})

    check(copy.deepcopy(FIG3))
    bad = copy.deepcopy(FIG3)
    del bad["runs"]["fresh"]
    with pytest.raises(ConfigError, match=r"fig3\.runs: no run given for the scene\(s\) fresh"):
        check(bad)
    bad = copy.deepcopy(FIG3)
    bad["scenes"]["thr"] = {"k_fr": 0.8}
    with pytest.raises(ConfigError, match=r"scenes\.thr: k_fr = 0\.8; thresholds are defined frictionless"):
        check(bad)
    bad = copy.deepcopy(FIG3)
    bad["scenes"]["fresh"]["L"] = 12
    with pytest.raises(ConfigError, match=r"fig3\.scenes\.fresh: L = 12"):
        check(bad)
    bad = copy.deepcopy(FIG3)
    bad["loads"]["min"] = 1e-4  # the round-off floor grows as 1/load: tol 1e-9 is out of reach there
    bad["defaults"]["tol"] = 1e-9
    with pytest.raises(ConfigError, match=r"scenes\.up at load 0\.0001 \(a load its run visits\).*'k_ph'"):
        check(bad)


def test_bifurcation_dataset_and_figure_from_real_runs():
    from confined_rod import pipeline
    from confined_rod.analysis.figures import bifurcation
    from confined_rod.io import check_finite

    config = {"figures": {"fig3": FIG3}}
    sims = {n: paths.run_spec(pipeline.build_scene(config, "fig3", n), pipeline.path_spec(config, "fig3", n))
            for n in pipeline.scenes(config, "fig3")}
    ds = bifurcation.build(FIG3, sims)
    check_finite(ds)
    lo, hi = ds.attrs["first_threshold"]
    F1 = bifurcation.theory.first_threshold(10.0, 1.0, 0.5, 1.0)
    assert lo <= F1 <= hi and hi - lo <= 0.05 * hi
    assert ds.L_z.dims == ("branch", "load") and ds.L_z.shape == (2, 5)
    # up and fresh agree frictionless (no hysteresis between them), class by class
    assert np.array_equal(ds.state_class.values[0], ds.state_class.values[1])
    import matplotlib

    matplotlib.use("Agg")
    fig = bifurcation.plot(ds)
    assert len(fig.axes) == 2


def test_a_stiff_twin_gives_each_threshold_its_bond_compliance_bias():
    """The L/R = 10 rod bisected at k_ph = 100 and at 1e4 (relative precision 2e-4): the twin is
    not a row of panel (b); the k_ph term of each threshold is its shift from the twin over
    1 - k_ph/k_ph_twin. The second threshold (F_2 ~ 3.7 pi^2 EI/L^2 = 0.37 EI/R^2) compresses the
    bonds by F_2/k_ph = 0.37 %: its bias is positive (a shorter, stiffer-loaded chain buckles
    later) and below that strain, and far above the bracket (2e-4); the first threshold's load
    compresses them by 0.1 %, and its bias is below the brackets' resolution of 4e-4 plus a tenth of that
    strain (measured 5e-5: the tilted rod's shortening is shared by its span and its bending)."""
    import copy

    from confined_rod import pipeline
    from confined_rod.analysis.figures import bifurcation

    fig = copy.deepcopy(FIG3)
    fig["precision"] = 2e-4
    fig["scenes"]["thr_stiff"] = {"k_ph": 10000.0}
    fig["runs"]["thr_stiff"] = "thresholds"
    config = {"figures": {"fig3": fig}}
    pipeline.validate(config)
    names = ("thr", "thr_stiff")
    sims = {n: paths.run_spec(pipeline.build_scene(config, "fig3", n), pipeline.path_spec(config, "fig3", n))
            for n in names}
    rows, twins = bifurcation.stiff_twins({n: tuple(float(sims[n].attrs[k]) for k in ("L", "R", "l0", "k_ph"))
                                           for n in names})
    assert rows == ["thr"] and twins == {"thr": "thr_stiff"}
    mid = {n: 0.5 * (sims[n].threshold_lo.values + sims[n].threshold_hi.values) for n in names}
    shift = (mid["thr"] / mid["thr_stiff"] - 1.0) / (1.0 - 100.0 / 10000.0)
    F2_strain = float(mid["thr"][1]) / 100.0
    assert 5 * 2e-4 < shift[1] < F2_strain, shift
    assert abs(shift[0]) < 4e-4 + 0.1 * float(mid["thr"][0]) / 100.0, shift
    ds = xr.Dataset({"threshold_lo": (("aspect", "threshold"), [sims["thr"].threshold_lo.values]),
                     "threshold_hi": (("aspect", "threshold"), [sims["thr"].threshold_hi.values]),
                     "threshold_lo_stiff": (("aspect", "threshold"), [sims["thr_stiff"].threshold_lo.values]),
                     "threshold_hi_stiff": (("aspect", "threshold"), [sims["thr_stiff"].threshold_hi.values]),
                     "aspect_k_ph": (("aspect",), [100.0]), "stiff_k_ph": (("aspect",), [10000.0])})
    for j in (0, 1):
        value, _, se, factor = bifurcation._bond_term(ds, 0, j)
        assert value == pytest.approx(shift[j], rel=1e-12) and factor == pytest.approx(1 / 0.99, rel=1e-12)
        # two brackets of relative half-width 1e-4 at most: 1e-4 sqrt(2/3) at most, times the factor
        assert 0 < se <= 1e-4 * math.sqrt(2 / 3) / 0.99 * (1 + 1e-9)


def test_a_transition_keeps_the_shapes_the_run_chooses_and_tests_the_defects():
    ds = paths.transition(Scene(L=40, load=0.25, k_fr=0.0, protocol="planar_then_3d", seed=1, name="tr"), [0.5])
    stage, oop = ds.snap_stage.values, ds.snap_out_of_plane.values
    assert stage[0] == 0 and oop[0] < 1e-9  # the planar stage ends exactly planar
    assert np.all(stage[1:] == 1) and 10 <= ds.sizes["snapshot"] <= 60  # a few dozen shapes, not a trajectory
    assert oop[-1] > 0.3 and np.all(np.diff(ds.snap_time.values) > 0)
    assert list(ds.state.values) == ["final", "reduced_0.5"]
    assert ds.state_load.values.tolist() == [0.25, 0.125] and np.all(ds.converged.values == 1)
    from confined_rod.io import check_finite

    check_finite(ds)


# -- the fold at large loads (Fig 8) -----------------------------------------------------------
def test_a_rod_well_below_the_fold_threshold_forms_a_helix_and_stays_in_the_pore():
    """The fold threshold is 0.66-0.67 EI/R^2 with k_fr = 0.8 (0.61 frictionless); at
    0.4 EI/R^2, well below, rods of two lengths and two seeds settle into helices inside
    the pore: no fold, no escape, L_z close to L."""
    from confined_rod.sim.simulation import simulate

    for L, seed in ((40.0, 1), (40.0, 2), (80.0, 1)):
        ds = simulate(Scene(L=L, load=0.4, k_fr=0.8, seed=seed, name="below"), progress=False)
        assert ds.attrs["status"] == "converged" and int(ds.escaped) == 0
        assert float(ds.L_z) > 0.85 * L and int(ds.contact.sum()) > 0.3 * ds.sizes["s_link"]  # a helix on the wall


def test_the_fold_threshold_scales_as_one_over_R_squared():
    """In units of EI/R^2 the threshold is the same for R = 1 and R = 2 (with l0, k_ph, k_w,
    and so every length and stiffness, scaled with R): a consequence of dimensional
    analysis that the discretisation must respect, and the paper's 1/R^2 claim; and it
    lies below the largest load a helix on the wall can carry, 4/(3 sqrt 3) EI/R^2."""
    from confined_rod import theory

    out = []
    for R in (1.0, 2.0):
        sc = Scene(L=20.0 * R, R=R, k_fr=0.0, seed=1, name="fold")
        lo, hi, _ = paths.bisect_threshold(sc, paths.folded, *theory.fold_bracket(R, 1.0), 2e-2)
        out.append((lo * R**2, hi * R**2))
    (lo1, hi1), (lo2, hi2) = out
    assert max(lo1, lo2) <= min(hi1, hi2)  # the brackets overlap
    assert hi1 < theory.helix_load_limit(1.0, 1.0)


def test_a_helix_well_below_the_escape_threshold_never_leaves_an_open_entrance():
    """Open entrance: the loaded end guided, a free span g = 5 R above the entrance, whose
    loop escapes above ~pi^2 EI/g^2 = 0.39 EI/R^2 (measured 0.38 at L/R = 80).  At 0.15,
    well below, the rod forms a helix, and no link end ever gets beyond the pore radius
    above the entrance: the shapes of the whole run stay within 1.0 R (a helix pushes the
    span outwards, to 0.9 R measured, never out)."""
    sc = Scene(L=40.0, load=0.15, k_fr=0.8, seed=1, ends="guided", pore_length=35.0, name="open")
    ds = paths.event(sc)
    assert int(ds.converged) == 1 and int(ds.escaped) == 0
    assert float(ds.snap_outside_radius.max()) < 1.0
    assert float(ds.snap_L_z[-1]) > 0.85 * sc.L


def test_the_escape_threshold_is_eulers_load_of_the_free_span():
    """Above the entrance the span g between the guided loaded end and the rim is a column
    laterally held at both ends: it bows out of the pore at about pi^2 EI/g^2, before the
    rod folds inside the pore (0.66 EI/R^2) when g >= 4 R (measured 0.90-1.02 times it for
    g = 4-8 R at L/R = 80), and with every length scaled with R it scales as 1/R^2.  The
    bracket at 5 % must overlap [0.8, 1.1] pi^2 EI/g^2 and the run above it must escape."""
    from confined_rod import theory

    for R in (1.0, 2.0):
        sc = Scene(L=20.0 * R, R=R, l0=R, k_ph=1000.0 * R, k_w=1000.0 / R, k_fr=0.8, seed=1,
                   ends="guided", pore_length=14.0 * R, name="span")
        ds = paths.fold_threshold(sc, 5e-2)
        lo, hi = float(ds.threshold_lo[0]), float(ds.threshold_hi[0])
        euler = theory.span_euler_load(1.0, 6.0 * R)
        assert 0.8 * euler <= hi and lo <= 1.1 * euler, (R, lo / euler, hi / euler)
        assert int(ds.escaped_above[0]) == 1


def test_an_unguided_end_above_the_entrance_is_refused_in_the_escape_figure():
    from confined_rod.analysis.figures import escape

    built = {"ev": Scene(L=40.0, load=0.5, pore_length=35.0, name="ev")}
    with pytest.raises(Exception, match=r"scenes\.ev: pore_length = 35 < L = 40 with ends = 'free'.*guided"):
        escape.validate("fig8", {"runs": {"ev": "event"}}, built)
