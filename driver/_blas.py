"""One BLAS thread while the tool computes, so results do not depend on the machine's cores.

scipy's SLSQP, ``least_squares`` and ``lstsq`` call OpenBLAS/LAPACK; with more than one BLAS
thread a reduction may be split differently, and the last digits of an optimum (and so the
printed tables) would change with the number of cores or ``OPENBLAS_NUM_THREADS``.  The tool's
linear algebra is small (a few dozen unknowns), so one thread costs nothing measurable, and the
committed outputs are those of one thread on every machine.

:func:`one_thread` limits the BLAS libraries loaded in this process (numpy's and scipy's
bundled OpenBLAS, MKL, BLIS) for the duration of a ``with`` block or a decorated call and
restores the previous setting afterwards: it is a scope, never a global switch.
"""
from __future__ import annotations

import functools
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

__all__ = ["one_thread"]


@functools.lru_cache(maxsize=1)
def _controller() -> Any:
    """The threadpoolctl controller of this process, built once after scipy's BLAS is loaded."""
    import numpy  # noqa: F401  (their BLAS libraries must be loaded before they are listed)
    import scipy.linalg  # noqa: F401
    from threadpoolctl import ThreadpoolController
    return ThreadpoolController()


@contextmanager
def one_thread() -> Iterator[None]:
    """Within this block (or decorated call) every BLAS library in the process uses one thread."""
    with _controller().limit(limits=1, user_api="blas"):
        yield
