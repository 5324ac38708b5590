"""The README's examples run: its dataset inspection block (on a simulation and a Fig 4 dataset
this test builds where the README expects them) and its command-line examples that cost seconds."""
from __future__ import annotations

import re
import subprocess
from pathlib import Path

import matplotlib
import numpy as np
import pytest
import xarray as xr

from confined_rod import layout, theory
from confined_rod.analysis import postprocess
from confined_rod.io import write_dataset
from confined_rod.sim.scenes import Scene
from confined_rod.sim.simulation import simulate

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text()


def _block(after: str, lang: str = "python") -> str:
    i = README.index(after)
    m = re.compile(rf"```{lang}\n(.*?)```", re.S).search(README, i)
    assert m, f"no {lang} block after {after!r}"
    return m.group(1)


def _profile_sim(k_fr: float, L=40.0, N=80, load=0.25) -> xr.Dataset:
    """A rod on the wall whose |F_z(s)| is the simple model's (Fig 4's kind reads profiles)."""
    s = np.linspace(0.0, L, N + 1)
    F = theory.force_decay(s, load, k_fr)
    fz = -(F[:-1] - F[1:])                       # every link slides, friction carries the decay
    attrs = {k: v for k, v in Scene(L=L, k_fr=k_fr, load=load, l0=L / N).to_dict().items()
             if not isinstance(v, (tuple, type(None)))}
    return xr.Dataset(
        {"F_z": ("s", -F), "contact": ("s_link", np.ones(N, np.int8)), "friction_z": ("s_link", fz),
         "friction_force": ("s_link", np.abs(fz)), "wall_force": ("s_link", np.abs(fz) / k_fr),
         "phi": ("s_helix", np.linspace(0, 9, N)), "F_transmitted": ((), F[-1]), "converged": ((), np.int8(1))},
        coords={"s": ("s", s), "s_link": ("s_link", 0.5 * (s[1:] + s[:-1]))}, attrs={**attrs, "git_commit": "test"})


def test_the_inspection_block_runs(tmp_path, monkeypatch):
    matplotlib.use("Agg")
    sim = simulate(Scene(name="L20-s0", L=20.0, load=0.25, k_fr=0.8), progress=False)
    write_dataset(sim, tmp_path / layout.sim_path("fig6_FonL", "L20-s0"))
    cfg = {"kind": "force_profile", "title": "t", "panel_parameter": "k_fr"}
    fig4 = postprocess.build("fig4_Fonl", cfg, {p: _profile_sim(k) for p, k in (("a", 0.1), ("b", 0.3), ("c", 0.8))})
    write_dataset(fig4, tmp_path / layout.dataset_path("fig4_Fonl"))
    monkeypatch.chdir(tmp_path)
    scope: dict = {}
    exec(compile(_block("**Inspect a dataset**"), "README.md", "exec"), scope)
    assert float(scope["f10"]) == pytest.approx(float(sim.F_z.sel(s=10.0)))
    assert float(scope["f10"]) < 0                 # compression
    assert float(scope["on_top"]) == pytest.approx(float(sim.wall_force.values[:10].sum()))


def test_the_command_line_block_runs(tmp_path):
    """Every line of the README's command-line block, in order, in a folder that sees the checkout's
    config/ and .venv/ (the outputs land in the folder, not in the checkout)."""
    for name in ("config", ".venv", "workflow"):
        (tmp_path / name).symlink_to(ROOT / name)
    lines = [ln.split("#")[0].strip() for ln in _block("**Command line**", "bash").splitlines()]
    lines = [ln for ln in lines if ln]
    assert len(lines) >= 5
    for line in lines:
        out = subprocess.run(["bash", "-c", line], cwd=tmp_path, capture_output=True, text=True, timeout=300)
        assert out.returncode == 0, f"{line}: {out.stderr[-2000:]}"
    assert xr.open_dataset(tmp_path / "helix_L30.nc").attrs["L"] == 30.0
