"""A rod you can turn in a browser: one self-contained HTML page (plotly) of a scene file (or of
several, with a selector); the pipeline's rule views writes one page per simulation of the figures
into ``results/views/`` (``index.html`` lists them), sharing one plotly.min.js.

    python -m confined_rod view results/sims/fig4_Fonl/a.nc -o rod.html [--color F_z]

The page shows the rod as a tube (radius :data:`TUBE_RADIUS`, for visibility: the model rod is the
line of its link centres) in the translucent pore (radius R, from the lower piston at z = 0 up to
the pore entrance), coloured by one of :data:`COLORS`, beside its axial force profile |F_z|(s),
with the scene's parameters and how the run ended. A file that stores shapes at several times
(``snap_x``... of a run with ``snapshot_interval``, the load paths of Figs 2 and 8, the loads of a
bifurcation path) gets a slider over them. Lengths are shown in R, forces in EI/R^2 (a scene with
R or EI other than 1 is rescaled); s = 0 is the loaded (upper) end.

Reads datasets only (no simulator, no numba: pyproject.toml's import contracts); plotly is an
optional dependency (``pip install confined_rod[view]``), imported inside the functions that draw.
"""
from __future__ import annotations

import dataclasses
import html
import json
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterable

import numpy as np

from .. import layout
from ..quantities import QUANTITIES, SCENE_PARAMETERS, pretty_unit

#: tube radius in R (drawing only: the model rod is the line of its link centres)
TUBE_RADIUS = 0.14
#: colour of the links that have no value of the chosen variable (not stored in a snapshot, no
#: friction on a link off the wall)
NONE_COLOR = "#c9c9c9"
#: --color choices: what each colours the rod by
COLORS = {
    "F_z": "|F_z|, the axial force transmitted through the joints (interpolated to the link centres)",
    "wall_force": "N, the magnitude of the wall's normal force on each link",
    "stuck": "each link's friction state: stuck (static friction), sliding on the wall, or off the wall",
    "friction_angle": "direction of the wall friction on each link in the wall's tangent plane, "
                      "θ_f = atan2(f_φ, f_z): 0° up (+z, against the push), ±180° down, "
                      "+90° counter-clockwise seen from above (links without friction: no value)",
}
DEFAULT_COLOR = "F_z"
#: the extra that provides plotly
EXTRA = "view"
#: the stuck/sliding categories, by code
CATEGORIES = {0: ("off the wall", "#4c78a8"), 1: ("sliding", "#f58518"), 2: ("stuck", "#b2182b")}
_FRICTION_FLOOR = 1e-9           # |f| (EI/R^2) below which a link has no friction direction
_LOG_SPAN = 30.0
#: a colour range narrower than this fraction of its value is widened to it
MIN_SPAN = 0.02
#: a pore taller than this many diameters is drawn with z squeezed to SQUEEZED diameters (a button
#: restores the true proportions)
SQUEEZE_ABOVE = 8.0
SQUEEZED = 6.0                 # a positive quantity spanning more than this factor is shown on a log scale


#: the simulated time
TIME = QUANTITIES["t"]


class ViewError(ValueError):
    """A file that cannot be viewed, or a bad choice; the message is one line naming the value."""


class PlotlyMissing(ImportError):
    """plotly is not installed."""


def require_plotly():
    """The plotly module, or PlotlyMissing with the one line that says what to install."""
    try:
        import plotly
        import plotly.graph_objects  # noqa: F401
    except ImportError:
        raise PlotlyMissing(f"the view needs plotly: pip install 'confined_rod[{EXTRA}]' "
                            "(or .venv/bin/pip install plotly)") from None
    return plotly


def check_color(color: str) -> str:
    if color not in COLORS:
        raise ViewError(f"unknown --color {color!r}; choose one of {', '.join(COLORS)}")
    return color


# -- text: the quantity table's LaTeX symbols and units as plotly/HTML text -----------------------
_TEX = [(r"\varphi", "φ"), (r"\phi", "φ"), (r"\beta", "β"), (r"\Delta", "Δ"), (r"\delta", "δ"),
        (r"\rho", "ρ"), (r"\epsilon", "ε"), (r"\theta", "θ"), (r"\perp", "⊥"), (r"\,", " ")]


def tex_html(tex: str) -> str:
    """'f_\\varphi' -> 'f<sub>φ</sub>', 'EI/R^2' -> 'EI/R<sup>2</sup>' (plotly and HTML text)."""
    s = html.escape(tex, quote=False)
    s = re.sub(r"\\mathrm\{([^}]*)\}", r"\1", s)
    s = re.sub(r"\\mathbf\{([^}]*)\}", r"<b>\1</b>", s)
    for a, b in _TEX:
        s = s.replace(a, b)
    for mark, tag in (("_", "sub"), (r"\^", "sup")):
        s = re.sub(mark + r"\{([^}]*)\}", rf"<{tag}>\1</{tag}>", s)
        s = re.sub(mark + r"(-?[A-Za-z0-9φβ])", rf"<{tag}>\1</{tag}>", s)
    return s


def unit_html(name: str) -> str:
    return tex_html(pretty_unit(QUANTITIES[name].units))


def label_html(name: str, symbol: str | None = None) -> str:
    """'|F<sub>z</sub>| [EI/R<sup>2</sup>]': a quantity's symbol and unit (quantities.py)."""
    q = QUANTITIES[name]
    sym = tex_html(symbol if symbol is not None else q.symbol) or q.long_name
    u = unit_html(name)
    return f"{sym} [{u}]" if u else sym


def _scale(units: str, R: float, EI: float) -> float:
    """The value of one unit ('EI R-2') for a scene of radius R and stiffness EI: dividing a stored
    value by it gives the value in reduced units (R = EI = 1; beta_ph is taken as 1)."""
    out = 1.0
    for token in units.split():
        m = re.fullmatch(r"(EI|R|rad|beta_ph|s|1)(-?\d+)?", token)
        if not m:
            continue
        base = {"EI": EI, "R": R}.get(m.group(1), 1.0)
        out *= base ** int(m.group(2) or 1)
    return out


# -- reading a scene file -----------------------------------------------------------------------
@dataclass
class Shape:
    """One stored shape of the rod (reduced units: R = EI = 1)."""
    label: str                                  # slider label
    centres: np.ndarray                         # (N, 3) link centres, link 0 at the loaded end
    tangents: np.ndarray | None = None          # (N, 3) unit tangents (final states of a run)
    fields: dict[str, np.ndarray] = field(default_factory=dict)    # per link: wall_force, stuck, ...
    force: np.ndarray | None = None             # (N + 1,) |F_z| at the joints


@dataclass
class Rod:
    """What the view shows of one scene file, read once (reduced units)."""
    name: str
    title: str
    L: float
    pore: float                 # height of the pore entrance
    link_length: float
    s_link: np.ndarray
    s_joint: np.ndarray
    shapes: list[Shape]
    frame_title: str            # what the slider runs over
    status: str
    reason: str
    settled: bool
    params: list[tuple[str, str, str]]      # (symbol HTML, value, description)
    results: list[tuple[str, str, str]]
    note: str = ""


