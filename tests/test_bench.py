"""bench/run_all.py runs (tiny sizes): every study's kernel is checked against its numpy
baseline inside it before timing, and the table carries the issue's targets.  No timing is
asserted here (targets live in the benchmark, not in the test suite)."""
from __future__ import annotations

import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[1] / "bench"


@pytest.fixture(scope="module")
def run_all():
    sys.path.insert(0, str(BENCH))
    try:
        import run_all
        yield run_all
    finally:
        sys.path.remove(str(BENCH))


def test_run_all_smoke(run_all, capsys):
    rows = run_all.main(["--smoke"])
    text = capsys.readouterr().out
    names = [r.name for r in rows]
    assert any(n.startswith("four-bar exact") for n in names)
    assert any(n.startswith("2R manipulator") for n in names)
    assert any(n.startswith("Hooke joint") for n in names)
    assert any(n.startswith("slider-crank") for n in names)
    targets = {r.name.split(":")[0].split(" (")[0]: (r.target_s, r.target_ratio) for r in rows if r.target_s}
    assert targets["four-bar exact states"] == (20e-9, 5.0)
    assert targets["2R manipulator"] == (0.04e-6, None)
    assert targets["Hooke joint"] == (5e-6, None)
    assert targets["slider-crank"] == (100e-3, 10.0)
    nl, = [r for r in rows if r.name.startswith("slider-crank nonlinear rod")]
    assert nl.target_s is None and nl.target_ratio == pytest.approx(1 / 25)   # issue 29: <= 25x the linear time
    # issue 27 (targets only above the sizes where fresh memory costs page faults: not at --smoke sizes)
    assert "four-bar exact, out= buffers vs fresh arrays" in names
    assert "slider-crank: study's record vs all fields" in names
    # issue 37: start-up rows, each against `import numpy` measured in the same rounds
    start = {r.name.split(": ", 1)[1]: r.target_ratio for r in rows if r.name.startswith("start-up")}
    assert start == {"--help": pytest.approx(1 / 1.5), "--examples": pytest.approx(1 / 1.5), "crank5": 0.5,
                     "manipulator case 1": 0.5, "U-joint option 0": 0.5}
    for r in rows:
        assert r.kernel_s > 0 and r.baseline_s > 0 and r.limit
        assert r.name in text
    assert "limits (floor" in text


def test_bench_optimize_times_the_kernels_the_optimiser_calls(capsys):
    """bench/bench_optimize.py (one seed): its kernel clock sees the batch summary kernel the
    population goes through, and the optimum's check run; the targets are printed, not asserted."""
    sys.path.insert(0, str(BENCH))
    try:
        import bench_optimize
        rows = bench_optimize.main(["--seeds", "1"])
    finally:
        sys.path.remove(str(BENCH))
    (seed, converged, fun, designs, reach, kernel, wall, by_kernel), = rows
    assert converged and fun >= 55.2846 and designs <= 0.05 * bench_optimize.GRID_EVALS
    assert set(by_kernel) >= {"fourbar_summaries", "fourbar_exact"}
    assert 0 < kernel == pytest.approx(sum(by_kernel.values())) and kernel < wall
    text = capsys.readouterr().out
    assert "kernel time < 1 s:" in text and "evaluations <= 5 % of the grid's (5120):" in text


def test_force_bytes_probe_runs(capsys):
    """bench/probe_force_bytes.py compiles its Fortran probe with the kernels' flags and prints the
    force kernel beside loops that only move its bytes (no timing asserted)."""
    sys.path.insert(0, str(BENCH))
    try:
        import probe_force_bytes
        probe_force_bytes.main(["--n", "20000", "--repeat", "3"])
    finally:
        sys.path.remove(str(BENCH))
    text = capsys.readouterr().out
    assert "force kernel" in text and "without its arithmetic" in text and "nan" not in text
