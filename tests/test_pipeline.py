"""Pipeline configuration (figure -> scenes -> parameters), its schema, the per-figure
datasets and the figures. The Snakemake run itself is exercised by .ci/run."""
import collections
import copy
import os
import subprocess
import sys
from pathlib import Path

import jsonschema
import numpy as np
import pytest
import xarray as xr
import yaml

from confined_rod import Scene, layout, pipeline, theory
from confined_rod.analysis import plotting, postprocess
from confined_rod.io import logged, write_dataset

from .shapes import sliding_friction

ROOT = Path(__file__).resolve().parents[1]
SCHEMA = yaml.safe_load((ROOT / "workflow/schemas/config.schema.yaml").read_text())
CONFIGS = [ROOT / "config/config.yaml", ROOT / "config/ci.yaml"]


def load(path):
    return yaml.safe_load(Path(path).read_text())


@pytest.mark.parametrize("path", CONFIGS, ids=lambda p: p.name)
def test_shipped_configs_are_valid(path):
    config = load(path)
    jsonschema.validate(config, SCHEMA)
    pipeline.validate(config)
    out = pipeline.expected_outputs(config)
    assert len(out["datasets"]) == len(config["figures"])
    assert len(out["figures"]) == 2 * len(config["figures"])


def test_schema_knows_exactly_the_scene_fields():
    fields = set(Scene.field_names()) - {"name"}
    # plus seeds: a seed ensemble, expanded into one scene per seed by the pipeline
    assert set(SCHEMA["$defs"]["scene"]["properties"]) == fields | {"seeds"}


def test_schema_rejects_unknown_keys_and_bad_types():
    config = load(CONFIGS[1])
    bad = copy.deepcopy(config)
    bad["figures"]["fig6_FonL"]["scenes"]["L10"]["lenght"] = 10
    with pytest.raises(jsonschema.ValidationError, match="lenght"):
        jsonschema.validate(bad, SCHEMA)
    bad = copy.deepcopy(config)
    bad["figures"]["fig6_FonL"]["defaults"]["k_fr"] = "lots"
    with pytest.raises(jsonschema.ValidationError, match="lots"):
        jsonschema.validate(bad, SCHEMA)


def test_validate_names_the_entry_and_the_value():
    config = load(CONFIGS[1])
    bad = copy.deepcopy(config)
    bad["figures"]["fig6_FonL"]["scenes"]["L20"]["L"] = 0.5  # shorter than l0 = 1
    with pytest.raises(pipeline.ConfigError, match=r"figures\.fig6_FonL\.scenes\.L20-s0: .*'l0'.*L = 0\.5"):
        pipeline.validate(bad)
    bad = copy.deepcopy(config)
    bad["figures"]["fig4_Fonl"]["scenes"]["b"]["seed"] = 7  # panels may differ only in k_fr
    with pytest.raises(pipeline.ConfigError, match=r"fig4_Fonl\.scenes\.b: seed = 7"):
        pipeline.validate(bad)
    bad = copy.deepcopy(config)
    bad["figures"]["fig4_Fonl"]["scenes"]["b"]["l0"] = 0.25  # a panel's own numerics: only the path's
    with pytest.raises(pipeline.ConfigError, match=r"fig4_Fonl\.scenes\.b.*: l0 = 0\.25 differs .*ramp_steps\)"):
        pipeline.validate(bad)
    ramped = copy.deepcopy(config)
    ramped["figures"]["fig4_Fonl"]["defaults"].update(protocol="ramp", ramp_steps=64)
    ramped["figures"]["fig4_Fonl"]["scenes"]["b"]["ramp_steps"] = 128
    pipeline.validate(ramped)  # a panel ramps more slowly: allowed, and named in the caption
    assert "(b) k_fr = 0.3, ramp_steps = 128" in pipeline.caption(ramped, "fig4_Fonl")
    bad = copy.deepcopy(config)
    bad["figures"]["fig4_Fonl"]["panel_parameter"] = "friction"
    with pytest.raises(pipeline.ConfigError, match="'friction' is not a Scene field"):
        pipeline.validate(bad)


