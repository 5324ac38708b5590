"""The dataset: interface names, CF attributes, provenance, netCDF round trip,
and no half-written files."""
import numpy as np
import pytest
import xarray as xr

from confined_rod import Scene, simulate
from confined_rod.io import write_dataset


@pytest.fixture(scope="module")
def ds():
    return simulate(Scene(L=10.0, load=0.25, k_fr=0.8, tol=1e-4, name="demo"), progress=False)


def test_interface(ds):
    assert ds.F_z.dims == ("s",) and "s" in ds.F_z.coords
    for v in ("x", "y", "z", "wall_force"):
        assert ds[v].dims == ("s_link",) and "s_link" in ds[v].coords
    for v in ("L_z", "F_transmitted", "converged"):
        assert ds[v].ndim == 0
    assert ds.sizes["s"] == ds.sizes["s_link"] + 1
    # arc length from the loaded end; F_z(0) is minus the load
    assert float(ds.s[0]) == 0.0 and float(ds.s[-1]) == pytest.approx(10.0)
    assert float(ds.F_z[0]) == -0.25
    assert float(ds.F_transmitted) == pytest.approx(-float(ds.F_z[-1]), rel=1e-9)
    # the upper end is loaded: link 0 of the dataset is the top link
    assert float(ds.z[0]) > float(ds.z[-1])


def test_cf_attributes_and_provenance(ds):
    for name, var in ds.variables.items():
        assert "units" in var.attrs and "long_name" in var.attrs, name
    for key in ("Conventions", "title", "history", "confined_rod_version", "git_commit",
                "numpy_version", "numba_version"):
        assert ds.attrs[key], key
    for key in ("L", "R", "EI", "load", "k_fr", "l0", "k_ph", "k_w", "seed", "friction_cap",
                "tol", "dt", "C", "k", "beta", "gamma_r", "protocol"):
        assert key in ds.attrs, key
    assert ds.attrs["C"] == pytest.approx(1.0 / 0.5)  # EI/l0


def test_netcdf_round_trip(ds, tmp_path):
    path = write_dataset(ds, tmp_path / "demo.nc")
    with xr.open_dataset(path) as back:
        xr.testing.assert_identical(back.load().drop_attrs(), ds.drop_attrs())
        assert back.attrs["name"] == "demo"
    assert [p.name for p in tmp_path.iterdir()] == ["demo.nc"]


def test_no_nan_is_written_and_no_file_is_left(ds, tmp_path):
    bad = ds.copy(deep=True)
    bad["x"][3] = np.nan
    with pytest.raises(ValueError, match="'x'"):
        write_dataset(bad, tmp_path / "bad.nc")
    assert list(tmp_path.iterdir()) == []


def test_contact_observables_are_consistent(ds):
    touching = ds.contact.values == 1
    assert touching.any()
    assert np.all(ds.wall_force.values[~touching] == 0) and np.all(ds.wall_force.values[touching] > 0)
    # Coulomb with the cap: |f| <= min(k_fr N, cap l0) link by link
    limit = np.minimum(0.8 * ds.wall_force.values, ds.attrs["friction_cap"])
    assert np.all(ds.friction_force.values <= limit * (1 + 1e-12))
    assert ds.sizes["s_helix"] == ds.s_helix.size
    if ds.sizes["s_helix"]:
        assert float(ds.s_helix[0]) >= float(ds.s_link[touching][0]) - 1e-12
