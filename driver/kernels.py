"""The one thin wrapper around the private Fortran extension ``driver._kernels``.

Nothing else imports ``_kernels``.  Wrappers convert inputs once to
Fortran-ordered float64 (f2py would otherwise copy C-ordered 2-D arrays
silently), loop nothing in Python, and return numpy arrays.  One section per
study; each kernel's physics and units are documented in ``fortran/<study>.f90``.
"""
from __future__ import annotations

import numpy as np

from driver import _kernels

__all__ = ["farray", "fourbar_listing", "fourbar_exact", "FOURBAR_STATUS"]


def farray(x, ndim: int | None = None) -> np.ndarray:
    """``x`` as a Fortran-contiguous float64 array (no copy when it already is one)."""
    a = np.asfortranarray(x, dtype=np.float64)
    if ndim is not None and a.ndim != ndim:
        raise ValueError(f"expected a {ndim}-D array, got shape {a.shape}")
    return a


# ----------------------------------------------------------------------------- four-bar

#: status codes of the four-bar kernels (fortran/fourbar.f90)
FOURBAR_STATUS = {"ok": int(_kernels.fourbar.st_ok), "no_assembly": int(_kernels.fourbar.st_no_assembly),
                  "toggle": int(_kernels.fourbar.st_toggle),
                  "indeterminate": int(_kernels.fourbar.st_indeterminate)}


def fourbar_listing(p: float, q: float, r: float, s: float, omega: float,
                    start: int, step: int, n: int) -> tuple[np.ndarray, np.ndarray]:
    """The published listing's table (single precision, as printed): (n, 10) rows and status.

    Columns: crank angle i [deg], epsl, phi, beta [whole deg, truncated], xa, ya, xb, yb,
    omr, oms [rad/s].  Status: 0 ok, 1 not assemblable, 2 velocities divide by zero.
    """
    table, status = _kernels.fourbar.listing_table(p, q, r, s, omega, int(start), int(step), int(n))
    return table, status


def fourbar_exact(theta: np.ndarray, p: float, q: float, r: float, s: float, omega: float,
                  alpha: float = 0.0, branch: int = 1, out: np.ndarray | None = None,
                  status: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Closed-loop states at crank angles ``theta`` [rad]: (n, 11) array and status (n,).

    Columns: coupler angle, rocker angle, transmission angle [rad]; xa, ya, xb, yb [length];
    coupler and rocker angular velocity [rad/s]; coupler and rocker angular acceleration
    [rad/s^2].  ``branch`` +1 open, -1 crossed.  Status: 0 ok, 1 cannot be assembled,
    2 toggle (velocities unbounded, returned as 0), 3 indeterminate (A on O_B).
    ``out`` (Fortran-ordered float64, (n, 11)) and ``status`` (int32, (n,)) may be passed
    to reuse buffers across calls; they are overwritten.
    """
    theta = farray(np.atleast_1d(theta), 1)
    n = theta.shape[0]
    if out is None:
        out = np.empty((n, 11), dtype=np.float64, order="F")
    if status is None:
        status = np.empty(n, dtype=np.int32)
    return _kernels.fourbar.exact_states(theta, p, q, r, s, omega, alpha, int(branch), out, status)
