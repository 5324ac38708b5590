"""Scenes: physical set-up, boundary conditions, protocols and numerical settings.

A :class:`Scene` is validated on construction: a bad value raises
:class:`SceneError` naming the key, the value and the valid range, before any
computation; so is a scene the model or float64 cannot compute (limits.py).
Numerical defaults given as ``None`` are resolved in units of the scene's R and
EI (so a scene in physical units gets the same discretisation relative to R);
``dataclasses.replace`` re-resolves them, so ``replace(Scene(L=12), R=2.0)``
has the l0, k_ph, ... of R = 2.
"""
from __future__ import annotations

import copy
import dataclasses
import math
import numbers
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .. import limits
from ..errors import SceneError
from ..errors import shorten as _short
from ..quantities import QUANTITIES
from . import perturbation
from .model import kernels as K
from .model.parameters import DiscreteConstants, discrete_constants

# Defaults of the numerical parameters, in units of R and EI (see docs/model.md,
# "numerical defaults", for how they were chosen).
DEFAULT_L0 = 0.5  # R
DEFAULT_K_PH = 1000.0  # EI/R^2: axial strain load/k_ph = 2.5e-4 at load 0.25
DEFAULT_K_W = 1000.0  # EI/R^3 per link end: penetration <= N/k_w
# stick stiffness of the friction springs (docs/model.md, "Friction"): with friction at the link
# centre, x k_w (F(L) moves 0.2 % from 0.1 k_w to 10 k_w); with friction at the link ends, x the bond
# constant k_ph/l0: the ends' F(L) reaches its rigid-stick limit only for k_t l0/k_ph >~ 0.5 (-8 % at 0.05)
DEFAULT_K_T = 0.1
DEFAULT_K_T_ENDS = 1.0
# EI/R^2, friction force per link: 0.1 EI/R^3 per length at the publication l0 = 0.5 R, 8x the bulk
# k_fr K l0 at load 0.25, so it acts on concentrated contacts only (docs/model.md, "friction cap")
DEFAULT_FRICTION_CAP = 0.05
DEFAULT_PERTURBATION = 1e-3  # R
DEFAULT_KICK = 0.1  # R
DEFAULT_T_MAX = 2e5  # beta_ph R^4/EI; explicit solver, whose cost is proportional to simulated time
DEFAULT_T_MAX_IMPLICIT = 1e9  # implicit solver: its steps grow as the rod settles, time is nearly free
DEFAULT_DX_MAX = 0.02  # R, largest displacement of a link end per implicit step

MAX_SCENE_FILE_BYTES = 1 << 20

# the allowed values of the categorical parameters are declared once, in quantities.py
PROTOCOLS = QUANTITIES["protocol"].choices
ENDS = QUANTITIES["ends"].choices
LOWER_END = QUANTITIES["lower_end"].choices
ROTATIONAL_DRAG = QUANTITIES["rotational_drag"].choices
FRICTION_AT = QUANTITIES["friction_at"].choices
SOLVERS = QUANTITIES["solver"].choices
BENDING_CONSTANT = QUANTITIES["bending_constant"].choices
UNIT_SYSTEMS = QUANTITIES["unit_system"].choices


