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
