"""The four-bar kernel's default path reuses its output memory across calls (issue 27), and
never hands out memory someone still holds.

Truth: the values equal those of a call into explicit fresh buffers; an array (or a view of
it) still referenced is never overwritten by a later call; memory is reused (same address)
only once the caller dropped every reference.
"""
from __future__ import annotations

import numpy as np

from driver import _fortran as kernels
from driver.fourbar import _kernel as fourbar_kernel

LINK = (12.0, 5.0, 15.0, 9.0, 5.0, 0.0)


def _addr(a: np.ndarray) -> int:
    return a.__array_interface__["data"][0]


def test_default_path_values_and_reuse():
    n = 300_000                      # 26 MB of states, 1.2 MB of status: above SPARE_MIN_BYTES
    theta = np.linspace(0.0, 2 * np.pi, n)
    ref = np.empty((n, 11), order="F")
    rst = np.empty(n, dtype=np.int32)
    fourbar_kernel.fourbar_exact(theta, *LINK, out=ref, status=rst)
    kernels.release_spares()
    out, st = fourbar_kernel.fourbar_exact(theta, *LINK)
    np.testing.assert_array_equal(out, ref)
    np.testing.assert_array_equal(st, rst)
    where = _addr(out), _addr(st)
    del out, st
    out, st = fourbar_kernel.fourbar_exact(theta * 0.5, *LINK)      # dropped: the same memory again
    assert (_addr(out), _addr(st)) == where
    half = np.empty((n, 11), order="F")
    fourbar_kernel.fourbar_exact(theta * 0.5, *LINK, out=half, status=np.empty(n, dtype=np.int32))
    np.testing.assert_array_equal(out, half)


def test_held_arrays_and_views_are_never_overwritten():
    n = 300_000
    theta = np.linspace(0.0, 2 * np.pi, n)
    kernels.release_spares()
    a, sa = fourbar_kernel.fourbar_exact(theta, *LINK)
    a_copy = a.copy()
    b, sb = fourbar_kernel.fourbar_exact(theta + 1.0, *LINK)        # a is held: new memory
    assert not np.shares_memory(a, b) and not np.shares_memory(sa, sb)
    np.testing.assert_array_equal(a, a_copy)
    col = b[:, 7]                                            # only a view of b survives
    col_copy = col.copy()
    del b, sb
    c, _ = fourbar_kernel.fourbar_exact(theta + 2.0, *LINK)
    assert not np.shares_memory(c, col)
    np.testing.assert_array_equal(col, col_copy)


def test_small_outputs_are_not_kept():
    theta = np.linspace(0.0, 1.0, 100)
    kernels.release_spares()
    out, _ = fourbar_kernel.fourbar_exact(theta, *LINK)
    assert out.nbytes < kernels.SPARE_MIN_BYTES and not kernels._spares
