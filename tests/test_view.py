"""confined-rod view: the rod as a tube in the pore (plotly), on a constructed helix of known
geometry; the command line's error paths; and the page rendered by a headless Chromium (skipped
without one, unless CI_REQUIRE_BROWSER=1, which .ci/run sets: then it fails)."""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from confined_rod.analysis import view
from confined_rod.cli import main

ROOT = Path(__file__).resolve().parents[1]
L, N, RHO, PITCH, LOAD = 24.0, 24, 0.85, 8.0, 0.25


def helix(s: np.ndarray, rho: float = RHO, pitch: float = PITCH, top: float = L - 1.0):
    """Points at arc length s on a helix of radius rho and pitch ``pitch`` going down from z = top
    (s = 0, the loaded end) and its unit tangents."""
    c = pitch / (2 * np.pi)
    k = 1 / np.hypot(rho, c)                    # dphi/ds
    phi = k * s
    pts = np.stack([rho * np.cos(phi), rho * np.sin(phi), top - c * phi], axis=1)
    tan = np.stack([-rho * k * np.sin(phi), rho * k * np.cos(phi), -c * k * np.ones_like(phi)], axis=1)
    return pts, tan


def helix_dataset(snapshots: int = 0, final_is_last_snapshot: bool = True, decay: float = 8.0,
                  R: float = 1.0, legacy: bool = False) -> xr.Dataset:
    """A scene dataset as the simulator writes it (dimension coordinates s, s_link, t; ``legacy``:
    dims joint, link, time, as files written before the CF units), in units of a scene with
    cylinder radius R (EI = 1)."""
    s = np.linspace(0.0, L, N + 1)
    s_link = 0.5 * (s[1:] + s[:-1])
    pts, tan = helix(s_link)
    F = -LOAD * np.exp(-s / decay)               # compression, decaying from the load at s = 0
    wall = 0.05 + 0.01 * np.arange(N)
    stuck = (np.arange(N) % 3 == 0).astype(np.int8)
    contact = (np.arange(N) % 3 != 2).astype(np.int8)
    fz = np.where(contact > 0, 0.02, 0.0)
    fphi = np.where(contact > 0, 0.02 * np.sin(np.arange(N)), 0.0)
    data = {"F_z": ("joint", F), "x": ("link", pts[:, 0]), "y": ("link", pts[:, 1]), "z": ("link", pts[:, 2]),
            "tx": ("link", tan[:, 0]), "ty": ("link", tan[:, 1]), "tz": ("link", tan[:, 2]),
            "wall_force": ("link", wall), "stuck": ("link", stuck), "contact": ("link", contact),
            "friction_z": ("link", fz), "friction_phi": ("link", fphi),
            "F_transmitted": ((), -F[-1]), "L_z": ((), float(pts[0, 2] - pts[-1, 2])),
            "converged": ((), np.int8(1)), "n_steps": ((), 1234), "t_final": ((), 500.0)}
    coords = {"s": ("joint", s), "s_link": ("link", s_link)}
    if snapshots:
        times = np.linspace(0, 500.0, snapshots)
        amp = np.linspace(0.1, 1.0, snapshots) if final_is_last_snapshot else np.linspace(0.1, 0.9, snapshots)
        sx = np.stack([pts[:, 0] * a for a in amp])
        sy = np.stack([pts[:, 1] * a for a in amp])
        sz = np.stack([pts[:, 2] for _ in amp])
        data.update({"snap_x": (("time", "link"), sx), "snap_y": (("time", "link"), sy),
                     "snap_z": (("time", "link"), sz),
                     "snap_F_z": (("time", "joint"), np.stack([F * a for a in amp])),
                     "snap_wall_force": (("time", "link"), np.stack([wall * a for a in amp]))})
        coords["time"] = ("time", times)
    ds = xr.Dataset(data, coords=coords)
    scale = {"x": R, "y": R, "z": R, "s": R, "s_link": R, "snap_x": R, "snap_y": R, "snap_z": R, "L_z": R,
             "F_z": R ** -2, "wall_force": R ** -2, "friction_z": R ** -2, "friction_phi": R ** -2,
             "snap_F_z": R ** -2, "snap_wall_force": R ** -2, "F_transmitted": R ** -2}
    for name, f in scale.items():
        if name in ds:
            ds[name] = ds[name] * f
    ds.attrs.update({"L": L * R, "R": R, "EI": 1.0, "load": LOAD / R ** 2, "k_fr": 0.8, "l0": R, "protocol": "straight",
                     "seed": 3, "solver": "implicit", "ends": "free", "pore_length": L * R, "name": "test/helix",
                     "title": "Confined elastic rod 'test/helix'", "status": "converged",
                     "status_reason": "equilibrium: a constructed helix"})
    if not legacy:
        ds = ds.swap_dims({"joint": "s", "link": "s_link"})
        if snapshots:
            ds = ds.rename({"time": "t"})
    return ds


