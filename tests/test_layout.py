"""The package's layout: its parts (sim, analysis, claims, pipeline and the shared modules), the
import contracts between them, and the one module that names the files of results/."""
import ast
import re
import subprocess
import sys
from pathlib import Path

from confined_rod import layout

PKG = Path(__file__).resolve().parents[1] / "src" / "confined_rod"
ROOT = PKG.parents[1]


def _modules():
    return sorted(PKG.rglob("*.py"))


def test_every_import_inside_the_package_names_a_module_that_exists():
    """A relative import resolves to a module or a package of this tree, also inside a function
    (a module moved one level deeper keeps its old dots, and '..x' then names the package root)."""
    bad = []
    for path in _modules():
        for node in ast.walk(ast.parse(path.read_text())):
            if not isinstance(node, ast.ImportFrom) or not node.level:
                continue
            base = path.parent
            for _ in range(node.level - 1):
                base = base.parent
            target = base.joinpath(*(node.module or "").split(".")) if node.module else base
            exists = target.with_suffix(".py").is_file() or (target / "__init__.py").is_file()
            if node.module is None:     # from .. import x: every x is a module of that package
                exists = all((target / f"{a.name}.py").is_file() or (target / a.name / "__init__.py").is_file()
                             for a in node.names)
            if not exists or not target.is_relative_to(PKG):
                bad.append(f"{path.relative_to(PKG)}:{node.lineno}: from {'.' * node.level}{node.module or ''}")
    assert not bad, bad


def test_the_import_contracts_hold():
    """pyproject.toml's contracts (analysis and claims never import the simulator or numba, ...);
    .ci/run runs the same command."""
    exe = Path(sys.executable).with_name("lint-imports")
    out = subprocess.run([str(exe)], cwd=ROOT, capture_output=True, text=True)
    assert out.returncode == 0, out.stdout[-3000:] + out.stderr[-2000:]
    assert "0 broken" in out.stdout


def test_no_results_path_is_written_outside_the_layout_module():
    """The files of results/ are named in confined_rod.layout; the rules call it for their
    patterns. A string that starts a results/ path anywhere else in the package, the workflow's
    scripts or the tools is a second place (docstrings and comments are documentation)."""
    literal = re.compile(r"""["'](?:\w*)?results/""")
    files = [p for p in _modules() if p != PKG / "layout.py"]
    files += sorted((ROOT / "workflow" / "scripts").glob("*.py")) + sorted((ROOT / "tools").glob("*.py"))
    found = []
    for path in files:
        tree = ast.parse(path.read_text())
        docstrings = {id(n.body[0].value) for n in ast.walk(tree)
                      if isinstance(n, (ast.Module, ast.FunctionDef, ast.ClassDef, ast.AsyncFunctionDef))
                      and n.body and isinstance(n.body[0], ast.Expr) and isinstance(n.body[0].value, ast.Constant)}
        for node in ast.walk(tree):
            if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docstrings \
                    and re.search(r"(^|[\s(`{'\"])results/", node.value) and "benchmarks/results" not in node.value:
                found.append(f"{path.relative_to(ROOT)}:{node.lineno}: {node.value[:60]!r}")
    assert not found, found
    assert literal  # (the pattern above is the one that matters)


def test_the_layout_names_each_file_once_and_relative_to_the_checkout():
    assert layout.sim_path("fig4", "a-s0") == "results/sims/fig4/a-s0.nc"
    assert layout.sim_key_path("fig4/a-s0") == layout.sim_path("fig4", "a-s0")
    assert layout.log_path("batch", "simulate", "fig4", "b") == "results/logs/batch/simulate/fig4/b.log"
    assert layout.benchmark_path("figure", "fig4") == "results/benchmarks/figure/fig4.tsv"
    assert layout.paper_pdf("reproduction") == "results/paper/reproduction.pdf"
    assert all(not Path(p).is_absolute() for p in (layout.CLAIMS_CSV, layout.dataset_path("x")))


def test_build_times_finds_the_figure_of_every_rule_that_writes_per_figure_benchmarks():
    """tools/build_times.py attributes a job's seconds to the figure its benchmark file is filed
    under (layout.benchmark_path, as the rules call it), and the build-wide rules to themselves."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("build_times", ROOT / "tools" / "build_times.py")
    bt = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bt)

    def job(*key):
        return str(Path(layout.benchmark_path(*key)).relative_to(layout.BENCHMARKS).with_suffix(""))

    assert bt.figure_of(job("batch", "simulate", "conv_l0", "n1-s0-to-n1-s9")) == "conv_l0"
    for rule in ("simulate", "probe", "load_path"):
        assert bt.figure_of(job(rule, "fig6_FonL", "L20-s1")) == "fig6_FonL"
    for rule in ("postprocess", "figure", "convergence_check"):
        assert bt.figure_of(job(rule, "conv_k_w")) == "conv_k_w"
    assert bt.figure_of(job("claims", "claims")) is None and bt.figure_of(job("paper", "reproduction")) is None
    jobs = [{"rule": "simulate", "job": job("simulate", "a", "s0"), "s": 2.0},
            {"rule": "batch", "job": job("batch", "simulate", "a", "s1-to-s2"), "s": 3.0},
            {"rule": "claims", "job": job("claims", "claims"), "s": 1.0}]
    assert bt.by_figure(jobs) == {"a": {"jobs": 2, "job_s": 5.0}, "claims": {"jobs": 1, "job_s": 1.0}}
