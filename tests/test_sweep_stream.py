"""A batch sweep whose rows exceed STREAM_ROWS writes its tables part by part from the resume
record (driver memory flat, issue 27): the files must be those the in-memory path writes, and
its outcome's summary is a lazy handle over the parts that reads as the summary file does.

The reference is the same deck run with streaming off (every row held, one ``to_parquet`` /
``write_tidy`` / ``render_table`` call): the ``.out`` and the ``_summary.csv`` byte for byte, the
``_summary.parquet`` as a table.  The shipped design search (102 400 cases) exercises the
second pass of the ``.out`` (the case column widens past 99 999); a grid with bad-input values
(object columns in some chunks) takes the fallback, rows in memory, with the same files and
exit status.
"""
from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest

from driver._cli import main
from driver.sweep import _assemble as stream
from driver.sweep import _executor as executor

ROOT = Path(__file__).resolve().parents[1]
SHIPPED = (ROOT / "inputs" / "fourbar_design_search.dat").read_text()
#: the crank axis reversed: kept cases beyond 99 999, so the .out's case column widens
REVERSED = SHIPPED.replace("start1 = 1.0,  stop1 = 7.0,  count1 = 25", "start1 = 9.0,  stop1 = 1.0,  count1 = 33")


def _run(tmp_path: Path, name: str, text: str, stream_rows: int, monkeypatch, jobs: str = "2") -> tuple[int, Path]:
    monkeypatch.setattr(executor, "STREAM_ROWS", stream_rows)
    deck = tmp_path / f"{name}.dat"
    deck.write_text(text)
    out = tmp_path / f"out_{stream_rows}_{jobs}"
    return main([str(deck), "-o", str(out), "-q", "-j", jobs]), out


def _same(a: Path, b: Path, stem: str) -> None:
    assert (a / f"{stem}.out").read_bytes() == (b / f"{stem}.out").read_bytes()
    assert (a / f"{stem}_summary.csv").read_bytes() == (b / f"{stem}_summary.csv").read_bytes()
    fa, fb = pd.read_parquet(a / f"{stem}_summary.parquet"), pd.read_parquet(b / f"{stem}_summary.parquet")
    pd.testing.assert_frame_equal(fa, fb)
    assert fa.attrs == fb.attrs and fa.attrs["summary_settings"]["transmission_band_deg"] == [40.0, 120.0]


def test_streamed_tables_equal_the_in_memory_ones(tmp_path, monkeypatch):
    calls = []
    real = stream.write_streamed
    monkeypatch.setattr(stream, "write_streamed", lambda *a, **k: calls.append(1) or real(*a, **k))
    st_ref, ref = _run(tmp_path, "s", REVERSED, 0, monkeypatch)
    assert not calls
    st_new, new = _run(tmp_path, "s", REVERSED, 50, monkeypatch)   # hundreds of kept rows in 16 parts
    assert st_ref == st_new == 0 and calls
    _same(ref, new, "s")
    text = (new / "s.out").read_text()
    assert "\n  11" in text and "\n    case  fourbar.crank" in text   # the case column widened (6 digits)
    st_one, one = _run(tmp_path, "s", REVERSED, 50, monkeypatch, jobs="1")
    _same(ref, one, "s")


@pytest.mark.parametrize("block_rows", [1, 300])
def test_streamed_tables_a_block_of_parts_at_a_time(tmp_path, monkeypatch, block_rows):
    """The CSV and the .out are written a block of parts at a time (STREAM_BLOCK_ROWS; the
    Parquet summary a row group per part): each part its own block, or several parts per block
    with a block ending inside the .out's second pass, the files are the in-memory path's."""
    from driver.sweep import _report
    _, ref = _run(tmp_path, "s", REVERSED, 0, monkeypatch)
    monkeypatch.setattr(_report, "STREAM_BLOCK_ROWS", block_rows)
    _, new = _run(tmp_path, "s", REVERSED, 50, monkeypatch)
    _same(ref, new, "s")


def test_streamed_tables_with_every_row(tmp_path, monkeypatch):
    """summary_rows = 'all': the tables hold every case, the .out the kept ones and a count."""
    text = SHIPPED.replace("count1 = 25", "count1 = 3").replace("summary_rows = 'kept'", "summary_rows = 'all'")
    _, ref = _run(tmp_path, "a", text, 0, monkeypatch)
    _, new = _run(tmp_path, "a", text, 1000, monkeypatch)
    _same(ref, new, "a")
    assert len(pd.read_parquet(new / "a_summary.parquet")) == 3 * 64 * 64
    assert "cases not kept are in the _summary table only" in (new / "a.out").read_text()


BAD_BASE = """&fourbar fixed_link = 12.0, crank = 3.0, coupler = 15.0, rocker = 9.0, omega = 5.0, step_deg = 10 /
&sweep
  {axes}
  keep = 'mu_min_deg >= 30'
  case_outputs = 'none', summary_rows = 'kept'
/
"""
START = "key{i} = 'fourbar.start_deg', values{i} = 0, 300, 10"
STOP = "key{j} = 'fourbar.stop_deg', values{j} = 200, 360, 350"
CRANK = "key{k} = 'fourbar.crank', start{k} = 1, stop{k} = 7, count{k} = 700"


def _bad_text(order: tuple[int, int, int]) -> str:
    i, j, k = order
    axes = "\n  ".join(sorted([START.format(i=i), STOP.format(j=j), CRANK.format(k=k)], key=lambda a: a[3]))
    return BAD_BASE.format(axes=axes)


