# The rods in 3-D: each simulation of a figure as a tube in the pore that the reader turns in a
# browser (confined_rod.analysis.view, plotly; the command line's `view`). A figure's views are
# one job (rule views); the report carries them all in one page with a selector, plotly.js once
# and compressed (rule views_page). Snakemake's embedded HTML report cannot carry a directory
# (report(directory(...), htmlindex=...) needs --report report.zip), hence one page.
VIEW_CODE = code.view_code()


rule views:
    """The 3-D views of a figure's simulations (figures whose scenes are simulations: not the
    probes of a stability map nor load paths), as plotly figures in one JSON file."""
    input:
        sims=scene_sims,
        code=VIEW_CODE,
    output:
        layout.view_path("{figure}"),
    params:
        scenes=lambda wildcards: pipeline.scenes(config, wildcards.figure),
    log:
        layout.log_path("views", "{figure}"),
    benchmark:
        layout.benchmark_path("views", "{figure}")
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    conda:
        "../envs/confined_rod.yaml"
    script:
        "../scripts/views.py"


rule views_page:
    """Every figure's views in one self-contained page: the report's 3-D views."""
    input:
        views=[layout.view_path(f) for f in pipeline.view_figures(config)],
        code=VIEW_CODE,
    output:
        report(
            layout.VIEWS_PAGE,
            caption="../report/views.rst",
            category="3-D views",
        ),
    params:
        figures=lambda wildcards: pipeline.view_figures(config),
    log:
        layout.log_path("views_page", "views_page"),
    benchmark:
        layout.benchmark_path("views_page", "views_page")
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    conda:
        "../envs/confined_rod.yaml"
    script:
        "../scripts/views_page.py"
