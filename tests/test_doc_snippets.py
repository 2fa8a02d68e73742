"""Every Python snippet of README.md and docs/*.md runs when pasted.

Each ```python block is executed as a reader would paste it: the blocks of one page in order, in
one interpreter session (a later block may use what an earlier one imported), in a fresh folder
holding a copy of the repository's ``inputs/`` (the snippets name decks as ``inputs/X.dat``).
A block written as an interactive session (``>>>`` lines) is run as a doctest: its printed
output, or the exception it shows, must be what the page says.  No block is exempt.
"""
from __future__ import annotations

import doctest
import re
import shutil
import traceback

import pytest

from conftest import INPUTS, ROOT

PAGES = ["README.md", *sorted(str(p.relative_to(ROOT)) for p in (ROOT / "docs").glob("*.md"))]
BLOCK = re.compile(r"^```python\n(.*?)^```", re.M | re.S)


def snippets(page: str) -> list[tuple[int, str]]:
    """(line number, text) of every ```python block of ``page``."""
    text = (ROOT / page).read_text()
    return [(text.count("\n", 0, m.start()) + 2, m.group(1)) for m in BLOCK.finditer(text)]


def test_the_extractor_finds_the_blocks():
    """The pages that hold snippets are seen (a changed fence style would otherwise skip them all)."""
    counts = {page: len(snippets(page)) for page in PAGES}
    assert counts["docs/api.md"] >= 4 and sum(counts.values()) >= 6, counts
    assert all(text.strip() for page in PAGES for _, text in snippets(page))


@pytest.mark.parametrize("page", [p for p in PAGES if snippets(p)])
def test_every_python_snippet_runs_when_pasted(page, tmp_path, monkeypatch):
    shutil.copytree(INPUTS, tmp_path / "inputs")
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    namespace: dict[str, object] = {"__name__": "__main__"}
    for line, text in snippets(page):
        where = f"{page}:{line}"
        if text.lstrip().startswith(">>>"):
            test = doctest.DocTestParser().get_doctest(text, namespace, where, page, line)
            runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
            runner.run(test, clear_globs=False)
            assert runner.failures == 0, f"{where}: the session's output is not what the page shows (see stdout)"
        else:
            try:   # compiled at its own line numbers: a failure names the page's line
                exec(compile("\n" * (line - 1) + text, page, "exec"), namespace)
            except Exception as exc:  # the snippet's own error, named by page and line
                lines = [f.lineno for f in traceback.extract_tb(exc.__traceback__) if f.filename == page]
                pytest.fail(f"{page}:{lines[-1] if lines else line}: {exc.__class__.__name__}: {exc}")
    import matplotlib.pyplot as plt
    plt.close("all")
