"""File-system faults: one line naming the path and the reason, exit 1 for that deck, the other
decks still run, and no temporary or partial file is left behind."""
from __future__ import annotations

import errno
import os
import signal
import subprocess
import sys
import time

import pytest

from conftest import INPUTS, ROOT
from driver import _atomic as atomic
from driver._atomic import output_set, remove_stale_temporaries, write_text
from driver._cli import main

DECK = str(INPUTS / "crank5.dat")
OTHER = str(INPUTS / "crank2.dat")


def _one_error(capsys, *words: str) -> str:
    err = [l for l in capsys.readouterr().err.splitlines() if l.startswith("error:")]
    assert len(err) == 1, err
    assert "Traceback" not in err[0]
    for w in words:
        assert w in err[0], err[0]
    return err[0]


def _no_temporaries(folder) -> None:
    assert not [p for p in folder.rglob(".*.tmp")] if folder.exists() else True


def test_outdir_is_a_file(tmp_path, capsys):
    f = tmp_path / "f"
    f.write_text("x")
    assert main([DECK, "-o", str(f), "-q"]) == 1
    _one_error(capsys, str(f), "not a folder")


def test_outdir_under_a_file(tmp_path, capsys):
    f = tmp_path / "f"
    f.write_text("x")
    assert main([DECK, "-o", str(f / "sub"), "-q"]) == 1
    _one_error(capsys, str(f), "is a file, not a folder")


def test_output_target_is_a_folder_and_the_next_deck_still_runs(tmp_path, capsys):
    out = tmp_path / "o"
    (out / "crank5.out").mkdir(parents=True)
    assert main([DECK, OTHER, "-o", str(out), "-q"]) == 1
    _one_error(capsys, str(out / "crank5.out"), "is a folder")
    assert (out / "crank2.out").is_file()
    _no_temporaries(out)


def test_read_only_outdir(tmp_path, capsys, monkeypatch):
    out = tmp_path / "ro"
    out.mkdir()
    if os.geteuid() == 0:   # root writes anywhere: simulate what the kernel answers a user
        def deny(*a, **k):
            raise PermissionError(errno.EACCES, "Permission denied", str(out / "x"))
        monkeypatch.setattr(atomic.tempfile, "mkstemp", deny)
    else:
        out.chmod(0o555)
    try:
        assert main([DECK, "-o", str(out), "-q"]) == 1
    finally:
        out.chmod(0o755)
    _one_error(capsys, "permission denied")


@pytest.mark.parametrize("code,words", [(errno.ENOSPC, "no space left"), (errno.EFBIG, "file too large"),
                                        (errno.EDQUOT, "quota")])
def test_full_disk_leaves_no_partial_file(code, words, tmp_path, capsys, monkeypatch):
    out = tmp_path / "o"
    real = os.fdopen

    class Full:
        def __init__(self, fh):
            self.fh = fh

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            self.fh.close()

        def write(self, data):
            raise OSError(code, os.strerror(code))

    monkeypatch.setattr(atomic.os, "fdopen", lambda fd, mode: Full(real(fd, mode)))
    assert main([DECK, "--csv", "-o", str(out), "-q"]) == 1
    _one_error(capsys, str(out / "crank5.out"), words)
    assert list(out.iterdir()) == []


def test_file_size_limit_is_an_error_not_a_kill(tmp_path):
    out = tmp_path / "o"
    code = ("import resource, sys; resource.setrlimit(resource.RLIMIT_FSIZE, (2000, 2000)); "
            "from driver._cli import main; sys.exit(main(sys.argv[1:]))")
    p = subprocess.run([sys.executable, "-c", code, DECK, OTHER, "-o", str(out), "-q"],
                       capture_output=True, text=True, cwd=ROOT, timeout=300)
    assert p.returncode == 1, p.stderr
    lines = [l for l in p.stderr.splitlines() if l.startswith("error:")]
    assert len(lines) == 2 and all("file too large" in l for l in lines), p.stderr
    assert "Traceback" not in p.stderr
    assert list(out.iterdir()) == []


def test_broken_pipe_is_quiet_and_the_decks_still_run(tmp_path):
    out = tmp_path / "o"
    p = subprocess.Popen([sys.executable, "-m", "driver", DECK, OTHER, "-o", str(out)],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, cwd=ROOT)
    p.stdout.close()   # like '| head -0'
    err = p.stderr.read().decode()
    assert p.wait(timeout=300) == 0
    assert "Traceback" not in err and "BrokenPipe" not in err, err
    assert (out / "crank5.out").is_file() and (out / "crank2.out").is_file()


def test_output_set_is_all_or_nothing(tmp_path):
    out = tmp_path / "o"
    write_text(out / "a.out", "old a")
    write_text(out / "a.csv", "old csv")
    with pytest.raises(RuntimeError):
        with output_set(out):
            write_text(out / "a.out", "new a")
            raise RuntimeError("interrupted between two files of the set")
    assert (out / "a.out").read_text() == "old a" and (out / "a.csv").read_text() == "old csv"
    _no_temporaries(out)
    with output_set(out):
        write_text(out / "a.out", "new a")
        write_text(out / "a.csv", "new csv")
    assert (out / "a.out").read_text() == "new a" and (out / "a.csv").read_text() == "new csv"
    with pytest.raises(PermissionError, match="outside the output folder"):
        with output_set(out):
            write_text(out / ".." / "escape.out", "x")
    assert not (tmp_path / "escape.out").exists()


def test_stale_temporaries_of_a_killed_run_are_removed(tmp_path, capsys):
    out = tmp_path / "o"
    out.mkdir()
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    stale = out / f".crank5.out.{dead.pid}.abc123.tmp"
    stale.write_text("x" * 1000)
    live = out / f".crank5.out.{os.getpid()}.def456.tmp"   # a writer still running: kept
    live.write_text("y")
    other = out / f".crank2.out.{dead.pid}.ghi789.tmp"     # another deck's: not this run's business
    other.write_text("z")
    assert main([DECK, "-o", str(out), "-q"]) == 0
    assert not stale.exists() and live.exists() and other.exists()
    assert remove_stale_temporaries(out, "crank2") == [other]


def test_sigterm_is_handled_like_ctrl_c(tmp_path):
    out = tmp_path / "o"
    deck = tmp_path / "slow.dat"
    # 10^8 linkages (about a minute on two cores): the signal is sent once the first chunk's part
    # is in the record, so the run is under way and far from done (no sleep decides it)
    deck.write_text((INPUTS / "fourbar_design_search.dat").read_text().replace("count1 = 25", "count1 = 25000"))
    p = subprocess.Popen([sys.executable, "-m", "driver", str(deck), "-o", str(out), "-q", "-j", "1"],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, cwd=ROOT, text=True)
    deadline = time.monotonic() + 300   # a bound for a broken tool only
    while not any(out.rglob("*.parquet")):
        assert p.poll() is None and time.monotonic() < deadline, p.communicate()[1] if p.poll() is not None else ""
        time.sleep(0.05)
    p.send_signal(signal.SIGTERM)
    _, err = p.communicate(timeout=120)
    assert p.returncode == 143, err
    assert "terminated" in err and "Traceback" not in err, err
    _no_temporaries(out)
