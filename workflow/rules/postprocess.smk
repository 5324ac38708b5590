rule postprocess:
    """Collect a figure's scenes into the dataset the figure plots (with fits and analytic curves)."""
    input:
        sims=scene_sims,
        datasets=read_datasets,
        code=postprocess_code,
    output:
        "results/datasets/{figure}.nc",
    params:
        figure_config=lambda wildcards: config["figures"][wildcards.figure],
        scenes=lambda wildcards: pipeline.scenes(config, wildcards.figure),
        wanted=lambda wildcards: pipeline.figure_wanted(config, wildcards.figure),
        context=build_context,
        read=lambda wildcards: list(pipeline.read_figures(config, wildcards.figure)),
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


rule convergence_check:
    """Fail the build if the publication settings are further from the extrapolated
    limit than the config's tolerance (or the check is inconclusive and the config
    says that fails too); otherwise write the one-line verdict."""
    input:
        "results/datasets/{figure}.nc",
    output:
        "results/checks/{figure}.txt",
    params:
        on_inconclusive=lambda wildcards: config["figures"][wildcards.figure].get(
            "on_inconclusive", "fail"
        ),
    log:
        "results/logs/convergence_check/{figure}.log",
    benchmark:
        "results/benchmarks/convergence_check/{figure}.tsv"
    threads: 1
    resources:
        mem_mb=500,
        runtime=5,
    conda:
        "../envs/confined_rod.yaml"
    script:
        "../scripts/convergence_check.py"
