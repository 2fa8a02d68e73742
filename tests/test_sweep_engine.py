"""The sweep engine (driver/sweep/: plan, executor, chunks, record): the batch path gives the same
tables as case by case, on one process, two workers and Dask; exact resume after SIGKILL; a
dying worker costs its one crashing case only, for both kinds of chunk; chunk sizes depend on
the number of cases only; workers never outlive the driver; bad values found without
validating every case; the one Ctrl-C rule of the pool and of Dask."""
from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from driver._cli import main
from driver.sweep import _chunks as chunks
from driver.sweep import _executor as executor
from driver.sweep import _plan as plan_mod
from driver.sweep._chunks import Span
from driver.sweep._spec import Grid

BASE = """&fourbar
  fixed_link = 12.0, crank = 3.0, coupler = 15.0, rocker = 9.0, omega = 5.0, step_deg = 10
/
"""
GRID = ("&sweep key1 = 'fourbar.crank', start1 = 1, stop1 = 7, count1 = {a}\n"
        "       key2 = 'fourbar.coupler', start2 = 6, stop2 = 20, count2 = {b}\n"
        "       key3 = 'fourbar.rocker', start3 = 4, stop3 = 16, count3 = {c}\n"
        "       keep = 'meets_transmission_band and rocker_swing_deg >= 40'\n"
        "       case_outputs = '{outputs}', summary_rows = '{rows}'{extra} /\n")


def deck(tmp_path: Path, a=4, b=5, c=6, outputs="none", rows="all", extra="", name="sw.dat") -> Path:
    path = tmp_path / name
    path.write_text(BASE + GRID.format(a=a, b=b, c=c, outputs=outputs, rows=rows, extra=extra))
    return path


def summary(out: Path, stem: str = "sw") -> pd.DataFrame:
    return pd.read_parquet(out / f"{stem}_summary.parquet")


def test_batch_path_equals_case_by_case(tmp_path):
    """The batch path (case_outputs = 'none') and the per-case path ('all') give the same rows."""
    batch, single = tmp_path / "b", tmp_path / "s"
    assert main([str(deck(tmp_path)), "-o", str(batch), "-q", "-j", "1"]) == 0
    assert (batch / "sw.sweep").is_dir() and not (batch / "sw").exists()
    assert main([str(deck(tmp_path, outputs="all")), "-o", str(single), "-q", "-j", "1"]) == 0
    a, b = summary(batch), summary(single)
    assert len(a) == 120 and a["kept"].sum() > 0
    pd.testing.assert_frame_equal(a, b, check_dtype=False)
    # the .out tables agree except for the case-output line
    ta = (batch / "sw.out").read_text().replace("case outputs                 none", "")
    tb = (single / "sw.out").read_text().replace("case outputs                 all", "")
    assert ta == tb


def test_one_process_two_workers_and_dask_agree(tmp_path):
    path = deck(tmp_path, 5, 6, 7, rows="kept", extra=", chunk = 37")
    one, two = tmp_path / "one", tmp_path / "two"
    assert main([str(path), "-o", str(one), "-q", "-j", "1"]) == 0
    assert main([str(path), "-o", str(two), "-q", "-j", "2"]) == 0
    pd.testing.assert_frame_equal(summary(one), summary(two))
    assert (one / "sw.out").read_text() == (two / "sw.out").read_text()
    distributed = pytest.importorskip("distributed")
    import dask
    with dask.config.set({"distributed.comm.timeouts.connect": "120s", "distributed.comm.timeouts.tcp": "120s"}), \
            distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                     dashboard_address=None) as cluster:
        dsk = tmp_path / "dask"
        assert main([str(path), "-o", str(dsk), "-q", "--scheduler", cluster.scheduler_address]) == 0
    pd.testing.assert_frame_equal(summary(one), summary(dsk))


def test_bad_values_refuse_the_sweep_before_anything_runs(tmp_path, capsys):
    path = tmp_path / "bad.dat"
    path.write_text(BASE + "&sweep key1 = 'fourbar.crank', values1 = 2, -1, 5\n"
                           "       key2 = 'fourbar.start_deg', values2 = 0, 400\n"
                           "       case_outputs = 'none' /\n")
    out = tmp_path / "o"
    assert main([str(path), "-o", str(out), "-q", "-j", "1"]) == 2
    assert "is bad input" in capsys.readouterr().err
    assert not out.exists()


