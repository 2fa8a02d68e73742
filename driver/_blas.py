"""One BLAS thread while the tool computes, so results do not depend on the machine's cores.

scipy's SLSQP, ``least_squares`` and ``lstsq`` call OpenBLAS/LAPACK; with more than one BLAS
thread a reduction may be split differently, and the last digits of an optimum (and so the
printed tables) would change with the number of cores or ``OPENBLAS_NUM_THREADS``.  The tool's
linear algebra is small (a few dozen unknowns), so one thread costs nothing measurable, and the
committed outputs are those of one thread on every machine.

:func:`one_thread` limits the BLAS libraries loaded in this process (numpy's and scipy's
bundled OpenBLAS, MKL, BLIS) for the duration of a ``with`` block or a decorated call and
restores the previous setting afterwards: it is a scope, never a global switch.  Libraries
loaded inside a block are not limited by it (import what calls BLAS first, then open the block).
"""
from __future__ import annotations

import sys
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

__all__ = ["one_thread"]

_cache: dict[str, Any] = {}


def _controller() -> Any:
    """The threadpoolctl controller over the BLAS libraries loaded in this process now.

    scipy is not imported for it: a run that does not use scipy never loads scipy's BLAS, and
    importing scipy.linalg only to limit it cost a fifth of a second per deck (docs/performance.md,
    *Start-up*).  The list is rescanned when modules were imported since the last scan (a new
    extension may have brought a BLAS library); a module that imports scipy lazily, inside a
    block, opens a nested ``one_thread()`` after the import, which limits the new library too."""
    stamp = len(sys.modules)
    if _cache.get("stamp") != stamp:
        from threadpoolctl import ThreadpoolController
        _cache["controller"], _cache["stamp"] = ThreadpoolController(), stamp
    return _cache["controller"]


@contextmanager
def one_thread() -> Iterator[None]:
    """Within this block (or decorated call) every BLAS library loaded in the process uses one thread."""
    with _controller().limit(limits=1, user_api="blas"):
        yield
