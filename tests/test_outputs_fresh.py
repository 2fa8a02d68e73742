"""Committed outputs equal a fresh run: every deck in inputs/ runs into a temporary folder
through the command line (from the repository root, as the outputs were made), and every text
file it writes (.out, .result.dat, .csv; sweep case folders included) must equal its copy in
outputs/ byte for byte.  So `git diff outputs/` shows only changes someone made.

Slow-marked (a few minutes on a loaded machine), but CI runs it.  Parquet files are binary and
carry writer metadata; their tables are the CSVs.  The four-bar design search (10^5 linkages,
minutes) runs on a 3 x 8 x 8 sub-grid of its own grid instead: every design it keeps must be
the committed summary's row at that grid point, column for column, and no other committed
row may lie on the sub-grid.
"""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from conftest import INPUTS, ROOT

OUTPUTS = ROOT / "outputs"
TEXT = (".out", ".dat", ".csv")
#: decks too long for a full fresh run here, checked on a sub-grid instead
SUBGRID = {"fourbar_design_search.dat": {"count1 = 25": "count1 = 3", "count2 = 64": "count2 = 8",
                                         "count3 = 64": "count3 = 8"}}
DECKS = sorted(p.name for p in INPUTS.glob("*.dat") if p.name not in SUBGRID)


@pytest.mark.slow
@pytest.mark.parametrize("deck", DECKS)
def test_committed_outputs_equal_a_fresh_run(tmp_path, deck):
    stem = Path(deck).stem
    run = subprocess.run([sys.executable, "-m", "driver", "-q", "-o", str(tmp_path), f"inputs/{deck}"],
                         cwd=ROOT, capture_output=True, text=True, timeout=900)
    written = sorted(p for p in tmp_path.rglob("*") if p.is_file() and p.suffix in TEXT)
    assert (tmp_path / f"{stem}.out") in written, run.stderr
    differ, missing = [], []
    for p in written:
        rel = p.relative_to(tmp_path)
        committed = OUTPUTS / rel
        if not committed.exists():
            missing.append(str(rel))
        elif committed.read_bytes() != p.read_bytes():
            differ.append(str(rel))
    assert not missing, f"fresh run writes files not committed in outputs/: {missing}"
    assert not differ, (f"outputs/ differs from a fresh run of inputs/{deck} in {differ}; "
                        f"regenerate with: .venv/bin/python -m driver inputs/{deck}")


@pytest.mark.slow
def test_design_search_subgrid_equals_committed_rows(tmp_path):
    deck = "fourbar_design_search.dat"
    text = (INPUTS / deck).read_text()
    for old, new in SUBGRID[deck].items():
        assert old in text, f"inputs/{deck} changed: update the sub-grid of this test ({old!r})"
        text = text.replace(old, new)
    sub = tmp_path / deck
    sub.write_text(text)
    out = tmp_path / "out"
    run = subprocess.run([sys.executable, "-m", "driver", "-q", "-j", "1", "-o", str(out), str(sub)],
                         cwd=ROOT, capture_output=True, text=True, timeout=900)
    assert run.returncode == 0, run.stderr
    keys = ["fourbar.crank", "fourbar.coupler", "fourbar.rocker"]
    fresh = pd.read_csv(out / "fourbar_design_search_summary.csv")
    committed = pd.read_csv(OUTPUTS / "fourbar_design_search_summary.csv")
    grids = [np.linspace(1.0, 7.0, 3), np.linspace(6.0, 20.0, 8), np.linspace(4.0, 16.0, 8)]
    on_sub = np.ones(len(committed), bool)
    for key, grid in zip(keys, grids):
        on_sub &= np.isclose(committed[key].to_numpy()[:, None], grid[None, :], rtol=1e-12).any(axis=1)
    expected = committed[on_sub].reset_index(drop=True)
    assert len(fresh) == len(expected) > 0
    fresh = fresh.sort_values(keys).reset_index(drop=True)
    expected = expected.sort_values(keys).reset_index(drop=True)
    for col in committed.columns.drop("case"):
        a, b = fresh[col].to_numpy(), expected[col].to_numpy()
        if np.issubdtype(a.dtype, np.number) and np.issubdtype(b.dtype, np.number):
            assert np.allclose(a, b, rtol=1e-10, atol=1e-12, equal_nan=True), col
        else:
            assert (a.astype(str) == b.astype(str)).all(), col