def test_shared_scenes_are_simulated_once():
    config = pipeline.expand(load(CONFIGS[0]))
    # Fig 4(c) (L 320, load 0.25, k_fr 0.8, seed 0) is the seed-0 member of the L = 320 point of Fig 6
    assert pipeline.canonical_scene(config, "fig4_Fonl", "c-s0") == ("fig6_FonL", "L320-s0")
    assert pipeline.canonical_scene(config, "fig4_Fonl", "c-s4") == ("fig6_FonL", "L320-s4")
    assert pipeline.canonical_scene(config, "fig4_Fonl", "a-s0") == ("fig4_Fonl", "a-s0")
    # every convergence ladder's publication rung is a scene simulated anyway
    assert pipeline.canonical_scene(config, "conv_l0", "l0_05-s0") == ("fig6_FonL", "L80-s0")
    assert pipeline.canonical_scene(config, "conv_l0", "l0_05-s7")[0] == "conv_l0"       # beyond Fig 6's seeds
    assert pipeline.canonical_scene(config, "conv_tol", "tol5-s0") == ("fig6_FonL", "L80-s0")
    assert pipeline.canonical_scene(config, "conv_k_ph", "k10000-s3") == ("fig6_FonL", "L80-s3")
    assert pipeline.canonical_scene(config, "conv_k_ph_frictionless", "k10000") == ("conv_l0_frictionless", "l0_05")
    # the jamming map's points at the paper's load and friction are Fig 6's seeds
    assert pipeline.canonical_scene(config, "jamming_map", "L80-F0p25-k0p8-s2") == ("fig6_FonL", "L80-s2")
    sims = pipeline.expected_outputs(config)["sims"]
    # Fig 5 shows the rod of Fig 4(c): the same simulation, not a new run
    assert pipeline.canonical_scene(config, "fig5_pitch", "c") == ("fig6_FonL", "L320-s0")
    by_folder = collections.Counter(str(Path(p).parent) for p in sims)
    assert len(sims) == len(set(sims)) == sum(by_folder.values())
    # Fig 6: 6 lengths x 5 seeds; Fig 4: 5 seeds of (a) and the 2 seeds of (b) beyond the jamming
    # map's 3 ((c) is Fig 6's L/R = 320);
    # the l0 ladder: 5 rungs x 64 seeds less the 5 of Fig 6; the jamming map: 72 points (6 L x 2 loads
    # x 2 k_fr x 3 seeds) less the 15 of Fig 6
    folder = lambda place, figure: str(place / figure)  # noqa: E731
    assert by_folder[folder(layout.SIMS, "fig6_FonL")] == 30 and by_folder[folder(layout.SIMS, "fig4_Fonl")] == 5 + 2
    assert by_folder[folder(layout.SIMS, "conv_l0")] == 5 * 64 - 5
    assert by_folder[folder(layout.SIMS, "jamming_map")] == 72 - 15
    assert by_folder[folder(layout.PROBES, "stability_map")] == 57
    assert sum(str(Path(p).parent) == folder(layout.PATHS, "fig3_bifurcation") for p in sims) == 11


def test_snakemake_stops_on_a_bad_config_before_any_job(tmp_path):
    snakemake = Path(sys.executable).with_name("snakemake")
    if not snakemake.exists():
        pytest.skip("snakemake not installed (pip install -e .[workflow])")
    config = load(CONFIGS[1])
    config["figures"]["fig6_FonL"]["scenes"]["L20"]["k_fr"] = -1.0
    bad = tmp_path / "bad.yaml"
    bad.write_text(yaml.safe_dump(config))
    out = subprocess.run([str(snakemake), "-n", "--configfile", str(bad), "--cores", "1"], cwd=ROOT,
                         capture_output=True, text=True, timeout=120,
                         env={**os.environ})
    assert out.returncode != 0
    msg = out.stdout + out.stderr
    assert "k_fr" in msg and "-1.0" in msg and "Job stats" not in msg


