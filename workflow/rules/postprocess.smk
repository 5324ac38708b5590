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
    limit than the config's tolerance (unless the config says a failure warns) or the
    check is inconclusive and the config says that fails too; otherwise write the verdict."""
    input:
        layout.dataset_path("{figure}"),
    output:
        layout.check_path("{figure}"),
    params:
        on_inconclusive=lambda wildcards: config["figures"][wildcards.figure].get(
            "on_inconclusive", "fail"
        ),
        on_fail=lambda wildcards: config["figures"][wildcards.figure].get("on_fail", "fail"),
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


rule error_budget:
    """The error budget of the headline numbers: for each number a figure reports, its
    statistical error (seed spread) beside its numerical bias per parameter (from the
    convergence ladders, or a threshold's bracket and discretisation): results/error_budget.nc
    and .csv (confined_rod.analysis.error_budget)."""
    input:
        datasets=ALL_TARGETS["datasets"],
        code=lambda wildcards: code_stamp(
            "error_budget",
            lambda: code.budget_code(
                {pipeline.kinds.module_path(config["figures"][f]["kind"]) for f in pipeline.figures(config)}
            ),
        ),
    output:
        nc=layout.ERROR_BUDGET_NC,
        csv=layout.ERROR_BUDGET_CSV,
    params:
        figures=lambda wildcards: pipeline.figures(config),
    log:
        layout.log_path("error_budget", "error_budget"),
    benchmark:
        layout.benchmark_path("error_budget", "error_budget")
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    conda:
        "../envs/confined_rod.yaml"
    script:
        "../scripts/error_budget.py"
