"""Shared test helpers."""
from __future__ import annotations

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
INPUTS = ROOT / "inputs"

#: a small valid four-bar deck that deck-reading tests mutate one change at a time
GOOD_DECK = """! a good deck
&fourbar
  fixed_link = 12.0, crank = 5.0
  coupler = 15.0
  rocker = 9.0
  omega = 5.0
  step_deg = 20
/
"""


@pytest.fixture
def write_deck(tmp_path):
    """Write deck text to tmp_path/<name> and return its path."""
    def _write(text: str, name: str = "deck.dat") -> Path:
        path = tmp_path / name
        path.write_text(text)
        return path
    return _write


@pytest.fixture(scope="session")
def report_runs(tmp_path_factory):
    """Decks run with --report in this process, once each per session (tests/report_runs.py)."""
    from report_runs import ReportRuns
    return ReportRuns(tmp_path_factory.mktemp("report_runs"))


@pytest.fixture(scope="session")
def browser():
    """One headless Chromium for the session, driven by Selenium (tests/browser.py).  Without
    selenium, chromium or chromedriver the browser tests skip on a developer's machine and fail
    in CI (CI set), where the pages must be tested."""
    import os

    from browser import Browser, selenium_missing
    why = selenium_missing()
    if why:
        if os.environ.get("CI"):
            pytest.fail(f"CI must test the report pages in Chromium: {why}", pytrace=False)
        pytest.skip(why)
    with Browser(width=1200, height=900) as b:
        yield b