def _attr(ds, key, default=None):
    v = ds.attrs.get(key, default)
    return v.item() if isinstance(v, np.generic) else v


def read_rod(path: str | Path) -> Rod:
    """Read a scene file (simulation, load path, probe) into a Rod; ViewError (one line) for a
    file that is not one."""
    import xarray as xr

    path = Path(path)
    where = repr(str(path))
    if not path.exists():
        raise ViewError(f"{where} does not exist")
    if path.is_dir():
        raise ViewError(f"{where} is a directory, not a scene dataset")
    try:
        ds = xr.load_dataset(path)
    except Exception as exc:  # noqa: BLE001 - anything that does not open is not a dataset
        raise ViewError(f"{where} is not a netCDF dataset ({type(exc).__name__})") from None
    try:
        return rod_from_dataset(ds, name=path.stem)
    except ViewError as exc:
        raise ViewError(f"{where} {exc}") from None


def _link_dim(ds) -> str | None:
    for dim in ("link", "s_link"):
        if dim in ds.dims:
            return dim
    return None


def rod_from_dataset(ds, name: str = "rod") -> Rod:
    """The Rod of an open dataset (see read_rod); ViewError says what is missing."""
    missing = [k for k in ("L", "R", "EI") if k not in ds.attrs]
    link = _link_dim(ds)
    has_shape = link is not None and (("x" in ds and link in ds["x"].dims) or "snap_x" in ds)
    if missing or not has_shape:
        what = f"no scene attribute {missing[0]}" if missing else "no rod shape: no x, y, z of the links"
        raise ViewError(f"is not a simulation dataset of confined_rod ({what})")
    R, EI = float(ds.attrs["R"]), float(ds.attrs["EI"])
    length = _scale("R", R, EI)
    force = _scale("EI R-2", R, EI)
    s_link = np.asarray(ds["s_link"].values, dtype=float) / length
    n = s_link.size
    if "s" in ds.coords and ds["s"].ndim == 1 and ds["s"].size == n + 1:
        s_joint = np.asarray(ds["s"].values, dtype=float) / length
    else:                                       # joints between the link centres, ends half a link out
        mid = 0.5 * (s_link[1:] + s_link[:-1])
        h = (s_link[1] - s_link[0]) / 2 if n > 1 else float(ds.attrs["L"]) / length / 2
        s_joint = np.concatenate([[s_link[0] - h], mid, [s_link[-1] + h]])
    L = float(ds.attrs["L"]) / length
    pore = _attr(ds, "pore_length")
    pore = L if pore in (None, "none") else float(pore) / length
    l0 = float(np.median(np.diff(s_joint))) if n > 0 else L

    def per_link(var, sel=None) -> np.ndarray | None:
        if var not in ds:
            return None
        v = ds[var] if sel is None else ds[var].isel(sel)
        if v.dims != (link,):
            return None
        units = QUANTITIES[var].units if var in QUANTITIES else "1"
        return np.asarray(v.values, dtype=float) / _scale(units, R, EI)

    def joints(var, sel=None) -> np.ndarray | None:
        if var not in ds:
            return None
        v = ds[var] if sel is None else ds[var].isel(sel)
        if v.ndim != 1 or v.size != n + 1:
            return None
        return np.abs(np.asarray(v.values, dtype=float)) / force

    shapes: list[Shape] = []
    frame_title = ""
    # shapes along the run: snap_x (time or snapshot, link)
    if "snap_x" in ds and ds["snap_x"].ndim == 2:
        tdim = ds["snap_x"].dims[0]
        tname = next((c for c in ("time", "t", "snap_time") if c in ds.coords and ds[c].dims == (tdim,)), None)
        times = (np.asarray(ds[tname].values, dtype=float) / _scale(TIME.units, R, EI)
                 if tname else np.arange(ds.sizes[tdim], dtype=float))
        stage = ds["snap_stage"].values if "snap_stage" in ds and ds["snap_stage"].dims == (tdim,) else None
        frame_title = f"simulated time {label_html(TIME.name)}" if tname else "snapshot"
        texts = distinct_numbers(times)
        for i in range(ds.sizes[tdim]):
            sel = {tdim: i}
            label = texts[i] + ("" if stage is None else (" (planar)" if int(stage[i]) == 0 else " (3-D)"))
            fields = {k: v for k in ("wall_force", "friction_z", "friction_phi", "stuck", "contact")
                      if (v := per_link(f"snap_{k}", sel)) is not None}
            shapes.append(Shape(label, _xyz(ds, "snap_", sel) / length, None, fields, joints("snap_F_z", sel)))
    # equilibria at several loads or states: x (load or state, link)
    if "x" in ds and ds["x"].ndim == 2 and link in ds["x"].dims:
        odim = next(d for d in ds["x"].dims if d != link)
        values = ds[odim].values if odim in ds.coords else np.arange(ds.sizes[odim])
        unit = unit_html(odim) if odim in QUANTITIES else ""
        numeric = np.issubdtype(np.asarray(values).dtype, np.number)
        texts = distinct_numbers(np.asarray(values, float)) if numeric else [str(v).replace("_", " ") for v in values]
        after_snapshots = bool(shapes)             # then each label says what it is
        if after_snapshots:                        # the slider mixes times and states: name each
            shapes = [dataclasses.replace(s, label=f"t = {s.label}") for s in shapes]
            frame_title = "shape"
        for i in range(ds.sizes[odim]):
            sel = {odim: i}
            label = f"{odim} {texts[i]}" if after_snapshots else texts[i]
            fields = {k: v for k in ("wall_force", "friction_z", "friction_phi", "stuck", "contact")
                      if (v := per_link(k, sel)) is not None}
            shapes.append(Shape(label, _xyz(ds, "", sel) / length, None, fields, joints("F_z", sel)))
        if not frame_title:
            frame_title = tex_html(QUANTITIES[odim].symbol) + (f" [{unit}]" if unit else "") \
                if odim in QUANTITIES and QUANTITIES[odim].symbol else odim
    # the final state of a run: x (link)
    if "x" in ds and ds["x"].dims == (link,):
        tangents = None
        if all(t in ds and ds[t].dims == (link,) for t in ("tx", "ty", "tz")):
            tangents = np.stack([ds[t].values for t in ("tx", "ty", "tz")], axis=1).astype(float)
        fields = {k: v for k in ("wall_force", "friction_z", "friction_phi", "stuck", "contact")
                  if (v := per_link(k)) is not None}
        final = Shape("final", _xyz(ds, "", None) / length, tangents, fields, joints("F_z"))
        t_final = float(ds["t_final"]) / _scale(TIME.units, R, EI) if "t_final" in ds else None
        if shapes and np.allclose(shapes[-1].centres, final.centres, atol=1e-9):
            final.label = shapes[-1].label + " (final)"
            shapes[-1] = final
        else:
            if shapes:
                final.label = f"{t_final:.4g} (final)" if t_final is not None else "final"
            shapes.append(final)
    for sh in shapes:
        if not np.all(np.isfinite(sh.centres)):
            raise ViewError(f"has non-finite link positions in the shape at {sh.label}")

    status, reason, settled = _status(ds)
    return Rod(name=str(_attr(ds, "name", name)), title=str(_attr(ds, "title", name)), L=L, pore=pore,
               link_length=l0, s_link=s_link, s_joint=s_joint, shapes=shapes,
               frame_title=frame_title, status=status, reason=reason, settled=settled,
               params=_params(ds), results=_results(ds),
               note=("" if R == 1 and EI == 1 else
                     f"shown in reduced units: lengths / R, forces / (EI/R<sup>2</sup>) "
                     f"(the file stores R = {R:g}, EI = {EI:g})"))


