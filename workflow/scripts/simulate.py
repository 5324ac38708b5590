"""Snakemake script of rule `simulate`: one scene -> one netCDF dataset."""
import _checkout  # noqa: F401  (this checkout's src/ first on sys.path)

# isort: split
from confined_rod import Scene, simulate
from confined_rod.io import logged, write_dataset

with logged(snakemake.log[0]):  # noqa: F821 (injected by Snakemake)
    scene = Scene.from_dict(dict(snakemake.params.scene))  # noqa: F821
    ds = simulate(scene, progress=True)
    if ds.attrs["status"] == "model_violated":  # not a result: fail the job, write nothing
        raise RuntimeError(f"scene {scene.name!r}: the final state violates the model: {ds.attrs['status_reason']}")
    write_dataset(ds, snakemake.output[0])  # noqa: F821
    print(f"{scene.name}: {ds.attrs['status']} ({ds.attrs['status_reason']}) "
          f"F_transmitted={float(ds.F_transmitted):.6g} L_z={float(ds.L_z):.6g} t={float(ds.t_final):.6g} "
          f"steps={int(ds.n_steps)} wall={float(ds.wall_time):.1f} s")