@dataclass(frozen=True)
class Scene:
    """One simulation: a rod of length L in a cylinder of radius R.

    Physical parameters (paper notation):
      L, R, EI     contour length, cylinder radius, bending stiffness
      load         |F_z(0)|, compressive force on the upper end (EI/R^2)
      k_fr         Coulomb friction coefficient of the wall
      friction_cap maximum friction force on one link (EI/R^2): the paper's cap for the
                   few hard-pressed points, which are concentrated contacts, so a force
                   (a cap per unit length would make them frictionless as l0 -> 0).
                   ``0`` = no cap
      body_force   external force per unit length (fx, fy, fz) on every link
    Boundary conditions and protocol:
      pore_length  z of the open pore entrance (default L: the top of the unloaded rod);
                   with pore_length < L the upper part starts outside the pore
      ends         'free': both ends free sideways (paper); 'pinned': held on the axis;
                   'guided': free, and the loaded end slides in a guide of radius R
                   (the pusher's sleeve) that continues above a pore entrance set lower
                   by pore_length: the rod between them can leave the pore (Fig 8)
      lower_end    'held': z of the lower end held at 0 (paper); 'free'
      floor        the lower piston at z = 0 is a wall for the whole rod (True), so
                   the rod cannot fold down past its support; False: no floor
      protocol     'straight': straight rod + 3-D random perturbation (paper);
                   'planar': perturbation in the x-z plane only -> planar confined state;
                   'planar_then_3d': planar equilibrium, then a 3-D perturbation (Fig 2);
                   'ramp': as 'straight', but the load is raised quasi-statically, in
                   ramp_steps geometric steps from ramp_start x Euler's load pi^2 EI/L^2 to
                   the load, each step relaxed to equilibrium from the last;
                   'helix': a right-handed helix on the wall (radius R - a, pitch rate of a
                   torque-free helix carrying the full load), plus the perturbation a
      ramp_steps   protocol 'ramp': number of load steps (default 16)
      ramp_start   protocol 'ramp': first load over Euler's load (default 2)
      perturbation amplitude of the random lateral displacement of link centres (R)
      kick         amplitude of the out-of-plane displacement that starts the second
                   stage of 'planar_then_3d' (default 0.1 R: large enough that the
                   residual criterion cannot stop the run on the planar saddle)
      seed         random seed of the perturbation
      saddle_kicks how often a run that stops on a known saddle (observables.SADDLES: straight
                   above Euler's load, planar and frictionless above the second threshold) is
                   kicked out of plane by ``kick`` and relaxed again (default 0: the run ends
                   there and its ``saddle`` flag says so)
    Numerics:
      l0, k_ph, k_w  link length, stretching stiffness (k = k_ph/l0), wall penalty
      k_t           stick stiffness of the wall friction: a stuck link (centre) or link end
                    (ends) is held by a tangential spring k_t to its anchor and slips once the
                    spring force reaches its Coulomb bound; rigid stick is k_t -> inf, which the
                    explicit scheme has at the centre. Default k_w/10 (centre) or k_ph/l0, the
                    bond constant (ends: F(L) is at its rigid-stick limit from k_t ~ 0.5 k_ph/l0)
      solver        'implicit' (backward Euler with Newton steps, the fast default) or
                    'explicit' (the paper's forward Euler, the reference)
      dx_max        implicit: largest displacement of a link end per step (R); the
                    accuracy knob of the implicit path (default 0.02 R)
      dt_factor     explicit: time step as a fraction of the estimated stability limit
                    (default 0.8; the scheme diverges above ~1.2; at most 10, for stress tests)
      tol           equilibrium when max|F_i| L/(l0 load) and max|M_i x t_i| L/(l0 load R) < tol
      t_max         cap on simulated time; reaching it flags the run as not converged
                    (default 2e5 beta_ph R^4/EI explicit, 1e9 implicit: a frictional helix
                    settles slowly, over ~5e5 at L = 320 R, and the implicit steps grow as it does)
      max_steps     cap on the number of steps, a work budget that is the same on every
                    machine (0 = none); reaching it ends the run as ``step_cap``
      friction_at   where a contact's friction acts: 'ends' (default: at each link end on the
                    wall, where the wall force acts, with that end's own normal force and stick
                    anchor; F(L) converges in l0 at the default k_t) or 'centre' (at the link
                    centre, with the normal force of both ends; a stuck link still turns freely
                    about its centre, so an end that touches the wall can slide, and F(L) creeps
                    up towards the ends' value as l0 -> 0). docs/model.md, "Friction"
      rotational_drag 'paper' (gamma_r = beta_ph l0 R^2) or 'rigid_link' (beta_ph l0^3/12)
      bending_constant 'corrected' (C = EI/l0, derived in docs/model.md) or 'paper' (the paper's
                    printed C = EI/l0^2 read in its units R = 1, i.e. C = EI R/l0^2: a rod of
                    effective bending stiffness EI R/l0). For reproducing the paper's numbers only
      snapshot_interval simulated time between stored shapes; 0 = none
      snapshot_growth 1 (default): a snapshot every snapshot_interval; g > 1: at t = 0,
                    snapshot_interval, then each time the simulated time has grown by g
                    (a few dozen snapshots of how a slow equilibrium forms, not a trajectory)
    """

    L: float = 20.0
    R: float = 1.0
    EI: float = 1.0
    load: float = 0.25
    k_fr: float = 0.8
    friction_cap: float | None = None
    body_force: tuple[float, float, float] = (0.0, 0.0, 0.0)
    pore_length: float | None = None
    ends: str = "free"
    lower_end: str = "held"
    floor: bool = True
    protocol: str = "straight"
    perturbation: float | None = None
    kick: float | None = None
    ramp_steps: int = 16
    ramp_start: float = 2.0
    seed: int = 0
    saddle_kicks: int = 0
    l0: float | None = None
    k_ph: float | None = None
    k_w: float | None = None
    k_t: float | None = None
    solver: str = "implicit"
    dx_max: float | None = None
    dt_factor: float = 0.8
    tol: float = 1e-5
    t_max: float | None = None
    max_steps: int = 0
    rotational_drag: str = "paper"
    friction_at: str = "ends"
    bending_constant: str = "corrected"
    snapshot_interval: float = 0.0
    snapshot_growth: float = 1.0
    unit_system: str = "reduced"
    name: str = "scene"
    #: identifies this instance: dataclasses.replace copies it, which tells a resolved
    #: default of the replaced scene (re-resolved) from one passed in (kept)
    _origin: object = field(default=None, repr=False, compare=False)

    def __post_init__(self) -> None:
        _validate(self)

    @classmethod
    def field_names(cls) -> tuple[str, ...]:
        """The parameters of a scene (every public field)."""
        return tuple(f.name for f in dataclasses.fields(cls) if not f.name.startswith("_"))

    def given(self, key: str) -> bool:
        """False if the value of ``key`` is a default resolved from other fields (R, EI, L, the
        solver; k_t from k_w or k_ph/l0)."""
        return not isinstance(getattr(self, key), _Default)

    # -- derived -----------------------------------------------------------
    @property
    def N(self) -> int:
        return int(round(self.L / self.l0))

    def constants(self) -> DiscreteConstants:
        ends = self.friction_at == "ends" and self.k_fr > 0.0  # stick springs at the link ends
        return discrete_constants(self.L, self.R, self.EI, self.l0, self.k_ph, self.k_w,
                                  self.rotational_drag, self.bending_constant, self.k_t if ends else 0.0)

    def free_span(self) -> float:
        """Length of the rod above the pore entrance at the start, L - pore_length (0 if
        the entrance is at or above the top): with ends = 'guided' the free span between
        the guided loaded end and the entrance."""
        return max(0.0, self.L - self.pore_length)

    def C_l0(self) -> float:
        """The bending stiffness the joints represent, C l0: EI, or EI R/l0 as printed."""
        return self.constants().C * self.l0

    def dt(self) -> float:
        return self.dt_factor * self.constants().dt_stable

    def params(self) -> np.ndarray:
        """The kernel parameter vector (see model.kernels)."""
        c = self.constants()
        p = np.zeros(K.NPAR)
        p[K.HALF] = 0.5 * self.l0
        p[K.K_BOND] = c.k
        p[K.K_WALL] = self.k_w
        p[K.R_WALL] = self.R
        p[K.Z_TOP] = self.pore_length
        p[K.LOAD] = self.load
        p[K.K_SUP] = c.k_support
        p[K.C_BEND] = c.C
        p[K.K_FR] = self.k_fr
        p[K.F_CAP] = self.friction_cap
        p[K.FX:K.FZ + 1] = np.asarray(self.body_force) * self.l0
        p[K.LOWER_HELD] = 1.0 if self.lower_end == "held" else 0.0
        p[K.ENDS_PINNED] = 1.0 if self.ends == "pinned" else 0.0
        p[K.GAMMA_T] = c.beta
        p[K.GAMMA_R] = c.gamma_r
        p[K.FLOOR] = 1.0 if self.floor else 0.0
        p[K.GUIDED] = 1.0 if self.ends == "guided" else 0.0
        p[K.R_ESCAPE] = limits.ESCAPE_RADIUS * self.R
        return p

    def initial_state(self) -> tuple[np.ndarray, np.ndarray]:
        """Straight rod on the axis from z = 0 to L, with the seeded perturbation: one continuous
        random function of the height (perturbation.lateral), sampled at the link centres, so
        that a seed is the same rod at every l0."""
        N = self.N
        r = np.zeros((N, 3))
        r[:, 2] = (np.arange(N) + 0.5) * self.l0
        t = np.zeros((N, 3))
        t[:, 2] = 1.0
        if self.protocol == "helix":
            return self._helix_start(perturbation.lateral(np.arange(1, N + 1) * self.l0, self.L, self.R,
                                                          self.perturbation, self.seed))
        d = perturbation.lateral(r[:, 2], self.L, self.R, self.perturbation, self.seed)
        r[:, 0] += d[:, 0]
        if self.protocol in ("straight", "ramp"):
            r[:, 1] += d[:, 1]
        return r, t

    def _helix_start(self, d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Right-handed helix on the wall from the support (link 0, z = 0) up: the link ends lie
        on a helix of radius R - a (a = perturbation) with the pitch angle of a torque-free
        helix on the wall carrying the full load, 2 EI w^2 sqrt(1 - R^2 w^2) = load (its largest
        w beyond the helix's load limit). The links are the chords of length l0 between
        consecutive ends, so every bond starts at its rest length (a chain of arcs would be
        prestressed by the chord-arc difference, ~ k l0^3 w^4 R^2/24 per bond, which static
        friction would then lock in). The seeded perturbation moves the target of each end
        laterally by d/2 (d at the arc length of each end from the support); the chain is then
        built end to end with chords of exactly l0 towards those targets, so the start is
        perturbed and still stress-free."""
        from ..theory import HELIX_F_MAX, helix_pitch_rate

        rho = self.R - self.perturbation
        F = min(self.load, HELIX_F_MAX * self.EI / self.R**2)
        Rw = float(helix_pitch_rate(np.array([F]), self.R, self.EI)[0]) * self.R      # sin of the pitch angle
        p = rho * np.sqrt(max(1.0 - Rw**2, 0.0)) / Rw                                # dz/dphi at radius rho
        # angle step Delta with chord 4 rho^2 sin^2(Delta/2) + p^2 Delta^2 = l0^2 (bisection)
        lo, hi = 0.0, self.l0 / p
        for _ in range(100):
            mid = 0.5 * (lo + hi)
            if 4 * rho**2 * np.sin(0.5 * mid) ** 2 + (p * mid) ** 2 < self.l0**2:
                lo = mid
            else:
                hi = mid
        phi = 0.5 * (lo + hi) * np.arange(self.N + 1)
        target = np.stack([rho * np.cos(phi), rho * np.sin(phi), p * phi], axis=1)
        target[1:, :2] += 0.5 * d     # |d/2| <= a/sqrt(2): the targets stay inside radius R
        ends = np.empty_like(target)
        ends[0] = target[0]
        for k in range(self.N):
            step = target[k + 1] - ends[k]
            ends[k + 1] = ends[k] + self.l0 * step / np.linalg.norm(step)
        r = 0.5 * (ends[1:] + ends[:-1])
        t = (ends[1:] - ends[:-1]) / self.l0
        return r, t

    def ramp_loads(self) -> np.ndarray:
        """The loads of protocol 'ramp': geometric from ramp_start x pi^2 EI/L^2 to load (the
        load alone if that is below the first)."""
        first = self.ramp_start * np.pi**2 * self.EI / self.L**2
        if first >= self.load or self.ramp_steps == 1:
            return np.array([self.load])
        return np.geomspace(first, self.load, self.ramp_steps)

    def perturb_3d(self, r: np.ndarray) -> None:
        """Second stage of 'planar_then_3d': seeded out-of-plane perturbation, a continuous
        function of the height of the straight rod (perturbation.lateral, its own stream)."""
        z = (np.arange(r.shape[0]) + 0.5) * self.l0
        r[:, 1] += perturbation.lateral(z, self.L, self.R, self.kick, self.seed, components=1,
                                        stream=perturbation.KICK)[:, 0]

    def to_dict(self) -> dict[str, Any]:
        return {k: float(v) if isinstance(v, _Default) else copy.deepcopy(v)
                for k in self.field_names() for v in (getattr(self, k),)}

    # -- construction from user input ----------------------------------------
    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> "Scene":
        if not isinstance(data, dict):
            raise SceneError(f"a scene must be a mapping of keys to values, got {type(data).__name__}")
        known = set(cls.field_names())
        if "name" in data and data["name"] is None:        # a template's 'name: null': the default
            data = {k: v for k, v in data.items() if k != "name"}
        for key in data:
            if key not in known:
                raise SceneError(f"unknown key {_short(key)} (value {_short(data[key])}); "
                                 f"known keys: {', '.join(sorted(known))}")
        scene = cls(**data)
        # user input (a scene file, run --set, a config): an entrance below the rod's top only with
        # the end condition that keeps the loaded end above it; a library call may still build the
        # free case (the rod's top then rests on the block's face; the tests of 'escaped' use it)
        if scene.free_span() > 0 and scene.ends != "guided":
            raise SceneError(
                f"scene {_short(scene.name)}: invalid value for 'pore_length': {scene.pore_length:g} (shorter than "
                f"L = {scene.L:g} with ends = {scene.ends!r}: the top {scene.free_span() / scene.R:g} R of the rod "
                "would start outside the pore and the run end 'escaped'; leave pore_length out (it follows L) or set "
                "ends: guided, the open entrance of Fig 8)")
        return scene

    @classmethod
    def from_yaml(cls, path: str | Path, overrides: dict[str, Any] | None = None) -> "Scene":
        """Read a scene file: a YAML mapping of Scene fields, at most 1 MiB, without
        duplicate keys or aliases; ``name`` defaults to the file's stem.  ``overrides`` (the
        command line's ``--set key=value``) replace the file's values."""
        from ..io import read_yaml

        path = Path(path)
        data = read_yaml(path, what="scene file", error=SceneError, max_bytes=MAX_SCENE_FILE_BYTES)
        if data is None and not overrides:
            raise SceneError(f"scene file {str(path)!r} is empty; give at least one key, e.g. 'L: 20' "
                             "(python -m confined_rod show-defaults lists them all)")
        data = {} if data is None else data
        if isinstance(data, dict):
            if data.get("name") is None:
                data["name"] = path.stem
            data.update(overrides or {})
        return cls.from_dict(data)

    def template(self) -> str:
        """This scene as a commented YAML scene file (``show-defaults``): every key with its unit
        and description; a default that follows other keys written as null (so an edited
        template stays consistent: change L and pore_length follows), its value in the comment."""
        from ..quantities import QUANTITIES, pretty_unit

        lines = []
        for key, value in self.to_dict().items():
            q = QUANTITIES.get(key)
            if not self.given(key):
                shown = "null"
                note = f"null: {float(getattr(self, key)):g} here, follows {DERIVED_FROM[key]}"
            else:
                shown = _yaml_value(value)
                note = ""
            unit = pretty_unit(q.units).replace("{", "").replace("}", "").replace("\\", "") if q else ""
            if key == "name":
                shown = "null"
            desc = q.long_name if q else ("name of the run (null: the scene file's name)" if key == "name" else "")
            if key in ("R", "EI"):          # they set the units: "[R]" would be circular
                unit, desc = "", desc + (" (sets the unit of length)" if key == "R"
                                         else " (sets the units: forces in EI/R^2)")
            comment = "; ".join(x for x in (f"[{unit}]" if unit else "", desc, note) if x)
            lines.append(f"{key}: {shown}  # {comment}" if comment else f"{key}: {shown}")
        return "\n".join(lines) + "\n"


#: what a numerical default follows (show-defaults writes it as null with this note)
DERIVED_FROM = {"l0": "R", "k_ph": "EI/R^2", "k_w": "EI/R^3", "friction_cap": "EI/R^2", "perturbation": "R",
                "kick": "R", "t_max": "R^4/EI and the solver", "pore_length": "L", "dx_max": "R",
                "k_t": "k_w (friction at the centre) or k_ph/l0 (at the ends)"}


def _yaml_value(value: Any) -> str:
    import yaml

    return yaml.safe_dump(value, default_flow_style=True).strip().removesuffix("...").strip()


class _Default(float):
    """A numerical default resolved from other fields (R, EI, L, solver), marked with
    the scene it was resolved for, so that ``dataclasses.replace`` re-resolves it when
    those fields change, while a default of another scene passed in is kept."""

    def __new__(cls, value: float, origin: object):
        obj = super().__new__(cls, value)
        obj.origin = origin
        return obj

    def __reduce__(self):
        return (_Default, (float(self), self.origin))


def _validate(s: Scene) -> None:
    def fail(key: str, msg: str) -> None:
        raise SceneError(f"scene {_short(s.name)}: invalid value for {key!r}: {_short(getattr(s, key))} ({msg})")

    def real(key: str, *, positive: bool = False, nonneg: bool = False, allow_none: bool = False) -> None:
        v = getattr(s, key)
        if v is None and allow_none:
            return
        if isinstance(v, bool) or not isinstance(v, numbers.Real):
            fail(key, "must be a number")
        if not math.isfinite(v):
            fail(key, "must be finite")
        if positive and not v > 0:
            fail(key, "must be > 0")
        if nonneg and not v >= 0:
            fail(key, "must be >= 0")

    if not isinstance(s.floor, bool):
        fail("floor", "must be true or false")
    if not isinstance(s.name, str) or not s.name:
        fail("name", "must be a non-empty string")
    for key in ("L", "R", "EI", "load"):
        real(key, positive=True)
    real("k_fr", nonneg=True)
    real("snapshot_interval", nonneg=True)
    real("snapshot_growth", positive=True)
    if not s.snapshot_growth >= 1.0:
        fail("snapshot_growth", "must be >= 1 (1: snapshots at a fixed interval; > 1: at geometrically growing times)")
    for key in ("l0", "k_ph", "k_w", "k_t", "perturbation", "kick", "t_max", "pore_length", "dx_max"):
        real(key, positive=True, allow_none=True)
    real("friction_cap", nonneg=True, allow_none=True)
    real("dt_factor", positive=True)
    real("tol", positive=True)
    if isinstance(s.ramp_steps, bool) or not isinstance(s.ramp_steps, numbers.Integral) or s.ramp_steps < 1:
        fail("ramp_steps", "must be an integer >= 1")
    real("ramp_start", positive=True)
    if not s.ramp_start > 1.0:
        fail("ramp_start", "must be > 1 (the ramp starts above Euler's load, where the rod buckles)")
    if isinstance(s.max_steps, bool) or not isinstance(s.max_steps, numbers.Integral) or s.max_steps < 0:
        fail("max_steps", "must be an integer >= 0 (0: no cap)")
    if isinstance(s.saddle_kicks, bool) or not isinstance(s.saddle_kicks, numbers.Integral) or s.saddle_kicks < 0:
        fail("saddle_kicks", "must be an integer >= 0 (0: a run may end on a saddle, flagged)")
    if (isinstance(s.seed, bool) or not isinstance(s.seed, numbers.Integral)
            or not 0 <= s.seed <= limits.SEED_MAX):
        fail("seed", f"must be an integer in [0, {limits.SEED_MAX}] (stored as a 64-bit integer)")
    for key, allowed in (("protocol", PROTOCOLS), ("ends", ENDS), ("lower_end", LOWER_END),
                         ("rotational_drag", ROTATIONAL_DRAG), ("solver", SOLVERS), ("friction_at", FRICTION_AT),
                         ("bending_constant", BENDING_CONSTANT), ("unit_system", UNIT_SYSTEMS)):
        if getattr(s, key) not in allowed:
            fail(key, f"must be one of {', '.join(allowed)}")
    bf = s.body_force
    if (not isinstance(bf, (list, tuple)) or len(bf) != 3
            or any(isinstance(v, bool) or not isinstance(v, numbers.Real) or not math.isfinite(v) for v in bf)):
        fail("body_force", "must be three finite numbers (fx, fy, fz)")
    # Without support or floor only wall friction can hold the rod, and friction needs a normal
    # force from the start: a sideways body force. An unloaded straight rod has no wall contact and
    # cannot buckle without something to push against, so it would drift down without end.
    pressed = isinstance(s.k_fr, numbers.Real) and s.k_fr > 0 and (bf[0] != 0 or bf[1] != 0)
    if s.lower_end == "free" and not s.floor and not pressed:
        fail("floor", "false with lower_end 'free' and nothing pressing the rod on the wall (k_fr > 0 and a "
                      "sideways body_force): nothing holds it against the load, so it drifts down without end; "
                      "set floor: true or lower_end: held")

    # resolve defaults in units of R and EI (R, EI bounded first: R**4/EI must not overflow)
    object.__setattr__(s, "R", float(s.R))
    object.__setattr__(s, "EI", float(s.EI))
    limits.check_magnitudes(s, [QUANTITIES["R"], QUANTITIES["EI"]], fail)
    R, EI = s.R, s.EI
    resolved = {
        "l0": DEFAULT_L0 * R, "k_ph": DEFAULT_K_PH * EI / R**2, "k_w": DEFAULT_K_W * EI / R**3,
        "friction_cap": DEFAULT_FRICTION_CAP * EI / R**2, "perturbation": DEFAULT_PERTURBATION * R,
        "kick": DEFAULT_KICK * R,
        "t_max": (DEFAULT_T_MAX_IMPLICIT if s.solver == "implicit" else DEFAULT_T_MAX) * R**4 / EI,
        "pore_length": float(s.L), "dx_max": DEFAULT_DX_MAX * R,
    }
    source, origin = s._origin, object()  # the scene replaced (None if made afresh), and this one

    def resolve(key: str, default: float) -> None:
        v = getattr(s, key)
        own = v is None or (isinstance(v, _Default) and source is not None and v.origin is source)
        object.__setattr__(s, key, _Default(default, origin) if own else float(v))

    for key, default in resolved.items():
        resolve(key, default)
    # follows k_w (centre) or the bond constant k_ph/l0 (ends), given or default
    resolve("k_t", DEFAULT_K_T_ENDS * s.k_ph / s.l0 if s.friction_at == "ends" else DEFAULT_K_T * s.k_w)
    object.__setattr__(s, "_origin", origin)
    for key in ("L", "R", "EI", "load", "k_fr", "dt_factor", "tol", "snapshot_interval", "snapshot_growth",
                "ramp_start"):
        object.__setattr__(s, key, float(getattr(s, key)))
    object.__setattr__(s, "seed", int(s.seed))
    object.__setattr__(s, "body_force", tuple(float(v) for v in bf))

    limits.check_magnitudes(s, [QUANTITIES[k] for k in s.field_names() if k in QUANTITIES], fail)
    if s.L / s.l0 > limits.MAX_LINKS:
        fail("L", f"L/l0 = {s.L / s.l0:.3g} links exceeds the limit of {limits.MAX_LINKS} (memory and run time); "
                  f"shorten L or raise l0 (now {s.l0:g})")
    if s.l0 > s.L:
        fail("l0", f"must not exceed L = {s.L}")
    n = s.L / s.l0
    if abs(n - round(n)) > 1e-9 * n:
        fail("l0", f"L = {s.L} must be an integer multiple of l0")
    if round(n) < 3:
        fail("l0", f"the rod needs at least 3 links, L/l0 = {n:g}")
    for key in ("perturbation", "kick"):
        if getattr(s, key) >= s.R:
            fail(key, f"must be smaller than R = {s.R}")
    if s.pore_length < 2.0 * s.l0:
        fail("pore_length", f"the pore must hold at least two links (2 l0 = {2 * s.l0})")
    limits.check_computable(s, fail)
