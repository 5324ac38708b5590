"""config/README.md: generated from the config schema, the config files and the Scene defaults
(confined_rod.pipeline.config_docs), and up to date."""
from pathlib import Path

from confined_rod import Scene
from confined_rod.analysis import figures
from confined_rod.cli import main
from confined_rod.pipeline.config_docs import CONFIG_FILES, OUTPUT, render, scene_defaults
from confined_rod.quantities import SCENE_PARAMETERS

ROOT = Path(__file__).resolve().parents[1]
REGENERATE = "regenerate: python -m confined_rod config-docs -o config/README.md"


def test_committed_config_docs_are_the_generated_ones():
    committed = (ROOT / OUTPUT).read_text(encoding="utf-8")
    assert committed == render(Scene), REGENERATE


def test_every_file_of_config_is_described():
    present = {p.relative_to(ROOT).as_posix() for p in (ROOT / "config").rglob("*")
               if p.is_file() and p.name != "README.md"}
    described = {path for path, *_ in CONFIG_FILES}
    assert present == described, ("describe every file of config/ in confined_rod.pipeline.config_docs.CONFIG_FILES "
                                  f"(missing: {sorted(present - described)}, gone: {sorted(described - present)}); "
                                  + REGENERATE)


def test_every_scene_parameter_and_kind_option_is_on_the_page():
    page = (ROOT / OUTPUT).read_text(encoding="utf-8")
    for q in SCENE_PARAMETERS:
        assert f"| `{q.name}` |" in page, q.name
    for k in figures.kinds():
        assert f"### `{k}`" in page, k
        for option in getattr(figures.get(k), "OPTIONS", {}):
            assert f"| `{option}` |" in page, (k, option)


def test_resolved_defaults_say_what_they_follow():
    text = scene_defaults(Scene)
    assert text["pore_length"] == "follows L"
    assert text["k_t"] == "follows k_ph/l0: 1 k_ph/l0 (2000); with friction_at: centre 0.1 k_w (100)"
    assert text["l0"] == "0.5; follows R" and text["k_ph"] == "1000; follows R, EI"
    assert text["t_max"].endswith("follows R, EI, the solver")
    assert text["load"] == "0.25" and text["body_force"] == "[0, 0, 0]" and text["floor"] == "true"


def test_check_flags_a_stale_page(tmp_path, capsys):
    stale = tmp_path / "README.md"
    stale.write_text("# Configs\n", encoding="utf-8")
    assert main(["config-docs", "--check", str(stale)]) == 1
    assert "config-docs -o" in capsys.readouterr().err
    assert main(["config-docs", "-o", str(stale)]) == 0
    assert main(["config-docs", "--check", str(stale)]) == 0