def test_interior_bad_combination_of_a_large_grid_is_a_failed_case(tmp_path):
    """Above FULL_VALIDATION cases only each value and the grid's corners are validated up
    front; a bad combination inside the grid is found per chunk and reported as bad input."""
    from driver import fourbar, sweep
    from driver._deck import read_deck, validate
    from driver.sweep._spec import swept_axes
    path = tmp_path / "inner.dat"
    path.write_text(BASE + "&sweep key1 = 'fourbar.start_deg', values1 = 0, 300, 0\n"
                           "       key2 = 'fourbar.stop_deg', values2 = 360, 200, 360\n"
                           "       key3 = 'fourbar.crank', start3 = 1, stop3 = 3, count3 = 700\n"
                           "       case_outputs = 'none' /\n")
    d = read_deck(path)
    sw = validate(d.groups["sweep"], sweep.SPEC, d.path)
    axes = swept_axes(sw, "fourbar", fourbar.SPEC)
    grid = Grid([a[0] for a in axes], [a[1] for a in axes], False)
    p = plan_mod.batch_plan(fourbar.STUDY, d.groups["fourbar"], str(path), grid, "", "all")
    res = chunks.batch_rows(p, Span(0, grid.n, range(1, grid.n + 1)))
    f = res.rows
    bad = (f["fourbar.start_deg"] == 300) & (f["fourbar.stop_deg"] == 200)
    assert res.n_failed == bad.sum() == 700
    assert (f.loc[bad, "status"] == "bad input").all() and f.loc[bad, "error"].str.contains("key 'step_deg'").all()
    assert f.loc[~bad, "mu_min_deg"].notna().all()


