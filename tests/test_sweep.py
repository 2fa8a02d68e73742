"""Sweeps: case generation, per-case outputs equal single runs, local vs Dask, failures, resume, interrupt."""
from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest

from conftest import INPUTS
from driver import sweep
from driver._cli import main
from test_fourbar_published import published, table_rows

BASE = """&fourbar
  fixed_link = 12.0, crank = 2.0, coupler = 15.0, rocker = 9.0
  omega = 5.0, step_deg = 20, method = 'listing'
/
"""


def deck(tmp_path: Path, sweep_text: str, base: str = BASE, name: str = "sw.dat") -> Path:
    path = tmp_path / name
    path.write_text(base + sweep_text)
    return path


def test_paper_study_in_one_run_reproduces_all_published_cells(tmp_path):
    out = tmp_path / "o"
    assert main([str(INPUTS / "fourbar_paper_sweep.dat"), "-o", str(out), "-q", "-j", "2"]) == 0
    for k, crank in enumerate((2, 3, 4, 5), start=1):
        text = (out / "fourbar_paper_sweep" / f"case_{k:04d}.out").read_text()
        assert table_rows(text) == published(crank)
    summary = pd.read_csv(out / "fourbar_paper_sweep_summary.csv")
    assert list(summary["fourbar.crank"]) == [2, 3, 4, 5]
    # the paper's conclusion: only crank 2 keeps the transmission angle within 40-120 deg,
    # and the lower bounds it quotes (36, 26, 17 deg, truncated) are the closed-loop minima
    assert list(summary["meets_transmission_band"]) == [True, False, False, False]
    assert [int(v) for v in summary["mu_min_deg"]] == [40, 33, 26, 17]
    cases = pd.read_parquet(out / "fourbar_paper_sweep_cases.parquet")
    assert len(cases) == 4 * 2 * 19 and "fourbar.crank" in cases


@pytest.mark.parametrize("text,n", [
    ("&sweep key1 = 'fourbar.crank', values1 = 2, 3 /\n", 2),
    ("&sweep key1 = 'fourbar.crank', values1 = 2, 3, key2 = 'fourbar.coupler', start2 = 14, stop2 = 16, count2 = 3 /\n", 6),
    ("&sweep key1 = 'fourbar.crank', values1 = 2, 3, key2 = 'fourbar.rocker', values2 = 8, 9, zip = .true. /\n", 2),
    ("&sweep key1 = 'fourbar.method', values1 = 'listing', 'exact' /\n", 2),
])
def test_case_counts(tmp_path, text, n):
    from driver import fourbar
    from driver._deck import read_deck, validate
    d = read_deck(deck(tmp_path, text))
    sw = validate(d.groups["sweep"], sweep.SPEC, d.path)
    cases = sweep.build_cases(sw, "fourbar", fourbar.SPEC)
    assert len(cases) == n and [c.index for c in cases] == list(range(1, n + 1))


