"""Constructed final states of a confined rod as datasets laid out as simulate() writes them:
link 0 and s = 0 at the loaded (upper) end, z falling from about L there to 0 at the support;
the wall-contact stretch as the helix variables phi, dphi_ds, s_helix. Units R = EI = 1."""
from __future__ import annotations

import numpy as np
import xarray as xr

from confined_rod import theory

L0 = 0.5  # link length


def arc(L: float, l0: float = L0) -> np.ndarray:
    """Arc lengths of the link centres from the loaded end."""
    return (np.arange(int(round(L / l0))) + 0.5) * l0


def rod(x, y, z, *, L: float, l0: float = L0, R: float = 1.0, attrs: dict | None = None, **scalars) -> xr.Dataset:
    """A rod dataset from its link centres (in order from the loaded end). Contact: centres
    within 0.05 R of the wall. Scalars (F_transmitted, L_z, ...) are added as given."""
    x, y, z = (np.asarray(v, dtype=float) for v in (x, y, z))
    s = arc(L, l0)
    contact = (np.hypot(x, y) >= 0.95 * R).astype(np.int8)
    idx = np.flatnonzero(contact)
    sl = slice(idx[0], idx[-1] + 1) if idx.size >= 3 else slice(0, 0)
    phi = np.unwrap(np.arctan2(y[sl], x[sl]))
    dphi = np.gradient(phi, s[sl]) if phi.size >= 2 else np.zeros_like(phi)
    data = {"x": ("s_link", x), "y": ("s_link", y), "z": ("s_link", z), "contact": ("s_link", contact),
            "phi": ("s_helix", phi), "dphi_ds": ("s_helix", dphi)}
    # the mechanics a simulation stores, here of a rod with no wall or friction force and a
    # constant axial force (the regions and local-law measures then find no bulk helix)
    load = float((attrs or {}).get("load", 0.25))
    data.update({"wall_force": ("s_link", np.zeros(x.size)), "friction_z": ("s_link", np.zeros(x.size)),
                 "friction_force": ("s_link", np.zeros(x.size)), "F_z": ("s", np.full(x.size + 1, -load))})
    data.update({k: ((), v) for k, v in scalars.items()})
    return xr.Dataset(data, coords={"s_link": ("s_link", s), "s_helix": ("s_helix", s[sl]),
                                    "s": ("s", np.arange(x.size + 1) * l0)},
                      attrs={"L": L, "l0": l0, "R": R, "EI": 1.0, **(attrs or {})})


def rotated(x, y, angle: float):
    """(x, y) rotated about the pore axis by `angle`."""
    c, s = np.cos(angle), np.sin(angle)
    return c * x - s * y, s * x + c * y


def planar_zigzag(L: float = 20.0, half_waves: int = 4, bow: float = 0.0, angle: float = 0.0,
                  l0: float = L0, **kw) -> xr.Dataset:
    """A rod buckled in the x-z plane (rotated by `angle` about the axis), lying on both walls
    (x = +-R) `half_waves` times; `bow`: an out-of-plane bow in y of that amplitude."""
    s = arc(L, l0)
    x = np.clip(1.3 * np.sin(np.pi * half_waves * s / L), -1.0, 1.0)
    y = bow * np.sin(np.pi * s / L)
    x, y = rotated(x, y, angle)
    return rod(x, y, 0.97 * (L - s), L=L, l0=l0, **kw)


def helix(L: float = 40.0, omega: float = 0.4, tips: float = 2.0, reverse_at: float | None = None,
          angle: float = 0.0, l0: float = L0, **kw) -> xr.Dataset:
    """A helix on the wall, phi = omega s (one handedness), whose ends detach over `tips` R
    towards the axis; with `reverse_at` the sense reverses there (a defect)."""
    s = arc(L, l0)
    phi = omega * s if reverse_at is None else omega * (reverse_at - np.abs(s - reverse_at))
    rho = np.clip(np.minimum(s, L - s) / tips, 0.2, 1.0) if tips > 0 else np.ones_like(s)
    x, y = rotated(rho * np.cos(phi), rho * np.sin(phi), angle)
    return rod(x, y, 0.9 * (L - s), L=L, l0=l0, **kw)


def straight(L: float = 20.0, tilt: float = 0.9, angle: float = 0.0, noise: float = 1e-4, seed: int = 0,
             **kw) -> xr.Dataset:
    """An unbuckled rod lying diagonally across the pore (x from -tilt to +tilt), with round-off
    noise of `noise` R."""
    s = arc(L)
    rng = np.random.default_rng(seed)
    x = tilt * (2 * s / L - 1) + noise * rng.standard_normal(s.size)
    y = noise * rng.standard_normal(s.size)
    x, y = rotated(x, y, angle)
    return rod(x, y, np.sqrt(1 - (2 * tilt / L) ** 2) * (L - s), L=L, **kw)


def sliding_friction(F_joint, k_fr: float) -> dict:
    """Link variables of a rod whose every link slides axially at the Coulomb limit, carrying
    the given |F_z| profile at the joints (from the loaded end): the axial friction of a link is
    the drop of |F_z| across it, and the wall force that friction's 1/k_fr."""
    F = np.abs(np.asarray(F_joint, dtype=float))
    fz = F[:-1] - F[1:]
    return {"friction_z": ("s_link", fz), "friction_force": ("s_link", np.abs(fz)),
            "wall_force": ("s_link", np.abs(fz) / k_fr)}


#: the rod of profile_rod (units R = EI = 1)
PROFILE = {"L": 100.0, "l0": 0.5, "R": 1.0, "EI": 1.0, "k_fr": 0.8, "load": 0.25}