def _kill_after_parts(cmd: list[str], folder: Path, parts: int, timeout: float = 120.0) -> None:
    proc = subprocess.Popen(cmd, start_new_session=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.time() + timeout
    while time.time() < deadline and proc.poll() is None:
        if folder.exists() and len(list(folder.glob("part-*.parquet"))) >= parts:
            break
        time.sleep(0.02)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()


def test_resume_after_sigkill_is_exact(tmp_path):
    path = deck(tmp_path, 10, 20, 30, rows="kept", extra=", chunk = 100")   # 6000 cases, 60 chunks
    ref = tmp_path / "ref"
    assert main([str(path), "-o", str(ref), "-q", "-j", "2"]) == 0
    out = tmp_path / "o"
    cmd = [sys.executable, "-m", "driver", str(path), "-o", str(out), "-q", "-j", "2"]
    _kill_after_parts(cmd, out / "sw.sweep", 5)
    done = len(list((out / "sw.sweep").glob("part-*.parquet")))
    assert not (out / "sw.out").exists() or done == 60
    res = subprocess.run(cmd[:-3] + ["-j", "2", "--resume"], capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr
    assert "resume:" in res.stdout and " of 6000 cases complete" in res.stdout
    pd.testing.assert_frame_equal(summary(ref), summary(out))
    assert (ref / "sw.out").read_text() == (out / "sw.out").read_text()
    assert not [p for p in (out / "sw.sweep").iterdir() if p.name.endswith(".tmp")]
    # a changed base deck invalidates every part: nothing is resumed
    path.write_text(path.read_text().replace("omega = 5.0", "omega = 4.0"))
    res = subprocess.run(cmd + ["--resume"], capture_output=True, text=True, timeout=300)
    assert res.returncode == 0
    assert len(list((out / "sw.sweep").glob("part-*.parquet"))) == 60


def test_resume_skips_complete_chunks(tmp_path, capsys):
    path = deck(tmp_path, extra=", chunk = 10")   # 120 cases, 12 chunks
    out = tmp_path / "o"
    assert main([str(path), "-o", str(out), "-q", "-j", "1"]) == 0
    first = summary(out)
    parts = sorted((out / "sw.sweep").glob("part-*.parquet"))
    parts[3].unlink()
    (out / "sw.sweep" / ".part-x.parquet.abc.tmp").write_text("partial")
    assert main([str(path), "-o", str(out), "-j", "1", "--resume"]) == 0
    assert "resume: 110 of 120 cases complete, 10 to run" in capsys.readouterr().out
    pd.testing.assert_frame_equal(first, summary(out))
    assert not list((out / "sw.sweep").glob("*.tmp"))


def _dies(p, span, _real=chunks.batch_rows):
    """A batch chunk function whose worker is SIGKILLed whenever its cases include case 35
    (always, or once when DIE_ONCE names a marker file)."""
    marker = os.environ.get("DIE_ONCE")
    if 35 in span.cases and (not marker or not os.path.exists(marker)):
        if marker:
            Path(marker).write_text("died")
        os.kill(os.getpid(), signal.SIGKILL)
    return _real(p, span)


@pytest.mark.parametrize("once", [True, False])
def test_dying_worker_costs_at_most_its_case(tmp_path, monkeypatch, capsys, once):
    """A batch chunk (cases 31-40) whose worker dies: retried once alone; when that dies too,
    bisected down to the one case that kills its worker (35): only that case is failed."""
    path = deck(tmp_path, extra=", chunk = 10")
    ref = tmp_path / "ref"
    assert main([str(path), "-o", str(ref), "-q", "-j", "1"]) == 0
    if once:
        monkeypatch.setenv("DIE_ONCE", str(tmp_path / "marker"))
    monkeypatch.setitem(chunks.CHUNK_FUNCTIONS, "batch", _dies)   # inherited by the forked workers
    out = tmp_path / "o"
    rc = main([str(path), "-o", str(out), "-q", "-j", "2"])
    s, r = summary(out), summary(ref)
    if once:   # retried once, alone: identical results
        assert rc == 0
        pd.testing.assert_frame_equal(s, r)
    else:      # reported as one failed case with the reason; every other case completes
        assert rc == 1
        bad = s["status"] != "ok"
        assert list(s.loc[bad, "case"]) == [35]
        assert s.loc[bad, "error"].str.contains("worker process died").all()
        pd.testing.assert_frame_equal(s[~bad].reset_index(drop=True), r[~bad].reset_index(drop=True), check_dtype=False)
        assert "case 35 (" in capsys.readouterr().err
        # the chunk's part was assembled by the driver: --resume takes it as it is
        assert main([str(path), "-o", str(out), "-q", "-j", "1", "--resume"]) == 1
        pd.testing.assert_frame_equal(summary(out), s)


def _raises_on(case: int):
    def rows(p, span, _real=chunks.batch_rows):
        if case in span.cases:
            os._exit(3)   # a crash in a kernel: the process is gone, no exception travels
        return _real(p, span)
    return rows


def test_a_crash_in_a_batch_chunk_of_the_default_size_is_bisected_to_its_case(tmp_path, monkeypatch, capsys):
    """The default layout (chunks of 64 cases, a function of the case count): case 77 ends its
    worker with os._exit, so the chunk of cases 65-120 is retried alone, then bisected down to
    case 77 (6 rounds); only case 77 is reported failed, the 55 others of its chunk complete."""
    path = deck(tmp_path)
    ref = tmp_path / "ref"
    assert main([str(path), "-o", str(ref), "-q", "-j", "1"]) == 0
    monkeypatch.setattr(executor, "POOL_MIN_SECONDS", 0.0)   # the pool even for this small sweep
    monkeypatch.setitem(chunks.CHUNK_FUNCTIONS, "batch", _raises_on(77))
    out = tmp_path / "o"
    assert main([str(path), "-o", str(out), "-q", "-j", "2"]) == 1
    s, r = summary(out), summary(ref)
    assert plan_mod.chunk_size(120, "batch") == 64 and s["case"].tolist() == list(range(1, 121))
    bad = s["status"] != "ok"
    assert s.loc[bad, "case"].tolist() == [77] and "worker process died" in s.loc[bad, "error"].iloc[0]
    pd.testing.assert_frame_equal(s[~bad].reset_index(drop=True), r[~bad].reset_index(drop=True), check_dtype=False)
    err = capsys.readouterr().err
    assert "case 77 (" in err and "case 76 (" not in err and "case 78 (" not in err


def test_workers_exit_when_the_driver_is_killed(tmp_path):
    psutil = pytest.importorskip("psutil")
    path = deck(tmp_path, 40, 50, 60, extra=", chunk = 500")   # 120 000 cases
    out = tmp_path / "o"
    _kill_driver_and_check_workers(psutil, path, out)


def test_grid_columns_follow_product_order():
    import itertools
    g = Grid(["a.x", "a.y", "a.z"], [[1.0, 2.0], [3.0, 4.0, 5.0], ["u", "v"]], False)
    combos = list(itertools.product(*g.values))
    cols = g.columns(0, g.n)
    assert g.n == 12 and list(zip(*cols.values())) == combos
    part = g.columns(5, 9)
    assert list(zip(*part.values())) == combos[5:9]
    assert list(zip(*g.columns_at(np.array([11, 0, 5])).values())) == [combos[11], combos[0], combos[5]]
    z = Grid(["a.x", "a.y"], [[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]], True)
    assert list(zip(*z.columns(1, 3).values())) == [(2.0, 5.0), (3.0, 6.0)]
    assert np.asarray(z.columns(0, 3)["a.x"]).dtype == np.float64


def test_a_warning_every_case_repeats_is_printed_once(tmp_path, capsys):
    path = tmp_path / "warn.dat"
    path.write_text("&fourbar fixed_link = 8.0, crank = 6.0, coupler = 2.0, rocker = 7.0, step_deg = 5.0 /\n"
                    "&sweep key1 = 'fourbar.omega', values1 = 1, 2, 3, 4\n"
                    "       key2 = 'fourbar.crank', values2 = 6, 6.5 /\n")
    assert main([str(path), "-o", str(tmp_path / "o"), "-q", "-j", "1"]) == 0
    err = [l for l in capsys.readouterr().err.splitlines() if l.startswith("warning:")]
    assert len(err) == 1 and "all 8 cases: the linkage cannot be assembled" in err[0], err


# ----------------------------------------------------------------------------- the per-case engine

PER_CASE = ("&sweep key1 = 'fourbar.crank', start1 = 1.5, stop1 = 5, count1 = {a}\n"
            "       key2 = 'fourbar.rocker', values2 = {rockers}\n"
            "       key3 = 'fourbar.method', values3 = 'exact'{extra} /\n")


def per_case_deck(tmp_path: Path, a=6, rockers="8, 9, 10", extra="", name="pc.dat") -> Path:
    path = tmp_path / name
    path.write_text(BASE + PER_CASE.format(a=a, rockers=rockers, extra=extra))
    return path


def tree(folder: Path) -> dict[str, bytes]:
    """Every file under ``folder`` (relative name -> bytes)."""
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def same_outputs(a: Path, b: Path, stem: str = "pc") -> None:
    pd.testing.assert_frame_equal(summary(a, stem), summary(b, stem))
    assert (a / f"{stem}.out").read_text() == (b / f"{stem}.out").read_text()
    assert (a / f"{stem}_cases.csv").read_bytes() == (b / f"{stem}_cases.csv").read_bytes()
    ta, tb = tree(a / stem), tree(b / stem)
    assert sorted(ta) == sorted(tb)
    assert [k for k in ta if ta[k] != tb[k]] == []


def test_per_case_resume_after_sigkill_is_exact(tmp_path):
    """SIGKILL of the driver in the middle of a per-case sweep (case_outputs = 'all'), then
    --resume: the summary, the .out and every case file equal an uninterrupted run, no
    temporary file is left, and only the missing cases run again."""
    path = per_case_deck(tmp_path, a=10, extra=", chunk = 2")   # 30 cases, 15 chunks
    ref = tmp_path / "ref"
    assert main([str(path), "-o", str(ref), "-q", "-j", "2"]) == 0
    out = tmp_path / "o"
    cmd = [sys.executable, "-m", "driver", str(path), "-o", str(out), "-j", "2"]
    _kill_after_parts(cmd, out / "pc.sweep", 4)
    assert not (out / "pc.out").exists()
    res = subprocess.run(cmd + ["--resume"], capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr
    line = next(l for l in res.stdout.splitlines() if l.startswith("resume:"))
    complete = int(line.split()[1])
    assert 8 <= complete < 30, line
    same_outputs(ref, out)
    assert not [p for p in out.rglob("*") if p.name.endswith(".tmp")]


def test_deleted_out_file_reruns_its_case(tmp_path, capsys):
    path = per_case_deck(tmp_path, a=3)
    out = tmp_path / "o"
    assert main([str(path), "-o", str(out), "-q", "-j", "1"]) == 0
    first = tree(out / "pc")
    (out / "pc" / "case_0005.out").unlink()          # the .json marker stays: not trusted alone
    capsys.readouterr()
    assert main([str(path), "-o", str(out), "-j", "1", "--resume"]) == 0
    assert "resume: 8 of 9 cases complete, 1 to run" in capsys.readouterr().out
    assert tree(out / "pc") == first


def test_shrunken_grid_removes_the_old_cases_files(tmp_path):
    path = per_case_deck(tmp_path, a=4)                       # 12 cases
    out = tmp_path / "o"
    assert main([str(path), "-o", str(out), "-q", "-j", "1"]) == 0
    (out / "pc" / "notes.txt").write_text("mine")            # not a case file: left alone
    path = per_case_deck(tmp_path, a=2)                       # 6 cases
    assert main([str(path), "-o", str(out), "-q", "-j", "1", "--resume"]) == 0
    names = sorted(p.name for p in (out / "pc").iterdir())
    assert {n.split(".")[0] for n in names if n.startswith("case_")} == {f"case_{k:04d}" for k in range(1, 7)}
    assert "notes.txt" in names
    assert len(summary(out, "pc")) == 6
    # no case files at all any more: the folder keeps only what is not the sweep's
    path = per_case_deck(tmp_path, a=2, extra=", case_outputs = 'none'")
    assert main([str(path), "-o", str(out), "-q", "-j", "1"]) == 0
    assert sorted(p.name for p in (out / "pc").iterdir()) == ["notes.txt"]


def test_a_grown_grid_resumes_its_unchanged_cases_across_a_new_chunk_layout(tmp_path, capsys):
    """Per case, the record's rows count case by case: 129 cases (chunks of 2) grown to 258
    (chunks of 3) by appending crank values keeps cases 1-129's numbers and values, so only
    the 129 new ones run; the record then holds the new layout's parts only, and the tables
    equal a fresh run of the larger grid."""
    def grown(k: int, name: str) -> Path:
        cranks = ", ".join(f"{1.5 + 0.05 * i:.2f}" for i in range(k))
        path = tmp_path / name
        path.write_text(BASE + f"&sweep key1 = 'fourbar.crank', values1 = {cranks}\n"
                               "       key2 = 'fourbar.rocker', values2 = 8, 9, 10\n"
                               "       key3 = 'fourbar.method', values3 = 'exact'\n"
                               "       case_outputs = 'all' /\n")
        return path
    out, fresh = tmp_path / "o", tmp_path / "fresh"
    assert main([str(grown(43, "g.dat")), "-o", str(out), "-q", "-j", "1"]) == 0
    assert _record_spans(out, "g") == [(s, min(s + 2, 129)) for s in range(0, 129, 2)]
    assert main([str(grown(86, "g.dat")), "-o", str(fresh), "-q", "-j", "1"]) == 0
    capsys.readouterr()
    assert main([str(grown(86, "g.dat")), "-o", str(out), "-j", "2", "--resume"]) == 0
    said = capsys.readouterr()
    assert "resume: 129 of 258 cases complete, 129 to run" in said.out and "redone" not in said.err
    assert _record_spans(out, "g") == [(s, min(s + 3, 258)) for s in range(0, 258, 3)]
    pd.testing.assert_frame_equal(summary(out, "g"), summary(fresh, "g"))
    assert (out / "g.out").read_text() == (fresh / "g.out").read_text()


def test_large_sweeps_shard_their_case_files(tmp_path, monkeypatch):
    from driver.sweep import _resume as store
    path = per_case_deck(tmp_path, a=3)                       # 9 cases
    flat = tmp_path / "flat"
    assert main([str(path), "-o", str(flat), "-q", "-j", "1"]) == 0
    monkeypatch.setattr(store, "FLAT_MAX", 4)
    monkeypatch.setattr(store, "SHARD", 4)
    out = tmp_path / "o"
    assert main([str(path), "-o", str(out), "-q", "-j", "1"]) == 0
    assert sorted(p.name for p in (out / "pc").iterdir()) == ["0001-0004", "0005-0008", "0009-0012"]
    assert (out / "pc" / "0009-0012" / "case_0009.out").read_bytes() == (flat / "pc" / "case_0009.out").read_bytes()
    pd.testing.assert_frame_equal(summary(flat, "pc"), summary(out, "pc"))
    assert (flat / "pc_cases.csv").read_bytes() == (out / "pc_cases.csv").read_bytes()
    # back to the flat layout: the shards go
    monkeypatch.setattr(store, "FLAT_MAX", 1000)
    assert main([str(path), "-o", str(out), "-q", "-j", "1", "--resume"]) == 0
    assert sorted(p.name for p in (out / "pc").iterdir()) == sorted(p.name for p in (flat / "pc").iterdir())


def _die_on_case(task, case, module, _real=chunks.compute_case):
    """A case computation whose worker is SIGKILLed on case 7 (always, or once with DIE_ONCE)."""
    marker = os.environ.get("DIE_ONCE")
    if case.index == 7 and (not marker or not os.path.exists(marker)):
        if marker:
            Path(marker).write_text("died")
        os.kill(os.getpid(), signal.SIGKILL)
    return _real(task, case, module)


@pytest.mark.parametrize("once", [True, False])
def test_per_case_dying_worker_is_retried_then_isolated(tmp_path, monkeypatch, capsys, once):
    path = per_case_deck(tmp_path, a=4, extra=", chunk = 4")   # 12 cases; case 7 in chunk 5-8
    ref = tmp_path / "ref"
    assert main([str(path), "-o", str(ref), "-q", "-j", "1"]) == 0
    if once:
        monkeypatch.setenv("DIE_ONCE", str(tmp_path / "marker"))
    monkeypatch.setattr(chunks, "compute_case", _die_on_case)   # inherited by the forked workers
    out = tmp_path / "o"
    rc = main([str(path), "-o", str(out), "-q", "-j", "2"])
    s, r = summary(out, "pc"), summary(ref, "pc")
    if once:   # retried once, alone: identical results
        assert rc == 0
        same_outputs(ref, out)
    else:      # the chunk is split down to the case that kills its worker; that case alone fails
        assert rc == 1
        bad = s["status"] != "ok"
        assert list(s.loc[bad, "case"]) == [7]
        assert s.loc[bad, "error"].str.contains("worker process died").all()
        keep = [c for c in s.columns if c in r.columns]
        pd.testing.assert_frame_equal(s.loc[~bad, keep].reset_index(drop=True),
                                      r.loc[~bad, keep].reset_index(drop=True), check_dtype=False)
        assert "case 7 (" in capsys.readouterr().err
        assert not (out / "pc" / "case_0007.out").exists() and (out / "pc" / "case_0008.out").exists()


def _record_spans(out: Path, stem: str) -> list[tuple[int, int]]:
    import json

    import pyarrow.parquet as pq
    metas = [json.loads(pq.read_schema(p).metadata[b"sweep"]) for p in (out / f"{stem}.sweep").glob("part-*.parquet")]
    return sorted((m["start"], m["stop"]) for m in metas)


@pytest.mark.parametrize("kind", ["batch", "cases"])
def test_chunk_sizes_depend_on_the_case_count_only(tmp_path, kind):
    """The chunks are the resume record's parts: one layout for a given number of cases, on one
    process, two workers and a Dask cluster, for both kinds of chunk; the rule in code
    (driver.sweep._plan.chunk_size) is the one the sweep used."""
    from driver import sweep
    from driver._deck import read_deck
    path = deck(tmp_path, 4, 5, 6) if kind == "batch" else per_case_deck(tmp_path, a=50)   # 120 / 150 cases
    stem = path.stem
    d = read_deck(path)
    outs = {}
    for label, options in [("one", {"jobs": 1}), ("two", {"jobs": 2})]:
        outs[label] = sweep.run_sweep_deck(d, tmp_path / label, [], False, **options)
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=3, processes=False, dashboard_address=None) \
            as cluster, distributed.Client(cluster) as client:
        outs["dask"] = sweep.run_sweep_deck(d, tmp_path / "dask", [], False, scheduler=client)
    n = outs["one"].n_cases
    size = sweep.chunk_size(n, kind)
    assert size == (64 if kind == "batch" else 2) and outs["one"].batch == (kind == "batch")
    assert {o.chunk for o in outs.values()} == {size}
    want = [(s, min(s + size, n)) for s in range(0, n, size)]
    for label in outs:
        assert _record_spans(tmp_path / label, stem) == want, label
    for label in ("two", "dask"):   # and the same answers
        pd.testing.assert_frame_equal(outs[label].summary, outs["one"].summary)
        assert outs[label].text == outs["one"].text


def test_dask_sizes_by_the_cluster_and_probes_its_file_system(tmp_path):
    """Chunks in flight follow the cluster's threads (not this machine's cores); workers that
    cannot see the output folder are found before anything runs."""

    class Client:   # the parts of a dask.distributed.Client the engine uses
        def __init__(self, root: Path | None = None):
            self.root = root

        def scheduler_info(self):
            return {"workers": {"tcp://10.0.0.7:4000": {"nthreads": 8}, "tcp://10.0.0.8:4000": {"nthreads": 4}}}

        def run(self, fn, folder, token):
            if self.root is not None:   # a worker on another machine: same path, its own disk
                folder = str(self.root / Path(folder).relative_to("/"))
            return {w: fn(folder, token) for w in self.scheduler_info()["workers"]}

    assert executor.cluster_workers(Client()) == 12
    assert executor.Workers(2, Client()).threads == 12
    executor.check_shared_folder(Client(), tmp_path / "shared")   # same file system: fine
    assert not list((tmp_path / "shared").iterdir())             # probes removed
    assert executor.Workers(2, Client()).shares(tmp_path / "shared")
    assert not executor.Workers(2, Client(tmp_path / "elsewhere")).shares(tmp_path / "o")
    with pytest.raises(OSError) as err:
        executor.check_shared_folder(Client(tmp_path / "elsewhere"), tmp_path / "o")
    msg = str(err.value)
    assert "do not share this output folder" in msg and "tcp://10.0.0.7:4000" in msg and "1 more" in msg


def test_plot_draws_the_summary_and_case_figures_only_when_asked(tmp_path):
    path = per_case_deck(tmp_path, a=1, rockers="9")   # one case
    out = tmp_path / "o"
    assert main([str(path), "-o", str(out), "-q", "-j", "1", "--plot"]) == 0
    assert (out / "pc_summary.png").exists() and not list((out / "pc").glob("*.png"))
    path = per_case_deck(tmp_path, a=1, rockers="9", extra=", case_plots = .true.")
    assert main([str(path), "-o", str(out), "-q", "-j", "1", "--plot"]) == 0
    assert list((out / "pc").glob("case_0001_*.png"))


def test_dask_is_imported_only_when_configured(tmp_path):
    """Reading Dask's scheduler-address costs a 0.2 s import of Dask, serial before every sweep:
    it is done only when some Dask configuration exists (environment or configuration file)."""
    code = ("import sys; from driver.sweep._spec import configured_scheduler as c; "
            "print(repr(c()), 'dask' in sys.modules)")
    env = {k: v for k, v in os.environ.items() if not k.startswith("DASK_")}
    env["HOME"] = str(tmp_path)
    run = lambda e: subprocess.run([sys.executable, "-c", code], env=e, capture_output=True, text=True,
                                   check=True).stdout.split()
    if not any(Path(p).is_dir() for p in ("/etc/dask", Path(sys.prefix) / "etc" / "dask")):
        assert run(env) == ["''", "False"]
    assert run({**env, "DASK_SCHEDULER_ADDRESS": "tcp://10.1.2.3:8786"}) == ["'tcp://10.1.2.3:8786'", "True"]
    (tmp_path / ".config" / "dask").mkdir(parents=True)
    (tmp_path / ".config" / "dask" / "site.yaml").write_text("scheduler-address: tcp://10.9.9.9:8786\n")
    assert run(env) == ["'tcp://10.9.9.9:8786'", "True"]


def test_cases_table_is_bounded_in_the_drivers_memory(tmp_path, monkeypatch):
    from driver.sweep import _report as sweep_pkg
    path = per_case_deck(tmp_path, a=1)   # 3 cases
    out = tmp_path / "o"
    assert main([str(path), "-o", str(out), "-q", "-j", "1"]) == 0
    assert len(pd.read_csv(out / "pc_cases.csv")) == 3 * len(pd.read_parquet(out / "pc" / "case_0001.parquet"))
    monkeypatch.setattr(sweep_pkg, "CASES_TABLE_BYTES", 1000)   # smaller than one case's table
    assert main([str(path), "-o", str(out), "-q", "-j", "1"]) == 0
    assert not (out / "pc_cases.csv").exists() and not (out / "pc_cases.parquet").exists()
    assert len(list((out / "pc").glob("case_*.parquet"))) == 3


def test_batch_kept_cases_files_resume(tmp_path, capsys):
    """On the batch path with case_outputs = 'kept' the kept cases' files have their own resume
    record: --resume writes only the missing ones (a deleted .out), identical to the first run."""
    path = deck(tmp_path, 5, 6, 7, outputs="kept")
    out = tmp_path / "o"
    assert main([str(path), "-o", str(out), "-q", "-j", "1"]) == 0
    first = tree(out / "sw")
    kept = sorted(p.name for p in (out / "sw").glob("case_*.out"))
    assert len(kept) >= 2
    (out / "sw" / kept[1]).unlink()
    capsys.readouterr()
    assert main([str(path), "-o", str(out), "-j", "1", "--resume"]) == 0
    assert f"resume: {len(kept) - 1} of {len(kept)} kept cases' files complete, 1 to write" in capsys.readouterr().out
    assert tree(out / "sw") == first


def test_per_case_workers_exit_when_the_driver_is_killed(tmp_path):
    psutil = pytest.importorskip("psutil")
    path = per_case_deck(tmp_path, a=200, rockers="8, 9")   # 400 cases with their files
    _kill_driver_and_check_workers(psutil, path, tmp_path / "o")


def _kill_driver_and_check_workers(psutil, path: Path, out: Path) -> None:
    """SIGKILL a 2-worker sweep's driver once its workers run; every worker must exit by itself."""
    cmd = [sys.executable, "-m", "driver", str(path), "-o", str(out), "-q", "-j", "2"]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    parent = psutil.Process(proc.pid)
    deadline, kids = time.time() + 120, []
    while time.time() < deadline and len(kids) < 2 and proc.poll() is None:
        kids = parent.children(recursive=True)
        time.sleep(0.05)
    assert kids, "no worker processes seen"
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    gone, alive = psutil.wait_procs(kids, timeout=20)
    assert not alive, f"workers still running after the driver died: {alive}"


# ----------------------------------------------------------------------------- the one Ctrl-C rule

@dataclass
class _Sleepy:
    """The work of a chunk function whose chunk 0 runs 3 s (a shell sleep, then a marker file)."""

    marker: str
    kind = "sleepy"


def _sleepy(work: _Sleepy, span: Span) -> chunks.ChunkResult:
    if span.start == 0:
        subprocess.run(["sh", "-c", f"sleep 3; touch {work.marker}"], check=True)
    return chunks.ChunkResult(span.start, span.stop, None)


@pytest.mark.parametrize("where", ["pool", "dask"])
def test_one_ctrl_c_rule_for_the_pool_and_dask(tmp_path, monkeypatch, where):
    """Ctrl-C while a chunk still runs (here: as another chunk's result comes in): the pool and
    Dask both tell ``notify`` at once, in the same words, before that chunk ends, cancel what
    is queued and re-raise; the pool lets the running chunk finish first."""
    monkeypatch.setitem(chunks.CHUNK_FUNCTIONS, "sleepy", _sleepy)   # forked workers inherit it
    marker = tmp_path / "done"
    heard: list[tuple[str, bool]] = []
    spans = [Span(0, 1, range(1, 2)), Span(1, 2, range(2, 3)), Span(2, 3, range(3, 4))]

    def on_result(res):
        assert res.start != 0
        raise KeyboardInterrupt   # Ctrl-C as the quick chunk's result comes in

    def notify(line: str) -> None:
        heard.append((line, marker.exists()))

    with contextlib.ExitStack() as stack:
        scheduler = None
        if where == "dask":
            distributed = pytest.importorskip("distributed")
            cluster = stack.enter_context(distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                                                   dashboard_address=None))
            scheduler = stack.enter_context(distributed.Client(cluster))
        workers = stack.enter_context(executor.open_workers(2, scheduler, notify))
        with pytest.raises(KeyboardInterrupt):
            executor.execute(_Sleepy(str(marker)), spans, on_result, workers, in_flight=2)
        assert heard == [("interrupt: cancelling queued chunks, finishing the running ones", False)]
        if where == "pool":
            assert marker.exists()   # the running chunk finished before the interrupt went on
