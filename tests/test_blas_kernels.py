"""The same outputs whatever BLAS kernel OpenBLAS picks (issue: the same results on every machine).

Each deck below runs twice from the command line, in subprocesses whose environment sets
OPENBLAS_CORETYPE = Haswell and SkylakeX (the process's own environment is never changed), and
everything the two runs write must agree: text files byte for byte, Parquet tables exactly --
except an optimiser's path records (``_history.csv`` / ``_evals.parquet`` of a method with a
BLAS-dependent step), which follow the floating-point path and are held to the rule of
tests/test_outputs_fresh.py (same columns, best feasible objective within PATH_RTOL).

The decks: every optimisation and synthesis deck (their iterative results are where a kernel's
last bits could reach a printed digit) but the slider-crank section search (differential
evolution over a BLAS-free kernel, 80 s a run), and one deck of each study.  A core type the
CPU cannot run falls back inside OpenBLAS, which only makes the test weaker, never wrong.
Slow-marked; CI runs it.
"""
from __future__ import annotations

import os
import subprocess
import sys

import pandas as pd
import pytest

from conftest import INPUTS, ROOT
from test_outputs_fresh import _sense, path_records, same_path_record

KERNELS = ("Haswell", "SkylakeX")
DECKS = sorted(p.name for p in INPUTS.glob("*.dat")
               if p.name.startswith(("optimize_", "synthesis_")) and p.name != "optimize_slidercrank_section.dat")
DECKS += ["crank5_exact.dat", "ujoint_steering.dat", "manipulator_case1_exact.dat", "slidercrank_aluminium.dat"]


def _run(deck: str, out, kernel: str) -> None:
    env = dict(os.environ, OPENBLAS_CORETYPE=kernel)
    run = subprocess.run([sys.executable, "-m", "driver", "-q", "-o", str(out), f"inputs/{deck}"],
                         cwd=ROOT, env=env, capture_output=True, text=True, timeout=900)
    assert (out / f"{deck[:-4]}.out").exists(), run.stderr


@pytest.mark.slow
@pytest.mark.parametrize("deck", DECKS)
def test_outputs_do_not_depend_on_the_blas_kernel(tmp_path, deck):
    outs = [tmp_path / k for k in KERNELS]
    for out, k in zip(outs, KERNELS):
        _run(deck, out, k)
    stem = deck[:-4]
    loose = path_records(deck)
    a_files = sorted(p.relative_to(outs[0]) for p in outs[0].rglob("*") if p.is_file())
    b_files = sorted(p.relative_to(outs[1]) for p in outs[1].rglob("*") if p.is_file())
    assert a_files == b_files
    differ = []
    for rel in a_files:
        a, b = outs[0] / rel, outs[1] / rel
        if loose and rel.name in (f"{stem}_history.csv", f"{stem}_evals.parquet"):
            read = pd.read_csv if rel.suffix == ".csv" else pd.read_parquet
            if not same_path_record(read(a), read(b), _sense(deck)):
                differ.append(str(rel))
        elif rel.suffix == ".parquet":
            try:
                pd.testing.assert_frame_equal(pd.read_parquet(a), pd.read_parquet(b), check_exact=True)
            except AssertionError:
                differ.append(str(rel))
        elif rel.suffix in (".png", ".svg", ".pdf"):
            continue
        elif a.read_bytes() != b.read_bytes():
            differ.append(str(rel))
    assert not differ, f"{deck}: outputs differ between OPENBLAS_CORETYPE={KERNELS[0]} and {KERNELS[1]}: {differ}"
