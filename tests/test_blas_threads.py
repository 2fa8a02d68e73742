"""Results do not depend on the number of BLAS threads (driver/_blas.py).

scipy's SLSQP calls LAPACK; before the tool limited BLAS to one thread while it computes,
``OPENBLAS_NUM_THREADS=1`` and ``=2`` gave optima differing in the ninth digit
(outputs/optimize_manipulator_torque.optimum.dat: designs_l2 = 4.540288591 vs ...592), so the
committed outputs held only on machines with the same core count.
"""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
threadpoolctl = pytest.importorskip("threadpoolctl")


def _blas_threads() -> set[int]:
    return {i["num_threads"] for i in threadpoolctl.threadpool_info() if i["user_api"] == "blas"}


def test_one_thread_is_a_scope():
    import scipy.linalg  # noqa: F401  (scipy's own OpenBLAS loaded)

    from driver import _blas as blas
    with threadpoolctl.threadpool_limits(limits=2, user_api="blas"):
        before = _blas_threads()
        with blas.one_thread():
            assert _blas_threads() == {1}
        assert _blas_threads() == before        # restored: never a global switch


@pytest.mark.slow
def test_optimum_independent_of_blas_threads(tmp_path):
    deck = ROOT / "inputs" / "optimize_manipulator_torque.dat"
    outs = []
    for n in ("1", "2"):
        env = dict(os.environ, OPENBLAS_NUM_THREADS=n, OMP_NUM_THREADS=n)
        out = tmp_path / f"t{n}"
        res = subprocess.run([sys.executable, "-m", "driver", str(deck), "-o", str(out), "-q"], cwd=ROOT, env=env,
                             capture_output=True, text=True, timeout=600)
        assert res.returncode == 0, res.stderr
        outs.append(out)
    for name in ("optimize_manipulator_torque.optimum.dat", "optimize_manipulator_torque.out"):
        assert (outs[0] / name).read_bytes() == (outs[1] / name).read_bytes(), name


def test_one_thread_limits_a_library_loaded_before_a_nested_block():
    """driver._blas no longer imports scipy to limit it (start-up, issue 37): a run that imports
    scipy inside the runner's block opens a nested block after the import, which limits scipy's
    BLAS too; the outer block's libraries are restored on exit.  In a fresh process, where scipy's
    BLAS is not loaded yet."""
    code = """
import threadpoolctl
from driver import _blas as blas
def threads():
    return sorted((i["internal_api"], i["filepath"], i["num_threads"])
                  for i in threadpoolctl.threadpool_info() if i["user_api"] == "blas")
with threadpoolctl.threadpool_limits(limits=2, user_api="blas"):
    with blas.one_thread():
        import scipy.linalg   # a new BLAS library, loaded inside the block
        with blas.one_thread():
            inner = threads()
    after = threads()
print(inner); print(after)
"""
    res = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr
    inner, after = (eval(line) for line in res.stdout.strip().splitlines())
    assert len(inner) >= 2 and {n for _, _, n in inner} == {1}, inner   # numpy's and scipy's BLAS
    assert [n for _, path, n in after if "numpy" in path] == [2], after   # the outer limit, restored
