"""The batch sweep's driver does per-chunk work only (issue 27, step 3).

* workers write their chunks' parts of the resume record themselves: with two workers no part
  is written by the driver's process (a spy on write_part records the writing pid in a file),
  every chunk's part is there with its case range and counts, and the tables equal those of a
  run where one process does everything;
* the driver merges the rows the workers return (kept and failed ones) and reads back only
  the parts of resumed chunks: a resumed run gives the same tables;
* the chunk layout depends on the number of cases only and is capped at MAX_CHUNKS chunks
  (10^9 cases: 4096 parts), for batch and per-case chunks alike; a small sweep (the shipped search) runs in the driver when the
  worker pool would cost more than it saves.
"""
from __future__ import annotations

import json
import os

import pandas as pd
import pyarrow.parquet as pq
import pytest

from driver._cli import main
from driver.sweep import _chunks as chunks
from driver.sweep import _executor as executor
from driver.sweep import _plan as plan
from driver.sweep import _resume as resume

SWEEP = """&fourbar fixed_link = 12.0, crank = 3.0, coupler = 15.0, rocker = 9.0, omega = 5.0, step_deg = 10 /
&sweep
  key1 = 'fourbar.crank',   start1 = 1.0, stop1 = 7.0,  count1 = 21
  key2 = 'fourbar.coupler', start2 = 6.0, stop2 = 20.0, count2 = 40
  key3 = 'fourbar.rocker',  start3 = 4.0, stop3 = 16.0, count3 = 40
  keep = 'meets_transmission_band and rocker_swing_deg >= 50'
  case_outputs = 'none', summary_rows = 'kept'
/
"""


@pytest.fixture
def writers(tmp_path, monkeypatch):
    """A file listing the pid of every write_part call (workers fork from this process)."""
    log = tmp_path / "writers.log"
    real = resume.write_part

    def spy(folder, rows, meta):
        with open(log, "a") as fh:
            fh.write(f"{os.getpid()} {meta['start']}\n")
        return real(folder, rows, meta)

    monkeypatch.setattr(chunks, "write_part", spy)     # where a worker writes its chunk's part
    monkeypatch.setattr(resume, "write_part", spy)     # where the driver writes one
    return log


def test_workers_write_their_parts_and_the_driver_merges(tmp_path, writers, monkeypatch):
    monkeypatch.setattr(executor, "POOL_MIN_SECONDS", 0.0)   # the pool even for this small sweep
    deck = tmp_path / "s.dat"
    deck.write_text(SWEEP)
    assert main([str(deck), "-o", str(tmp_path / "two"), "-q", "-j", "2"]) == 0
    lines = [line.split() for line in writers.read_text().splitlines()]
    n = 21 * 40 * 40
    size = plan.chunk_size(n, "batch")
    assert sorted(int(s) for _, s in lines) == list(range(0, n, size))
    assert all(int(pid) != os.getpid() for pid, _ in lines)   # not one part from the driver
    parts = sorted((tmp_path / "two" / "s.sweep").glob("part-*.parquet"))
    assert len(parts) == len(lines)
    meta = [json.loads(pq.read_schema(p).metadata[b"sweep"]) for p in parts]
    assert sum(m["stop"] - m["start"] for m in meta) == n and sum(m["n_ok"] for m in meta) == n
    writers.unlink()
    assert main([str(deck), "-o", str(tmp_path / "one"), "-q", "-j", "1"]) == 0   # all in this process
    a = pd.read_parquet(tmp_path / "two" / "s_summary.parquet")
    b = pd.read_parquet(tmp_path / "one" / "s_summary.parquet")
    pd.testing.assert_frame_equal(a, b)
    assert 0 < a["kept"].sum() == sum(m["n_kept"] for m in meta) == len(a)
    assert (tmp_path / "two" / "s.out").read_text() == (tmp_path / "one" / "s.out").read_text()
    # a resumed run reads the parts back and writes the same tables
    writers.unlink()
    assert main([str(deck), "-o", str(tmp_path / "two"), "-q", "-j", "2", "--resume"]) == 0
    pd.testing.assert_frame_equal(pd.read_parquet(tmp_path / "two" / "s_summary.parquet"), b)
    assert not writers.exists()   # nothing recomputed


