"""Figure kinds (src/confined_rod/analysis/figures/): the registry, the generated schema, the
separation of post-processing from the simulator, and the physics of Figs 1, 5 and 7."""
import dataclasses
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from confined_rod import Scene, simulate, theory
from confined_rod.analysis import figures, plotting, postprocess
from confined_rod.analysis.figure_quantities import QUANTITIES
from confined_rod.errors import ConfigError
from confined_rod.io import check_finite
from confined_rod.pipeline.schema import render, scene_schema
from confined_rod.quantities import SCENE_PARAMETERS, param_text

from .shapes import sliding_friction

ROOT = Path(__file__).resolve().parents[1]


# -- registry, declarations, schema ------------------------------------------------------
def test_every_kind_module_has_the_interface():
    assert {"transmitted_force", "force_profile", "convergence", "time_vs_error", "stability_map",
            "pitch_profile", "helix_views"} <= set(figures.kinds())
    for k in figures.kinds():
        m = figures.get(k)
        for fn in ("build", "plot", "caption"):
            assert callable(getattr(m, fn)), (k, fn)
        assert callable(getattr(m, "validate", None)) or callable(getattr(m, "validate_config", None)), k
    with pytest.raises(ConfigError, match="'nope' is not one of"):
        figures.get("nope")


def test_scene_parameters_are_declared_once_and_agree_with_scene():
    fields = set(Scene.field_names()) - {"name"}
    assert [q.name for q in SCENE_PARAMETERS] == [k for k in Scene.field_names() if k != "name"]
    # plus the one config-only entry: seeds (an ensemble of scenes, expanded by the pipeline)
    assert set(scene_schema()["properties"]) == fields | {"seeds"}
    for q in SCENE_PARAMETERS:  # the same object serves the dataset attributes and the figure symbols
        assert QUANTITIES[q.name] is q
        assert q.long_name and q.units  # every parameter is described and has a unit
    # categorical values: Scene accepts exactly the declared ones
    for q in SCENE_PARAMETERS:
        for v in q.choices:
            Scene(**{q.name: v})
    assert param_text("L", 320) == r"$L = 320\,R$" and param_text("k_fr", 0.8) == r"$k_{fr} = 0.8$"


def test_committed_schema_is_the_generated_one():
    committed = (ROOT / "workflow/schemas/config.schema.yaml").read_text()
    assert committed == render(), "regenerate: python -m confined_rod schema -o workflow/schemas/config.schema.yaml"


