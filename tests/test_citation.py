"""The citation metadata (CITATION.cff) and the licence: the software's version is pyproject.toml's,
the original paper is cited, and the licence named is the one in LICENSE. (Its validity against the
CFF 1.2.0 schema is checked with ``cffconvert --validate``, a tool this project does not install.)"""
import tomllib
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]


def _cff():
    return yaml.safe_load((ROOT / "CITATION.cff").read_text(encoding="utf-8"))


def _project():
    return tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]


def test_citation_cites_this_version_of_the_software():
    cff, project = _cff(), _project()
    assert cff["cff-version"] == "1.2.0"
    assert cff.get("type", "software") == "software"
    assert str(cff["version"]) == project["version"], "CITATION.cff's version differs from pyproject.toml's"
    assert "preferred-citation" not in cff  # the software itself is what is cited
    assert cff["license"] == project["license"]
    assert (ROOT / "LICENSE").is_file() and project["license-files"] == ["LICENSE"]
    assert all(a.get("name") or a.get("family-names") for a in cff["authors"])


def test_citation_references_the_original_paper():
    papers = [r for r in _cff().get("references", [])
              if r.get("type") == "article" and "jamming due to helical buckling" in r.get("title", "").lower()]
    assert len(papers) == 1, "the original paper is missing from CITATION.cff's references"
    assert [a["family-names"] for a in papers[0]["authors"]] == ["Svenšek", "Podgornik"]
