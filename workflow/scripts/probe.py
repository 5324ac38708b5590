"""Snakemake script of rule `probe`: one stability-map point -> its status dataset."""
import _checkout  # noqa: F401  (this checkout's src/ first on sys.path)

# isort: split
from confined_rod.io import finalize, logged, write_dataset
from confined_rod.stability import probe

with logged(snakemake.log[0]):  # noqa: F821 (injected by Snakemake)
    params = dict(snakemake.params.scene)  # noqa: F821
    ds = probe(params)
    write_dataset(finalize(ds, f"stability probe {params['name']}", {k: str(v) for k, v in params.items()}),
                  snakemake.output[0])  # noqa: F821
    print(f"{params['name']}: {ds.attrs['status_name']}: {ds.attrs['message']}")