@pytest.fixture(scope="module")
def plotly():
    return pytest.importorskip("plotly", reason="plotly not installed (pip install -e .[view])")


# -- the geometry ------------------------------------------------------------------------------------
def test_the_tube_encloses_the_centreline_at_its_radius():
    s = np.linspace(0.0, L, N + 1)
    s_link = 0.5 * (s[1:] + s[:-1])
    centres, tangents = helix(s_link)
    joints = view.joints_of(centres, tangents, link_length=1.0)
    exact, _ = helix(s)
    assert joints.shape == (N + 1, 3)
    # the joints are where the links (tangent to the helix at their centres) meet: within a link's
    # sagitta l0^2 kappa / 8 of the helix
    kappa = RHO / (RHO ** 2 + (PITCH / (2 * np.pi)) ** 2)
    assert np.max(np.linalg.norm(joints - exact, axis=1)) < 1.05 * kappa / 8
    r, sides = 0.12, 12
    verts, faces, link = view.tube_mesh(joints, r, sides)
    assert verts.shape == ((N + 1) * sides + 2, 3)
    assert faces.shape == (2 * sides * N + 2 * sides, 3) and faces.min() == 0 and faces.max() == len(verts) - 1
    assert link.shape == (len(faces),) and set(link) == set(range(N))
    rings = verts[:-2].reshape(N + 1, sides, 3)
    t, _, _ = view.ring_frames(joints)
    offset = rings - joints[:, None, :]
    np.testing.assert_allclose(np.linalg.norm(offset, axis=2), r, rtol=1e-12)       # at the radius
    assert np.max(np.abs(np.einsum("psk,pk->ps", offset, t))) < 1e-12              # around the tangent
    # every link centre lies on the axis of its piece of tube (up to where two links' ends are
    # averaged into their joint), so the tube encloses the centreline, about r from each centre
    a, b = joints[:-1], joints[1:]
    u = (b - a) / np.linalg.norm(b - a, axis=1, keepdims=True)
    d = centres - a
    along = np.sum(d * u, axis=1)
    off_axis = np.linalg.norm(d - along[:, None] * u, axis=1)
    assert np.max(off_axis) < 0.05 * r
    assert np.all((along > 0) & (along < np.linalg.norm(b - a, axis=1)))
    # and every triangle is a piece of the tube of its own link: its vertices are rings j, j + 1
    ring_of = np.minimum(faces // sides, N)
    quads = faces[: 2 * sides * N]
    assert np.all((ring_of[: 2 * sides * N] == link[: 2 * sides * N, None])
                  | (ring_of[: 2 * sides * N] == link[: 2 * sides * N, None] + 1))
    assert len(quads)


def test_without_tangents_the_joints_are_the_midpoints_and_the_ends_half_a_link_out():
    c = np.array([[0.0, 0, 3.5], [0, 0, 2.5], [0, 0, 1.5], [0, 0, 0.5]])
    j = view.joints_of(c)
    np.testing.assert_allclose(j[:, 2], [4, 3, 2, 1, 0])


# -- colours and the stored shapes ---------------------------------------------------------------------
def _tube_link(fig, rod):
    sides = view._sides(len(rod.s_link))
    _, _, link = view.tube_mesh(view.joints_of(rod.shapes[-1].centres, rod.shapes[-1].tangents, rod.link_length),
                                view.TUBE_RADIUS, sides)
    return link


@pytest.mark.parametrize("color", list(view.COLORS))
def test_the_colour_of_each_link_is_the_variable(plotly, color):
    ds = helix_dataset()
    rod = view.rod_from_dataset(ds)
    fig = view.figure(rod, color)
    mesh = fig.data[0]
    assert mesh.type == "mesh3d" and mesh.intensitymode == "cell"
    link = _tube_link(fig, rod)
    c = view.coloring(rod, color)
    if color == "F_z":                          # |F_z| of the joints at the link centres: the mean of its two
        want = 0.5 * (np.abs(ds.F_z.values[1:]) + np.abs(ds.F_z.values[:-1]))
    elif color == "wall_force":
        want = ds.wall_force.values
    elif color == "stuck":                      # 2 stuck, 1 sliding on the wall, 0 off it
        want = np.where(ds.stuck > 0, 2, np.where(ds.contact > 0, 1, 0)).astype(float)
    else:                                       # degrees from +z towards +phi; none off the wall
        want = np.where(ds.contact > 0, np.degrees(np.arctan2(ds.friction_phi, ds.friction_z)), np.nan)
    np.testing.assert_allclose(c.values[-1], want, rtol=1e-12, atol=1e-12)
    expected = view.intensities(c, want)[link]
    np.testing.assert_allclose(np.asarray(mesh.intensity), expected, rtol=1e-6)
    if color == "friction_angle":               # links without friction: the none band of the colour bar
        assert c.has_none and "no value" in c.ticktext
        assert np.all(np.asarray(mesh.intensity)[np.isnan(want)[link]] < -180)
    for tr in fig.data:                         # no NaN reaches the page
        for name in ("x", "y", "z", "intensity", "customdata"):
            v = getattr(tr, name, None)
            if isinstance(v, np.ndarray) and v.dtype.kind == "f":
                assert np.all(np.isfinite(v)), (tr.type, name)
    assert "NaN" not in fig.to_json().replace('"bdata"', "")


def test_s_is_zero_at_the_loaded_upper_end(plotly):
    ds = helix_dataset()
    rod = view.rod_from_dataset(ds)
    fig = view.figure(rod)
    prof = fig.data[-1]
    assert prof.x[0] == 0 and prof.y[0] == pytest.approx(LOAD)              # |F_z(0)| is the load
    mesh = fig.data[0]
    sides = view._sides(N)
    z = np.asarray(mesh.z)[: (N + 1) * sides].reshape(N + 1, sides).mean(axis=1)
    assert z[0] > z[-1] and np.all(np.diff(z) < 0)                            # ring 0 on top
    assert np.asarray(mesh.customdata)[0] == 0                                # its hover: s = 0
    assert fig.layout.xaxis.range[0] == 0 and fig.layout.xaxis.range[1] == pytest.approx(L)


def test_a_force_spanning_decades_is_shown_on_log_scales(plotly):
    rod = view.rod_from_dataset(helix_dataset(decay=2.0))                    # exp(-12): five decades
    fig = view.figure(rod)
    assert fig.layout.yaxis.type == "log"
    assert "log" in fig.data[0].colorbar.title.text and "10<sup>" in "".join(fig.data[0].colorbar.ticktext)
    rod = view.rod_from_dataset(helix_dataset(decay=100.0))
    assert view.figure(rod).layout.yaxis.type == "linear"


def test_a_constant_force_is_one_colour_not_a_rainbow_of_round_off(plotly):
    ds = helix_dataset(decay=1e9)
    ds["F_z"] = ds.F_z + 1e-7 * np.sin(np.arange(N + 1))                    # frictionless: |F_z| = load
    c = view.coloring(view.rod_from_dataset(ds), "F_z")
    assert c.cmax - c.cmin >= 0.03 * LOAD and c.cmin < LOAD < c.cmax


def test_files_written_before_the_cf_units_are_read_alike():
    new, old = (view.rod_from_dataset(helix_dataset(snapshots=3, legacy=v)) for v in (False, True))
    assert [s.label for s in new.shapes] == [s.label for s in old.shapes]
    for a, b in zip(new.shapes, old.shapes):
        np.testing.assert_array_equal(a.centres, b.centres)
        np.testing.assert_array_equal(a.force, b.force)
    np.testing.assert_array_equal(new.s_joint, old.s_joint)


def test_other_units_are_rescaled_to_R_and_EI():
    a = view.rod_from_dataset(helix_dataset())
    b = view.rod_from_dataset(helix_dataset(R=2.0))
    np.testing.assert_allclose(b.shapes[-1].centres, a.shapes[-1].centres)
    np.testing.assert_allclose(b.shapes[-1].force, a.shapes[-1].force)
    assert b.L == a.L == L and "R = 2" in b.note


@pytest.mark.parametrize("final_is_last", [True, False])
def test_the_slider_has_one_step_per_stored_shape(plotly, final_is_last):
    snaps = 5
    rod = view.rod_from_dataset(helix_dataset(snapshots=snaps, final_is_last_snapshot=final_is_last))
    fig = view.figure(rod)
    n = snaps if final_is_last else snaps + 1     # the final state is the last snapshot, or one more step
    assert len(rod.shapes) == len(fig.frames) == n
    steps = fig.layout.sliders[0].steps
    assert len(steps) == n and fig.layout.sliders[0].active == n - 1
    assert [s.args[0][0] for s in steps] == [f.name for f in fig.frames]
    assert steps[0].label == "0" and "final" in steps[-1].label
    assert "simulated time" in fig.layout.sliders[0].currentvalue.prefix
    # each frame moves the tube and the profile, with the snapshot's values
    np.testing.assert_allclose(fig.frames[0].data[1].y, np.abs(helix_dataset(snapshots=snaps).snap_F_z[0]))
    # the snapshots store no friction state: their links have no value
    c = view.coloring(rod, "stuck")
    assert np.all(np.isnan(c.values[0])) and np.all(np.isfinite(c.values[-1]))


def test_a_file_without_any_value_of_the_colour_draws_a_grey_rod_and_says_so(plotly):
    ds = helix_dataset().drop_vars(["stuck"])
    rod = view.rod_from_dataset(ds)
    assert view.coloring(rod, "stuck").empty
    assert view.figure(rod, "stuck").data[0].showscale is False
    assert "does not store it" in view.entry(rod, "stuck")["header"]


def test_labels_come_from_the_quantity_table():
    assert view.label_html("F_z", "|F_z|") == "|F<sub>z</sub>| [EI/R<sup>2</sup>]"
    assert view.label_html("wall_force") == "N [EI/R<sup>2</sup>]"
    assert view.label_html(view.TIME.name) == "t [β<sub>ph</sub> R<sup>4</sup>/EI]"
    assert view.tex_html(r"f_\varphi") == "f<sub>φ</sub>"


# -- the command line ---------------------------------------------------------------------------------
def _run(capsys, *args):
    rc = main(["view", *map(str, args)])
    return rc, capsys.readouterr().err.strip()


def test_the_command_writes_one_self_contained_page(plotly, tmp_path, capsys):
    src = tmp_path / "helix.nc"
    helix_dataset(snapshots=3).to_netcdf(src)
    out = tmp_path / "rod.html"
    rc, err = _run(capsys, src, "-o", out, "--color", "stuck")
    assert rc == 0, err
    text = out.read_text()
    assert text.startswith("<!DOCTYPE html>") and "Plotly" in text and "<script src=" not in text
    assert "status: converged" in text and "wall friction coefficient" in text
    assert not list(tmp_path.glob(".*.tmp"))


@pytest.mark.parametrize("case", ["color", "not_netcdf", "no_rod", "missing", "output"])
def test_bad_input_is_one_line_naming_the_value_before_any_work(plotly, tmp_path, capsys, case):
    src = tmp_path / "helix.nc"
    helix_dataset().to_netcdf(src)
    out = tmp_path / "rod.html"
    args, named = {
        "color": ([src, "-o", out, "--color", "curvature"], "'curvature'"),
        "not_netcdf": ([tmp_path / "notes.nc", "-o", out], "notes.nc"),
        "no_rod": ([tmp_path / "other.nc", "-o", out], "other.nc"),
        "missing": ([tmp_path / "absent.nc", "-o", out], "absent.nc"),
        "output": ([src, "-o", tmp_path / "rod.png"], "rod.png"),
    }[case]
    (tmp_path / "notes.nc").write_text("not a dataset\n")
    xr.Dataset({"a": ("x", [1.0, 2.0])}, attrs={"L": 1.0}).to_netcdf(tmp_path / "other.nc")
    rc, err = _run(capsys, *args)
    assert rc == 2
    assert len(err.splitlines()) == 1 and err.startswith("error: ") and named in err, err
    assert not out.exists() and not (tmp_path / "rod.png").exists()


def test_without_plotly_the_command_names_the_extra(tmp_path, capsys, monkeypatch):
    src = tmp_path / "helix.nc"
    helix_dataset().to_netcdf(src)
    for mod in [m for m in sys.modules if m == "plotly" or m.startswith("plotly.")]:
        monkeypatch.delitem(sys.modules, mod)
    monkeypatch.setitem(sys.modules, "plotly", None)                      # import plotly -> ImportError
    rc, err = _run(capsys, src, "-o", tmp_path / "rod.html")
    assert rc == 2 and len(err.splitlines()) == 1 and "confined_rod[view]" in err, err


def test_the_view_never_imports_the_simulator(plotly, tmp_path):
    src = tmp_path / "helix.nc"
    helix_dataset().to_netcdf(src)
    code = ("import sys; from confined_rod.cli import main; "
            f"rc = main(['view', {str(src)!r}, '-o', {str(tmp_path / 'r.html')!r}]); "
            "bad = [m for m in sys.modules if m == 'numba' or m.startswith(('numba.', 'confined_rod.sim'))]; "
            "assert rc == 0 and not bad, bad")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]


