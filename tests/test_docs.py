"""The documentation lives in the repository: every reference resolves inside it, nothing cites
files outside it, and the deck-key tables equal what the code declares."""
from __future__ import annotations

import re
import subprocess
import sys

import pytest

from conftest import ROOT

# what the repository must never cite: files outside it, or sources by an internal number
FORBIDDEN = re.compile(r"\bseeds?[ _-]?0{2}[0-9]\b|shared/|\bstudy notes?\b|\bseeds/", re.I)
SCANNED = ["README.md", "CHANGELOG.md", "docs", "inputs", "outputs", "driver", "fortran", "published", "bench",
           "meson.build", "pyproject.toml"]
TEXT = {".md", ".py", ".f90", ".dat", ".out", ".txt", ".csv", ".build", ".toml", ".json", ""}


def _files():
    for name in SCANNED:
        path = ROOT / name
        if path.is_file():
            yield path
        elif path.is_dir():
            yield from (p for p in sorted(path.rglob("*")) if p.is_file() and p.suffix in TEXT
                        and "__pycache__" not in p.parts)


def test_nothing_outside_the_repository_is_cited():
    hits = []
    for path in _files():
        for n, line in enumerate(path.read_text(errors="replace").splitlines(), 1):
            if FORBIDDEN.search(line):
                hits.append(f"{path.relative_to(ROOT)}:{n}: {line.strip()[:100]}")
    assert not hits, "\n".join(hits[:30])


def test_every_docs_reference_exists():
    missing = []
    for path in _files():
        for ref in re.findall(r"\bdocs/([\w.-]+\.(?:md|py))", path.read_text(errors="replace")):
            if not (ROOT / "docs" / ref).is_file():
                missing.append(f"{path.relative_to(ROOT)} -> docs/{ref}")
    for page in (ROOT / "docs").glob("*.md"):
        for ref in re.findall(r"\]\(([^)#:]+)\)", page.read_text()):
            if not (page.parent / ref).exists():
                missing.append(f"docs/{page.name} -> {ref}")
    assert not missing, "\n".join(missing)


def test_bibliography_has_every_cited_key():
    bib = (ROOT / "docs" / "bibliography.md").read_text()
    keys = set(re.findall(r"\*\*\[([^\]]+)\]\*\*", bib))
    assert {"Soegihardjo 2003", "Fajar", "Andalas", "Ma'arif 2006", "Simeon 1996", "Taylor 1996"} <= keys
    cited = set()
    for path in _files():
        cited |= set(re.findall(r"\[((?:Soegihardjo|Fajar|Andalas|Ma'arif|Simeon|Taylor|Caro|Craig|Newmark|"
                                r"Erdman|Fischer|SAE|IVP)[^\]]*)\]", path.read_text(errors="replace")))
    assert cited - keys == set(), f"cited but not in docs/bibliography.md: {sorted(cited - keys)}"


def test_study_pages_have_the_required_sections_and_every_group_has_a_key_table():
    sys.path.insert(0, str(ROOT / "docs"))
    try:
        import gen_keys
    finally:
        sys.path.pop(0)
    from driver.runner import CONTROL_GROUPS
    from driver.study import study_names
    assert set(study_names()) | set(CONTROL_GROUPS) <= gen_keys.groups_documented()
    for page in ("fourbar", "ujoint", "slidercrank", "manipulator"):
        text = (ROOT / "docs" / f"{page}.md").read_text()
        for section in ("## What the", "wrong", "## What we implement", "## How the tests check it"):
            assert section in text, (page, section)


def test_key_tables_are_up_to_date():
    res = subprocess.run([sys.executable, str(ROOT / "docs" / "gen_keys.py"), "--check"], capture_output=True,
                         text=True)
    assert res.returncode == 0, res.stderr


@pytest.mark.parametrize("group", ["fourbar", "sweep"])
def test_key_table_lists_units_and_defaults(group):
    sys.path.insert(0, str(ROOT / "docs"))
    try:
        import gen_keys
    finally:
        sys.path.pop(0)
    table = gen_keys.table(group)
    if group == "fourbar":
        assert "| `omega` | float | rad/s | `1.0` |" in table and "| `crank` | float | length | **required** |" in table
    else:
        assert "`key1`" in table
