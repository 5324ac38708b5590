# The rods in 3-D: every simulation of the figures whose scenes are simulations (not the probes of
# a stability map nor load paths) as a tube in the pore that the reader turns in a browser
# (confined_rod.analysis.view, plotly; the command line's `view`): results/views/index.html lists
# them, one page each, all loading one plotly.min.js (4.8 MB) beside them.
#
# The report: Snakemake embeds a folder only in a zip report (snakemake --report results/report.zip);
# its single-file HTML report refuses report(directory(...)), and a browser shows no embedded page
# over 2 MB, which plotly.js alone is. So the folder is marked for the report only when the report
# asked for is a zip; the HTML report names it on its front page (workflow/report/workflow.rst).
VIEW_CODE = code_stamp("view", code.view_code)
VIEWS_IN_REPORT = any(
    (a == "--report" and b.endswith(".zip"))
    or (a.startswith("--report=") and a.endswith(".zip"))
    for a, b in zip(sys.argv, sys.argv[1:] + [""])
)


rule views:
    """Every simulation of the figures in 3-D: results/views/ (index.html, one page per simulation,
    the plotly.js they share)."""
    input:
        sims=lambda wildcards: pipeline.view_sims(config),
        code=VIEW_CODE,
    output:
        (
            report(
                directory(layout.VIEWS_FOLDER),
                htmlindex="index.html",
                caption="../report/views.rst",
                category="3-D views",
            )
            if VIEWS_IN_REPORT
            else directory(layout.VIEWS_FOLDER)
        ),
    params:
        figures=lambda wildcards: pipeline.view_scenes(config),
    log:
        layout.log_path("views", "views"),
    benchmark:
        layout.benchmark_path("views", "views")
    threads: 1
    resources:
        mem_mb=1000,
        runtime=10,
        est_s=lambda wildcards: progress.views_estimate(len(pipeline.view_sims(config))),
    conda:
        "../envs/confined_rod.yaml"
    script:
        "../scripts/views.py"
