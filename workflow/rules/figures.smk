rule figure:
    """Draw one figure (PDF for the paper, PNG for the report) from its dataset."""
    input:
        data=layout.dataset_path("{figure}"),
        code=figure_code,
    output:
        pdf=layout.figure_paths("{figure}")[0],
        png=report(
            layout.figure_paths("{figure}")[1],
            caption="../report/figure.rst",
            category="Figures",
            labels={"figure": "{figure}"},
        ),
    params:
        caption=lambda wildcards: pipeline.caption(config, wildcards.figure),
    log:
        layout.log_path("figure", "{figure}"),
    benchmark:
        layout.benchmark_path("figure", "{figure}")
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    conda:
        "../envs/confined_rod.yaml"
    script:
        "../scripts/figure.py"
