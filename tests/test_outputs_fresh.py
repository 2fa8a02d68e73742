"""Committed outputs equal a fresh run: every deck in inputs/ runs into a temporary folder
through the command line (from the repository root, as the outputs were made), and every text
file it writes (.out, .result.dat, .csv; sweep case folders included) must equal its copy in
outputs/ byte for byte.  So `git diff outputs/` shows only changes someone made.

Parquet files are binary and carry writer metadata, so their tables are compared instead
(exactly, columns and dtypes included): an optimiser's `_evals.parquet` has no CSV twin, and a
summary column added to a study went stale there once unnoticed.  The resume records
(`<stem>.sweep/`) are not committed and not compared.

An optimiser's path records -- ``<stem>_history.csv`` and ``<stem>_evals.parquet`` of an
``&optimize`` deck whose method has a BLAS-dependent step (SLSQP, trust-constr, a polish) -- follow
the floating-point path, which changes with the BLAS kernel (OPENBLAS_CORETYPE): their rows are
not compared.  They must have the same columns (and dtypes), and their best feasible objective
must agree with the committed one within PATH_RTOL (relative).  Everything else, the .out, the
optimum deck and its run included, is compared byte for byte (see docs/optimize.md, "The same
result on every machine").

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
#: relative tolerance of the best feasible objective of an optimiser's path records
PATH_RTOL = 1e-6


def path_records(deck: str) -> bool:
    """The deck is an optimisation whose method has a BLAS-dependent step (its path records vary)."""
    from driver._deck import read_deck
    d = read_deck(INPUTS / deck)
    if "optimize" not in d.groups:
        return False
    vals = {k.lower(): v for k, v in d.groups["optimize"].values.items()}
    method = str(vals.get("method", "differential_evolution")).lower()
    return method in ("slsqp", "trust-constr") or bool(vals.get("polish", False))


def same_path_record(fresh: pd.DataFrame, committed: pd.DataFrame, sense: int) -> bool:
    """Same columns and dtypes; best feasible objective within PATH_RTOL."""
    if list(fresh.columns) != list(committed.columns) or list(fresh.dtypes) != list(committed.dtypes):
        return False
    best = []
    for f in (fresh, committed):
        feas = f[f["feasible"].astype(bool)]["objective"].dropna()
        if feas.empty:
            best.append(None)
        else:
            best.append(float(feas.min() if sense > 0 else feas.max()))
    if best[0] is None or best[1] is None:
        return best[0] is best[1]
    return abs(best[0] - best[1]) <= PATH_RTOL * max(1.0, abs(best[1]))


def _sense(deck: str) -> int:
    from driver._deck import read_deck
    vals = {k.lower(): v for k, v in read_deck(INPUTS / deck).groups["optimize"].values.items()}
    return 1 if vals.get("minimize") is not None else -1


@pytest.mark.slow
@pytest.mark.parametrize("deck", DECKS)
def test_committed_outputs_equal_a_fresh_run(tmp_path, deck):
    stem = Path(deck).stem
    run = subprocess.run([sys.executable, "-m", "driver", "-q", "-o", str(tmp_path), f"inputs/{deck}"],
                         cwd=ROOT, capture_output=True, text=True, timeout=900)
    written = sorted(p for p in tmp_path.rglob("*") if p.is_file() and p.suffix in TEXT)
    assert (tmp_path / f"{stem}.out") in written, run.stderr
    differ, missing = [], []
    loose = path_records(deck)
    for p in written:
        rel = p.relative_to(tmp_path)
        committed = OUTPUTS / rel
        if not committed.exists():
            missing.append(str(rel))
        elif loose and p.name == f"{stem}_history.csv":
            if not same_path_record(pd.read_csv(p), pd.read_csv(committed), _sense(deck)):
                differ.append(str(rel))
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
        if loose and p.name == f"{stem}_evals.parquet":
            if not same_path_record(pd.read_parquet(p), pd.read_parquet(committed), _sense(deck)):
                differ.append(str(rel))
            continue
        try:
            pd.testing.assert_frame_equal(pd.read_parquet(p), pd.read_parquet(committed), check_exact=True)
        except AssertionError:
            differ.append(str(rel))
    assert not missing, f"fresh run writes files not committed in outputs/: {missing}"
    assert not differ, (f"outputs/ differs from a fresh run of inputs/{deck} in {differ}; "
                        f"regenerate with: .venv/bin/python -m driver inputs/{deck}")