def test_deleted_datasets_and_simulations_are_rebuilt(tmp_path):
    """Every product of the CI config present (empty files, newer than the code) except the
    datasets and the simulations: the default target plans them again (the datasets are
    products; a build that kept only figures and the paper used to answer 'Nothing to be done')."""
    snakemake = Path(sys.executable).with_name("snakemake")
    if not snakemake.exists():
        pytest.skip("snakemake not installed (pip install -e .[workflow])")
    config = load(CONFIGS[1])
    outs = pipeline.expected_outputs(copy.deepcopy(config))
    for kind in ("figures", "checks", "paper"):
        for p in outs[kind]:
            (tmp_path / p).parent.mkdir(parents=True, exist_ok=True)
            (tmp_path / p).write_text("")
    out = subprocess.run([str(snakemake), "-n", "--snakefile", str(ROOT / "Snakefile"), "--directory", str(tmp_path),
                          "--configfile", str(CONFIGS[1]), "--cores", "1", "--quiet", "rules"], cwd=ROOT,
                         capture_output=True, text=True, timeout=300, env={**os.environ})
    msg = out.stdout + out.stderr
    assert out.returncode == 0, msg[-2000:]
    planned = {line.split()[0]: int(line.split()[1]) for line in msg.splitlines()
               if len(line.split()) == 2 and line.split()[1].isdigit()}
    assert planned.get("postprocess") == len(outs["datasets"]), msg[-2000:]
    assert planned.get("simulate", 0) > 0


# -- per-figure datasets built from model data -------------------------------------------
def fake_sim(L, k_fr, load=0.25, N=100, s_h=2.0, F_end=None):
    """A scene dataset whose force profile is the simple model from s_h on (constant before)."""
    s = np.linspace(0.0, L, N + 1)
    s_link = 0.5 * (s[1:] + s[:-1])
    F = theory.force_decay(np.maximum(s - s_h, 0.0), load, k_fr)
    contact = (s_link >= s_h).astype(np.int8)
    phi = np.linspace(0, 3 * np.pi, int(contact.sum()))
    attrs = dict(Scene(L=L, k_fr=k_fr, load=load, l0=L / N).to_dict())
    attrs = {k: v for k, v in attrs.items() if not isinstance(v, (tuple, type(None)))}
    return xr.Dataset(
        {"F_z": ("s", -F), "contact": ("s_link", contact), "phi": ("s_helix", phi), **sliding_friction(F, k_fr),
         "F_transmitted": ((), F[-1] if F_end is None else F_end), "L_z": ((), 0.9 * L),
         "converged": ((), np.int8(1)), "escaped": ((), np.int8(0)), "residual_force": ((), 1e-6),
         "wall_time": ((), 1.0)},
        coords={"s": ("s", s), "s_link": ("s_link", s_link)}, attrs={**attrs, "git_commit": "test"})


def test_force_profile_fit_recovers_the_simple_model():
    """On model data |F| = 4EI/(k_fr R) / (s - s_h - l_c) the fit must give c = -1,
    A = 4EI/(k_fr R) and l0' = -l_c - s_h, and the stored model curve equals the data."""
    cfg = {"kind": "force_profile", "panel_parameter": "k_fr", "paper_figure": 4, "title": "t"}
    sims = {"a": fake_sim(200.0, 0.1), "b": fake_sim(200.0, 0.8)}
    ds = postprocess.build("fig4", cfg, sims)
    for i, k_fr in enumerate((0.1, 0.8)):
        d = ds.isel(panel=i)
        assert float(d.fit_c) == pytest.approx(-1.0, abs=1e-6)
        assert float(d.fit_A) == pytest.approx(4.0 / k_fr, rel=1e-5)
        assert float(d.fit_l0) == pytest.approx(-theory.critical_length(0.25, k_fr) - 2.0, rel=1e-5)
        np.testing.assert_allclose(d.F_simple, d.F_abs, rtol=1e-12)
        assert float(d.panel_value) == k_fr
        # the contact stretch from s_h on is all bulk helix, decaying by the corrected local law
        assert int(d.has_bulk) == 1 and float(d.decay_ratio) == pytest.approx(1.0, rel=1e-6)
        assert float(d.s_bulk_start) == pytest.approx(2.0, abs=0.5 * 4.0 + 2.0)
    np.testing.assert_allclose(ds.F_simple_paper.values[:, 0], 0.25)
    assert float(ds.F_simple_paper.isel(panel=1)[-1]) < float(ds.F_simple.isel(panel=1)[-1])
    for name, var in ds.variables.items():
        assert "long_name" in var.attrs, name
        if var.dtype.kind == "f":
            assert np.all(np.isfinite(var.values)), name