def test_a_small_sweep_runs_in_the_driver_when_the_pool_would_not_pay(tmp_path, writers):
    """33 600 linkages (about 0.03 s of kernel): with -j 2 the first chunk runs in the driver,
    timed, and so do the rest (no worker forked); an explicit chunk size keeps the pool."""
    deck = tmp_path / "s.dat"
    deck.write_text(SWEEP)
    assert main([str(deck), "-o", str(tmp_path / "two"), "-q", "-j", "2"]) == 0
    pids = {int(line.split()[0]) for line in writers.read_text().splitlines()}
    assert pids == {os.getpid()} and len(writers.read_text().splitlines()) == plan.MIN_CHUNKS
    writers.unlink()
    assert main([str(deck), "-o", str(tmp_path / "one"), "-q", "-j", "1"]) == 0
    assert (tmp_path / "two" / "s.out").read_text() == (tmp_path / "one" / "s.out").read_text()
    writers.unlink()
    deck.write_text(SWEEP.replace("summary_rows = 'kept'", "summary_rows = 'kept', chunk = 4200"))
    assert main([str(deck), "-o", str(tmp_path / "pool"), "-q", "-j", "2"]) == 0
    assert os.getpid() not in {int(line.split()[0]) for line in writers.read_text().splitlines()}


def test_chunk_layout_depends_on_the_case_count_only_and_is_capped():
    assert plan.chunk_size(102400, "batch") == 12800         # the shipped search: 8 chunks
    assert plan.chunk_size(10**7, "batch") == plan.CHUNK
    for n in (10**8, 10**9, 10**10):
        size = plan.chunk_size(n, "batch")
        assert -(-n // size) <= plan.MAX_CHUNKS and size >= plan.CHUNK
    # case by case: small chunks (whole decks per case), as many as MAX_CHUNKS at most
    assert [plan.chunk_size(n, "cases") for n in (1, 18, 128, 129, 900, 8192, 10**6)] == [1, 1, 1, 2, 8, 64, 245]
    assert -(-10**6 // plan.chunk_size(10**6, "cases")) <= plan.MAX_CHUNKS
    assert plan.chunk_size(10**6, "cases", given=7) == 7   # the deck's chunk


def _decimal_half_up(value: float, decimals: int) -> str:
    """The reference: the exact binary value rounded half away from zero by Decimal."""
    from decimal import ROUND_HALF_UP, Context, Decimal, localcontext
    with localcontext(Context(prec=330 + decimals)):
        return format(Decimal(value).quantize(Decimal(1).scaleb(-decimals), rounding=ROUND_HALF_UP), "f")


def test_fast_fixed_point_text_equals_decimal_half_up():
    """The table writer's fast path (Python's correctly rounded 'f' text unless the double is an
    exact tie) gives Decimal's half-up text for every value: ties, negative zero, huge and tiny."""
    from hypothesis import given, settings
    from hypothesis import strategies as st

    from driver._table import _round_half_up
    for v in (0.5, 1.5, 2.5, -2.5, 0.125, -0.125, 2.675, 0.045, 0.0, -0.0, 1e-5, -1e-5, 1e20, 1e300, 5e-324):
        for d in range(0, 9):
            assert _round_half_up(v, d) == _decimal_half_up(v, d), (v, d)

    @settings(max_examples=3000, deadline=None)
    @given(st.one_of(st.floats(allow_nan=False, allow_infinity=False),
                     st.integers(-10**7, 10**7).map(lambda k: k / 2 ** 9)), st.integers(0, 10))
    def same(v, d):
        assert _round_half_up(v, d) == _decimal_half_up(v, d)
    same()