# -- in a browser -------------------------------------------------------------------------------------
def _chromium() -> str:
    for name in ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable"):
        exe = shutil.which(name)
        if exe:
            return exe
    msg = "no Chromium installed (Debian: apt-get install chromium; tools/setup.sh installs it as root)"
    if os.environ.get("CI_REQUIRE_BROWSER") == "1":
        pytest.fail(f"CI_REQUIRE_BROWSER=1 but {msg}")
    pytest.skip(msg)


def _render(pages: list[Path], tmp: Path) -> list[tuple[Path, str]]:
    """Open each page in its own headless Chromium (at the same time: two cores), save a
    screenshot; the screenshots and the browsers' logs (console lines included)."""
    exe = _chromium()
    runs = []
    for k, page in enumerate(pages):
        shot = tmp / f"shot{k}.png"
        cmd = [exe, "--headless", "--no-sandbox", "--disable-gpu", "--enable-unsafe-swiftshader", "--no-first-run",
               "--disable-dev-shm-usage", f"--user-data-dir={tmp / f'profile{k}'}", "--enable-logging=stderr",
               "--v=0", "--virtual-time-budget=10000", "--window-size=1200,800", f"--screenshot={shot}",
               page.resolve().as_uri()]
        runs.append((shot, subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)))
    out = []
    for shot, proc in runs:
        try:
            _, log = proc.communicate(timeout=90)
        except subprocess.TimeoutExpired:
            proc.kill()
            _, log = proc.communicate()
        assert shot.is_file(), log[-3000:]
        out.append((shot, log))
    return out


