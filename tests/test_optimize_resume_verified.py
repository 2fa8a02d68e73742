"""An ``&optimize`` resume record is verified, never believed (issue 23, section 2).

Every journal line and every row of a finished run's ``_evals`` table carries a checksum of its
content (driver/optimize/_journal.py).  Real tampering -- a digit changed, a file cut, a byte
damaged -- makes ``--resume`` compute those designs again and say how many and why; the files
it writes equal those of an uninterrupted run (the truth: a fresh run into another folder), and
the number of designs computed again is exactly the number of records that failed.
"""
from __future__ import annotations

import json

import pyarrow as pa
import pyarrow.parquet as pq
import pytest

import driver.optimize as opt
from driver._cli import main

DECK = """&fourbar fixed_link = 12, crank = 3, coupler = 15, rocker = 9, omega = 5, step_deg = 10 /
&optimize
  var1 = 'fourbar.coupler', lower1 = 10, upper1 = 20
  var2 = 'fourbar.rocker', lower2 = 6, upper2 = 12
  maximize = 'mu_min_deg'
  method = 'grid', grid_count = 5
/
"""
COMPARED = ("opt.out", "opt_history.csv", "opt.optimum.dat", "opt.optimum.out")
N_DESIGNS = 25


@pytest.fixture
def deck(tmp_path):
    path = tmp_path / "opt.dat"
    path.write_text(DECK)
    fresh = tmp_path / "fresh"
    assert main([str(path), "-o", str(fresh), "-q", "-j", "1"]) == 0
    return path, fresh


def _interrupted(path, out, monkeypatch) -> list[str]:
    """A run stopped after every design was computed but before its outputs were written: the
    journal is all that is left.  Its lines."""
    def stop(*_a, **_k):
        raise KeyboardInterrupt
    with monkeypatch.context() as m:
        m.setattr(opt, "_write", stop)
        with pytest.raises(KeyboardInterrupt):
            opt.optimize(path, out, jobs=1)
    journal = out / "opt.journal.jsonl"
    assert journal.is_file() and not (out / "opt.out").exists()
    return journal.read_text().splitlines(keepends=True)


def _resume(path, out, capsys) -> tuple[str, int]:
    capsys.readouterr()
    assert main([str(path), "-o", str(out), "-j", "1", "--resume"]) == 0
    cap = capsys.readouterr()
    computed = int(cap.out.split(" designs computed (")[0].rsplit(" ", 1)[1]) if " designs computed (" in cap.out else 0
    return cap.out + cap.err, computed


def _same(fresh, out):
    for name in COMPARED:
        assert (out / name).read_bytes() == (fresh / name).read_bytes(), name
    assert not (out / "opt.journal.jsonl").exists()


def test_an_intact_journal_replays_every_design(deck, tmp_path, monkeypatch, capsys):
    path, fresh = deck
    out = tmp_path / "out"
    lines = _interrupted(path, out, monkeypatch)
    assert len(lines) == N_DESIGNS
    said, computed = _resume(path, out, capsys)
    assert computed == 0 and "not replayed" not in said
    _same(fresh, out)


def _best_line(lines: list[str]) -> int:
    """The journal line of the best design (the one whose mu_min_deg a forger would raise)."""
    mus = [json.loads(s)["record"]["summary"]["mu_min_deg"] or -1 for s in lines]
    return max(range(len(lines)), key=lambda i: mus[i])


def test_a_changed_digit_in_a_journal_record_is_caught(deck, tmp_path, monkeypatch, capsys):
    path, fresh = deck
    out = tmp_path / "out"
    lines = _interrupted(path, out, monkeypatch)
    # make a poor design look best: its mu_min_deg's first digit raised (the JSON stays valid)
    worst = min(range(len(lines)), key=lambda i: json.loads(lines[i])["record"]["summary"]["mu_min_deg"] or 99)
    rec = json.loads(lines[worst])["record"]
    old = repr(rec["summary"]["mu_min_deg"])
    assert f'"mu_min_deg":{old}' in lines[worst]
    lines[worst] = lines[worst].replace(f'"mu_min_deg":{old}', f'"mu_min_deg":9{old}', 1)
    (out / "opt.journal.jsonl").write_text("".join(lines))
    said, computed = _resume(path, out, capsys)
    assert "1 evaluation record(s) not replayed" in said and "1 because a journal record failed its checksum" in said
    assert computed == 1
    _same(fresh, out)


