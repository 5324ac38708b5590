"""The command line as a user meets it: --version, run --set, show-defaults as a safe template,
the refused open entrance, the kernel-compilation notice, and no forced matplotlib backend."""
from __future__ import annotations

import os
import subprocess
import sys

import pytest
import yaml

from confined_rod import __version__
from confined_rod.cli import _overrides, main
from confined_rod.errors import SceneError
from confined_rod.sim.scenes import DERIVED_FROM, Scene


def test_version(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0 and __version__ in capsys.readouterr().out


def test_set_reads_yaml_values_and_names_a_bad_key():
    assert _overrides(["L=40", "k_fr=0.3", "body_force=[0.1, 0, 0]", "ends=guided", "R=1e-9"]) == {
        "L": 40, "k_fr": 0.3, "body_force": [0.1, 0, 0], "ends": "guided", "R": 1e-9}   # 1e-9: YAML 1.2
    with pytest.raises(SceneError, match="unknown key 'Lx'"):
        _overrides(["Lx=40"])
    with pytest.raises(SceneError, match="expected KEY=VALUE"):
        _overrides(["L40"])


@pytest.mark.parametrize("sets, message", [
    (["L=abc"], "invalid value for 'L': 'abc'"),
    (["pore_length=15"], "invalid value for 'pore_length': 15 (shorter than L = 20 with ends = 'free'"),
    (["bogus=1"], "unknown key 'bogus'"),
])
def test_run_refuses_bad_settings_before_any_work(tmp_path, capsys, sets, message):
    out = tmp_path / "x.nc"
    argv = ["run", "-o", str(out)] + [a for s in sets for a in ("--set", s)]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1 and not out.exists()


def test_set_overrides_the_scene_file(tmp_path, capsys):
    f = tmp_path / "rod.yaml"
    f.write_text("L: 10\nk_fr: 0.8\n")
    out = tmp_path / "rod.nc"
    assert main(["run", str(f), "--set", "L=8", "-q", "-o", str(out)]) == 0
    import xarray as xr

    ds = xr.open_dataset(out)
    assert ds.attrs["L"] == 8.0 and ds.attrs["k_fr"] == 0.8 and ds.attrs["name"] == "rod"


def test_show_defaults_is_a_template_that_stays_consistent(capsys):
    assert main(["show-defaults"]) == 0
    text = capsys.readouterr().out
    data = yaml.safe_load(text)
    # every derived default is null, with what it follows in the comment; units and descriptions
    for key in DERIVED_FROM:
        assert data[key] is None, key
    assert "pore_length: null  # [R]; height of the open pore entrance" in text and "follows L" in text
    assert "load: 0.25  # [EI/R^2]" in text
    data["L"] = 40                                         # the user's edit: only L
    scene = Scene.from_dict(data)
    assert scene.pore_length == 40 and scene.free_span() == 0


def test_first_run_says_it_compiles(tmp_path):
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "empty_cache")}
    os.makedirs(env["NUMBA_CACHE_DIR"])
    from confined_rod.cli import _kernels_cached

    assert _kernels_cached()                              # this test session's cache is warm
    env_check = subprocess.run([sys.executable, "-c", "from confined_rod.cli import _kernels_cached as k; "
                                "print(k())"], env=env, capture_output=True, text=True, check=True)
    assert env_check.stdout.strip() == "False"            # an empty cache: the run will say so


def test_no_backend_is_forced_on_import():
    code = ("import matplotlib; import confined_rod.analysis.plotting, confined_rod.analysis.figures; "
            "print(matplotlib.get_backend())")
    out = subprocess.run([sys.executable, "-c", code], env={**os.environ, "MPLBACKEND": "svg"},
                         capture_output=True, text=True, check=True).stdout.strip()
    assert out == "svg"
