"""A resume record is verified, never believed (issue 23, section 2).

Every record part's name carries the sha256 of its bytes and every case file's digest is in
its record row; ``--resume`` re-runs whatever fails, says how many cases and why, and the
tables equal those of an uninterrupted run (the truth: a fresh run into another folder).
"""
from __future__ import annotations

import json

import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from driver._cli import main

DECK = """&fourbar
  fixed_link = 12.0, crank = 2.0, coupler = 15.0, rocker = 9.0
  omega = 5.0, step_deg = 20, method = 'listing'
/
&sweep
  key1 = 'fourbar.crank', values1 = 2, 3, 4, 5
/
"""
TABLES = ("sw.out", "sw_summary.csv", "sw_cases.csv")


@pytest.fixture
def runs(tmp_path):
    deck = tmp_path / "sw.dat"
    deck.write_text(DECK)
    fresh, out = tmp_path / "fresh", tmp_path / "out"
    assert main([str(deck), "-o", str(fresh), "-q", "-j", "1"]) == 0
    assert main([str(deck), "-o", str(out), "-q", "-j", "1"]) == 0
    return deck, fresh, out


def _resume(deck, out, capsys) -> str:
    capsys.readouterr()
    assert main([str(deck), "-o", str(out), "-j", "1", "--resume"]) == 0
    cap = capsys.readouterr()
    return cap.out + cap.err


def _same(fresh, out):
    for name in TABLES:
        assert (out / name).read_bytes() == (fresh / name).read_bytes(), name
    for f in sorted((fresh / "sw").iterdir()):
        assert (out / "sw" / f.name).read_bytes() == f.read_bytes(), f.name


def test_intact_record_resumes_everything(runs, capsys):
    deck, fresh, out = runs
    said = _resume(deck, out, capsys)
    assert "resume: 4 of 4 cases complete, 0 to run" in said and "redone" not in said
    _same(fresh, out)


def test_a_changed_digit_in_a_record_part_is_caught(runs, capsys):
    deck, fresh, out = runs
    part = next((out / "sw.sweep").glob("part-*.parquet"))
    t = pq.read_table(part)
    rec = t.column("record").to_pylist()
    summary = json.loads(rec[0])
    assert "48.5" in rec[0] or summary["summary"]["mu_min_deg"]   # the published crank-2 figure
    rec[0] = rec[0].replace(str(summary["summary"]["mu_min_deg"])[:2], "18", 1)
    t = t.set_column(t.schema.get_field_index("record"), "record", pa.array(rec))
    pq.write_table(t, part)                            # same name, same metadata, one digit changed
    said = _resume(deck, out, capsys)
    assert "failed its checksum" in said and "redone" in said
    _same(fresh, out)


@pytest.mark.parametrize("suffix,damage", [
    (".json", lambda b: b[:10] + bytes([b[10] ^ 0x20]) + b[11:]),   # one byte
    (".parquet", lambda b: b[: len(b) // 2]),                        # cut in half
    (".out", lambda b: b.replace(b"5", b"6", 1)),                    # one digit of the table
])
def test_a_damaged_case_file_is_redone(runs, capsys, suffix, damage):
    deck, fresh, out = runs
    f = out / "sw" / f"case_0002{suffix}"
    f.write_bytes(damage(f.read_bytes()))
    said = _resume(deck, out, capsys)
    assert "1 cases redone" in said and f"case_0002{suffix} failed its checksum" in said
    assert "resume: 3 of 4 cases complete, 1 to run" in said
    _same(fresh, out)


def test_a_deleted_case_file_is_redone_and_said(runs, capsys):
    deck, fresh, out = runs
    (out / "sw" / "case_0003.out").unlink()
    said = _resume(deck, out, capsys)
    assert "case_0003.out is missing" in said
    _same(fresh, out)


def test_damaged_batch_part_is_redone(tmp_path, capsys):
    deck = tmp_path / "b.dat"
    deck.write_text(DECK.replace("method = 'listing'", "").replace("values1 = 2, 3, 4, 5",
                                                                      "start1 = 2, stop1 = 5, count1 = 400")
                    + "")
    deck.write_text(deck.read_text().replace("/\n&sweep", "/\n&sweep\n  case_outputs = 'none', chunk = 100"))
    fresh, out = tmp_path / "fresh", tmp_path / "out"
    assert main([str(deck), "-o", str(fresh), "-q", "-j", "1"]) == 0
    assert main([str(deck), "-o", str(out), "-q", "-j", "1"]) == 0
    parts = sorted((out / "b.sweep").glob("part-*.parquet"))
    assert len(parts) == 4, "the batch path writes one part per chunk"
    t = pq.read_table(parts[1])
    col = t.schema.get_field_index("mu_min_deg")
    vals = [v + 30.0 for v in t.column(col).to_pylist()]
    pq.write_table(t.set_column(col, "mu_min_deg", pa.array(vals)), parts[1])
    capsys.readouterr()
    assert main([str(deck), "-o", str(out), "-q", "-j", "1", "--resume"]) == 0
    assert "100 cases redone" in capsys.readouterr().err
    for name in ("b.out", "b_summary.csv"):
        assert (out / name).read_bytes() == (fresh / name).read_bytes(), name


BIG = DECK.replace("values1 = 2, 3, 4, 5", "start1 = 2, stop1 = 5, count1 = 200\n  key2 = 'fourbar.rocker', values2 = 8, 9")


@pytest.mark.parametrize("outputs, per_part", [("none", 64), ("all", 4)])
def test_a_part_cut_in_half_is_redone_counted_and_said(tmp_path, capsys, outputs, per_part):
    """A record part cut in half (a crash while copying the folder, a full disk) cannot even
    be read: its chunk runs again, and the warning counts its cases with the reason, for both
    kinds of record (batch: 400 cases in parts of 64; per case: 100 parts of 4).  The
    tables equal a fresh run's."""
    deck = tmp_path / "c.dat"
    deck.write_text(BIG.replace("&sweep\n", f"&sweep\n  case_outputs = '{outputs}'\n"))
    fresh, out = tmp_path / "fresh", tmp_path / "out"
    assert main([str(deck), "-o", str(fresh), "-q", "-j", "1"]) == 0
    assert main([str(deck), "-o", str(out), "-q", "-j", "1"]) == 0
    parts = sorted((out / "c.sweep").glob("part-*.parquet"))
    assert len(parts) == -(-400 // per_part)
    cut = parts[3]   # the chunk of cases 3 * per_part + 1 ...
    cut.write_bytes(cut.read_bytes()[: cut.stat().st_size // 2])
    with pytest.raises(pa.ArrowInvalid):
        pq.read_schema(cut)   # unreadable: only its name tells which chunk it was
    capsys.readouterr()
    assert main([str(deck), "-o", str(out), "-j", "1", "--resume"]) == 0
    said = capsys.readouterr()
    assert f"resume: {400 - per_part} of 400 cases complete, {per_part} to run" in said.out
    assert (f"resume: {per_part} cases redone ({per_part} because a record part was cut short or cannot be read)"
            in said.err), said.err
    for name in ("c.out", "c_summary.csv"):
        assert (out / name).read_bytes() == (fresh / name).read_bytes(), name
    assert len(list((out / "c.sweep").glob("part-*.parquet"))) == -(-400 // per_part)
