rule postprocess:
    """Collect a figure's scenes into the dataset the figure plots (with fits and analytic curves)."""
    input:
        sims=scene_sims,
        code=POSTPROCESS_CODE,
    output:
        "results/datasets/{figure}.nc",
    params:
        figure_config=lambda wildcards: config["figures"][wildcards.figure],
        scenes=lambda wildcards: pipeline.scenes(config, wildcards.figure),
    log:
        "results/logs/postprocess/{figure}.log",
    benchmark:
        "results/benchmarks/postprocess/{figure}.tsv"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    conda:
        "../envs/confined_rod.yaml"
    script:
        "../scripts/postprocess.py"
