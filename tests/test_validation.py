"""Bad input is rejected before any computation, naming the key and the value,
and the CLI writes nothing."""
import subprocess
import sys

import pytest
import yaml

from confined_rod import Scene, SceneError

BAD = [
    ({"L": -5.0}, "'L'", "-5.0"),
    ({"L": 10.0, "l0": 20.0}, "'l0'", "20.0"),
    ({"L": 10.0, "l0": 0.3}, "'l0'", "0.3"),  # L not a multiple of l0
    ({"k_fr": -0.1}, "'k_fr'", "-0.1"),
    ({"load": "heavy"}, "'load'", "'heavy'"),
    ({"load": True}, "'load'", "True"),
    ({"k_ph": 0.0}, "'k_ph'", "0.0"),
    ({"k_w": float("nan")}, "'k_w'", "nan"),
    ({"seed": 1.5}, "'seed'", "1.5"),
    ({"protocol": "twisted"}, "'protocol'", "'twisted'"),
    ({"ends": "clamped"}, "'ends'", "'clamped'"),
    ({"dt_factor": 20.0}, "'dt_factor'", "20.0"),
    ({"body_force": [1.0, 2.0]}, "'body_force'", "[1.0, 2.0]"),
    ({"pore_length": 0.5, "L": 10.0}, "'pore_length'", "0.5"),
    ({"perturbation": 2.0}, "'perturbation'", "2.0"),
    ({"friction_cap": -1.0}, "'friction_cap'", "-1.0"),
]


@pytest.mark.parametrize("data,key,value", BAD)
def test_invalid_values_name_key_and_value(data, key, value):
    with pytest.raises(SceneError) as exc:
        Scene.from_dict(data)
    assert key in str(exc.value) and value in str(exc.value)


def test_unknown_key_is_rejected():
    with pytest.raises(SceneError, match=r"unknown key 'lenght'.*20"):
        Scene.from_dict({"lenght": 20})


def test_defaults_scale_with_R_and_EI():
    s = Scene(L=40.0, R=2.0, EI=3.0)
    assert s.l0 == pytest.approx(0.5 * 2.0)
    assert s.k_ph == pytest.approx(1000.0 * 3.0 / 4.0)
    assert s.k_w == pytest.approx(1000.0 * 3.0 / 8.0)
    assert s.friction_cap == pytest.approx(0.05 * 3.0 / 4.0)


@pytest.mark.parametrize("content,needle", [
    ("L: -3\n", "'L': -3"),
    ("L: 20\nlenght: 3\n", "unknown key 'lenght'"),
    ("L: [1, 2\n", "not valid YAML"),
    ("L: 10\nl0: 0.3\n", "'l0': 0.3"),
    ("k_fr: abc\n", "'k_fr': 'abc'"),
])
def test_cli_rejects_bad_scene_and_writes_nothing(tmp_path, content, needle):
    scene = tmp_path / "bad.yaml"
    scene.write_text(content)
    out = tmp_path / "out.nc"
    proc = subprocess.run([sys.executable, "-m", "confined_rod", "run", str(scene), "-o", str(out)],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2
    assert needle in proc.stderr
    assert list(tmp_path.iterdir()) == [scene]


def test_yaml_scientific_notation_is_a_number(tmp_path):
    path = tmp_path / "sci.yaml"
    path.write_text("L: 10\nload: 2.5e-1\nk_w: 1e3\n")  # YAML 1.1 reads '1e3' as a string
    s = Scene.from_yaml(path)
    assert s.k_w == 1000.0 and s.load == 0.25 and s.name == "sci"


def test_cli_runs_a_scene(tmp_path):
    import xarray as xr

    scene = tmp_path / "short.yaml"
    scene.write_text(yaml.safe_dump({"L": 4.0, "load": 1.0, "k_fr": 0.0, "tol": 1e-3}))
    out = tmp_path / "short.nc"
    proc = subprocess.run([sys.executable, "-m", "confined_rod", "run", str(scene), "-o", str(out), "-q"],
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    with xr.open_dataset(out) as ds:
        assert ds.attrs["name"] == "short"
        assert int(ds.converged) == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["short.nc", "short.yaml"]


def test_the_stick_stiffness_follows_its_law_unless_given():
    """k_t defaults to the bond constant k_ph/l0 with friction at the link ends and to k_w/10 at
    the centre, also when those are given or replaced; a given k_t stays; k_t <= 0 is refused
    naming the key."""
    import dataclasses

    from confined_rod import Scene
    from confined_rod.errors import SceneError

    assert Scene().friction_at == "ends"
    assert Scene().k_t == pytest.approx(Scene().k_ph / Scene().l0)
    assert Scene(k_ph=1.0e4, l0=0.25).k_t == pytest.approx(4.0e4)
    assert dataclasses.replace(Scene(), l0=1.0).k_t == pytest.approx(Scene().k_ph)
    assert dataclasses.replace(Scene(k_t=3.0), l0=1.0).k_t == 3.0
    centre = Scene(friction_at="centre")
    assert centre.k_t == pytest.approx(0.1 * centre.k_w)
    assert Scene(friction_at="centre", k_w=500.0).k_t == pytest.approx(50.0)
    assert dataclasses.replace(centre, k_w=200.0).k_t == pytest.approx(20.0)
    assert dataclasses.replace(Scene(), friction_at="centre").k_t == pytest.approx(0.1 * centre.k_w)
    assert dataclasses.replace(Scene(friction_at="centre", k_t=3.0), k_w=200.0).k_t == 3.0
    with pytest.raises(SceneError, match="'k_t': 0"):
        Scene(k_t=0)
