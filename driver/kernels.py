"""The one thin wrapper around the private Fortran extension ``driver._kernels``.

Nothing else imports ``_kernels``.  Wrappers convert inputs once to
Fortran-ordered float64 (f2py would otherwise copy C-ordered 2-D arrays
silently), loop nothing in Python, and return numpy arrays.  One section per
study; each kernel's physics and units are documented in ``fortran/<study>.f90``.
"""
from __future__ import annotations

import numpy as np

from driver import _kernels

__all__ = ["farray", "fourbar_listing", "fourbar_exact", "FOURBAR_STATUS",
           "UJOINT_MODELS", "UJOINT_OBJECTIVES", "ujoint_speed", "ujoint_objective",
           "ujoint_equivalent", "ujoint_geometry"]


def farray(x, ndim: int | None = None) -> np.ndarray:
    """``x`` as a Fortran-contiguous float64 array (no copy when it already is one)."""
    a = np.asfortranarray(x, dtype=np.float64)
    if ndim is not None and a.ndim != ndim:
        raise ValueError(f"expected a {ndim}-D array, got shape {a.shape}")
    return a


# ----------------------------------------------------------------------------- four-bar

#: status codes of the four-bar kernels (fortran/fourbar.f90)
FOURBAR_STATUS = {"ok": int(_kernels.fourbar.st_ok), "no_assembly": int(_kernels.fourbar.st_no_assembly),
                  "toggle": int(_kernels.fourbar.st_toggle)}


def fourbar_listing(p: float, q: float, r: float, s: float, omega: float,
                    start: int, step: int, n: int) -> tuple[np.ndarray, np.ndarray]:
    """The published listing's table (single precision, as printed): (n, 10) rows and status.

    Columns: crank angle i [deg], epsl, phi, beta [whole deg, truncated], xa, ya, xb, yb,
    omr, oms [rad/s].  Status: 0 ok, 1 not assemblable, 2 velocities divide by zero.
    """
    table, status = _kernels.fourbar.listing_table(p, q, r, s, omega, int(start), int(step), int(n))
    return table, status


def fourbar_exact(theta: np.ndarray, p: float, q: float, r: float, s: float, omega: float,
                  alpha: float = 0.0, branch: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """Closed-loop states at crank angles ``theta`` [rad]: (n, 11) array and status (n,).

    Columns: coupler angle, rocker angle, transmission angle [rad]; xa, ya, xb, yb [length];
    coupler and rocker angular velocity [rad/s]; coupler and rocker angular acceleration
    [rad/s^2].  ``branch`` +1 open, -1 crossed.  Status: 0 ok, 1 cannot be assembled,
    2 toggle (velocities unbounded, returned as 0).
    """
    theta = farray(np.atleast_1d(theta), 1)
    return _kernels.fourbar.exact_states(theta, p, q, r, s, omega, alpha, int(branch))


# ----------------------------------------------------------------------------- ujoint

#: model codes of fortran/ujoint.f90: the paper's eq. 13 as printed, the paper's text
#: (cumulative phases), the exact chain
UJOINT_MODELS = {"eq13": int(_kernels.ujoint.model_eq13), "cumulative": int(_kernels.ujoint.model_cumulative),
                 "exact": int(_kernels.ujoint.model_exact)}
#: objective codes of fortran/ujoint.f90
UJOINT_OBJECTIVES = {"mean_square": int(_kernels.ujoint.obj_mean_square), "rms": int(_kernels.ujoint.obj_rms),
                     "peak_to_peak": int(_kernels.ujoint.obj_peak_to_peak)}


def _ujoint_chain(beta, phi, rho) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """beta (n,), phi and rho (n-1,) [rad; rho None = coplanar] as float64 arrays."""
    beta = farray(np.atleast_1d(beta), 1)
    if beta.size == 1:   # f2py refuses a 0-length input for dimension(n-1); it takes a dummy of 1
        return beta, _ONE_ZERO, _ONE_ZERO
    ph = farray(np.atleast_1d(phi), 1)
    rh = np.zeros(ph.size) if rho is None else farray(np.atleast_1d(rho), 1)
    return beta, ph, rh


_ONE_ZERO = np.zeros(1)


def ujoint_speed(model: int, beta, phi, rho, theta) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Chain speed ratio at input angles ``theta`` [rad]: (R, dR/dtheta, output angle).

    beta (n,) joint angles [rad]; phi (n-1,) the paper's phases [rad] (pi/2 = yokes in
    phase); rho (n-1,) plane angles between successive joints [rad] or None (coplanar).
    R = omega_out/omega_in [-]; dR/dtheta [1/rad] times omega_in**2 [rad/s]**2 is the
    output angular acceleration [rad/s**2] at constant input speed; the output shaft angle
    [rad] is given by the exact model only (zeros for the paper models).
    """
    b, ph, rh = _ujoint_chain(beta, phi, rho)
    return _kernels.ujoint.chain_speed(int(model), b, ph, rh, farray(np.atleast_1d(theta), 1))


def ujoint_objective(model: int, kind: int, beta, phi, rho, m: int,
                     grad: bool = True) -> tuple[float, np.ndarray]:
    """Objective over ``m`` uniform input angles per revolution and its gradient.

    Returns (f, g): f dimensionless (mean (R-1)**2, its root, or max R - min R);
    g (2n-1,) = df/d(beta_1..beta_n [rad], phi_1..phi_(n-1) [rad]); zeros when ``grad``
    is False.
    """
    b, ph, rh = _ujoint_chain(beta, phi, rho)
    return _kernels.ujoint.chain_objective(int(model), int(kind), b, ph, rh, int(m), int(bool(grad)))


def ujoint_equivalent(model: int, beta, phi, rho, tol: float = 1e-7) -> tuple[float, float | None]:
    """Closed-form equivalent angles [rad]: (beta_e, beta_res or None).

    beta_e from the first-order phasor sum of the model's phasing; beta_res of the exact
    chain when every phi_k - rho_k is a multiple of pi/2 within ``tol`` [rad], else None.
    """
    b, ph, rh = _ujoint_chain(beta, phi, rho)
    be, br, st = _kernels.ujoint.chain_equivalent(int(model), b, ph, rh, float(tol))
    return float(be), (float(br) if st == int(_kernels.ujoint.st_ok) else None)


def ujoint_geometry(axes) -> tuple[np.ndarray, np.ndarray, int]:
    """Joint angles beta (n,) and plane angles rho (n-1,) [rad] of shaft directions ``axes``.

    axes: (n+1, 3) direction vectors, input shaft first (any length unit, nonzero).
    Status 0 ok, 2 an axis of zero length, 3 a joint angle of 90 deg or more.
    """
    a = farray(np.asarray(axes, dtype=np.float64).T, 2)
    beta, rho, status = _kernels.ujoint.chain_geometry(a)
    return beta, rho, int(status)