def _flip_a_digit_bit(b: bytes) -> bytes:
    """One bit of one byte: the low bit of the first digit of the first record (a digit stays a
    digit, the line stays JSON: only the checksum can tell)."""
    i = b.index(b'"record":')
    while not chr(b[i]).isdigit():
        i += 1
    return b[:i] + bytes([b[i] ^ 0x01]) + b[i + 1:]


@pytest.mark.parametrize("damage, why", [
    (lambda b: b[: len(b) // 2], "a journal line is not complete"),          # cut in the middle of a line
    (_flip_a_digit_bit, "a journal record failed its checksum"),             # one bit of one byte
    (lambda b: b.replace(b"\n", b"\n\x00", 1), "a journal line is not complete"),   # a stray NUL byte
])
def test_a_damaged_journal_is_redone_and_said(deck, tmp_path, monkeypatch, capsys, damage, why):
    path, fresh = deck
    out = tmp_path / "out"
    lines = _interrupted(path, out, monkeypatch)
    journal = out / "opt.journal.jsonl"
    journal.write_bytes(damage(journal.read_bytes()))
    after = journal.read_bytes().split(b"\n")
    intact = sum(1 for s in after if s.decode(errors="replace") + "\n" in lines)
    said, computed = _resume(path, out, capsys)
    assert f"1 evaluation record(s) not replayed, their designs computed again (1 because {why}" in said, said
    assert computed == N_DESIGNS - intact          # the damaged record's design, and those cut off
    assert intact >= N_DESIGNS // 2 - 1
    _same(fresh, out)


def test_an_old_journal_without_checksums_is_not_believed(deck, tmp_path, monkeypatch, capsys):
    path, fresh = deck
    out = tmp_path / "out"
    lines = _interrupted(path, out, monkeypatch)
    plain = [json.dumps(json.loads(s)["record"]) + "\n" for s in lines]   # the former format
    (out / "opt.journal.jsonl").write_text("".join(plain))
    said, computed = _resume(path, out, capsys)
    assert f"{N_DESIGNS} because a journal line carries no checksummed record" in said
    assert computed == N_DESIGNS
    _same(fresh, out)


def _finished(path, out) -> None:
    assert main([str(path), "-o", str(out), "-q", "-j", "1"]) == 0


def test_a_finished_runs_table_replays_and_a_changed_row_is_caught(deck, tmp_path, capsys):
    path, fresh = deck
    out = tmp_path / "out"
    _finished(path, out)
    said, computed = _resume(path, out, capsys)
    assert computed == 0 and "not replayed" not in said
    table = out / "opt_evals.parquet"
    t = pq.read_table(table)
    col = t.schema.get_field_index("summary.mu_min_deg")
    vals = t.column(col).to_pylist()
    worst = min(range(len(vals)), key=lambda i: vals[i] if vals[i] is not None else 99)
    vals[worst] = vals[worst] + 40.0                     # a poor design made to look best
    pq.write_table(t.set_column(col, t.schema.field(col), pa.array(vals)), table)   # metadata kept
    assert pq.read_table(table).schema.metadata == t.schema.metadata
    said, computed = _resume(path, out, capsys)
    assert "1 because a row of opt_evals.parquet failed its checksum" in said
    assert computed == 1
    _same(fresh, out)


def test_a_cut_table_is_redone_and_said(deck, tmp_path, capsys):
    path, fresh = deck
    out = tmp_path / "out"
    _finished(path, out)
    table = out / "opt_evals.parquet"
    table.write_bytes(table.read_bytes()[: table.stat().st_size // 2])
    said, computed = _resume(path, out, capsys)
    assert "opt_evals.parquet cannot be read" in said
    assert computed == N_DESIGNS
    _same(fresh, out)


# ----------------------------------------------------------------------------- round three (issue 36)
# A resume record is bound to the whole problem and to the code: replayed only into the same one.

SWAP = """&fourbar fixed_link = 10, crank = 2, coupler = 9, rocker = 6, omega = 5, step_deg = 10 /
&optimize
  var1 = 'fourbar.rocker', lower1 = 2, upper1 = 8
  var2 = 'fourbar.crank', lower2 = 2, upper2 = 8
  maximize = 'mu_min_deg'
  constraint1 = 'grashof_class == "crank-rocker"'
  method = 'grid', grid_count = 4
/
"""
SWAPPED = SWAP.replace("var1 = 'fourbar.rocker'", "var1 = 'fourbar.CRANK'").replace(
    "var2 = 'fourbar.crank'", "var2 = 'fourbar.rocker'").replace("CRANK", "crank")


def _fresh(tmp_path, text: str):
    """The truth: an uninterrupted run of the deck (the same file as the resumed one's, written first)."""
    path = tmp_path / "opt.dat"
    path.write_text(text)
    fresh = tmp_path / "fresh"
    assert main([str(path), "-o", str(fresh), "-q", "-j", "1"]) == 0
    return fresh


def _interrupt(path, out, monkeypatch) -> None:
    def stop(*_a, **_k):
        raise KeyboardInterrupt
    with monkeypatch.context() as m:
        m.setattr(opt, "_write", stop)
        with pytest.raises(KeyboardInterrupt):
            opt.optimize(path, out, jobs=1)
    assert (out / "opt.journal.jsonl").is_file()


def _same_as(fresh, out):
    import pandas as pd
    for name in COMPARED:
        assert (out / name).read_bytes() == (fresh / name).read_bytes(), name
    # the evaluations table too, its columns in the same order as a fresh run's
    pd.testing.assert_frame_equal(pd.read_parquet(out / "opt_evals.parquet"),
                                  pd.read_parquet(fresh / "opt_evals.parquet"), check_exact=True)


def test_a_journal_of_swapped_variables_is_not_replayed(tmp_path, monkeypatch, capsys):
    """Issue 36 item 1: var1/var2 swapped after an interrupt; the old records were replayed in the
    wrong order (an optimum that cannot be assembled, CONVERGED, exit 0)."""
    fresh = _fresh(tmp_path, SWAPPED)
    path = tmp_path / "opt.dat"
    path.write_text(SWAP)
    out = tmp_path / "out"
    _interrupt(path, out, monkeypatch)
    path.write_text(SWAPPED)
    said, computed = _resume(path, out, capsys)
    assert "16 evaluation record(s) not replayed" in said and "written for another problem" in said, said
    assert computed == 16
    _same_as(fresh, out)


@pytest.mark.parametrize("change", [
    ("upper1 = 8", "upper1 = 8.5"),                                  # a bound
    ("maximize = 'mu_min_deg'", "minimize = 'mu_min_deg'"),          # the objective's sense
    ("constraint1 = 'grashof_class == \"crank-rocker\"'", "constraint1 = 'mu_min_deg > 1'"),
    ("method = 'grid', grid_count = 4", "method = 'grid', grid_count = 4, constraint_tol = 1e-3"),   # a setting
    ("coupler = 9", "coupler = 9.5"),                                # the study group
])
def test_a_journal_of_another_problem_is_not_replayed(tmp_path, monkeypatch, capsys, change):
    changed = SWAP.replace(*change)
    assert changed != SWAP
    fresh = _fresh(tmp_path, changed)
    path = tmp_path / "opt.dat"
    path.write_text(SWAP)
    out = tmp_path / "out"
    _interrupt(path, out, monkeypatch)
    path.write_text(changed)
    said, computed = _resume(path, out, capsys)
    assert "written for another problem" in said, said
    _same_as(fresh, out)


def test_jobs_do_not_change_the_problem(tmp_path, monkeypatch, capsys):
    path = tmp_path / "opt.dat"
    path.write_text(SWAP)
    out = tmp_path / "out"
    _interrupt(path, out, monkeypatch)
    path.write_text(SWAP.replace("grid_count = 4", "grid_count = 4, jobs = 2"))
    said, computed = _resume(path, out, capsys)
    assert computed == 0 and "not replayed" not in said


def test_a_journal_of_other_code_is_not_replayed(tmp_path, monkeypatch, capsys):
    fresh = _fresh(tmp_path, SWAP)
    path = tmp_path / "opt.dat"
    path.write_text(SWAP)
    out = tmp_path / "out"
    _interrupt(path, out, monkeypatch)
    from driver.optimize._problem import Problem
    monkeypatch.setattr(Problem, "code_digest", lambda self: "0" * 16)   # as if the tool had changed since
    said, computed = _resume(path, out, capsys)
    assert "16 because it was computed by other code" in said, said
    assert computed == 16
    monkeypatch.undo()
    _same_as(fresh, out)


def _forge(lines: list[str], i: int, change) -> list[str]:
    """Line i's record changed by ``change`` and checksummed again (anyone can: sha256 has no key)."""
    from driver.optimize import _journal
    rec = json.loads(lines[i])["record"]
    change(rec)
    return lines[:i] + [_journal.line(rec)] + lines[i + 1:]


@pytest.mark.parametrize("change, why", [
    (lambda r: r.update(summary="mu_min_deg"), "its summary is not a table"),       # was: run failed: AttributeError
    (lambda r: r.update(summary={"mu_min_deg": [1, 2]}), "its summary is not a table"),
    (lambda r: r.update(x=[1.0]), "its design is not 2 finite number(s)"),
    (lambda r: r.update(x=[None, 3.0]), "its design is not 2 finite number(s)"),
    (lambda r: r.update(status="excellent"), "its status is not one of"),
    (lambda r: r.pop("code"), "its fields are not those of a record"),
])
def test_a_checksummed_record_of_the_wrong_shape_is_redone(deck, tmp_path, monkeypatch, capsys, change, why):
    path, fresh = deck
    out = tmp_path / "out"
    lines = _interrupted(path, out, monkeypatch)
    (out / "opt.journal.jsonl").write_text("".join(_forge(lines, 3, change)))
    said, computed = _resume(path, out, capsys)
    assert "1 because a journal record is not of the shape this tool writes" in said and why in said, said
    assert computed == 1
    _same(fresh, out)


def test_a_forged_record_that_wins_fails_the_run(deck, tmp_path, monkeypatch, capsys):
    """A record with a valid checksum but a forged figure is replayed (its shape is right): the
    optimum's re-run by the full study then DIFFERS from its evaluation, which is a failure
    (exit 1, stated), never a success (it printed DIFFERS and exited 0)."""
    path, _ = deck
    out = tmp_path / "out"
    lines = _interrupted(path, out, monkeypatch)
    worst = min(range(len(lines)), key=lambda i: json.loads(lines[i])["record"]["summary"]["mu_min_deg"] or 99)
    (out / "opt.journal.jsonl").write_text(
        "".join(_forge(lines, worst, lambda r: r["summary"].update(mu_min_deg=89.0))))
    capsys.readouterr()
    assert main([str(path), "-o", str(out), "-j", "1", "--resume"]) == 1
    err = capsys.readouterr().err
    assert "DIFFERS from its evaluation" in err and "no optimum is claimed" in err, err
    assert "DIFFERS from the evaluation" in (out / "opt.out").read_text()


def test_a_resumed_runs_evaluations_table_equals_a_fresh_ones(deck, tmp_path, monkeypatch, capsys):
    """Its columns came in another order (the journal's summaries have sorted keys)."""
    path, fresh = deck
    out = tmp_path / "out"
    lines = _interrupted(path, out, monkeypatch)
    (out / "opt.journal.jsonl").write_text("".join(lines[: len(lines) // 2]))
    _resume(path, out, capsys)
    _same_as(fresh, out)
