"""A design search on a real Dask cluster (``dask scheduler`` + ``dask worker`` processes on
loopback, started as docs/performance.md says) writes the same summary tables as one in-process run.

This is the path a user takes on a cluster: separate scheduler and worker processes talking
TCP, the command line with ``--scheduler``; the LocalCluster tests in test_sweep_engine.py do
not cross a process boundary the same way.
"""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "bench"))
bench = pytest.importorskip("bench_dask_cluster")
pytest.importorskip("dask.distributed")

pytestmark = pytest.mark.slow


def _cli(deck: Path, out: Path, *extra: str) -> None:
    res = subprocess.run([sys.executable, "-m", "driver", str(deck), "-o", str(out), "-q", *extra],
                         cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert res.returncode == 0, res.stderr


def test_cluster_equals_one_process(tmp_path):
    deck, n = bench.big_deck(tmp_path, 2 * 64 * 64)        # 8192 linkages, two crank values
    assert n == 8192
    _cli(deck, tmp_path / "local", "-j", "1")
    address, procs = bench.cluster(2, tmp_path)
    try:
        _cli(deck, tmp_path / "dask", "--scheduler", address)
    finally:
        bench.stop(procs)
    for name in (f"{deck.stem}.out", f"{deck.stem}_summary.csv"):
        local = (tmp_path / "local" / name).read_bytes()
        assert local == (tmp_path / "dask" / name).read_bytes(), name
    text = (tmp_path / "local" / f"{deck.stem}.out").read_text()
    assert "8192" in text.replace(" ", "")
