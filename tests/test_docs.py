"""The documentation lives in the repository: every reference resolves inside it, nothing cites
files outside it, and the deck-key tables equal what the code declares."""
from __future__ import annotations

import re
import subprocess
import sys
import tomllib

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
    from driver._runner import CONTROL_GROUPS
    from driver._study import study_names
    assert set(study_names()) | set(CONTROL_GROUPS) <= gen_keys.groups_documented()
    pages = [name for name in study_names() if (ROOT / "docs" / f"{name}.md").is_file()]
    assert len(pages) >= 4   # robust_example is a section of manipulator.md
    for page in pages:
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


def _slug(heading: str) -> str:
    """GitHub's anchor for a heading: lower case, punctuation but '-' and '_' dropped, spaces to '-'."""
    text = re.sub(r"[`*]", "", heading.strip().lower())
    return re.sub(r"[^\w\- ]", "", text).replace(" ", "-")


def _anchors(page) -> set[str]:
    text = re.sub(r"^```.*?^```", "", page.read_text(), flags=re.M | re.S)   # no headings inside code
    return {_slug(h) for h in re.findall(r"^#{1,6} (.+)$", text, flags=re.M)}


def test_every_link_and_anchor_resolves():
    """Links of README.md and docs/*.md reach an existing file and, with #anchor, a heading there."""
    assert _slug("As a user: `pip install .`") == "as-a-user-pip-install-"
    bad = []
    for page in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]:
        for target in re.findall(r"\]\(([^)\s]+)\)", page.read_text()):
            if re.match(r"\w+:", target):
                continue   # an URL
            path, _, anchor = target.partition("#")
            dest = (page.parent / path) if path else page
            if not dest.exists():
                bad.append(f"{page.relative_to(ROOT)} -> {target}: no such file")
            elif anchor and dest.suffix == ".md" and anchor not in _anchors(dest):
                bad.append(f"{page.relative_to(ROOT)} -> {target}: no such heading")
    assert not bad, "\n".join(bad)


def test_readme_first_screen_is_for_a_newcomer():
    """What it is, the two commands, install choices, one example, where the docs are -- first, and
    the long reference material in docs/ (the README stays short)."""
    lines = (ROOT / "README.md").read_text().splitlines()
    first = "\n".join(lines[:45])
    assert "bash .ci/setup && .venv/bin/python -m driver inputs/crank5.dat" in first
    assert "bash .ci/setup && .venv/bin/python -m pytest -q" in first
    assert "## Install" in first and "pip install ." in first and "docs/install.md" in first
    heads = [n for n, line in enumerate(lines) if line.startswith("## ")]
    names = [lines[n] for n in heads]
    assert names[:3] == ["## Install", "## An example: run a deck, compare it with the paper", "## Documentation"]
    assert heads[2] < 60, "the documentation index must start within the first screenful or two"
    assert len(lines) <= 120, "reference material belongs in docs/, not the README"
    # the CI line is exactly the README's test command
    assert "bash .ci/setup && .venv/bin/python -m pytest -q" in (ROOT / ".ci" / "run").read_text()


def _doc_blocks():
    sys.path.insert(0, str(ROOT / ".ci"))
    try:
        import doc_blocks
    finally:
        sys.path.pop(0)
    return doc_blocks.blocks()


def test_every_documented_install_command_is_run_by_clean_clone():
    """Every bash block of the docs that installs is marked for .ci/clean-clone (which runs it word
    for word), clean-clone has checks for exactly the marked blocks, and the README's install
    table names commands those blocks run."""
    blocks = _doc_blocks()
    installing = re.compile(r"pip (install|wheel)|\.ci/setup")
    for page in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]:
        text = page.read_text()
        for m in re.finditer(r"^```bash\n(.*?)^```", text, flags=re.M | re.S):
            if installing.search(m.group(1)) and "pytest" not in m.group(1):
                marked = text[:m.start()].rstrip().endswith("-->") and \
                    text[:m.start()].rstrip().splitlines()[-1].startswith("<!-- clean-clone:")
                assert marked or page.name == "README.md" and "bash .ci/setup && " in m.group(1), \
                    f"{page.relative_to(ROOT)}: an install block not marked <!-- clean-clone: NAME -->"
    script = (ROOT / ".ci" / "clean-clone").read_text()
    expected = re.search(r'^EXPECTED="([^"]+)"', script, flags=re.M).group(1).split()
    assert sorted(expected) == sorted(blocks)
    assert all(f"run_block {name}" in script for name in blocks)
    run_lines = [line.split("#")[0].strip() for _, text in blocks.values() for line in text.splitlines()]
    readme = (ROOT / "README.md").read_text()
    table = readme[readme.index("## Install"):readme.index("## An example")]
    for code in re.findall(r"`([^`]*pip (?:install|wheel)[^`]*)`", table):
        for command in code.split(" && "):
            assert any(command.strip() in line for line in run_lines), f"README: {command!r} is run by no block"


def test_documented_build_requirements_are_the_build_system_requirements():
    requires = tomllib.loads((ROOT / "pyproject.toml").read_text())["build-system"]["requires"]
    line = next(line for line in _doc_blocks()["editable"][1].splitlines() if "meson-python" in line)
    assert re.findall(r'"([^"]+)"|\b(ninja)\b', line.split("#")[0]) and \
        sorted(a or b for a, b in re.findall(r'"([^"]+)"|\b(ninja)\b', line.split("#")[0])) == sorted(requires)
