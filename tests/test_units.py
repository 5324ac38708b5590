"""CF units: every unit string of the quantity tables parses with cf-units (UDUNITS-2) and means
what it says, in both unit systems; a scene given in SI gives the reduced scene's numbers scaled;
the datasets index their dimensions by arc length."""
from __future__ import annotations

import cf_units as udunits
import numpy as np
import pytest
import xarray as xr

from confined_rod import quantities
from confined_rod.analysis.figure_quantities import QUANTITIES as FIGURE_QUANTITIES
from confined_rod.io import finalize, write_dataset
from confined_rod.quantities import UNIT_SYSTEMS, apply_unit_system, cf_attrs, cf_units, is_reduced

ALL_UNITS = sorted({q.units for q in FIGURE_QUANTITIES.values()})      # extends the scene-file table
#: what the reduced symbols are in SI (R in m, EI in J m, beta_ph in Pa s), written independently
#: of the package's dimension table
SI_OF = {"R": "m", "EI": "(J m)", "beta_ph": "(Pa s)"}


def _composed_si(units: str) -> udunits.Unit:
    out = udunits.Unit("1")
    for tok in units.split():
        base = tok.rstrip("-0123456789")
        exp = int(tok[len(base):] or 1)
        out = out * udunits.Unit(SI_OF.get(base, base)) ** exp
    return out


def test_the_tables_cover_every_unit():
    assert {q.units for q in quantities.QUANTITIES.values()} <= set(ALL_UNITS)


@pytest.mark.parametrize("units", ALL_UNITS)
@pytest.mark.parametrize("system", UNIT_SYSTEMS)
def test_every_unit_parses_and_means_what_it_says(units, system):
    cf = cf_units(units, system)
    unit = udunits.Unit(cf)                      # raises on a string UDUNITS cannot read
    if units in ("mixed",) or "-c" in units:       # no fixed dimension: dimensionless, the reduced unit beside
        assert cf == "1" and cf_attrs(units, system)["units_reduced"] == units
        return
    if not is_reduced(units):                      # '1', 'rad', 's' (a wall time) are what they say
        assert cf == units
        return
    if system == "reduced":
        # multiples of the reduced unit: dimensionless (an angle per reduced length stays an angle)
        assert unit.is_dimensionless() or unit == udunits.Unit("rad")
        assert not unit.is_convertible(udunits.Unit("R")) or unit.is_dimensionless()
    else:
        # the SI unit is the reduced combination with R in m, EI in J m, beta_ph in Pa s
        assert unit.is_convertible(_composed_si(units)) and np.isclose(unit.convert(1.0, _composed_si(units)), 1.0)
    assert cf_attrs(units, system)["units_reduced"] == units


def test_no_variable_reads_as_the_roentgen():
    """The reason for the whole scheme: UDUNITS reads 'R' as the roentgen, a radiation exposure."""
    assert udunits.Unit("R").is_convertible(udunits.Unit("C kg-1"))
    for units in ALL_UNITS:
        for system in UNIT_SYSTEMS:
            cf = udunits.Unit(cf_units(units, system))
            assert not (cf.is_convertible(udunits.Unit("C kg-1")) and not cf.is_dimensionless()), units


def test_unknown_unit_system_is_refused():
    with pytest.raises(ValueError, match="'cgs'"):
        cf_units("EI R-2", "cgs")


def test_finalize_converts_and_writing_refuses_a_reduced_unit(tmp_path):
    ds = xr.Dataset({"F": ((), 1.0, {"units": "EI R-2", "long_name": "a force"}),
                     "w": ((), 2.0, {"units": "s", "long_name": "a wall time"})})
    with pytest.raises(ValueError, match="'F' has the reduced unit 'EI R-2'"):
        write_dataset(ds, tmp_path / "raw.nc")
    assert not (tmp_path / "raw.nc").exists()
    out = finalize(ds.copy(deep=True), "t", {"unit_system": "SI"})
    assert out.F.attrs["units"] == "N" and out.F.attrs["units_reduced"] == "EI R-2" and out.w.attrs["units"] == "s"
    assert "SI units" in out.attrs["units_note"]
    write_dataset(out, tmp_path / "si.nc")
    back = xr.open_dataset(tmp_path / "si.nc")
    assert back.F.attrs["units"] == "N"
    assert apply_unit_system(ds.copy(deep=True)).F.attrs["units"] == "1"


def test_a_scene_in_SI_is_the_reduced_scene_scaled():
    """Same rod, once in reduced units and once in SI (R = 2 nm, EI = 4e-26 J m, load 0.25 EI/R^2 =
    2.5 nN): the defaults resolve in units of R and EI, so every number is the reduced one times
    its unit, to round-off (measured 1e-13 relative); the SI file says N, m, s."""
    from confined_rod.sim.scenes import Scene
    from confined_rod.sim.simulation import simulate

    R, EI = 2e-9, 4e-26
    red = simulate(Scene(name="red", L=12.0, k_fr=0.8), progress=False)
    si = simulate(Scene(name="si", unit_system="SI", R=R, EI=EI, L=12.0 * R, load=0.25 * EI / R**2, k_fr=0.8),
                  progress=False)
    assert si.F_z.attrs["units"] == "N" and si.s.attrs["units"] == "m" and si.t_final.attrs["units"] == "s"
    assert red.F_z.attrs["units"] == "1" and red.F_z.attrs["units_reduced"] == "EI R-2"
    assert int(si.n_steps) == int(red.n_steps)
    np.testing.assert_allclose(si.F_z.values / (EI / R**2), red.F_z.values, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(si.z.values / R, red.z.values, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(float(si.t_final) / (R**4 / EI), float(red.t_final), rtol=1e-9)


def test_arc_length_indexes_the_dimensions():
    """s, s_link, s_helix are dimension coordinates: .sel and .plot() work along the rod."""
    from confined_rod.sim.scenes import Scene
    from confined_rod.sim.simulation import simulate

    ds = simulate(Scene(name="c", L=12.0, k_fr=0.8), progress=False)
    assert ds.F_z.dims == ("s",) and ds.x.dims == ("s_link",) and ds.dphi_ds.dims == ("s_helix",)
    assert set(ds.indexes) >= {"s", "s_link", "s_helix"}
    assert float(ds.F_z.sel(s=0.0)) == pytest.approx(-0.25, rel=1e-3)      # the loaded end
    assert float(ds.s.sel(s=5.1, method="nearest")) == 5.0
