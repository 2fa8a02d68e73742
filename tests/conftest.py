"""Shared test helpers."""
from __future__ import annotations

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
INPUTS = ROOT / "inputs"



@pytest.fixture
def write_deck(tmp_path):
    """Write deck text to tmp_path/<name> and return its path."""
    def _write(text: str, name: str = "deck.dat") -> Path:
        path = tmp_path / name
        path.write_text(text)
        return path
    return _write
