"""The loader of the private Fortran extension ``driver._kernels``, shared by every study.

It imports the extension once (with words on what to do when it is not built) and holds
:func:`farray`.
Each study wraps its own modules of the extension in its ``kernel.py``
(``driver.fourbar._kernel``, ``driver.ujoint._kernel``, ...; named in its ``Study.kernel``):
wrappers convert inputs once to Fortran-ordered float64 (f2py would otherwise copy C-ordered
2-D arrays silently), loop nothing in Python, and return numpy arrays.  Nothing else imports
``_kernels``.  Each kernel's physics and units are documented in ``fortran/<study>.f90``.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

try:
    from driver import _kernels  # noqa: F401 - the studies' kernel modules take it from here
except ImportError as _exc:
    _root = Path(__file__).resolve().parents[1]
    if (_root / "meson.build").is_file() and (_root / "fortran").is_dir():
        raise ImportError(
            f"the Fortran kernels (driver._kernels) are not built in the source checkout {_root}, and "
            f"Python imports 'driver' from there because it is the current folder (or on sys.path). "
            f"Run from another folder to use an installed copy, or build this checkout in place: "
            f"bash .ci/setup (see docs/install.md)") from _exc
    raise ImportError(f"the Fortran kernels (driver._kernels) cannot be loaded: {_exc}; reinstall "
                      f"mechanism-driver (see docs/install.md)") from _exc

__all__ = ["farray"]


def farray(x, ndim: int | None = None) -> np.ndarray:
    """``x`` as a Fortran-contiguous float64 array (no copy when it already is one)."""
    if type(x) is np.ndarray and x.dtype == np.float64 and x.flags.f_contiguous \
            and (ndim is None or x.ndim == ndim):
        return x          # fast path: the optimisers call kernels with such arrays (~1 us saved)
    a = np.asfortranarray(x, dtype=np.float64)
    if ndim is not None and a.ndim != ndim:
        raise ValueError(f"expected a {ndim}-D array, got shape {a.shape}")
    return a
