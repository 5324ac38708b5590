rule postprocess:
    """Collect a figure's scenes into the dataset the figure plots (with fits and analytic curves)."""
    input:
        sims=scene_sims,
        datasets=read_datasets,
        code=postprocess_code,
    output:
        layout.dataset_path("{figure}"),
    params:
        figure_config=lambda wildcards: config["figures"][wildcards.figure],
        scenes=lambda wildcards: pipeline.scenes(config, wildcards.figure),
        wanted=lambda wildcards: pipeline.figure_wanted(config, wildcards.figure),
        context=build_context,
        read=lambda wildcards: list(pipeline.read_figures(config, wildcards.figure)),
    log:
        layout.log_path("postprocess", "{figure}"),
    benchmark:
        layout.benchmark_path("postprocess", "{figure}")
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
        layout.dataset_path("{figure}"),
    output:
        layout.check_path("{figure}"),
    params:
        on_inconclusive=lambda wildcards: config["figures"][wildcards.figure].get(
            "on_inconclusive", "fail"
        ),
    log:
        layout.log_path("convergence_check", "{figure}"),
    benchmark:
        layout.benchmark_path("convergence_check", "{figure}")
    threads: 1
    resources:
        mem_mb=500,
        runtime=5,
    conda:
        "../envs/confined_rod.yaml"
    script:
        "../scripts/convergence_check.py"
