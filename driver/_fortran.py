"""The loader of the private Fortran extension ``driver._kernels``, shared by every study.

It imports the extension once (with words on what to do when it is not built) and holds
:func:`farray` and the spare output buffers of large kernel outputs (:func:`release_spares`).
Each study wraps its own modules of the extension in its ``kernel.py``
(``driver.fourbar._kernel``, ``driver.ujoint._kernel``, ...; named in its ``Study.kernel``):
wrappers convert inputs once to Fortran-ordered float64 (f2py would otherwise copy C-ordered
2-D arrays silently), loop nothing in Python, and return numpy arrays.  Nothing else imports
``_kernels``.  Each kernel's physics and units are documented in ``fortran/<study>.f90``.
"""
from __future__ import annotations

import sys
import threading
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

__all__ = ["farray", "release_spares", "spare_buffer"]


def farray(x, ndim: int | None = None) -> np.ndarray:
    """``x`` as a Fortran-contiguous float64 array (no copy when it already is one)."""
    if type(x) is np.ndarray and x.dtype == np.float64 and x.flags.f_contiguous \
            and (ndim is None or x.ndim == ndim):
        return x          # fast path: the optimisers call kernels with such arrays (~1 us saved)
    a = np.asfortranarray(x, dtype=np.float64)
    if ndim is not None and a.ndim != ndim:
        raise ValueError(f"expected a {ndim}-D array, got shape {a.shape}")
    return a


# ----------------------------------------------------------------------------- output buffers

#: outputs at least this large [bytes] are kept for the next call of the same shape (smaller
#: ones come from numpy's own cache and cost no page faults)
SPARE_MIN_BYTES = 1 << 20
_spares: dict[str, np.ndarray] = {}
_spares_lock = threading.Lock()


def _refs(store: dict[str, np.ndarray], name: str) -> int:
    """References to ``store[name]`` as this function sees them (for :data:`_FREE_REFS`)."""
    a = store.get(name)
    return sys.getrefcount(a)


#: what :func:`_refs` counts for an array only ``store`` holds, measured on this interpreter (the
#: count of the dict entry, the local name and getrefcount's argument differs between versions)
_FREE_REFS = _refs({"probe": np.empty(1)}, "probe")


def spare_buffer(name: str, shape: tuple[int, ...], dtype: type[np.generic]) -> np.ndarray:
    """A fresh-to-the-caller output array of ``shape`` (Fortran order) for kernel output ``name``.

    A large output array (``SPARE_MIN_BYTES`` or more) is remembered; the next call of the
    same output and shape gets the same memory back when nobody holds it any more -- no
    reference to it or to a view of it (numpy views and pandas columns built without a copy
    hold their base) -- instead of new memory whose first touch costs a page fault per 4 KiB
    (at 10^6 four-bar positions, 88 MB: most of the call).  An array still held anywhere is
    never handed out again: the caller then gets new memory, which becomes the spare."""
    dt = np.dtype(dtype)
    if int(np.prod(shape)) * dt.itemsize < SPARE_MIN_BYTES:
        return np.empty(shape, dtype=dt, order="F")
    with _spares_lock:
        # held only by the dict (counted as for the probe array at import): nobody else has it
        if name in _spares and _refs(_spares, name) == _FREE_REFS:
            a = _spares[name]
            if a.shape == shape and a.dtype == dt:
                return a
        a = np.empty(shape, dtype=dt, order="F")
        _spares[name] = a
        return a


def release_spares() -> None:
    """Forget the remembered output arrays (their memory is freed once nobody holds them)."""
    with _spares_lock:
        _spares.clear()