def test_postprocessing_never_imports_the_simulator():
    """At run time, beside the static import contracts (pyproject.toml, lint-imports): every module
    of analysis/ and claims/ imported, and every figure kind, loads neither sim/ nor numba."""
    code = ("import importlib, pkgutil, sys\n"
            "for pkg in ('confined_rod.analysis', 'confined_rod.analysis.figures', 'confined_rod.claims'):\n"
            "    p = importlib.import_module(pkg)\n"
            "    for m in pkgutil.iter_modules(p.__path__):\n"
            "        importlib.import_module(f'{pkg}.{m.name}')\n"
            "bad = sorted(m for m in sys.modules if m.startswith('confined_rod.sim') or m == 'numba')\n"
            "print(bad); sys.exit(1 if bad else 0)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 0, out.stdout + out.stderr


# -- the helix relation (Fig 5) -------------------------------------------------------------
def test_helix_pitch_rate_inverts_the_helix_force():
    w = np.array([1e-3, 0.1, 0.3, 0.5, 0.8])  # R w < sqrt(2/3) = 0.816
    F = theory.helix_force(w)
    np.testing.assert_allclose(theory.helix_pitch_rate(F), w, rtol=1e-9)
    # scaling law: the force F EI/R^2 on a rod of stiffness EI in a pore of radius R winds at w(F)/R
    np.testing.assert_allclose(theory.helix_pitch_rate(F * 0.75 / 2.0**2, R=2.0, EI=0.75),
                               theory.helix_pitch_rate(F) / 2.0, rtol=1e-9)
    assert theory.helix_pitch_rate(1e-6) ** 2 == pytest.approx(1e-6 / 2, rel=1e-5)  # lowest order
    with pytest.raises(ValueError, match="largest force a helix"):
        theory.helix_pitch_rate(0.8)


@pytest.fixture(scope="module")
def frictionless_helix():
    # implicit solver, publication numerics, about 1 s
    return simulate(Scene(L=60.0, load=0.25, k_fr=0.0, k_ph=1e4, tol=1e-6), progress=False)


def test_pitch_profile_satisfies_the_helix_relation_without_friction(frictionless_helix):
    """Without friction the bulk is a torque-free helix: |F_z| = 2 EI w^2 sqrt(1 - R^2 w^2)
    with the measured w. The discrete helix (chords of l0 = 0.5 R) differs from the
    continuum by O((w l0)^2/12) = 0.3 % at w = 0.37 (measured 0.26 % at L/R = 640); 1 %."""
    ds = postprocess.build("fig5", {"kind": "pitch_profile", "title": "t"}, {"c": frictionless_helix})
    check_finite(ds)
    bulk = ds.in_bulk.values == 1
    assert bulk.sum() > 40
    assert float(ds.helix_ratio_median) == pytest.approx(1.0, abs=0.01)
    # pointwise in the middle half: the pitch relaxes to the bulk value over ~10 R from each end
    # transition zone (measured 12 % off at the stretch's first tenth on this short rod)
    mid = bulk & (np.abs(ds.s_helix.values - 30.0) < 15.0)
    np.testing.assert_allclose(ds.helix_ratio.values[mid], 1.0, atol=0.01)
    np.testing.assert_allclose(np.abs(ds.omega.values[mid]), ds.omega_helix.values[mid], rtol=0.01)
    assert abs(float(ds.drop_F)) < 1e-3  # no friction: the force does not fall along the rod


def test_pitch_profile_on_a_model_helix_with_a_reversal():
    """Synthetic: |F| decays, w = helix_pitch_rate(|F|) exactly, handedness flips once.
    The ratio is 1 wherever the pitch is defined, the reversal is found between the right
    links, and the slope of ln w against ln F is the exact relation's (about 1/2)."""
    n = 200
    s = (np.arange(n) + 0.5) * 0.5
    F_j = 0.2 / (1 + 0.02 * np.arange(n + 1) * 0.5)
    F_l = 0.5 * (F_j[1:] + F_j[:-1])
    w = theory.helix_pitch_rate(F_l)
    w[120:] *= -1
    phi = np.concatenate([[0.0], np.cumsum(0.5 * 0.5 * (w[1:] + w[:-1]))])
    sim = xr.Dataset({"F_z": ("s", -F_j), "contact": ("s_link", np.ones(n, np.int8)), "dphi_ds": ("s_helix", w),
                      "phi": ("s_helix", phi), **sliding_friction(F_j, 0.8)},
                     coords={"s_link": ("s_link", s), "s_helix": ("s_helix", s), "s": ("s", np.arange(n + 1) * 0.5)},
                     attrs={"R": 1.0, "EI": 1.0, "L": 100.0, "l0": 0.5, "load": 0.2, "k_fr": 0.8})
    ds = postprocess.build("fig5", {"kind": "pitch_profile", "title": "t"}, {"m": sim})
    assert ds.attrs["n_reversals"] == 1
    assert float(ds.s_reversal[0]) == pytest.approx(0.5 * (s[119] + s[120]))
    ok = ds.pitch_defined.values == 1
    assert not ok[117:123].any() and ok[:117].all() and ok[123:].all()  # 2 links either side of the pair
    np.testing.assert_allclose(ds.helix_ratio.values[ok], 1.0, rtol=1e-9)
    assert 0.45 < float(ds.exponent_omega_F) < 0.6
    # the same slope over the whole stretch and over the detected bulk (here the whole rod)
    assert float(ds.exponent_omega_F_bulk) == pytest.approx(float(ds.exponent_omega_F_whole), abs=0.02)
    assert ds.attrs["claim_holds"] == 1 and 0 < float(ds.drop_omega) < float(ds.drop_F)


# -- Fig 1 ---------------------------------------------------------------------------------
def test_helix_views_dataset_and_figure(tmp_path):
    sims = {f"L{L}": simulate(Scene(L=float(L), load=0.25, k_fr=0.0, l0=1.0, tol=1e-4), progress=False)
            for L in (10, 40)}
    cfg = {"kind": "helix_views", "title": "t", "paper_euler_ratio": {"L10": 10}, "column_length": 15}
    ds = postprocess.build("fig1", cfg, sims)
    check_finite(ds)
    # the caption's ratio: load L^2 / (pi^2 EI), 2.5 at L = 10 (the paper's 10 is for L = 20)
    assert float(ds.euler_ratio.sel(scene="L10")) == pytest.approx(0.25 * 100 / np.pi**2, rel=1e-12)
    assert float(ds.paper_euler_ratio.sel(scene="L10")) == 10 and float(ds.paper_euler_ratio.sel(scene="L40")) == 0
    for n in ("L10", "L40"):
        rho = np.hypot(ds[f"x_{n}"], ds[f"y_{n}"]).values
        assert rho.max() < 1.0 + 1e-3  # inside the pore to the penalty's resolution
        assert int(ds[f"contact_{n}"].sum()) == int(sims[n].contact.sum())
    L40 = ds.sel(scene="L40")
    assert 0 < float(L40.detached_top) < 40 and 0 < float(L40.detached_bottom) < 40
    plotting.plot(ds, tmp_path / "f.pdf", tmp_path / "f.png")
    assert (tmp_path / "f.png").stat().st_size > 20_000


# -- Figs 4 / 7: the paper's printed fits, and the saddle guard -------------------------------
def _model_sim(L=200.0, N=200, k_fr=0.8, load=0.25, contact=True):
    s = np.linspace(0.0, L, N + 1)
    s_link = 0.5 * (s[1:] + s[:-1])
    F = theory.force_decay(s, load, k_fr)
    attrs = {k: v for k, v in Scene(L=L, k_fr=k_fr, load=load, l0=L / N).to_dict().items()
             if not isinstance(v, (tuple, type(None)))}
    return xr.Dataset(
        {"F_z": ("s", -F), "contact": ("s_link", np.full(N, int(contact), np.int8)),
         **sliding_friction(F, k_fr),
         "phi": ("s_helix", np.linspace(0, 9, N)), "F_transmitted": ((), F[-1]), "converged": ((), np.int8(1))},
        coords={"s": ("s", s), "s_link": ("s_link", s_link)}, attrs={**attrs, "git_commit": "test"})


def test_paper_fit_comparison_is_stored_both_ways():
    """A printed fit equal to the data (the simple model is A (l0' + s)^-1 with A = 4EI/(k_fr R),
    l0' = 4EI/(k_fr R F0)) deviates by 0; a printed fit with another l0' by a known amount."""
    sim = _model_sim()
    A, l0p = 4.0 / 0.8, 4.0 / (0.8 * 0.25)
    cfg = {"kind": "force_profile", "title": "t", "paper_fits": {"same": {"A": A, "l0": l0p, "c": -1.0},
                                                                  "other": {"A": A, "l0": 2 * l0p, "c": -1.0}}}
    ds = postprocess.build("fig7", cfg, {"same": sim, "other": sim, "none": sim})
    same, other, none = (ds.sel(panel=p) for p in ("same", "other", "none"))
    assert float(same.paper_rms_log_ratio) == pytest.approx(0.0, abs=1e-9)
    expect = float(sim.F_transmitted) / 0.25
    for v in (same.paper_fit_fraction, same.fit_fraction, same.transmitted_fraction):
        assert float(v) == pytest.approx(expect, rel=1e-6)
    assert float(other.paper_fit_fraction) == pytest.approx(2 * l0p / (2 * l0p + 200.0), rel=1e-12)
    assert float(other.paper_rms_log_ratio) > 0.1
    assert int(none.has_paper_fit) == 0 and float(none.F_paper_fit.max()) == 0.0
    # every link slides axially at the limit: the whole rod is bulk helix, and its local decay
    # rate is the simple model's k_fr R/(4EI) (the profile was built with it)
    assert int(same.has_bulk) == 1 and float(same.tip_length) <= 1.0 and float(same.lower_length) <= 1.0
    assert float(same.decay_ratio) == pytest.approx(1.0, rel=1e-6)
    assert float(same.bulk_decay_rate) == pytest.approx(0.8 / 4.0, rel=1e-6)
    assert float(same.fit_c_bulk) == pytest.approx(-1.0, abs=1e-6)


def test_a_profile_without_wall_contact_is_refused():
    with pytest.raises(ValueError, match="saddle"):
        postprocess.build("fig7", {"kind": "force_profile", "title": "t"}, {"x": _model_sim(contact=False)})


# -- the paper's bending constant, as printed ---------------------------------------------------
def test_paper_bending_constant_is_a_stiffer_rod():
    """C = EI/l0^2 (as printed, R = 1) is the corrected C = EI_eff/l0 of a rod with
    EI_eff = EI R/l0: the two scenes have the same discrete energy, hence the same
    equilibrium (frictionless: unique), to the equilibrium tolerance."""
    a = Scene(L=10.0, load=0.5, k_fr=0.0, l0=0.5, bending_constant="paper", tol=1e-6)
    b = Scene(L=10.0, load=0.5, k_fr=0.0, l0=0.5, EI=2.0, k_ph=1000.0 * 2, k_w=1000.0 * 2,
              friction_cap=0.05 * 2, tol=1e-6)
    assert a.constants().C == pytest.approx(4.0) and b.constants().C == pytest.approx(4.0)
    b = dataclasses.replace(b, k_ph=a.k_ph, k_w=a.k_w, friction_cap=a.friction_cap)
    ra, rb = (simulate(s, progress=False) for s in (a, b))
    np.testing.assert_allclose(ra.F_z.values, rb.F_z.values, atol=1e-5)
    np.testing.assert_allclose(ra.x.values, rb.x.values, atol=1e-4)
    assert int(ra.contact.sum()) == int(rb.contact.sum()) > 0


def test_new_config_entries_are_checked_before_any_work():
    import copy

    import yaml

    from confined_rod import pipeline
    from confined_rod.errors import SceneError

    config = yaml.safe_load((ROOT / "config/ci.yaml").read_text())
    bad = copy.deepcopy(config)
    bad["figures"]["fig4_Fonl"]["paper_fits"]["d"] = {"A": 1.0, "l0": 1.0, "c": -1.0}
    with pytest.raises(ConfigError, match=r"fig4_Fonl\.paper_fits: 'd' is not one of its scenes"):
        pipeline.validate(bad)
    bad = copy.deepcopy(config)
    bad["figures"]["fig5_pitch"]["scenes"]["d"] = {"L": 20}
    with pytest.raises(ConfigError, match=r"fig5_pitch\.scenes: a pitch profile shows one rod, got 2"):
        pipeline.validate(bad)
    bad = copy.deepcopy(config)
    bad["figures"]["fig7_tiny_force_as_printed"]["defaults"]["bending_constant"] = "wrong"
    with pytest.raises(ConfigError, match=r"'bending_constant': 'wrong' \(must be one of corrected, paper\)"):
        pipeline.validate(bad)
    with pytest.raises(SceneError, match="bending_constant"):
        Scene(bending_constant="EI/l0^2")


def test_a_figure_is_written_atomically_and_a_killed_writers_temporary_is_removed(tmp_path):
    """Figures go through io.atomic_write like the datasets: the temporary of a writer killed
    earlier (a pid that cannot run) is removed by the next write of the same file."""
    import matplotlib.pyplot as plt

    from confined_rod.analysis.plotting import _save

    target = tmp_path / "f.png"
    stale = tmp_path / ".f.png.999999999.tmp"
    stale.write_bytes(b"half a figure")
    fig = plt.figure()
    fig.add_subplot().plot([0, 1])
    _save(fig, target)
    plt.close(fig)
    assert target.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["f.png"]


def test_a_caption_names_a_style_by_what_is_drawn():
    """plotting.words turns a named style into the caption's words; every named style has words."""
    assert plotting.words(plotting.MODEL) == "blue dashed"
    assert plotting.words(plotting.PAPER) == "grey dotted"
    assert plotting.words(plotting.PAPER_FIT) == "orange dash-dotted"
    assert plotting.words(plotting.SIM) == "black"
    for style in (plotting.FIT, plotting.SEEDS, plotting.GUIDE, plotting.MARK, plotting.CONTACT, plotting.WALL,
                  plotting.FOLDED, plotting.ENSEMBLE_BAND, *plotting.REGIONS.values()):
        assert plotting.words(style)
