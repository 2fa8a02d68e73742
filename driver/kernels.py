"""The one thin wrapper around the private Fortran extension ``driver._kernels``.

Nothing else imports ``_kernels``.  Wrappers convert inputs once to
Fortran-ordered float64 (f2py would otherwise copy C-ordered 2-D arrays
silently), loop nothing in Python, and return numpy arrays.  One section per
study; each kernel's physics and units are documented in ``fortran/<study>.f90``.
"""
from __future__ import annotations

import numpy as np

from driver import _kernels

__all__ = ["farray", "fourbar_listing", "fourbar_exact", "FOURBAR_STATUS", "SLIDERCRANK_STATUS",
           "slidercrank_simulate", "slidercrank_matrices", "slidercrank_rigid", "slidercrank_axial_force",
           "slidercrank_frequencies"]


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


# ----------------------------------------------------------------------------- slidercrank

#: status codes of the slider-crank kernel (fortran/slidercrank.f90)
SLIDERCRANK_STATUS = {"ok": int(_kernels.slidercrank.st_ok), "buckled": int(_kernels.slidercrank.st_buckled),
                      "diverged": int(_kernels.slidercrank.st_diverged),
                      "not_spd": int(_kernels.slidercrank.st_not_spd),
                      "bad_args": int(_kernels.slidercrank.st_bad_args)}
_SC_START = {"rest": 0, "quasistatic": 1, "given": 2}


def slidercrank_simulate(n_elements: int, crank_radius: float, rod_length: float, rho_a: float,
                         ea: float, ei: float, half_depth: float, slider_mass: float, omega: float,
                         dt: float, n_steps: int, rec_start: int, n_rec: int, alpha: float = 0.0,
                         beta: float = 0.0, start: str = "quasistatic", dynamic: bool = True,
                         geometric_stiffness: bool = False, fast: bool = True,
                         q_init: np.ndarray | None = None, qd_init: np.ndarray | None = None) -> dict:
    """Elastic connecting rod of a slider-crank, whole time loop in Fortran.

    SI units: lengths [m], rho_a mass per length [kg/m], ea [N], ei [N m^2], masses [kg],
    omega crank speed [rad/s] (theta2 = omega t from 0), dt [s].  alpha [1/s] and beta [s]
    are the Rayleigh coefficients (C = alpha M + beta K).  start: 'rest', 'quasistatic' or
    'given' (q_init, qd_init in the kernel's q ordering, 3*n_elements values [m, rad]).
    Records steps rec_start .. rec_start + n_rec - 1 (step 0 is the start).

    Returns a dict: eps_ax, eps_of (n_elements, n_rec) axial and outer-fibre strain [-];
    n_avg (n_elements, n_rec) element-averaged rigid-body axial force [N]; mid midpoint
    deflection from the chord [m]; slider position [m]; elong rod elongation [m];
    q_end, qd_end final state; status (a SLIDERCRANK_STATUS value) and fail_step.
    """
    nq = 3 * int(n_elements)
    q0 = farray(np.zeros(nq) if q_init is None else q_init, 1)
    qd0 = farray(np.zeros(nq) if qd_init is None else qd_init, 1)
    out = _kernels.slidercrank.simulate(
        int(n_elements), int(n_rec), crank_radius, rod_length, rho_a, ea, ei, half_depth, slider_mass,
        omega, dt, int(n_steps), int(rec_start), alpha, beta, _SC_START[start], int(bool(dynamic)),
        int(bool(geometric_stiffness)), int(bool(fast)), q0, qd0)
    names = ("eps_ax", "eps_of", "n_avg", "mid", "slider", "elong", "q_end", "qd_end", "status", "fail_step")
    res = dict(zip(names, out))
    res["status"], res["fail_step"] = int(res["status"]), int(res["fail_step"])
    return res


def slidercrank_matrices(n_elements: int, crank_radius: float, rod_length: float, rho_a: float,
                         ea: float, ei: float, slider_mass: float, theta2: float, omega: float = 0.0,
                         geometric_stiffness: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Banded mass and stiffness (LAPACK lower storage, shape (6, 3 n)) at crank angle theta2 [rad].

    The mass includes the slider mass on U_X; with geometric_stiffness the stiffness includes
    K_G of the rigid-body axial force at crank speed omega [rad/s].
    """
    mb, kb = _kernels.slidercrank.assemble_matrices(
        int(n_elements), 3 * int(n_elements), crank_radius, rod_length, rho_a, ea, ei, slider_mass,
        theta2, omega, int(bool(geometric_stiffness)))
    return mb, kb


def slidercrank_rigid(theta2: np.ndarray, omega: float, crank_radius: float, rod_length: float) -> np.ndarray:
    """Rigid kinematics at crank angles theta2 [rad], constant crank speed omega [rad/s]: (n, 7).

    Columns: theta3 [rad], theta3' [rad/s], theta3'' [rad/s^2], slider position x4 [m],
    slider acceleration A_h [m/s^2], crank-pin acceleration along and across the rod [m/s^2].
    """
    theta2 = farray(np.atleast_1d(theta2), 1)
    return _kernels.slidercrank.rigid_states(theta2, omega, crank_radius, rod_length)


def slidercrank_axial_force(theta2: np.ndarray, s: np.ndarray, omega: float, crank_radius: float,
                            rod_length: float, rho_a: float, slider_mass: float) -> np.ndarray:
    """Rigid-body axial force N [N] (tension positive) at stations s [m]: shape (len(s), len(theta2))."""
    theta2 = farray(np.atleast_1d(theta2), 1)
    s = farray(np.atleast_1d(s), 1)
    return _kernels.slidercrank.axial_force_at(theta2, s, omega, crank_radius, rod_length, rho_a, slider_mass)


def slidercrank_frequencies(rho_a: float, ea: float, ei: float, rod_length: float,
                            slider_mass: float) -> tuple[float, float, float]:
    """Closed forms: first bending (pinned-pinned) and first axial (fixed / slider mass) natural
    frequencies [rad/s], and the pinned-pinned Euler load pi^2 EI / L^2 [N]."""
    wb, wa, pe = _kernels.slidercrank.analytic_frequencies(rho_a, ea, ei, rod_length, slider_mass)
    return float(wb), float(wa), float(pe)