def profile_rod(tip_end=6.0, bulk_end=70.0, q_lower=0.1, tip_contacts=(1, 7), detached_bottom=None, seed=0):
    """A rod with a tip (0 <= s < tip_end: isolated contacts, friction axial at the limit there),
    a bulk (tip_end <= s <= bulk_end: every link on the wall, sliding axially at the Coulomb
    limit, 1/|F| linear in s with the corrected slope) and a lower region (on the wall, axial
    friction q_lower of the limit, so |F| falls slowly). Friction and F_z are consistent:
    |F_z| falls along s by the axial friction of each link. Returns (dataset, the built bulk
    rate d(1/|F_z|)/ds = k_fr R/(4EI)); parameters in PROFILE."""
    L, L0, R, EI, K_FR, LOAD = (PROFILE[k] for k in ("L", "l0", "R", "EI", "k_fr", "load"))
    N = int(round(L / L0))
    s = np.arange(N + 1) * L0
    s_link = (np.arange(N) + 0.5) * L0
    contact = np.zeros(N, dtype=np.int8)
    contact[list(tip_contacts)] = 1
    contact[(s_link >= tip_end) & (s_link <= L)] = 1
    if detached_bottom is not None:
        contact[s_link > L - detached_bottom] = 0
    rate = K_FR * R / (4 * EI)
    F_tip = 0.2                                       # after the tip drop
    F = np.empty(N + 1)
    F[0] = LOAD
    fz = np.zeros(N)
    # the tip: the contacts carry the drop from LOAD to F_tip
    tips = [i for i in tip_contacts]
    for i in range(N):
        if s_link[i] < tip_end:
            fz[i] = (LOAD - F_tip) / len(tips) if i in tips else 0.0
        elif s_link[i] <= bulk_end:
            F_here = F[i]
            fz[i] = F_here - 1.0 / (1.0 / F_here + rate * L0)
        else:
            fz[i] = q_lower * 1e-3
        F[i + 1] = F[i] - fz[i]
    # wall force: in the tip and bulk the friction is at its limit (fz = k_fr N);
    # in the lower region N is that of the bulk's end and fz a share q_lower of k_fr N
    N_w = np.where(contact == 1, np.where(s_link <= bulk_end, fz / K_FR, 1e-3 / K_FR), 0.0)
    ds = xr.Dataset(
        {"F_z": (("s",), -F), "contact": (("s_link",), contact), "wall_force": (("s_link",), N_w),
         "friction_z": (("s_link",), fz * (contact == 1)), "friction_force": (("s_link",), fz * (contact == 1))},
        coords={"s": (("s",), s), "s_link": (("s_link",), s_link)},
        attrs={"L": L, "l0": L0, "R": R, "EI": EI, "k_fr": K_FR, "friction_cap": 0.0, "load": LOAD,
               "seed": seed, "status": "converged"})
    return ds, rate


def prescribed_helix(L=100.0, l0=0.5, k_fr=0.8, load=0.25, c_K=1.1, c_w=0.95, tip=4.0, bottom=0.0,
                     seed=0, scale=1.0):
    """A rod detached over the first `tip` R from the loaded end (|F_z| = load there), then on the
    wall with wall force per length K = c_K R F^2/(4EI) and axial friction at its Coulomb limit
    k_fr K, so d(1/|F_z|)/ds = c_K k_fr R/(4EI) exactly per link; pitch rate c_w w(F). Detached
    again over the last `bottom` R (no friction there). A complete scene dataset for the ladders:
    F_transmitted is the support's |F_z| times `scale` (a final state set apart from the local
    relations, which hold in whichever equilibrium a seed reached)."""
    R = EI = 1.0
    N = int(round(L / l0))
    s = np.arange(N + 1) * l0
    s_link = (np.arange(N) + 0.5) * l0
    contact = ((s_link > tip) & (s_link < L - bottom)).astype(np.int8)
    rate = c_K * k_fr * R / (4 * EI)
    F = np.empty(N + 1)
    F[0] = load
    fz = np.zeros(N)
    for i in range(N):
        if contact[i] and k_fr > 0:
            fz[i] = F[i] - 1.0 / (1.0 / F[i] + rate * l0)
        F[i + 1] = F[i] - fz[i]
    F_link = 0.5 * (F[1:] + F[:-1])
    K = np.where(contact == 1, c_K * R * F_link**2 / (4 * EI), 0.0)
    if k_fr > 0:        # the friction per link is exactly k_fr times the wall force per link
        K = np.where(contact == 1, fz / (k_fr * l0), 0.0)
    on = np.flatnonzero(contact)
    w = c_w * theory.helix_pitch_rate(F_link[on], R, EI)
    phi = np.concatenate([[0.0], np.cumsum(w[1:] * l0)])
    rho = np.where(contact == 1, R, 0.5 * R)
    phi_all = np.interp(s_link, s_link[on], phi)
    ds = xr.Dataset(
        {"F_z": (("s",), -F), "contact": (("s_link",), contact), "wall_force": (("s_link",), K * l0),
         "wall_force_density": (("s_link",), K), "friction_z": (("s_link",), fz),
         "friction_force": (("s_link",), fz), "phi": (("s_helix",), phi), "dphi_ds": (("s_helix",), w),
         "x": (("s_link",), rho * np.cos(phi_all)), "y": (("s_link",), rho * np.sin(phi_all)),
         "z": (("s_link",), L - s_link), "F_transmitted": F[-1] * scale, "L_z": 0.97 * L,
         "converged": np.int8(1), "wall_time": 0.1},
        coords={"s": s, "s_link": s_link, "s_helix": s_link[on]},
        attrs={"L": L, "l0": l0, "R": R, "EI": EI, "k_fr": k_fr, "friction_cap": 0.0, "load": load,
               "seed": seed, "status": "converged"})
    return ds
