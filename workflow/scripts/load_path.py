"""Snakemake script of rule `load_path`: one scene of a path figure -> its dataset."""
import _checkout  # noqa: F401  (this checkout's src/ first on sys.path)

# isort: split
from confined_rod import Scene
from confined_rod.io import logged, write_dataset
from confined_rod.sim.load_paths import run_spec

with logged(snakemake.log[0]):  # noqa: F821 (injected by Snakemake)
    scene = Scene.from_dict(dict(snakemake.params.scene))  # noqa: F821
    spec = dict(snakemake.params.spec)  # noqa: F821
    ds = run_spec(scene, spec)
    write_dataset(ds, snakemake.output[0])  # noqa: F821
    print(f"{scene.name}: {spec['run']}")
    print(ds)