def test_bad_interior_combination_is_refused_before_anything_runs(tmp_path, monkeypatch, capsys):
    """The 2 100-case grid's interior combination start_deg 300, stop_deg 200 is found by the
    sweep's validation of its coupled axes: exit 2 naming the line and key, nothing written."""
    status, out = _run(tmp_path, "b", _bad_text((1, 2, 3)), 10, monkeypatch)
    err = capsys.readouterr().err
    assert status == 2 and not out.exists()
    assert "b.dat:3: key 'values1'" in err and "start_deg = 300, fourbar.stop_deg = 200 is bad input" in err


@pytest.mark.parametrize("order, streamed", [((1, 2, 3), False), ((2, 3, 1), None)])
def test_bad_input_rows(tmp_path, monkeypatch, order, streamed):
    """Should a bad case pass the sweep's validation (here switched off), the batch path's own
    check gives bad-input rows.  Only in some chunks (their summary columns are objects, the
    others' floats): not streamed, the rows read into memory; spread over every chunk: streamed
    when the parts' columns agree (a column that is blank in a whole part does not).  The same
    files either way."""
    from driver.sweep import _plan
    monkeypatch.setattr(_plan, "validate_sweep", lambda *a, **k: {})
    text = _bad_text(order)
    calls = []
    real = stream.write_streamed
    monkeypatch.setattr(stream, "write_streamed", lambda *a, **k: calls.append(real(*a, **k)) or calls[-1])
    st_ref, ref = _run(tmp_path, "b", text, 0, monkeypatch)
    st_new, new = _run(tmp_path, "b", text, 10, monkeypatch)
    assert st_ref == st_new == 2
    assert len(calls) == 1 and (streamed is None or (calls[0] is not None) == streamed)
    _same(ref, new, "b")
    out = (new / "b.out").read_text()
    assert out.count("bad input") == 700
    assert "    failed                       700" in out


def test_run_stops_holding_rows_above_the_threshold(tmp_path, monkeypatch):
    from driver._deck import read_deck
    from driver._outcome import StreamedSummary
    from driver.sweep import run_sweep_deck
    from driver.sweep._plan import plan_sweep
    from driver.sweep._report import read_columns
    deck = tmp_path / "s.dat"
    deck.write_text(SHIPPED.replace("count1 = 25", "count1 = 4"))
    d = read_deck(deck)
    monkeypatch.setattr(executor, "STREAM_ROWS", 10)
    plan = plan_sweep(d, tmp_path / "rec", [], False)
    with executor.open_workers(1) as workers:
        streamed = executor.run_chunks(plan, workers).main
    assert streamed.rows is None and streamed.n_rows == streamed.counts["n_kept"] > 10
    paths = streamed.record.paths(with_rows=True)
    assert sum(len(pd.read_parquet(q)) for q in paths) == streamed.counts["n_kept"]
    held_plan = plan_sweep(d, tmp_path / "rec2", [], False, stream=False)
    with executor.open_workers(1) as workers:
        held = executor.run_chunks(held_plan, workers).main
    assert held.rows is not None and held.counts == streamed.counts
    pd.testing.assert_frame_equal(read_columns(paths), held.frame())
    # the outcome: a lazy summary over the parts, equal to the file it wrote
    oc = run_sweep_deck(d, tmp_path / "o", [], False, jobs=1)
    assert isinstance(oc.summary, StreamedSummary) and oc.text is None
    written = pd.read_parquet(tmp_path / "o" / "s_summary.parquet")
    assert oc.summary.num_rows == len(oc.summary) == len(written) == oc.n_kept
    pd.testing.assert_frame_equal(oc.summary.to_pandas(), written)
    assert oc.summary.to_pandas().attrs == written.attrs
    pd.testing.assert_frame_equal(oc.summary.to_pandas(["case", "mu_min_deg"]), written[["case", "mu_min_deg"]])
    pd.testing.assert_frame_equal(oc.kept.reset_index(drop=True),
                                  written[written["kept"]].reset_index(drop=True))
    assert oc.out == (tmp_path / "o" / "s.out").read_text()
    held_oc = run_sweep_deck(d, tmp_path / "h", [], False, jobs=1, stream=False)
    pd.testing.assert_frame_equal(held_oc.summary, written)
    assert held_oc.text == oc.out


def test_a_cell_wider_than_its_column_redoes_the_table(tmp_path, monkeypatch):
    """A crank speed of 2e9 rad/s does not fit fourbar.omega's 13 characters: the column widens
    for every row, found in the first pass and written in the second."""
    text = SHIPPED.replace("key1 = 'fourbar.crank',   start1 = 1.0,  stop1 = 7.0,  count1 = 25",
                           "key1 = 'fourbar.omega',   values1 = 5.0, 2.0e9\n"
                           "  key4 = 'fourbar.crank', start4 = 1.0, stop4 = 7.0, count4 = 5")
    _, ref = _run(tmp_path, "w", text, 0, monkeypatch)
    calls = []
    real = stream.write_streamed
    monkeypatch.setattr(stream, "write_streamed", lambda *a, **k: calls.append(real(*a, **k)) or calls[-1])
    _, new = _run(tmp_path, "w", text, 5, monkeypatch)
    assert calls and calls[0] is not None
    _same(ref, new, "w")
    assert "2000000000.0000" in (new / "w.out").read_text()
