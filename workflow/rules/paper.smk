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
        csv=layout.CLAIMS_CSV,
        nc=layout.CLAIMS_NC,
    params:
        figures=lambda wildcards: pipeline.figures(config),
        sim_keys=lambda wildcards: list(pipeline.claim_sims(config)),
        wanted=lambda wildcards: pipeline.claim_wanted(config),
    log:
        layout.log_path("claims", "claims"),
    benchmark:
        layout.benchmark_path("claims", "claims")
    threads: 1
    resources:
        mem_mb=2000,
        runtime=10,
    conda:
        "../envs/confined_rod.yaml"
    script:
        "../scripts/claims.py"


rule paper_sources:
    """The manuscript's generated parts: numbers (macros), the results, claims and readings
    tables, the figure floats of the main part and of the supplement with captions and
    provenance, and the text the PDF check expects."""
    input:
        claims=layout.CLAIMS_NC,
        claims_spec=claims_file,
        datasets=ALL_TARGETS["datasets"],
        budget=ALL_TARGETS["budget"],
        studies=sorted(glob.glob(layout.STUDIES_GLOB)),
        code=PAPER_CODE,
    output:
        numbers=layout.paper_source("numbers"),
        table=layout.paper_source("table"),
        readings=layout.paper_source("readings"),
        results=layout.paper_source("results"),
        figures=layout.paper_source("figures"),
        supplement_figures=layout.paper_source("supplement_figures"),
        expected=layout.paper_source("expected"),
    params:
        figures=lambda wildcards: pipeline.figures(config),
        order=lambda wildcards: manuscript.figure_order(config),
        supplement=lambda wildcards: sorted(manuscript.in_supplement(config)),
        captions=lambda wildcards: {f: pipeline.caption(config, f) for f in pipeline.figures(config)},
        config_name=CONFIG_NAME,
    log:
        layout.log_path("paper_sources", "paper_sources"),
    benchmark:
        layout.benchmark_path("paper_sources", "paper_sources")
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
        layout.paper_pdf("{name}"),
    log:
        layout.log_path("paper", "{name}"),
    benchmark:
        layout.benchmark_path("paper", "{name}")
    threads: 1
    resources:
        mem_mb=1000,
        runtime=10,
    conda:
        "../envs/confined_rod.yaml"
    script:
        "../scripts/paper.py"