def distinct_numbers(values: np.ndarray) -> list[str]:
    """Short labels of a sequence of numbers, with as many digits as it takes to tell them apart
    (the snapshot times of a second stage are 2628.0091, 2628.0114, ...)."""
    for digits in range(4, 12):
        texts = [f"{v:.{digits}g}" for v in values]
        if len(set(texts)) == len(texts):
            return texts
    return texts


def _xyz(ds, prefix: str, sel) -> np.ndarray:
    cols = []
    for c in "xyz":
        v = ds[prefix + c] if sel is None else ds[prefix + c].isel(sel)
        cols.append(np.asarray(v.values, dtype=float))
    return np.stack(cols, axis=1)


def _status(ds) -> tuple[str, str, bool]:
    from .run_checks import EQUILIBRIUM, status

    if "status" in ds.attrs:
        st = status(ds)
        return st, str(ds.attrs.get("status_reason", "")), st == EQUILIBRIUM
    parts = []
    settled = True
    for var in ("converged", "escaped"):
        if var in ds:
            v = np.asarray(ds[var].values).ravel()
            parts.append(f"{var}: {int(v.sum())} of {v.size}" if v.size > 1 else f"{var}: {'yes' if v[0] else 'no'}")
            if var == "converged":
                settled = bool(np.all(v == 1))
    return ("load path" if parts else "no status"), "; ".join(parts), settled


def _value_text(v: Any) -> str:
    if isinstance(v, np.ndarray):
        return "(" + ", ".join(f"{x:g}" for x in v.ravel()) + ")"
    if isinstance(v, (float, np.floating)):
        return f"{float(v):.6g}"
    return str(v)


#: the parameters shown first (the rest are under "all parameters")
MAIN_PARAMETERS = ("L", "R", "load", "k_fr", "l0", "protocol", "seed", "solver", "ends", "pore_length",
                   "friction_cap", "tol")


def _params(ds) -> list[tuple[str, str, str]]:
    out = []
    by_name = {q.name: q for q in SCENE_PARAMETERS}
    order = [n for n in MAIN_PARAMETERS if n in by_name] + [q.name for q in SCENE_PARAMETERS
                                                             if q.name not in MAIN_PARAMETERS]
    for n in order:
        if n not in ds.attrs:
            continue
        q = by_name[n]
        v = _attr(ds, n)
        u = unit_html(n)
        text = _value_text(v)
        if u and not isinstance(v, str):
            text += f" {u}"
        sym = tex_html(q.symbol) if q.symbol else n.replace("_", " ")
        out.append((sym, text, html.escape(q.long_name)))
    return out


def _results(ds) -> list[tuple[str, str, str]]:
    out = []
    for n in ("F_transmitted", "L_z", "residual_force", "residual_torque", "t_final", "n_steps", "wall_time"):
        if n in ds and ds[n].ndim == 0:
            q = QUANTITIES[n]
            u = unit_html(n)
            v = float(ds[n])
            text = (f"{int(v)}" if n == "n_steps" else f"{v:.4g}") + (f" {u}" if u else "")
            out.append((tex_html(q.symbol) if q.symbol else n.replace("_", " "), text, html.escape(q.long_name)))
    return out


# -- the tube ---------------------------------------------------------------------------------------
def joints_of(centres: np.ndarray, tangents: np.ndarray | None = None,
              link_length: float | None = None) -> np.ndarray:
    """The N + 1 joint positions of N link centres: where consecutive links meet (the mean of their
    ends, from the tangents when known, else the midpoint of the two centres); the two free ends
    half a link beyond the end centres."""
    c = np.asarray(centres, dtype=float)
    n = len(c)
    if n == 1:
        t = tangents[0] if tangents is not None else np.array([0.0, 0.0, -1.0])
        h = (link_length or 1.0) / 2
        return np.stack([c[0] - h * t, c[0] + h * t])
    if tangents is not None and link_length is not None:
        h = link_length / 2
        lo, hi = c - h * tangents, c + h * tangents          # each link's upper (s) and lower end
        inner = 0.5 * (hi[:-1] + lo[1:])
        return np.concatenate([lo[:1], inner, hi[-1:]])
    inner = 0.5 * (c[1:] + c[:-1])
    return np.concatenate([c[:1] - (inner[:1] - c[:1]), inner, c[-1:] + (c[-1:] - inner[-1:])])


