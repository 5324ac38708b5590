rule figure:
    """Draw one figure (PDF for the paper, PNG for the report) from its dataset."""
    input:
        data="results/datasets/{figure}.nc",
        code=figure_code,
    output:
        pdf="results/figures/{figure}.pdf",
        png=report(
            "results/figures/{figure}.png",
            caption="../report/figure.rst",
            category="Figures",
            labels={"figure": "{figure}"},
        ),
    params:
        caption=lambda wildcards: pipeline.caption(config, wildcards.figure),
    log:
        "results/logs/figure/{figure}.log",
    benchmark:
        "results/benchmarks/figure/{figure}.tsv"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    conda:
        "../envs/confined_rod.yaml"
    script:
        "../scripts/figure.py"