@pytest.mark.parametrize("text,line,key,words", [
    ("&sweep\n key1 = 'fourbar.crnk', values1 = 2 /\n", 6, "key1", "no key 'crnk'"),
    ("&sweep\n key1 = 'ujoint.beta', values1 = 2 /\n", 6, "key1", "not this deck's study group"),
    ("&sweep\n key1 = 'fourbar.crank', values1 = 2, 3\n key2 = 'fourbar.rocker', values2 = 8\n zip = .true. /\n",
     7, "values2", "equally long"),
    ("&sweep\n key1 = 'fourbar.crank' /\n", 6, "key1", "needs values1"),
    ("&sweep\n values1 = 2, 3 /\n", 6, "values1", "without key1"),
    ("&sweep\n key1 = 'fourbar.crank', start1 = 1, stop1 = 2 /\n", 5, "count1", "go together"),
    ("&sweep\n key1 = 'fourbar.crank', start1 = 1, stop1 = 2, count1 = 1e8 /\n", 6, "count1", "beyond the 10000000"),
    ("&sweep\n key1 = 'fourbar.crank', values1 = 2\n keep = 'no_such_column > 1' /\n", 7, "keep",
     "unknown column 'no_such_column'"),
])
def test_sweep_deck_errors(tmp_path, capsys, text, line, key, words):
    path = deck(tmp_path, text)
    assert main([str(path), "-o", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert f"{path}:{line}: key '{key}'" in err and words in err
    assert not (tmp_path / "o").exists()


def test_bad_input_refuses_the_whole_sweep_before_anything_runs(tmp_path, capsys):
    path = deck(tmp_path, "&sweep key1 = 'fourbar.crank', values1 = 2, -1, 5 /\n")
    out = tmp_path / "o"
    assert main([str(path), "-o", str(out), "-q", "-j", "1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1
    assert err[0].startswith(f"error: {path}:5: key 'values1': case 2 (fourbar.crank = -1)")
    assert "must be positive" in err[0] and "nothing was run" in err[0]
    assert not out.exists()


def test_failed_case_is_reported_and_the_others_complete(tmp_path, capsys):
    # case 2 is a degenerate linkage (all links 1): the listing's table cannot be computed
    path = deck(tmp_path, "&sweep zip = .true., key1 = 'fourbar.fixed_link', values1 = 12, 1, 12\n"
                          "  key2 = 'fourbar.crank', values2 = 2, 1, 5, key3 = 'fourbar.coupler', values3 = 15, 1, 15\n"
                          "  key4 = 'fourbar.rocker', values4 = 9, 1, 9 /\n")
    out = tmp_path / "o"
    assert main([str(path), "-o", str(out), "-q", "-j", "1"]) == 1
    err = capsys.readouterr().err
    assert "case 2 (fourbar.fixed_link = 1, fourbar.crank = 1" in err and "divide 0 by 0" in err
    assert table_rows((out / "sw" / "case_0003.out").read_text()) == published(5)
    assert not (out / "sw" / "case_0002.out").exists()
    summary = pd.read_csv(out / "sw_summary.csv")
    assert list(summary["status"]) == ["ok", "failed", "ok"]
    assert "Failed cases" in (out / "sw.out").read_text()


def _tables(out: Path, stem: str) -> tuple[pd.DataFrame, pd.DataFrame, str]:
    return (pd.read_parquet(out / f"{stem}_summary.parquet"), pd.read_parquet(out / f"{stem}_cases.parquet"),
            "".join(p.read_text() for p in sorted((out / stem).glob("*.out"))))


SWEEP_GRID = ("&sweep key1 = 'fourbar.crank', values1 = 2, 3, 4, 5, 6\n"
              "       key2 = 'fourbar.rocker', values2 = 8, 9, 10\n"
              "       key3 = 'fourbar.method', values3 = 'exact' /\n")


def test_results_do_not_depend_on_scheduling(tmp_path):
    path = deck(tmp_path, SWEEP_GRID)
    a, b = tmp_path / "one", tmp_path / "two"
    assert main([str(path), "-o", str(a), "-q", "-j", "1"]) == 0
    assert main([str(path), "-o", str(b), "-q", "-j", "2"]) == 0
    ta, tb = _tables(a, "sw"), _tables(b, "sw")
    pd.testing.assert_frame_equal(ta[0], tb[0])
    pd.testing.assert_frame_equal(ta[1], tb[1])
    assert ta[2] == tb[2]
    assert list(ta[0]["case"]) == list(range(1, 16))


def test_dask_local_cluster_gives_identical_tables(tmp_path):
    distributed = pytest.importorskip("distributed")
    import dask
    path = deck(tmp_path, SWEEP_GRID)
    local = tmp_path / "local"
    assert main([str(path), "-o", str(local), "-q", "-j", "2"]) == 0
    # generous timeouts: worker start-up and connections are slow on a loaded CI machine
    with dask.config.set({"distributed.comm.timeouts.connect": "120s", "distributed.comm.timeouts.tcp": "120s"}), \
            distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                     dashboard_address=None) as cluster:
        dsk = tmp_path / "dask"
        assert main([str(path), "-o", str(dsk), "-q", "--scheduler", cluster.scheduler_address]) == 0
    tl, td = _tables(local, "sw"), _tables(dsk, "sw")
    pd.testing.assert_frame_equal(tl[0], td[0])
    pd.testing.assert_frame_equal(tl[1], td[1])
    assert tl[2] == td[2]


def test_resume_runs_only_missing_cases(tmp_path, capsys):
    path = deck(tmp_path, SWEEP_GRID)
    out = tmp_path / "o"
    assert main([str(path), "-o", str(out), "-j", "1"]) == 0
    first = _tables(out, "sw")
    for suffix in (".json", ".out"):
        (out / "sw" / f"case_0007{suffix}").unlink()
    capsys.readouterr()
    assert main([str(path), "-o", str(out), "-j", "1", "--resume"]) == 0
    assert "resume: 14 of 15 cases complete, 1 to run" in capsys.readouterr().out
    again = _tables(out, "sw")
    pd.testing.assert_frame_equal(first[0], again[0])
    pd.testing.assert_frame_equal(first[1], again[1])
    # a changed base deck makes every earlier case stale
    path.write_text(path.read_text().replace("omega = 5.0", "omega = 4.0"))
    capsys.readouterr()
    assert main([str(path), "-o", str(out), "-j", "1", "--resume"]) == 0
    assert "resume: 0 of 15 cases complete" in capsys.readouterr().out


def test_interrupt_keeps_finished_cases_and_leaves_no_partial_file(tmp_path, monkeypatch):
    path = deck(tmp_path, SWEEP_GRID)
    out = tmp_path / "o"
    from driver.sweep import _chunks as chunks
    real = chunks.compute_case

    def interrupted(task, case, module):
        if case.index == 6:
            raise KeyboardInterrupt
        return real(task, case, module)

    monkeypatch.setattr(chunks, "compute_case", interrupted)
    assert main([str(path), "-o", str(out), "-q", "-j", "1"]) == 130
    names = sorted(p.name for p in (out / "sw").iterdir())
    assert [n for n in names if n.endswith(".json")] == [f"case_{k:04d}.json" for k in range(1, 6)]
    assert not any(n.startswith(".") or n.endswith(".tmp") for n in names)
    assert not (out / "sw.out").exists() and not (out / "sw_summary.csv").exists()
    monkeypatch.setattr(chunks, "compute_case", real)
    assert main([str(path), "-o", str(out), "-q", "-j", "1", "--resume"]) == 0
    assert len(pd.read_csv(out / "sw_summary.csv")) == 15


def test_design_search_filter_and_kept_rows(tmp_path):
    text = ("&sweep key1 = 'fourbar.crank', start1 = 1, stop1 = 6, count1 = 6\n"
            "       key2 = 'fourbar.method', values2 = 'exact'\n"
            "       keep = 'meets_transmission_band and rocker_swing_deg > 30'\n"
            "       case_outputs = 'kept', summary_rows = 'kept' /\n")
    out = tmp_path / "o"
    assert main([str(deck(tmp_path, text)), "-o", str(out), "-q", "-j", "1"]) == 0
    summary = pd.read_csv(out / "sw_summary.csv")
    # crank 2 keeps mu in 40-120 deg with a 32.3 deg swing; crank 1 swings too little; crank >= 3 leaves the band
    assert list(summary["fourbar.crank"]) == [2.0]
    assert sorted(p.name for p in (out / "sw").glob("*.out")) == ["case_0002.out"]


#: the driver of the Ctrl-C test: the command line, its workers forked after a gate is put in
#: front of every case (``gate/slot-<k>`` claims one of the first 20 places; every later case
#: says so in ``gate/waiting-<case>`` and waits for ``gate/go``).  So the sweep cannot finish
#: before the test's SIGINT, which arrives while both workers wait and the driver is idle.
GATED = """
import os, sys, time
from pathlib import Path
from driver.sweep import _chunks
gate, real = Path(sys.argv[1]), _chunks.compute_case

def gated(task, case, module):
    for k in range(20):
        try:
            os.close(os.open(gate / f"slot-{k}", os.O_CREAT | os.O_EXCL))
            return real(task, case, module)
        except FileExistsError:
            pass
    (gate / f"waiting-{case.index}").touch()
    while not (gate / "go").exists():
        time.sleep(0.01)
    return real(task, case, module)

_chunks.compute_case = gated
from driver._cli import main
sys.exit(main(sys.argv[2:]))
"""


def test_ctrl_c_on_worker_processes(tmp_path):
    """Real SIGINT to the whole process group of a 2-worker sweep: the driver says at once that
    it cancels the queued cases, lets the running ones finish, exits 130; every started case is
    complete (.json marker <=> .out), no temporary file is left, then --resume finishes.

    No sleeps decide anything: the signal is sent once 20 cases are complete and a worker
    waits at the gate (the sweep cannot have finished), and the waiting cases are released
    only once the driver has announced the interrupt on stderr."""
    import os
    import select
    import signal
    import subprocess
    import sys
    import time
    path = deck(tmp_path, "&sweep key1 = 'fourbar.crank', start1 = 1, stop1 = 5, count1 = 30\n"
                          "       key2 = 'fourbar.rocker', start2 = 6, stop2 = 12, count2 = 10 /\n",
                base=BASE.replace("method = 'listing'", "method = 'exact'"))
    out, gate = tmp_path / "o", tmp_path / "gate"
    gate.mkdir()
    cmd = [str(path), "-o", str(out), "-q", "-j", "2"]
    proc = subprocess.Popen([sys.executable, "-c", GATED, str(gate), *cmd], start_new_session=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    case_dir = out / "sw"
    try:
        deadline = time.monotonic() + 300   # a bound for a broken tool only: nothing below waits on time
        while not (list(gate.glob("waiting-*")) and case_dir.is_dir()
                   and len(list(case_dir.glob("*.json"))) >= 20):
            assert proc.poll() is None and time.monotonic() < deadline, "the sweep ended before its cases waited"
            time.sleep(0.02)
        os.killpg(proc.pid, signal.SIGINT)
        heard = ""
        while "interrupt: cancelling queued cases" not in heard:   # the driver's own notice
            assert select.select([proc.stderr], [], [], max(0.0, deadline - time.monotonic()))[0], heard
            line = proc.stderr.readline()
            assert line, f"stderr closed before the notice: {heard!r}"
            heard += line
        (gate / "go").touch()   # the running cases may finish now
        _, err = proc.communicate(timeout=300)
    finally:
        (gate / "go").touch()
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    assert proc.returncode == 130, heard + err
    assert "interrupted: finished outputs are complete" in err
    names = [p.name for p in case_dir.iterdir()]
    assert not [n for n in names if n.startswith(".") or n.endswith(".tmp")]
    done = {n[:-5] for n in names if n.endswith(".json")}
    assert 20 <= len(done) < 300
    assert done == {n[:-4] for n in names if n.endswith(".out")}
    assert not (out / "sw_summary.csv").exists()
    # the running chunks finished in their workers, which wrote their record parts: all resumed
    res = subprocess.run([sys.executable, "-m", "driver", *cmd[:-3], "-j", "2", "--resume"], capture_output=True,
                         text=True)
    assert res.returncode == 0, res.stderr
    assert f"resume: {len(done)} of 300 cases complete, {300 - len(done)} to run" in res.stdout
    assert len(pd.read_csv(out / "sw_summary.csv")) == 300


def test_keep_filter_is_never_code(tmp_path, capsys):
    """A keep filter that would run a command under a pandas query is a deck error; no canary file."""
    canary = tmp_path / "canary"
    for keep in (f'@os.system("touch {canary}") == 1', f'__import__("os").system("touch {canary}")',
                 "@time.sleep(30) is None", f'open("{canary}", "w").close() is None'):
        deck = tmp_path / "inject.dat"
        deck.write_text(BASE + f"&sweep\n key1 = 'fourbar.crank', values1 = 2, 3\n keep = '{keep}' /\n")
        assert main([str(deck), "-o", str(tmp_path / "out"), "-q", "-j", "1"]) == 2
        assert "key 'keep'" in capsys.readouterr().err
    assert not canary.exists() and not (tmp_path / "out" / "inject.out").exists()


def test_the_outcome_carries_the_tables_it_wrote_and_the_best_case(tmp_path):
    """run_sweep_deck's outcome holds the _summary and _cases tables and the .out exactly as
    written (what pandas reads back from the files); with best=True the run of the best kept
    case.  The paper's sweep: crank 2 keeps the largest minimum transmission angle (the
    paper's conclusion), and its run reproduces the published table and the case's own file."""
    from driver._deck import read_deck
    out = tmp_path / "o"
    oc = sweep.run_sweep_deck(read_deck(INPUTS / "fourbar_paper_sweep.dat"), out, [], False, jobs=2, best=True)
    stem = out / "fourbar_paper_sweep"
    written = pd.read_parquet(f"{stem}_summary.parquet")
    pd.testing.assert_frame_equal(oc.summary, written)
    assert oc.summary.attrs == written.attrs == {"summary_settings": {"transmission_band_deg": [40.0, 120.0]}}
    pd.testing.assert_frame_equal(oc.cases, pd.read_parquet(f"{stem}_cases.parquet"))
    assert oc.text == oc.out == (out / "fourbar_paper_sweep.out").read_text()
    assert (oc.best_case, oc.best_metric) == (1, "mu_min_deg")
    assert oc.best is not None and oc.best.params["crank"] == 2.0 and oc.best.name == "fourbar_paper_sweep_case1"
    assert table_rows(oc.best.out) == published(2)
    assert oc.best.out == (stem / "case_0001.out").read_text()
    assert sweep.run_sweep_deck(read_deck(INPUTS / "fourbar_paper_sweep.dat"), tmp_path / "n", [], False,
                                jobs=1).best is None   # the run only when asked


def test_the_best_case_of_a_batch_search_and_of_its_streamed_tables(tmp_path, monkeypatch):
    """The shipped design search (batch path, kept rows only): the best kept design by its first
    plotted column (rocker_swing_deg, larger is better) is found by a plain scan of the summary
    file; the same when the tables are streamed (a lazy summary), and its run gives that swing."""
    from driver._deck import read_deck
    from driver._outcome import StreamedSummary
    from driver.sweep import _executor as executor
    deck = read_deck(INPUTS / "fourbar_design_search.dat")
    held = sweep.run_sweep_deck(deck, tmp_path / "held", [], False, jobs=1)
    written = pd.read_parquet(tmp_path / "held" / "fourbar_design_search_summary.parquet")
    pd.testing.assert_frame_equal(held.summary, written)
    best_row, best_swing = None, -1.0
    for case, status, kept, swing in zip(written["case"], written["status"], written["kept"],
                                         written["rocker_swing_deg"]):
        if status == "ok" and kept and swing > best_swing:
            best_row, best_swing = int(case), float(swing)
    assert (held.best_case, held.best_metric) == (best_row, "rocker_swing_deg") and held.best is None
    monkeypatch.setattr(executor, "STREAM_ROWS", 50)
    streamed = sweep.run_sweep_deck(deck, tmp_path / "streamed", [], False, jobs=1, best=True)
    assert isinstance(streamed.summary, StreamedSummary) and streamed.best_case == best_row
    assert streamed.best.summary["rocker_swing_deg"] == pytest.approx(best_swing, rel=1e-12)


def test_the_best_case_is_the_one_the_maps_mark_and_the_page_names(tmp_path):
    """One rule for the best case, the design-space maps' star and the report page: the first
    plotted column (here plot_y = rocker_swing_deg, larger is better; not the study's first
    sweep_plot column, mu_min_deg, which picks another case) over the kept, ok cases, found again
    by a plain scan of the summary file; the page names that case and why.  A plotted expression
    has no better end: the best case is then the first kept case (no metric)."""
    from driver import _report_page as report_page
    from driver._deck import read_deck
    from driver._output import best_index
    grid = ("key1 = 'fourbar.crank', values1 = 2, 2.5, 3, 3.5\n key2 = 'fourbar.rocker', values2 = 8, 9, 10\n"
            " keep = 'rocker_swing_deg > 40'\n")
    path = deck(tmp_path, f"&sweep\n {grid} plot_y = 'rocker_swing_deg' /\n")
    oc = sweep.run_sweep_deck(read_deck(path), tmp_path / "o", [], False, jobs=1, best=True)
    written = pd.read_parquet(tmp_path / "o" / "sw_summary.parquet")
    best, best_value = None, -1.0
    for case, status, kept, value in zip(written["case"], written["status"], written["kept"],
                                         written["rocker_swing_deg"]):
        if status == "ok" and kept and value > best_value:
            best, best_value = int(case), float(value)
    kept = written[(written["status"] == "ok") & written["kept"].astype(bool)]
    assert 0 < len(kept) < len(written)   # the filter keeps some, not all
    assert best not in (int(kept["case"].iloc[0]), int(kept.loc[kept["mu_min_deg"].idxmax(), "case"]))
    assert (oc.best_case, oc.best_metric) == (best, "rocker_swing_deg")
    assert int(written.loc[best_index(written, "rocker_swing_deg", "max"), "case"]) == best   # the maps' star
    assert oc.best is not None and oc.best.summary["rocker_swing_deg"] == pytest.approx(best_value, rel=1e-12)
    assert f"Case {best}, largest rocker swing" in report_page.page(oc, read_deck(path))
    path = deck(tmp_path, f"&sweep\n {grid} plot_y = 'rocker_swing_deg - mu_min_deg' /\n", name="expr.dat")
    oc = sweep.run_sweep_deck(read_deck(path), tmp_path / "e", [], False, jobs=1)
    assert (oc.best_case, oc.best_metric) == (int(kept["case"].iloc[0]), None)


def test_run_sweep_reads_nothing_back(tmp_path, monkeypatch):
    """driver.run_sweep builds its result from the engine's outcome: with the Parquet and text
    readers of pandas and pathlib made to fail, the tables are there all the same."""
    import driver
    monkeypatch.setattr(pd, "read_parquet", lambda *a, **k: pytest.fail("read back a Parquet file"))
    monkeypatch.setattr(pd, "read_csv", lambda *a, **k: pytest.fail("read back a CSV file"))
    s = driver.run_sweep({"fourbar": {"fixed_link": 12, "crank": 2, "coupler": 15, "rocker": 9, "step_deg": 20}},
                         grid={"crank": [2, 3, 4, 5]}, jobs=1)
    assert s.outdir is None and s.summary["fourbar.crank"].tolist() == [2, 3, 4, 5]
    assert [int(v) for v in s.summary["mu_min_deg"]] == [40, 33, 26, 17]   # the paper's closed-loop minima
    assert len(s.cases) == 4 * 19 and "fourbar.crank" in s.cases and s.out.startswith("  sweep over &fourbar")
