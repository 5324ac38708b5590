"""Measures of the paper's physical scales: a nanotube's and a DNA pore's radius."""
from __future__ import annotations

import math

from ._base import Measured, measure

# material numbers of the paper's conclusions (SI units)
NANOTUBE = {"L": 100e-6, "E": 1e12, "R": 1e-6, "load": 0.25, "F_range": (1e-9, 10e-9),
            "plausible_radius": (1e-9, 50e-9)}


DNA = {"persistence_length": 50e-9, "diameter": 2e-9, "aspect_ratio": 100.0}


@measure
def nanotube_radius(ev, spec, claim):
    """Tube radius r (solid section, I = pi r^4/4) for which load EI/R^2 lies in the nN range."""
    p = NANOTUBE
    r = [(4 * F * p["R"] ** 2 / (p["load"] * math.pi * p["E"])) ** 0.25 for F in p["F_range"]]
    ok = p["L"] / p["R"] >= 100 and p["plausible_radius"][0] <= r[0] and r[1] <= p["plausible_radius"][1]
    return Measured(r[0] * 1e9, ok, f"{__name__}.NANOTUBE (computed)", \
        f"L/R = {p['L'] / p['R']:g}; tube radius {r[0] * 1e9:.3g}-{r[1] * 1e9:.3g} nm for 1-10 nN")


@measure
def dna_pore_radius(ev, spec, claim):
    p = DNA
    R = p["persistence_length"] / p["aspect_ratio"]
    return Measured(R * 1e9, R < p["diameter"] / 2, f"{__name__}.DNA (computed)", \
        f"pore radius {R * 1e9:.2g} nm against the DNA radius {p['diameter'] / 2 * 1e9:.2g} nm")