def _console_problems(log: str) -> list[str]:
    """Console lines of the page that are errors: an uncaught exception, the page's own
    '[view error]' (console.error is routed there), a browser-reported 'Error: ...'."""
    lines = [ln for ln in log.splitlines() if ":CONSOLE" in ln]
    return [ln for ln in lines if "Uncaught" in ln or "[view error]" in ln or '"Error' in ln]


def test_the_pages_render_in_a_browser(plotly, tmp_path):
    """The command's page (plotly.js inline) and a page of the pipeline's views folder (loading the
    folder's plotly.min.js): rendered without a console error, the rod visible in its colour (all
    links stuck: dark red) in the 3-D part of the page."""
    ds = helix_dataset(snapshots=3)
    ds["stuck"][:] = 1
    src = tmp_path / "helix.nc"
    ds.to_netcdf(src)
    page = tmp_path / "rod.html"
    assert main(["view", str(src), "-o", str(page), "--color", "stuck"]) == 0
    folder = view.write_views(tmp_path / "views", [("test", "a test figure", [("helix", str(src))])], color="stuck")
    pages = [page, folder / view.page_name("test", "helix")]
    from PIL import Image

    for k, (page, (shot, log)) in enumerate(zip(pages, _render(pages, tmp_path))):
        assert not _console_problems(log), (page.name, _console_problems(log))
        assert "[view rendered] " in log, (page.name, log[-3000:])
        img = np.asarray(Image.open(shot).convert("RGB")).astype(int)
        if os.environ.get("VIEW_SHOT"):        # keep a copy to look at
            shutil.copy(shot, Path(os.environ["VIEW_SHOT"]).with_suffix(f".{k}.png"))
        background = np.all(img > 245, axis=2)
        assert (~background).mean() > 0.03, f"{page}: the page is blank"
        r, g, b = img[..., 0], img[..., 1], img[..., 2]
        rod_red = (r > 70) & (r > 2.2 * g) & (r > 2.0 * b)        # #b2182b under the lights
        assert rod_red.sum() > 400, f"{page}: only {rod_red.sum()} pixels of the rod's colour"
        cols = np.nonzero(rod_red.any(axis=0))[0]
        assert cols.max() < 0.5 * img.shape[1], page                # in the 3-D part, not the profile


def test_the_views_folder_lists_every_simulation_and_shares_one_plotly(plotly, tmp_path):
    paths = []
    for k, decay in enumerate((8.0, 30.0)):
        p = tmp_path / f"s{k}.nc"
        helix_dataset(decay=decay).to_netcdf(p)
        paths.append(str(p))
    folder = view.write_views(tmp_path / "views", [("figA", "Figure A", [("a", paths[0]), ("b", paths[1])]),
                                                   ("figB", "Figure B", [("c", paths[0])])])
    files = sorted(str(p.relative_to(folder)) for p in folder.rglob("*") if p.is_file())
    assert files == ["figA/a.html", "figA/b.html", "figB/c.html", "index.html", "plotly.min.js"]
    index = (folder / "index.html").read_text()
    assert all(f'href="{n}"' in index for n in ("figA/a.html", "figA/b.html", "figB/c.html"))
    page = (folder / "figA" / "b.html").read_text()
    assert '<script src="../plotly.min.js">' in page and len(page) < 500_000     # plotly.js not inside
