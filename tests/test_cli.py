"""The command line as a user runs it: python -m driver in a fresh folder."""
from __future__ import annotations

import subprocess
import sys

import pandas as pd
import pytest

from conftest import INPUTS


def run(args, cwd):
    return subprocess.run([sys.executable, "-m", "driver", *args], cwd=cwd, capture_output=True, text=True)


def test_main_job_writes_outputs_folder(tmp_path):
    deck = tmp_path / "inputs" / "crank5.dat"
    deck.parent.mkdir()
    deck.write_text((INPUTS / "crank5.dat").read_text())
    res = run(["inputs/crank5.dat", "--csv", "--format", "parquet", "--plot"], tmp_path)
    assert res.returncode == 0, res.stderr
    out = tmp_path / "outputs"
    names = sorted(p.name for p in out.iterdir())
    assert names == ["crank5.csv", "crank5.out", "crank5.parquet", "crank5_curves.png", "crank5_linkage.png"]
    assert "quadrant" in (out / "crank5.out").read_text()
    csv = pd.read_csv(out / "crank5.csv")
    pq = pd.read_parquet(out / "crank5.parquet")
    assert set(csv["method"]) == {"listing", "exact"} and len(csv) == 38
    pd.testing.assert_frame_equal(csv, pq, check_dtype=False, rtol=1e-9)
    assert (out / "crank5_curves.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_help_lists_groups_and_options(tmp_path):
    res = run(["--help"], tmp_path)
    assert res.returncode == 0
    for word in ("--outdir", "--csv", "--format", "--plot", "&fourbar", "Exit status"):
        assert word in res.stdout
    keys = run(["--keys", "fourbar"], tmp_path)
    assert "fixed_link" in keys.stdout and "rad/s" in keys.stdout


def test_failed_rerun_leaves_previous_output_intact(tmp_path):
    """Atomic writes: a failing deck never truncates an existing .out."""
    deck = tmp_path / "c.dat"
    deck.write_text((INPUTS / "crank5_exact.dat").read_text())
    assert run([str(deck), "-o", "o"], tmp_path).returncode == 0
    before = (tmp_path / "o" / "c.out").read_text()
    deck.write_text(deck.read_text().replace("crank = 5.0", "crank = -5.0"))
    res = run([str(deck), "-o", "o"], tmp_path)
    assert res.returncode == 2
    assert (tmp_path / "o" / "c.out").read_text() == before
    assert [p.name for p in (tmp_path / "o").iterdir()] == ["c.out"]   # no temporary left over


def test_keys_of_sweep_and_unknown_group(tmp_path):
    sweep = run(["--keys", "sweep"], tmp_path)
    assert sweep.returncode == 0 and "key1" in sweep.stdout and "keep" in sweep.stdout
    bogus = run(["--keys", "bogus"], tmp_path)
    assert bogus.returncode == 2 and "no namelist group &bogus" in bogus.stderr and "&fourbar" in bogus.stderr


@pytest.mark.parametrize("jobs", ["0", "-3", "two"])
def test_jobs_must_be_a_positive_count(tmp_path, jobs):
    res = run([str(INPUTS / "crank5.dat"), "-j", jobs, "-o", "o"], tmp_path)
    assert res.returncode == 2 and "-j/--jobs" in res.stderr and not (tmp_path / "o").exists()


def test_sweep_options_on_a_plain_deck_are_reported(tmp_path):
    res = run([str(INPUTS / "crank5_exact.dat"), "-j", "2", "--resume", "-o", "o"], tmp_path)
    assert res.returncode == 0
    assert "-j/--jobs, --resume apply to sweep and optimisation decks" in res.stderr and "ignored" in res.stderr


def test_help_and_version_import_no_study(tmp_path):
    code = ("import sys\nfrom driver._cli import main\n"
            "try:\n    main(['--help'])\nexcept SystemExit:\n    pass\n"
            "heavy = [m for m in ('pandas', 'scipy', 'driver._fortran', 'driver.fourbar', 'matplotlib') if m in sys.modules]\n"
            "print('HEAVY', heavy)")
    res = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True)
    assert "HEAVY []" in res.stdout, res.stdout[-300:] + res.stderr