def test_transmitted_force_dataset_and_figures(tmp_path):
    cfg = {"kind": "transmitted_force", "paper_figure": 6, "title": "t"}
    sims = {f"L{L}": fake_sim(float(L), 0.8) for L in (40, 20, 80)}
    ds = postprocess.build("fig6", cfg, sims)
    assert list(ds.L.values) == [20.0, 40.0, 80.0]  # sorted by L
    np.testing.assert_allclose(ds.F_simple, 1.0 / (4.0 + 0.2 * ds.L_model), rtol=1e-12)
    np.testing.assert_allclose(ds.F_simple_paper, 1.0 / (4.0 + 0.4 * ds.L_model), rtol=1e-12)
    path = write_dataset(ds, tmp_path / "fig6.nc")
    back = xr.load_dataset(path)
    plotting.plot(back, tmp_path / "fig6.pdf", tmp_path / "fig6.png")
    assert (tmp_path / "fig6.pdf").read_bytes().startswith(b"%PDF")
    assert (tmp_path / "fig6.png").stat().st_size > 10_000
    back["F_transmitted"][0] = np.nan
    with pytest.raises(ValueError, match="F_transmitted"):
        plotting.plot(back, tmp_path / "x.pdf", tmp_path / "x.png")
    assert not (tmp_path / "x.pdf").exists()


def test_captions_state_what_and_with_which_parameters():
    config = load(CONFIGS[0])
    c6 = pipeline.caption(config, "fig6_FonL")
    assert "the paper's sixth figure" in c6 and "L/R = 20, 40, 80, 160, 320, 640" in c6
    assert "k_fr = 0.8" in c6 and "load |F_z(0)| = 0.25" in c6 and "l0 = 0.5" in c6 and "4EI" in c6
    c4 = pipeline.caption(config, "fig4_Fonl")
    assert "the paper's fourth figure" in c4 and "L/R = 320" in c4
    assert "(a) k_fr = 0.1; (b) k_fr = 0.3; (c) k_fr = 0.8" in c4
    c_map = pipeline.caption(config, "jamming_map")     # a figure the original does not have
    assert "(not in the paper)" in c_map and "paper's" not in c_map


def test_logged_keeps_the_traceback(tmp_path):
    log = tmp_path / "sub" / "job.log"
    with pytest.raises(ZeroDivisionError):
        with logged(log):
            print("started")
            1 / 0
    text = log.read_text()
    assert "started" in text and "ZeroDivisionError" in text


def test_numerical_study_figures_are_validated():
    config = load(ROOT / "config/ci.yaml")
    bad = copy.deepcopy(config)
    del bad["figures"]["conv_l0"]["scenes"]["l0_1"]  # the publication value l0 = 1 is no longer a rung
    with pytest.raises(pipeline.ConfigError, match=r"conv_l0.*at least 3 values|conv_l0.*publication value"):
        pipeline.validate(bad)
    bad = copy.deepcopy(config)
    bad["figures"]["conv_k_ph"]["scenes"]["k100"]["L"] = 30  # rungs must differ only in k_ph
    with pytest.raises(pipeline.ConfigError, match=r"conv_k_ph.*differ only in k_ph"):
        pipeline.validate(bad)
    bad = copy.deepcopy(config)
    bad["figures"]["benchmark_time_vs_error"]["reference"] = "nope"
    with pytest.raises(pipeline.ConfigError, match=r"benchmark_time_vs_error\.reference: 'nope'"):
        pipeline.validate(bad)
    # one reference per k_ph: a run whose k_ph has none, and two references of one k_ph, are refused
    bad = copy.deepcopy(config)
    bad["figures"]["benchmark_time_vs_error"]["reference"] = ["ref"]
    with pytest.raises(pipeline.ConfigError, match=r"benchmark_time_vs_error\.scenes\.\w+_k4: k_ph = 10000 has no "
                                                   r"reference scene"):
        pipeline.validate(bad)
    bad = copy.deepcopy(config)
    bad["figures"]["benchmark_time_vs_error"]["reference"] = ["ref", "imp_l1_d02", "ref_k4"]
    with pytest.raises(pipeline.ConfigError, match=r"benchmark_time_vs_error\.reference: .* two scenes of the "
                                                   r"same k_ph"):
        pipeline.validate(bad)
    assert pipeline.publication_value(config, "conv_l0") == 1.0
    assert pipeline.publication_value(config, "conv_k_ph") == Scene(L=10.0).k_ph  # Scene default
    # a setting of some figures only (the ramped ones) is the figure's own publication_value
    assert pipeline.publication_value(config, "conv_ramp_steps") == 128.0 != Scene(L=10.0).ramp_steps
    outs = pipeline.expected_outputs(config)
    assert sorted(outs["checks"]) == sorted(layout.check_path(f) for f in
                                            ("conv_l0", "conv_k_ph", "conv_l0_friction", "conv_ramp_steps",
                                             "conv_ramp_steps_b"))


