"""The one place where the files of ``results/`` are named.

Every path the rules (their patterns are these functions called with wildcards, e.g.
``sim_path("{figure}", "{scene}")``), the claims' evidence, the manuscript generator and the
tools use, relative to the checkout. ``results/`` is generated and git-ignored:

    results/
      sims/<figure>/<scene>.nc        one relaxed rod (rule simulate)
      probes/<figure>/<scene>.nc      one point of a stability map, however it ended (rule probe)
      paths/<figure>/<scene>.nc       equilibria along a load sweep (rule load_path)
      batches/<kind>/<figure>/        small scenes run in one process, and their manifests
      datasets/<figure>.nc            what a figure plots (rule postprocess)
      checks/<figure>.txt             a convergence verdict (rule convergence_check)
      figures/<figure>.{pdf,png}      the figure (rule figure)
      views/                          every simulation of the figures in 3-D (rule views):
        index.html, plotly.min.js,    the list of them and the plotly.js their pages share,
        <figure>/<scene>.html         one page per simulation
      error_budget.nc, error_budget.csv  numerical bias beside statistical error of every headline
                                      number (rule error_budget)
      claims.csv, claims.nc           the verdicts on the paper's claims (rule claims)
      paper/                          the manuscript's generated parts and PDF
      logs/<rule>/..., benchmarks/<rule>/...   one log and one benchmark per job
      .rebuild/<figure>/<scene>.stale markers that rebuild a scene file that is not the config's run
      .code/<part>.sha256             the code a step depends on, one file per part (pipeline.code.stamp)
"""
from __future__ import annotations

from pathlib import Path

#: a figure's and a scene's name (they name files and Snakemake wildcards)
NAME_PATTERN = r"[A-Za-z0-9_-]+"
RESULTS = Path("results")
SIMS = RESULTS / "sims"
PROBES = RESULTS / "probes"
PATHS = RESULTS / "paths"
DATASETS = RESULTS / "datasets"
CHECKS = RESULTS / "checks"
#: the 3-D views (rule views): a folder, its index page, the plotly.js its pages share, and a page
#: relative to the folder
VIEWS = RESULTS / "views"
VIEWS_FOLDER = str(VIEWS)
VIEWS_INDEX = str(VIEWS / "index.html")
VIEWS_PLOTLY = "plotly.min.js"
VIEW_PAGE = "{figure}/{scene}.html"
PAPER = RESULTS / "paper"
LOGS = RESULTS / "logs"
BENCHMARKS = RESULTS / "benchmarks"
#: the committed studies outside the build that the manuscript cites (benchmarks/study_*.py write
#: them; claims.manuscript.study_macros reads their seed counts)
STUDIES_GLOB = "benchmarks/results/study_*.json"
ERROR_BUDGET_NC = str(RESULTS / "error_budget.nc")
ERROR_BUDGET_CSV = str(RESULTS / "error_budget.csv")
CLAIMS_CSV = str(RESULTS / "claims.csv")
CLAIMS_NC = str(RESULTS / "claims.nc")
#: the folders of scene files (whatever rule made them)
SCENE_FOLDERS = (SIMS, PROBES, PATHS)
#: the manuscript's generated parts (rule paper_sources), by output name
PAPER_SOURCES = {"numbers": "numbers.tex", "table": "claims_table.tex", "readings": "readings_table.tex",
                 "results": "results_table.tex", "figures": "figures.tex",
                 "supplement_figures": "supplement_figures.tex", "expected": "expected.json"}


def sim_path(figure: str, scene: str) -> str:
    return str(SIMS / figure / f"{scene}.nc")


def sim_key_path(key: str) -> str:
    """The simulation file of a 'figure/scene' key."""
    figure, scene = key.split("/", 1)
    return sim_path(figure, scene)


def sims_folder(figure: str) -> str:
    return str(SIMS / figure) + "/"


def dataset_path(figure: str) -> str:
    return str(DATASETS / f"{figure}.nc")


def figure_paths(figure: str) -> tuple[str, str]:
    return str(RESULTS / "figures" / f"{figure}.pdf"), str(RESULTS / "figures" / f"{figure}.png")


def view_page(figure: str, scene: str) -> str:
    """The 3-D view of one simulation of a figure (rule views)."""
    return str(VIEWS / VIEW_PAGE.format(figure=figure, scene=scene))


def probe_path(figure: str, scene: str) -> str:
    return str(PROBES / figure / f"{scene}.nc")


def path_file(figure: str, scene: str) -> str:
    return str(PATHS / figure / f"{scene}.nc")


def batch_manifest(kind: str, figure: str, batch: str) -> str:
    return str(RESULTS / "batches" / kind / figure / f"{batch}.json")


def batch_folder(kind: str, figure: str, batch: str) -> str:
    """Where a batch leaves its members' datasets, for their own jobs to move into place."""
    return str(RESULTS / "batches" / kind / figure / batch)


def batch_member(kind: str, figure: str, batch: str, scene: str) -> str:
    return str(Path(batch_folder(kind, figure, batch)) / f"{scene}.nc")


def batch_log(kind: str, figure: str, batch: str) -> str:
    return log_path("batch", kind, figure, batch)


def log_path(rule: str, *key: str) -> str:
    """results/logs/<rule>/<key...>.log: the log of one job."""
    return str(LOGS.joinpath(rule, *key[:-1], f"{key[-1]}.log"))


def benchmark_path(rule: str, *key: str) -> str:
    """results/benchmarks/<rule>/<key...>.tsv: Snakemake's benchmark of one job."""
    return str(BENCHMARKS.joinpath(rule, *key[:-1], f"{key[-1]}.tsv"))


def rebuild_marker(figure: str, scene: str) -> Path:
    """An empty file whose fresh mtime makes Snakemake rebuild a scene file that is not the
    run the config asks for (see targets.stale_inputs)."""
    return RESULTS / ".rebuild" / figure / f"{scene}.stale"


def code_stamp(part: str) -> str:
    """results/.code/<part>.sha256: the checksums of the modules one kind of step runs, with the
    newest module's mtime (confined_rod.pipeline.code.stamp)."""
    return str(RESULTS / ".code" / f"{part}.sha256")


def check_path(figure: str) -> str:
    return str(CHECKS / f"{figure}.txt")


def paper_source(name: str) -> str:
    """One generated part of the manuscript (PAPER_SOURCES)."""
    return str(PAPER / PAPER_SOURCES[name])


def paper_pdf(stem: str) -> str:
    """The manuscript built from paper/<stem>.tex."""
    return str(PAPER / f"{stem}.pdf")


def under(results: str | Path, path: str | Path) -> Path:
    """A path of this layout moved under another results folder (a copy of the checkout, a
    build kept for comparison): ``under("/tmp/b/results", dataset_path("fig4"))``."""
    return Path(results) / Path(path).relative_to(RESULTS)
