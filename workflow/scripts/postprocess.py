"""Snakemake script of rule `postprocess`: a figure's scene datasets -> the figure's dataset."""
import _checkout  # noqa: F401  (this checkout's src/ first on sys.path)

# isort: split
from confined_rod.analysis import postprocess, run_checks
from confined_rod.io import logged, write_dataset

with logged(snakemake.log[0]):  # noqa: F821 (injected by Snakemake)
    # each scene file is checked against the scene the config asks for (one line if not)
    sims = {name: run_checks.load(path, wanted)
            for name, path, wanted in zip(snakemake.params.scenes, snakemake.input.sims,  # noqa: F821
                                          snakemake.params.wanted)}  # noqa: F821
    read = {name: run_checks.load(path)
            for name, path in zip(snakemake.params.read, snakemake.input.datasets)}  # noqa: F821
    ds = postprocess.build(snakemake.wildcards.figure, snakemake.params.figure_config, sims,  # noqa: F821
                           context={**snakemake.params.context, "datasets": read})  # noqa: F821
    write_dataset(ds, snakemake.output[0])  # noqa: F821
    print(ds)