def test_a_ladder_serves_only_the_rod_of_its_publication_rung():
    """``serves`` names figure scenes whose ensemble means a ladder vouches for: resolved to their
    seed counts and the quantities their kinds report, and refused (naming the entry and why) when
    the scene is missing, reports nothing a ladder compares, or is another rod."""
    config = load(ROOT / "config/config.yaml")
    served = pipeline.context(config, "conv_ramp_steps_a")["served"]
    seeds = config["figures"]["fig4_Fonl_ramp"]["defaults"]["seeds"]
    assert served == [{"name": "fig4_Fonl_ramp.a", "seeds": seeds, "reports": ["F_transmitted", "decay_ratio"]}]
    assert pipeline.context(config, "conv_l0")["served"] == []
    for entry, why in (("fig4_Fonl_ramp.b", r"not the rod of this ladder's publication rung \(k_fr 0\.3 against "
                                            r"0\.1; ramp_steps 256 against 128\)"),
                       ("nope.a", r"is not '<figure>\.<scene>' of another figure"),
                       ("fig4_Fonl_ramp.z", r"figure 'fig4_Fonl_ramp' has no scene 'z' \(scenes: a, b, c\)"),
                       ("fig2_transition.seed0", r"kind 'transition'\) reports no ensemble mean")):
        bad = copy.deepcopy(config)
        bad["figures"]["conv_ramp_steps_a"]["serves"] = [entry]
        head = r"figures\.conv_ramp_steps_a\.serves: '" + entry.replace(".", r"\.") + "'.*"
        with pytest.raises(pipeline.ConfigError, match=head + why):
            pipeline.validate(bad)


@pytest.mark.parametrize("order", ["ensemble first", "entry first"])
def test_a_seed_ensemble_and_an_entry_of_the_same_expanded_name_are_refused(order):
    """`L20: {seeds: 2}` beside `L20-s1` used to drop one of them silently (a caption then spoke
    of 1.5 runs per length); the config is refused, naming both entries, in either order."""
    config = load(CONFIGS[1])
    entries = [("L20", {"L": 20, "seeds": 2}), ("L20-s1", {"L": 20, "seed": 1, "k_fr": 0.3})]
    if order == "entry first":
        entries.reverse()
    config["figures"]["fig6_FonL"]["scenes"] = dict(entries)
    config["figures"]["fig6_FonL"]["defaults"].pop("seeds", None)      # L20-s1 is then a single run
    with pytest.raises(pipeline.ConfigError, match=r"figures\.fig6_FonL\.scenes: .*'L20'.* and .*'L20-s1'.*|"
                                                   r"figures\.fig6_FonL\.scenes: .*'L20-s1'.* and .*'L20'.*"):
        pipeline.expand(config)


def test_jamming_map_loads_that_round_to_one_name_are_refused():
    config = load(CONFIGS[1])
    config["figures"]["jamming_map"]["grid"]["load"] = [0.1, 0.1000001, 0.25]
    with pytest.raises(pipeline.ConfigError, match=r"figures\.jamming_map\.grid\.load: 0\.1 and 0\.1000001"):
        pipeline.expand(config)
    config["figures"]["jamming_map"]["grid"]["load"] = [0.1, 0.1001]     # distinct names: accepted
    names = pipeline.expand(config)["figures"]["jamming_map"]["scenes"]
    assert any("-F0p1-" in n for n in names) and any("-F0p1001-" in n for n in names)


