# The reproduction manuscript: the original's claims evaluated on this build's datasets, the
# generated numbers and tables, and the PDF (latexmk). Only for a config with a `paper:` section
# (the helpers are in common.smk).


rule claims:
    """Evaluate every claim of the original (paper/claims.yaml) on the datasets: results/claims.csv
    and results/claims.nc (paper value, ours, computed verdict, evidence). Fails if any claim's
    evidence is missing."""
    input:
        claims=claims_file,
        datasets=ALL_TARGETS["datasets"],
        sims=claim_sims,
        code=CLAIMS_CODE,
    output:
        csv="results/claims.csv",
        nc="results/claims.nc",
    params:
        figures=lambda wildcards: pipeline.figures(config),
        sim_keys=lambda wildcards: list(pipeline.claim_sims(config)),
        wanted=lambda wildcards: pipeline.claim_wanted(config),
    log:
        "results/logs/claims/claims.log",
    benchmark:
        "results/benchmarks/claims/claims.tsv"
    threads: 1
    resources:
        mem_mb=2000,
        runtime=10,
    conda:
        "../envs/confined_rod.yaml"
    script:
        "../scripts/claims.py"


rule paper_sources:
    """The manuscript's generated parts: numbers (macros), claims and readings tables, figure
    floats with captions and provenance, and the text the PDF check expects."""
    input:
        claims="results/claims.nc",
        datasets=ALL_TARGETS["datasets"],
        code=PAPER_CODE,
    output:
        numbers="results/paper/numbers.tex",
        table="results/paper/claims_table.tex",
        readings="results/paper/readings_table.tex",
        figures="results/paper/figures.tex",
        expected="results/paper/expected.json",
    params:
        figures=lambda wildcards: pipeline.figures(config),
        order=lambda wildcards: paper.figure_order(config),
        captions=lambda wildcards: {f: pipeline.caption(config, f) for f in pipeline.figures(config)},
        config_name=CONFIG_NAME,
    log:
        "results/logs/paper_sources/paper_sources.log",
    benchmark:
        "results/benchmarks/paper_sources/paper_sources.tsv"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    conda:
        "../envs/confined_rod.yaml"
    script:
        "../scripts/paper_sources.py"


rule paper:
    """Build the manuscript with latexmk (pdflatex, REVTeX 4.2). Needs TeX: tools/setup.sh installs
    it from Debian (latexmk, texlive-publishers) when run as root; otherwise this rule fails with
    what to install, after every other target has been built."""
    input:
        tex="paper/{name}.tex",
        sources=rules.paper_sources.output,
        figures=ALL_TARGETS["figures"],
    output:
        "results/paper/{name}.pdf",
    log:
        "results/logs/paper/{name}.log",
    benchmark:
        "results/benchmarks/paper/{name}.tsv"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=10,
    conda:
        "../envs/confined_rod.yaml"
    script:
        "../scripts/paper.py"
