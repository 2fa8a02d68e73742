"""The loader of the private Fortran extension ``driver._kernels``, shared by every study.

It imports the extension once (with words on what to do when it is not built) and holds
:func:`farray` and the one wrapper of every kernel's status word (:class:`KernelStatus`,
:func:`kernel_status`: a status a kernel returns is a member of its kernel's status table, and a
code that means the kernel refused its call becomes a :class:`driver._errors.KernelError`, a
``driver.DriverError``; as pyshtools turns every Fortran exit status into one exception type and
SciPy's ``_odepack_py`` keeps one message table per routine).
Each study wraps its own modules of the extension in its ``kernel.py``
(``driver.fourbar._kernel``, ``driver.ujoint._kernel``, ...; named in its ``Study.kernel``):
wrappers convert inputs once to Fortran-ordered float64 (f2py would otherwise copy C-ordered
2-D arrays silently), loop nothing in Python, and return numpy arrays.  Nothing else imports
``_kernels``.  Each kernel's physics and units are documented in ``fortran/<study>.f90``.
"""
from __future__ import annotations

from enum import IntEnum
from pathlib import Path
from typing import TypeVar

import numpy as np

from driver._errors import KernelError

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

__all__ = ["farray", "KernelStatus", "kernel_status"]


def farray(x, ndim: int | None = None) -> np.ndarray:
    """``x`` as a Fortran-contiguous float64 array (no copy when it already is one)."""
    if type(x) is np.ndarray and x.dtype == np.float64 and x.flags.f_contiguous \
            and (ndim is None or x.ndim == ndim):
        return x          # fast path: the optimisers call kernels with such arrays (~1 us saved)
    a = np.asfortranarray(x, dtype=np.float64)
    if ndim is not None and a.ndim != ndim:
        raise ValueError(f"expected a {ndim}-D array, got shape {a.shape}")
    return a


# ----------------------------------------------------------------------------- status words

class KernelStatus(IntEnum):
    """Base of a kernel's status table: one subclass per kernel, its members the Fortran module's
    status parameters (``st_no_assembly`` -> ``no_assembly``, so ``Status["no_assembly"]`` reads
    as the Fortran does), each with its words for reports and messages.

    A member is declared ``name = code, what, why, refused``: ``what`` a short heading, ``why`` the
    explanation, ``refused`` True for a code that means the kernel refused its call (bad
    arguments: a wrapper's mistake, never the deck's), which :func:`kernel_status` raises.  A
    status of each element of a result (a crank angle where the linkage does not assemble) is a
    result, named by the same table and not checked: the kernel writes only its table's codes.
    """

    what: str
    why: str
    refused: bool

    def __new__(cls, code: int, what: str = "", why: str = "", refused: bool = False) -> KernelStatus:
        member = int.__new__(cls, code)
        member._value_ = code
        member.what, member.why, member.refused = what, why, refused
        return member


S = TypeVar("S", bound=KernelStatus)


def kernel_status(codes: type[S], code: int, routine: str) -> S:
    """The member of status table ``codes`` for the status word ``code`` a kernel returned.

    Parameters
    ----------
    codes : type of KernelStatus
        The kernel's status table.
    code : int
        The status word.
    routine : str
        The kernel routine, ``'<fortran module>.<routine>'`` (named in the error).

    Returns
    -------
    KernelStatus
        The member (an int: it compares equal to the code).

    Raises
    ------
    driver._errors.KernelError
        The code means the kernel refused its call, or the table has no such code.
    """
    try:
        member = codes(int(code))
    except ValueError:
        raise KernelError(routine, int(code), f"not a status of {codes.__name__} "
                                              f"({', '.join(f'{m.value} {m.name}' for m in codes)})") from None
    if member.refused:
        raise KernelError(routine, member.value, f"{member.what}: {member.why}")
    return member