def test_code_inputs_follow_the_imports_and_never_reach_the_simulator():
    """A kind's code inputs are the modules it imports, transitively: editing the helper that the
    escape and transition kinds import from helix_views re-runs their figures too; the styling is
    not an input of a step that makes data; no analysis or claims step depends on simulator code
    (the import boundary, read from the source); the simulations depend on every module of sim/
    and on no figure quantity, and the claims not on the manuscript generator."""
    from confined_rod.pipeline import code

    pkg = code.PACKAGE
    rel = lambda paths: {Path(p).relative_to(pkg).as_posix() for p in paths}  # noqa: E731
    for kind in ("escape", "transition"):
        assert "analysis/figures/helix_views.py" in rel(code.code_closure(code.ANALYSIS / "figures" / f"{kind}.py"))
    data = rel(code.postprocess_code(code.ANALYSIS / "figures" / "escape.py"))
    assert "analysis/plotting.py" not in data
    assert {"analysis/postprocess.py", "analysis/figures/escape.py", "analysis/measure.py"} <= data
    for module in [*sorted(code.ANALYSIS.rglob("*.py")), *sorted(code.CLAIMS.rglob("*.py"))]:
        reached = rel(code.code_closure(module))
        assert not any(r.startswith("sim/") for r in reached), (module.name, sorted(reached))
    sim = rel(code.simulation_code())
    assert {p.relative_to(pkg).as_posix() for p in code.SIM.rglob("*.py")} <= sim
    assert {"quantities.py", "io.py", "limits.py", "theory.py"} <= sim
    assert not any(r.startswith(("analysis/", "claims/", "pipeline/")) for r in sim), sorted(sim)
    assert "claims/manuscript.py" not in rel(code.claims_code())
    assert "claims/manuscript.py" in rel(code.paper_code())


def test_a_code_stamp_changes_with_a_module_and_is_dated_like_the_newest(tmp_path):
    """A step's code enters its rule as one stamp: the modules' checksums, rewritten when one
    changes (Snakemake compares its checksum) and dated like the newest module (its mtime trigger),
    so a re-run happens exactly when it did with the modules themselves as inputs."""
    import os

    from confined_rod.pipeline import code

    mods = [tmp_path / "pkg" / n for n in ("a.py", "b.py")]
    mods[0].parent.mkdir()
    for i, m in enumerate(mods):
        m.write_text(f"x = {i}\n")
        os.utime(m, ns=(10**18 + i * 10**9, 10**18 + i * 10**9))
    orig, code.PACKAGE = code.PACKAGE, tmp_path / "pkg"   # the paths in the stamp are relative to it
    try:
        out = Path(code.stamp("demo", [str(m) for m in mods], tmp_path / "s" / "demo.sha256"))
        first = out.read_text()
        assert out.stat().st_mtime_ns == 10**18 + 10**9
        assert first.count("pkg/") == 2 and "a.py" in first
        code.stamp("demo", [str(m) for m in mods], out)                  # nothing changed
        assert out.read_text() == first
        os.utime(mods[0], ns=(2 * 10**18, 2 * 10**18))                   # touched only: same checksums
        code.stamp("demo", [str(m) for m in mods], out)
        assert out.read_text() == first and out.stat().st_mtime_ns == 2 * 10**18
        mods[1].write_text("x = 5\n")                                    # a change of content
        code.stamp("demo", [str(m) for m in mods], out)
        assert out.read_text() != first and out.stat().st_mtime_ns == max(m.stat().st_mtime_ns for m in mods)
    finally:
        code.PACKAGE = orig


def test_expand_leaves_the_config_as_it_is_and_its_result_pickles_as_a_plain_dict():
    """The expanded config goes to every job's script by pickle: unpickling it must not import
    this package (a job puts its own checkout's src/ first only after the preamble)."""
    import pickle

    config = {"figures": {"f": {"kind": "transmitted_force", "defaults": {"seeds": 2}, "scenes": {"L20": {"L": 20}}}}}
    before = copy.deepcopy(config)
    out = pipeline.expand(config)
    assert config == before
    assert list(out["figures"]["f"]["scenes"]) == ["L20-s0", "L20-s1"]
    assert pipeline.expand(out) is out
    assert type(pickle.loads(pickle.dumps(out))) is dict
    assert b"confined_rod" not in pickle.dumps(out)