def ring_frames(points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unit tangent, normal and binormal at each point of a polyline: the tangent bisects the two
    segments at a point, the normal is carried along by parallel transport (no twist of the tube)."""
    p = np.asarray(points, dtype=float)
    seg = np.diff(p, axis=0)
    seg /= np.maximum(np.linalg.norm(seg, axis=1, keepdims=True), 1e-300)
    t = np.empty_like(p)
    t[0], t[-1] = seg[0], seg[-1]
    t[1:-1] = seg[:-1] + seg[1:]
    bad = np.linalg.norm(t, axis=1) < 1e-9                      # a link folded back onto the last one
    t[bad] = np.vstack([seg, seg[-1:]])[bad]
    t /= np.linalg.norm(t, axis=1, keepdims=True)
    nrm = np.empty_like(p)
    a = np.eye(3)[int(np.argmin(np.abs(t[0])))]                 # the axis least along the first tangent
    nrm[0] = a - (a @ t[0]) * t[0]
    nrm[0] /= np.linalg.norm(nrm[0])
    for i in range(1, len(p)):
        v = nrm[i - 1] - (nrm[i - 1] @ t[i]) * t[i]
        norm = np.linalg.norm(v)
        if norm < 1e-9:                                         # tangent turned onto the old normal
            a = np.eye(3)[int(np.argmin(np.abs(t[i])))]
            v, norm = a - (a @ t[i]) * t[i], np.linalg.norm(a - (a @ t[i]) * t[i])
        nrm[i] = v / norm
    return t, nrm, np.cross(t, nrm)


def tube_mesh(points: np.ndarray, radius: float = TUBE_RADIUS, sides: int = 12
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A closed tube of ``radius`` around the polyline ``points`` (the joints, P = N + 1 of them):
    vertices (P * sides + 2, 3): a ring of ``sides`` around each point, perpendicular to the local
    tangent, then the centres of the two end caps; triangles (2 * sides * N + 2 * sides, 3);
    and the segment (link) of each triangle, so that a value per link colours its piece of tube."""
    p = np.asarray(points, dtype=float)
    n_pts = len(p)
    _, nrm, bi = ring_frames(p)
    theta = 2 * np.pi * np.arange(sides) / sides
    ring = (np.cos(theta)[None, :, None] * nrm[:, None, :] + np.sin(theta)[None, :, None] * bi[:, None, :])
    vertices = np.concatenate([(p[:, None, :] + radius * ring).reshape(-1, 3), p[:1], p[-1:]])
    j = np.arange(n_pts - 1)[:, None]
    k = np.arange(sides)[None, :]
    a = j * sides + k
    b = j * sides + (k + 1) % sides
    c, d = a + sides, b + sides
    quads = np.stack([np.stack([a, b, d], -1), np.stack([a, d, c], -1)], axis=2).reshape(-1, 3)
    first, last = n_pts * sides, n_pts * sides + 1
    cap0 = np.stack([np.full(sides, first), (np.arange(sides) + 1) % sides, np.arange(sides)], -1)
    top = (n_pts - 1) * sides
    cap1 = np.stack([np.full(sides, last), top + np.arange(sides), top + (np.arange(sides) + 1) % sides], -1)
    faces = np.concatenate([quads, cap0, cap1]).astype(np.int64)
    link = np.concatenate([np.repeat(np.arange(n_pts - 1), 2 * sides), np.zeros(sides, int),
                           np.full(sides, n_pts - 2)])
    return vertices, faces, link


# -- colours ----------------------------------------------------------------------------------------
@dataclass
class Coloring:
    """How one --color choice maps a shape's links to numbers and colours."""
    name: str
    title: str                      # colour bar title (HTML)
    hover: str                      # hover label
    values: list[np.ndarray]        # per shape, per link; NaN: no value
    categorical: bool = False
    log: bool = False
    cmin: float = 0.0
    cmax: float = 1.0
    colorscale: list = field(default_factory=list)
    tickvals: list = field(default_factory=list)
    ticktext: list = field(default_factory=list)
    has_none: bool = False
    none_value: float | None = None            # the number of the none band

    @property
    def empty(self) -> bool:
        """No link of any shape has a value (the file does not store the variable)."""
        return not any(np.isfinite(v).any() for v in self.values)


def link_values(shape: Shape, s_link: np.ndarray, s_joint: np.ndarray, color: str) -> np.ndarray:
    """The chosen variable on each link of a shape (reduced units; NaN where it has none)."""
    n = len(shape.centres)
    nan = np.full(n, np.nan)
    f = shape.fields
    if color == "F_z":
        return nan if shape.force is None else np.interp(s_link, s_joint, shape.force)
    if color == "wall_force":
        return f.get("wall_force", nan).astype(float)
    if color == "stuck":
        if "stuck" not in f or "contact" not in f:
            return nan
        return np.where(f["stuck"] > 0, 2.0, np.where(f["contact"] > 0, 1.0, 0.0))
    if color == "friction_angle":
        if "friction_z" not in f or "friction_phi" not in f:
            return nan
        fz, fphi = f["friction_z"], f["friction_phi"]
        angle = np.degrees(np.arctan2(fphi, fz))
        return np.where(np.hypot(fz, fphi) > _FRICTION_FLOOR, angle, np.nan)
    raise ViewError(f"unknown --color {color!r}; choose one of {', '.join(COLORS)}")


def coloring(rod: Rod, color: str) -> Coloring:
    check_color(color)
    values = [link_values(sh, rod.s_link, rod.s_joint, color) for sh in rod.shapes]
    allv = np.concatenate(values) if values else np.array([])
    finite = allv[np.isfinite(allv)]
    has_none = bool(np.any(~np.isfinite(allv)))
    if color == "stuck":
        codes = [k for k in CATEGORIES]
        scale, ticks, texts = [], [], []
        cats = ([(-1, ("no value", NONE_COLOR))] if has_none else []) + [(k, CATEGORIES[k]) for k in codes]
        lo, hi = cats[0][0] - 0.5, cats[-1][0] + 0.5
        for k, (text, col) in cats:
            a, b = (k - 0.5 - lo) / (hi - lo), (k + 0.5 - lo) / (hi - lo)
            scale += [[a, col], [b, col]]
            ticks.append(k)
            texts.append(text)
        return Coloring(color, "friction state", "state", values, categorical=True, cmin=lo, cmax=hi,
                        colorscale=scale, tickvals=ticks, ticktext=texts, has_none=has_none)
    if color == "friction_angle":
        title = "friction direction<br>θ<sub>f</sub> = atan2(f<sub>φ</sub>, f<sub>z</sub>) [°]"
        ticks = [-90, 0, 90, 180]
        texts = ["−90° cw", "0° up", "90° ccw", "±180° down"]
        c = Coloring(color, title, "θ<sub>f</sub> [°]", values, cmin=-180.0, cmax=180.0,
                     colorscale=_named_scale("phase"), tickvals=ticks, ticktext=texts, has_none=has_none)
        return _with_none(c)
    if color == "F_z":
        title, hover = label_html("F_z", "|F_z|"), f"|F<sub>z</sub>| [{unit_html('F_z')}]"
        scale = "viridis"
    else:
        title, hover = label_html("wall_force"), label_html("wall_force")
        scale = "plasma"
    c = Coloring(color, title, hover, values, colorscale=_named_scale(scale), has_none=has_none)
    pos = finite[finite > 0]
    if color == "F_z" and pos.size and pos.max() / pos.min() > _LOG_SPAN:
        c.log = True
        c.cmin, c.cmax = float(np.log10(pos.min())), float(np.log10(pos.max()))
        c.tickvals, c.ticktext = _decade_ticks(c.cmin, c.cmax)
        c.title += "<br>(log scale)"
    elif finite.size:
        c.cmin, c.cmax = float(finite.min()), float(finite.max())
        if color == "wall_force":
            c.cmin = min(c.cmin, 0.0)
        mid, half = 0.5 * (c.cmin + c.cmax), 0.5 * (c.cmax - c.cmin)
        if half < MIN_SPAN * abs(mid):          # a constant (up to round-off): one colour, not a rainbow of noise
            c.cmin, c.cmax = mid - MIN_SPAN * abs(mid), mid + MIN_SPAN * abs(mid)
    if not c.cmax > c.cmin:
        c.cmax = c.cmin + (abs(c.cmin) or 1.0)
    return _with_none(c)


def _named_scale(name: str) -> list:
    from plotly.colors import get_colorscale

    return [[float(a), b] for a, b in get_colorscale(name)]


def _decade_ticks(lo: float, hi: float) -> tuple[list, list]:
    ticks, texts = [], []
    for e in range(int(np.floor(lo)), int(np.ceil(hi)) + 1):
        for m in (1, 2, 5):
            v = np.log10(m) + e
            if lo - 1e-9 <= v <= hi + 1e-9:
                ticks.append(float(v))
                texts.append(f"10<sup>{e}</sup>".replace("-", "−") if m == 1 else
                             (f"{m}·10<sup>{e}</sup>".replace("-", "−") if hi - lo > 1.5 else f"{m * 10.0 ** e:g}"))
    if hi - lo > 2.5:                                   # a wide span: decades only
        keep = [i for i, t in enumerate(ticks) if abs(t - round(t)) < 1e-9]
        ticks, texts = [ticks[i] for i in keep], [texts[i] for i in keep]
    return ticks, texts


def _linear_ticks(lo: float, hi: float) -> tuple[list, list]:
    """About five round ticks between lo and hi."""
    raw = (hi - lo) / 5
    mag = 10 ** np.floor(np.log10(raw))
    step = mag * min((m for m in (1, 2, 2.5, 5, 10) if m * mag >= raw), default=10)
    ticks = np.arange(np.ceil(lo / step) * step, hi + 1e-9 * step, step)
    return [float(t) for t in ticks], [f"{t:.4g}" for t in ticks]


def _with_none(c: Coloring) -> Coloring:
    """Room below cmin for the links without a value: a grey band of the colour bar, 'none'."""
    if not c.has_none:
        return c
    if not c.tickvals:
        c.tickvals, c.ticktext = _linear_ticks(c.cmin, c.cmax)
    band = 0.12 * (c.cmax - c.cmin)
    lo = c.cmin - band
    frac = band / (c.cmax - lo)
    c.colorscale = [[0.0, NONE_COLOR], [frac * 0.999, NONE_COLOR]] + [
        [frac + (1 - frac) * a, col] for a, col in c.colorscale]
    c.none_value = lo + band / 2
    c.tickvals = [c.none_value] + list(c.tickvals)
    c.ticktext = ["no value"] + list(c.ticktext)
    c.cmin = lo
    return c


def intensities(c: Coloring, values: np.ndarray) -> np.ndarray:
    """The numbers the colour scale maps (log10 for a log scale; the none band for NaN)."""
    v = np.asarray(values, dtype=float)
    if c.categorical:
        return np.where(np.isfinite(v), v, -1.0)
    if c.log:
        with np.errstate(divide="ignore", invalid="ignore"):
            v = np.log10(np.where(v > 0, v, 10 ** c.cmin))
    none = c.cmin if c.none_value is None else c.none_value
    return np.where(np.isfinite(v), np.clip(v, c.cmin, c.cmax), none)


# -- the figure ----------------------------------------------------------------------------------
def _sides(n_links: int) -> int:
    return 12 if n_links <= 150 else 8 if n_links <= 600 else 6


def _value_texts(c: Coloring, values: np.ndarray) -> np.ndarray:
    """Each link's value as the hover shows it ('none' without one)."""
    if c.categorical:
        return np.array([CATEGORIES[int(v)][0] if np.isfinite(v) else "none" for v in values], dtype=object)
    return np.array([f"{v:.4g}" if np.isfinite(v) else "none" for v in values], dtype=object)


def tube_data(shape: Shape, rod: Rod, c: Coloring, values: np.ndarray, sides: int) -> dict:
    """The tube of one shape: vertices (float32), triangles, the colour numbers of the triangles
    (intensitymode cell: one colour per link), and per vertex the arc length of its joint and the
    text of its link's value (the hover)."""
    pts = joints_of(shape.centres, shape.tangents, rod.link_length)
    verts, faces, link = tube_mesh(pts, TUBE_RADIUS, sides)
    n_links = len(pts) - 1
    s_vert = np.concatenate([np.repeat(rod.s_joint, sides), [rod.s_joint[0], rod.s_joint[-1]]])
    link_of_vertex = np.minimum(np.concatenate([np.repeat(np.arange(len(pts)), sides), [0, n_links - 1]]),
                                n_links - 1)
    return dict(x=verts[:, 0].astype(np.float32), y=verts[:, 1].astype(np.float32),
                z=verts[:, 2].astype(np.float32), faces=faces, link=link,
                intensity=intensities(c, values)[link].astype(np.float32),
                customdata=s_vert.astype(np.float32), text=_value_texts(c, values)[link_of_vertex])


def figure(rod: Rod, color: str = DEFAULT_COLOR):
    """The plotly Figure of a rod: tube in the pore (scene), |F_z|(s) (xy), a slider over the stored
    shapes if there are several."""
    import plotly.graph_objects as go

    c = coloring(rod, color)
    sides = _sides(len(rod.s_link))
    n_shapes = len(rod.shapes)
    active = n_shapes - 1
    tubes = [tube_data(sh, rod, c, v, sides) for sh, v in zip(rod.shapes, c.values)]
    faces = tubes[active]["faces"]
    idx = faces.astype(np.uint16 if faces.max() < 2 ** 16 else np.uint32)
    hover = (f"s = %{{customdata:.3g}} R<br>{c.hover} = %{{text}}"
             "<br>(x, y, z) = (%{x:.2f}, %{y:.2f}, %{z:.2f}) R<extra></extra>")
    colorbar = dict(title=dict(text=c.title, side="top", font=dict(size=15)), x=0.42, xanchor="left",
                    len=0.7, y=0.45, thickness=16, tickfont=dict(size=13), outlinewidth=0)
    if c.tickvals:
        colorbar.update(tickvals=c.tickvals, ticktext=c.ticktext)

    def moving(t):                                  # what changes from one shape to the next
        return {k: t[k] for k in ("x", "y", "z", "intensity", "customdata", "text")}

    mesh = go.Mesh3d(**moving(tubes[active]), i=idx[:, 0], j=idx[:, 1], k=idx[:, 2], intensitymode="cell",
                     colorscale=c.colorscale, cmin=c.cmin, cmax=c.cmax, colorbar=colorbar, showscale=not c.empty,
                     flatshading=False, hovertemplate=hover, name="rod",
                     lighting=dict(ambient=0.45, diffuse=0.8, specular=0.35, roughness=0.45, fresnel=0.2),
                     lightposition=dict(x=2000, y=1000, z=3000))
    traces = [mesh, *_pore_traces(rod), _profile_trace(rod, rod.shapes[active])]
    n_traces = len(traces)
    fig = go.Figure(data=traces, layout=_layout(rod, c))
    if n_shapes > 1:
        frames, steps = [], []
        for k, (sh, t) in enumerate(zip(rod.shapes, tubes)):
            frames.append(go.Frame(name=str(k), traces=[0, n_traces - 1],
                                   data=[go.Mesh3d(**moving(t)), _profile_trace(rod, sh)]))
            steps.append(dict(label=sh.label, method="animate",
                              args=[[str(k)], dict(mode="immediate", frame=dict(duration=0, redraw=True),
                                                   transition=dict(duration=0))]))
        fig.frames = frames
        fig.layout.sliders = [dict(active=active, steps=steps, x=0.04, len=0.92, y=-0.02, yanchor="top",
                                   pad=dict(t=36, b=6), font=dict(size=12),
                                   currentvalue=dict(prefix=f"{rod.frame_title} = ", font=dict(size=15)))]
        fig.layout.updatemenus = list(fig.layout.updatemenus) + [dict(
            type="buttons", direction="left", x=0.0, y=-0.02, xanchor="right", yanchor="top",
            pad=dict(t=44, r=6), showactive=False, buttons=[
                dict(label="▶", method="animate",
                     args=[None, dict(frame=dict(duration=500, redraw=True), fromcurrent=True,
                                      transition=dict(duration=0), mode="immediate")]),
                dict(label="❚❚", method="animate",
                     args=[[None], dict(frame=dict(duration=0, redraw=False), mode="immediate")])])]
    return fig


def profile_kind(rod: Rod) -> str:
    """What the 2-D panel shows: 'F_z' (|F_z|(s)) if every shape stores it, else 'rho' (the distance
    of the link centres from the axis: where the rod touches the wall or has left the pore)."""
    return "F_z" if all(sh.force is not None for sh in rod.shapes) else "rho"


def profile_data(rod: Rod, shape: Shape) -> tuple[np.ndarray, np.ndarray]:
    """The panel's curve of one shape: (s at the joints, |F_z|) or (s at the link centres, rho)."""
    if profile_kind(rod) == "F_z":
        return rod.s_joint, shape.force
    return rod.s_link, np.hypot(shape.centres[:, 0], shape.centres[:, 1])


def _profile_trace(rod: Rod, shape: Shape):
    import plotly.graph_objects as go

    x, y = profile_data(rod, shape)
    if profile_kind(rod) == "F_z":
        hover = "s = %{x:.3g} R<br>|F<sub>z</sub>| = %{y:.4g} EI/R<sup>2</sup><extra></extra>"
    else:
        hover = "s = %{x:.3g} R<br>ρ = %{y:.4g} R<extra></extra>"
    return go.Scatter(x=x.astype(float), y=y.astype(float), mode="lines+markers", xaxis="x", yaxis="y",
                      line=dict(color="#222222", width=2), marker=dict(size=4, color="#222222"),
                      name=profile_kind(rod), showlegend=False, hovertemplate=hover)


def _pore_traces(rod: Rod) -> list:
    import plotly.graph_objects as go

    theta = np.linspace(0, 2 * np.pi, 49)
    top = rod.pore
    zs = np.array([0.0, top])
    cyl = go.Surface(x=np.outer(np.ones(2), np.cos(theta)), y=np.outer(np.ones(2), np.sin(theta)),
                     z=np.outer(zs, np.ones_like(theta)), surfacecolor=np.zeros((2, theta.size)),
                     colorscale=[[0, "#6aaed6"], [1, "#6aaed6"]], showscale=False, opacity=0.16,
                     hoverinfo="skip", name="pore", lighting=dict(ambient=1.0, diffuse=0.0, specular=0.0))
    rx, ry, rz = [], [], []
    for z in zs:
        rx += list(np.cos(theta)) + [None]
        ry += list(np.sin(theta)) + [None]
        rz += [z] * theta.size + [None]
    for a in (0, np.pi / 2, np.pi, 3 * np.pi / 2):
        rx += [np.cos(a), np.cos(a), None]
        ry += [np.sin(a), np.sin(a), None]
        rz += [0.0, top, None]
    rims = go.Scatter3d(x=rx, y=ry, z=rz, mode="lines", line=dict(color="#4a8fc4", width=3),
                        hoverinfo="skip", name="pore wall", showlegend=False, connectgaps=False)
    r = np.linspace(0, 1, 2)
    floor = go.Surface(x=np.outer(r, np.cos(theta)), y=np.outer(r, np.sin(theta)), z=np.zeros((2, theta.size)),
                       surfacecolor=np.zeros((2, theta.size)), colorscale=[[0, "#7f7f7f"], [1, "#7f7f7f"]],
                       showscale=False, opacity=0.45, hoverinfo="skip", name="piston")
    return [cyl, rims, floor]


def _layout(rod: Rod, c: Coloring) -> dict:
    L = max(rod.pore, float(np.max([sh.centres[:, 2].max() for sh in rod.shapes])), 1.0)
    width = 2.0 + 2 * TUBE_RADIUS
    ratio = L / width
    squeeze = ratio > SQUEEZE_ABOVE
    zr = SQUEEZED if squeeze else ratio
    aspect = dict(x=1.0, y=1.0, z=zr)
    true_aspect = dict(x=1.0, y=1.0, z=ratio)
    axis = dict(showbackground=False, gridcolor="#dddddd", zerolinecolor="#bbbbbb", tickfont=dict(size=11),
                title=dict(font=dict(size=14)))
    d = 1.05 * zr + 1.5                                  # far enough to see the whole pore
    scene = dict(domain=dict(x=[0.0, 0.42], y=[0.0, 1.0]), aspectmode="manual", aspectratio=aspect,
                 xaxis=dict(axis, title=dict(text="x [R]", font=dict(size=14)), range=[-1.25, 1.25],
                            tickvals=[-1, 0, 1]),
                 yaxis=dict(axis, title=dict(text="y [R]", font=dict(size=14)), range=[-1.25, 1.25],
                            tickvals=[-1, 0, 1]),
                 zaxis=dict(axis, title=dict(text="z [R]", font=dict(size=14)), range=[-0.2, L + 0.3]),
                 camera=dict(eye=dict(x=0.80 * d, y=0.56 * d, z=0.22 * d), up=dict(x=0, y=0, z=1),
                             center=dict(x=0, y=0, z=0)))
    kind = profile_kind(rod)
    ys = np.concatenate([profile_data(rod, sh)[1] for sh in rod.shapes])
    pos = ys[ys > 0]
    ylog = bool(kind == "F_z" and pos.size and pos.max() / pos.min() > _LOG_SPAN)
    ytitle = ("|F<sub>z</sub>| [EI/R<sup>2</sup>]" if kind == "F_z" else
              "ρ = (x<sup>2</sup> + y<sup>2</sup>)<sup>1/2</sup> [R]")
    yaxis = dict(title=dict(text=ytitle, font=dict(size=16)),
                 type="log" if ylog else "linear", showline=True, mirror=True, linecolor="#444", ticks="inside",
                 gridcolor="#eeeeee", tickfont=dict(size=13), exponentformat="power")
    if ylog:
        yaxis["range"] = [np.log10(pos.min()) - 0.15, np.log10(pos.max()) + 0.15]
    else:
        yaxis["range"] = [0, max(float(ys.max()) if ys.size else 1.0, 1.0 if kind == "rho" else 0.0) * 1.08 or 1.0]
    xaxis = dict(title=dict(text="s [R]  (s = 0: the loaded end)", font=dict(size=16)),
                 domain=[0.66, 0.99], range=[0, float(rod.s_joint[-1])], showline=True, mirror=True,
                 linecolor="#444", ticks="inside", gridcolor="#eeeeee", tickfont=dict(size=13), anchor="y")
    yaxis["domain"] = [0.12, 0.95]
    yaxis["anchor"] = "x"
    annotations = []
    shapes = []
    if kind == "rho":
        shapes.append(dict(type="line", xref="x domain", yref="y", x0=0, x1=1, y0=1, y1=1,
                           line=dict(color="#4a8fc4", dash="dash", width=1.5)))
        annotations.append(dict(text="pore wall ρ = R (|F<sub>z</sub>| is not stored in this file)",
                                xref="x domain", yref="y", x=0.02, y=1, xanchor="left", yanchor="bottom",
                                showarrow=False, font=dict(size=12, color="#4a8fc4")))
    annotations.append(dict(text="axial force along the rod" if kind == "F_z" else "distance from the axis",
                            xref="x domain", yref="y domain", x=0.5, y=1.0,
                            yanchor="bottom", showarrow=False, font=dict(size=15)))
    note = f"tube radius {TUBE_RADIUS:g} R (drawing); pore radius R"
    if squeeze:
        note += f"; z squeezed ×{ratio / zr:.2g} (button: true proportions)"
    annotations.append(dict(text=note, xref="paper", yref="paper", x=0.0, y=1.0, xanchor="left",
                            yanchor="bottom", showarrow=False, font=dict(size=12, color="#555")))
    menus = []
    if squeeze:
        menus.append(dict(type="buttons", direction="down", x=0.0, y=0.02, xanchor="left", yanchor="bottom",
                          showactive=True, active=0, font=dict(size=12), bgcolor="#f4f4f4", buttons=[
                              dict(label=f"z squeezed ×{ratio / zr:.2g}", method="relayout",
                                   args=[{"scene.aspectratio": aspect}]),
                              dict(label="true proportions", method="relayout",
                                   args=[{"scene.aspectratio": true_aspect}])]))
    return dict(template="none", font=dict(family="DejaVu Sans, Arial, sans-serif", size=14,
                                                        color="#222"),
                paper_bgcolor="white", plot_bgcolor="white", margin=dict(l=10, r=20, t=30, b=20),
                scene=scene, xaxis=xaxis, yaxis=yaxis, annotations=annotations, updatemenus=menus, shapes=shapes,
                showlegend=False, hoverlabel=dict(font=dict(size=13)), uirevision="keep")


# -- pages ------------------------------------------------------------------------------------------
def entry(rod: Rod, color: str = DEFAULT_COLOR, key: str | None = None, group: str = "") -> dict:
    """One scene of a page: its figure (plotly JSON, arrays base64-encoded) and its header and
    parameter HTML."""
    fig = figure(rod, color)
    _assert_finite(fig)
    return {"key": key or rod.name, "group": group, "label": rod.name.split("/")[-1],
            "header": _header_html(rod, color), "params": _params_html(rod),
            "figure": json.loads(fig.to_json())}


def _assert_finite(fig) -> None:
    """No NaN or inf reaches the page (links without a value have the none colour)."""
    for tr in list(fig.data) + [d for f in fig.frames for d in f.data]:
        for name in ("x", "y", "z", "intensity", "customdata", "surfacecolor"):
            v = getattr(tr, name, None)
            if isinstance(v, np.ndarray) and v.dtype.kind == "f" and not np.all(np.isfinite(v)):
                raise AssertionError(f"non-finite {name} in the {tr.type} trace of the view")


def _status_class(rod: Rod) -> str:
    return "ok" if rod.settled else "warn"


def _header_html(rod: Rod, color: str) -> str:
    st = html.escape(rod.status.replace("_", " "))
    missing = (" <b>This file does not store it: the rod is grey.</b>" if coloring(rod, color).empty else "")
    reason = f" — {html.escape(rod.reason)}" if rod.reason else ""
    note = f'<div class="note">{rod.note}</div>' if rod.note else ""
    title = re.sub(r"\^(-?\d+)", r"<sup>\1</sup>", html.escape(rod.title))
    return (f'<h1>{title}</h1>'
            f'<div class="status {_status_class(rod)}"><b>status: {st}</b>{reason}</div>'
            f'<div class="note">colour: {html.escape(COLORS[color])}.{missing} Drag to turn, scroll to zoom, '
            f'double-click to reset.</div>{note}')


def _params_html(rod: Rod) -> str:
    def rows(items):
        return "".join(f'<tr title="{d}"><th>{s}</th><td>{v}</td><td class="d">{d}</td></tr>' for s, v, d in items)

    main = [p for p in rod.params if p[0] in {tex_html(q.symbol) if q.symbol else q.name.replace("_", " ")
                                               for q in SCENE_PARAMETERS if q.name in MAIN_PARAMETERS}]
    rest = [p for p in rod.params if p not in main]
    out = (f'<div class="cols"><div><h2>scene {html.escape(rod.name)}</h2><table>{rows(main)}</table></div>'
           + (f'<div><h2>result</h2><table>{rows(rod.results)}</table></div>' if rod.results else "")
           + '</div>')
    if rest:
        out += f'<details><summary>all parameters</summary><table>{rows(rest)}</table></details>'
    return out


_CSS = """
body{font-family:"DejaVu Sans",Arial,sans-serif;margin:0;padding:10px 18px;color:#222;background:#fff}
h1{font-size:20px;margin:4px 0 6px} h2{font-size:16px;margin:10px 0 4px}
.status{font-size:15px;padding:4px 8px;border-radius:4px;display:inline-block;margin:2px 0}
.status.ok{background:#e6f4ea;border:1px solid #8cc79b} .status.warn{background:#fff1e0;border:1px solid #e8a552}
.note{font-size:13px;color:#555;margin:3px 0}
#plot{width:100%;height:74vh;min-height:520px}
nav{margin:4px 0 8px;font-size:15px} nav select{font-size:15px;padding:2px 4px}
table{border-collapse:collapse;font-size:14px} th{text-align:left;padding:1px 10px 1px 0;font-weight:normal}
td{padding:1px 12px 1px 0} td.d{color:#666;font-size:12px}
.cols{display:flex;gap:40px;flex-wrap:wrap} details{margin-top:6px;font-size:14px}
table.index td{padding:2px 14px 2px 0} .status.small{font-size:12px;padding:0 6px;margin:0}
#errors{color:#b00020;font-family:monospace;white-space:pre-wrap}
"""

_JS = """
function viewsStart(VIEWS){
  const byKey = {}; VIEWS.entries.forEach(e => byKey[e.key] = e);
  const sel = document.getElementById('scene');
  if (sel) {
    const groups = {};
    VIEWS.entries.forEach(e => {
      let g = sel;
      if (e.group) { g = groups[e.group]; if (!g) { g = document.createElement('optgroup'); g.label = e.group;
                     sel.appendChild(g); groups[e.group] = g; } }
      const o = document.createElement('option'); o.value = e.key; o.textContent = e.label; g.appendChild(o);
    });
    sel.addEventListener('change', () => { location.hash = encodeURIComponent(sel.value); });
  }
  function show(key){
    const e = byKey[key] || VIEWS.entries[0];
    if (sel) sel.value = e.key;
    document.getElementById('head').innerHTML = e.header;
    document.getElementById('params').innerHTML = e.params;
    const f = e.figure;
    return Plotly.react('plot', {data: f.data, layout: f.layout, frames: f.frames || [],
        config: {responsive: true, displaylogo: false, toImageButtonOptions: {format: 'png', scale: 2}}})
      .then(() => { document.body.dataset.rendered = e.key; console.log('[view rendered] ' + e.key); });
  }
  const current = () => decodeURIComponent(location.hash.slice(1));
  window.addEventListener('hashchange', () => show(current()));
  return show(current());
}
// errors show on the page and in the console as '[view error] ...' (tests/test_view.py looks for it)
function viewError(msg){
  const box = document.getElementById('errors'); if (box) box.textContent += msg + '\\n';
  console.log('[view error] ' + msg);
}
window.addEventListener('error', ev => viewError('uncaught: ' + ev.message));
window.addEventListener('unhandledrejection', ev => viewError('unhandled: ' + ev.reason));
(function(){ const original = console.error;
  console.error = function(...args){ original.apply(console, args); viewError(args.map(String).join(' ')); }; })();
"""


def _script_json(obj: Any) -> str:
    """JSON for a <script type="application/json"> block (no '</' can end it early)."""
    return json.dumps(obj, separators=(",", ":"), allow_nan=False).replace("</", "<\\/")


def page_html(entries: list[dict], title: str, plotlyjs: str = "inline") -> str:
    """One HTML page of one or several scenes (a selector for several; the URL's #key picks one).

    plotlyjs: "inline" (plotly.js in the page: self-contained, 4.8 MB) or the relative address of a
    plotly.min.js that the page loads (the pipeline's pages share one)."""
    from plotly.offline import get_plotlyjs

    data = {"title": title, "entries": entries}
    nav = '<nav><label>scene: <select id="scene"></select></label></nav>' if len(entries) > 1 else ""
    head = f"<meta charset=\"utf-8\"><title>{html.escape(title)}</title><style>{_CSS}</style>"
    body = (f"{nav}<div id=\"head\"></div><div id=\"plot\"></div><div id=\"params\"></div>"
            "<div id=\"errors\"></div>")
    if plotlyjs == "inline":
        plotly = f"<script>{get_plotlyjs()}</script>"
    elif plotlyjs.endswith(".js"):
        plotly = f"<script src=\"{html.escape(plotlyjs)}\"></script>"
    else:
        raise ValueError(f"plotlyjs must be 'inline' or the address of plotly.min.js, not {plotlyjs!r}")
    scripts = (f"<script>{_JS}</script>{plotly}"
               f"<script type=\"application/json\" id=\"views-data\">{_script_json(data)}</script>"
               "<script>if (typeof Plotly === 'undefined') viewError('plotly.js did not load');"
               "else viewsStart(JSON.parse(document.getElementById('views-data').textContent));</script>")
    return f"<!DOCTYPE html>\n<html lang=\"en\"><head>{head}</head><body>{body}{scripts}</body></html>\n"


def page_of(rods: list[Rod], color: str = DEFAULT_COLOR) -> str:
    """The self-contained page (plotly.js inline) of read rods: one, or several with a selector."""
    entries = [entry(r, color, key=r.name) for r in rods]
    return page_html(entries, rods[0].title if len(rods) == 1 else f"{len(rods)} rods", "inline")


def write_page(datasets: Iterable[str | Path], output: str | Path, color: str = DEFAULT_COLOR) -> Path:
    """Read scene files and write their self-contained view page atomically (io.write_text)."""
    from ..io import write_text

    return write_text(page_of([read_rod(p) for p in datasets], color), output)


# -- the pipeline: every simulation of the figures, one page each, one plotly.js ---------------------------
PLOTLY_JS = layout.VIEWS_PLOTLY


def page_name(figure: str, scene: str) -> str:
    """A scene's page in the views folder, relative to it."""
    return layout.VIEW_PAGE.format(figure=figure, scene=scene)


def write_views(folder: str | Path, figures: list[tuple[str, str, list[tuple[str, str]]]],
                color: str = DEFAULT_COLOR) -> Path:
    """The views folder (rule views): ``index.html`` (every figure's simulations, with their status,
    linked), one page per simulation (``<figure>/<scene>.html``) and the one ``plotly.min.js`` they
    load. ``figures``: (figure, title, [(scene, scene file), ...]), in the config's order. Every file
    is written atomically; the folder opens from disk in any browser, and a zip report
    (``snakemake --report results/report.zip``) carries it whole."""
    from plotly.offline import get_plotlyjs

    from ..io import write_text

    folder = Path(folder)
    write_text(get_plotlyjs(), folder / PLOTLY_JS)
    sections = []
    n = 0
    for figure, title, scenes in figures:
        rows = []
        for scene, path in scenes:
            rod = read_rod(path)
            name = page_name(figure, scene)
            write_text(page_html([entry(rod, color, key=f"{figure}/{scene}")], rod.title, f"../{PLOTLY_JS}"),
                       folder / name)
            params = ", ".join(f"{s} = {v}" for s, v, _ in rod.params[:5])
            rows.append(f'<tr><td><a href="{html.escape(name)}">{html.escape(scene)}</a></td>'
                        f'<td><span class="status small {_status_class(rod)}">'
                        f'{html.escape(rod.status.replace("_", " "))}</span></td><td>{params}</td></tr>')
            n += 1
        sections.append(f'<h2 id="{html.escape(figure)}">{html.escape(figure)}</h2><div class="note">'
                        f'{html.escape(title)}</div><table class="index">{"".join(rows)}</table>')
    page = (f"<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>Rods in 3-D</title>"
            f"<style>{_CSS}</style></head><body><h1>Rods in the pore, in 3-D</h1>"
            f'<div class="note">{n} simulations of {len(figures)} figures: open one to turn the rod in the pore '
            f"(coloured by |F<sub>z</sub>|, beside its profile |F<sub>z</sub>|(s)).</div>{''.join(sections)}"
            "</body></html>\n")
    write_text(page, folder / Path(layout.VIEWS_INDEX).name)
    return folder


# -- the command line ---------------------------------------------------------------------------------
def main(datasets: list[Path], output: Path, color: str) -> int:
    """``confined-rod view``: 0 on success, 2 with a one-line message on bad input."""
    import sys

    from ..errors import OutputPathError
    from ..io import check_output_path

    def refuse(msg: str) -> int:
        print(f"error: {msg}", file=sys.stderr)
        return 2

    try:
        check_color(color)
        require_plotly()
        check_output_path(output, suffix=".html")
        rods = [read_rod(p) for p in datasets]
    except (ViewError, PlotlyMissing, OutputPathError) as exc:
        return refuse(str(exc))
    from ..io import write_text

    try:
        write_text(page_of(rods, color), output)
    except OSError as exc:
        return refuse(f"cannot write {str(output)!r} ({exc.strerror or type(exc).__name__})")
    print(f"{', '.join(r.name for r in rods)} -> {output}", file=sys.stderr)
    return 0
