"""Committed outputs equal a fresh run: every deck in inputs/ runs into a temporary folder
through the command line (from the repository root, as the outputs were made), and every text
file it writes (.out, .result.dat, .csv; sweep case folders included) must equal its copy in
outputs/ byte for byte.  So `git diff outputs/` shows only changes someone made.

Parquet files are binary and carry writer metadata, so their tables are compared instead
(exactly, columns and dtypes included): an optimiser's `_evals.parquet` has no CSV twin, and a
summary column added to a study went stale there once unnoticed.  The resume records
(`<stem>.sweep/`) are not committed and not compared.

Slow-marked (a few minutes on a loaded machine), but CI runs it.
"""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

from conftest import INPUTS, ROOT

OUTPUTS = ROOT / "outputs"
TEXT = (".out", ".dat", ".csv")
DECKS = sorted(p.name for p in INPUTS.glob("*.dat"))


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
    for p in sorted(tmp_path.rglob("*.parquet")):
        rel = p.relative_to(tmp_path)
        if ".sweep" in rel.parts[0]:
            continue
        committed = OUTPUTS / rel
        if not committed.exists():
            missing.append(str(rel))
            continue
        try:
            pd.testing.assert_frame_equal(pd.read_parquet(p), pd.read_parquet(committed), check_exact=True)
        except AssertionError:
            differ.append(str(rel))
    assert not missing, f"fresh run writes files not committed in outputs/: {missing}"
    assert not differ, (f"outputs/ differs from a fresh run of inputs/{deck} in {differ}; "
                        f"regenerate with: .venv/bin/python -m driver inputs/{deck}")

