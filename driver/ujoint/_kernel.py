"""The ujoint study's kernel wrappers: ujoint.f90 (chain speed, objective and gradient, equivalent angle, batch summaries,
3-D geometry).

Thin wrappers over the study's modules of the compiled extension (loaded once by
:mod:`driver._fortran`): inputs are converted once to Fortran-ordered float64 (f2py would
otherwise copy C-ordered 2-D arrays silently), nothing is looped in Python, numpy arrays come
back.  Each kernel's physics and units are documented in its Fortran source.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from driver._docs import fill_doc
from driver._fortran import KernelStatus, farray, kernel_status

if TYPE_CHECKING:   # the study's modules of the extension, typed (generated: tools/gen_kernel_stub.py)
    from driver.ujoint import _kernels
else:
    from driver._fortran import _kernels

__all__ = ['UjointStatus', 'UJOINT_PASSES', 'UJOINT_MODELS', 'UJOINT_OBJECTIVES', 'UJOINT_ROOTS', 'ujoint_speed',
           'ujoint_objective', 'ujoint_equivalent', 'ujoint_geometry', 'ujoint_summaries', 'UJOINT_SUMMARY_COLUMNS',
           'ujoint_jet', 'ujoint_roots', 'ujoint_input_torque', 'UJOINT_CV_TOL']


class UjointStatus(KernelStatus):
    """Status words of the chain kernels (fortran/ujoint.f90 ``st_*``).

    Of the resultant angle (chain_equivalent, a summary column) and of a 3-D chain's geometry
    (chain_geometry).
    """

    ok = int(_kernels.ujoint.st_ok), "ok"
    res_undefined = (int(_kernels.ujoint.st_res_undefined), "no resultant angle",
                     "a phase minus its plane angle is not a multiple of 90 deg")
    zero_axis = int(_kernels.ujoint.st_zero_axis), "zero axis", "a shaft direction of zero length"
    right_angle = int(_kernels.ujoint.st_right_angle), "right angle", "a joint angle of 90 deg or more"


#: model codes of fortran/ujoint.f90: the paper's eq. 13 as printed, the paper's text
#: (cumulative phases), the exact chain
UJOINT_MODELS = {"eq13": int(_kernels.ujoint.model_eq13), "cumulative": int(_kernels.ujoint.model_cumulative),
                 "exact": int(_kernels.ujoint.model_exact)}
#: objective codes of fortran/ujoint.f90
UJOINT_OBJECTIVES = {"mean_square": int(_kernels.ujoint.obj_mean_square), "rms": int(_kernels.ujoint.obj_rms),
                     "peak_to_peak": int(_kernels.ujoint.obj_peak_to_peak)}


_doc = fill_doc(
    chain="""beta : array_like
        (n,) joint angles, rad.
    phi : array_like
        (n-1,) the paper's phases, rad (pi/2 = yokes in phase).
    rho : array_like or None
        (n-1,) angles between the planes of successive joints, rad; None: coplanar.""",
)


def _ujoint_chain(beta, phi, rho) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """beta (n,), phi and rho (n-1,) [rad; rho None = coplanar] as float64 arrays."""
    beta = _vector(beta)
    if beta.size == 1:   # f2py refuses a 0-length input for dimension(n-1); it takes a dummy of 1
        return beta, _ONE_ZERO, _ONE_ZERO
    ph = _vector(phi)
    rh = np.zeros(ph.size) if rho is None else _vector(rho)
    return beta, ph, rh


_ONE_ZERO = np.zeros(1)


def _vector(x) -> np.ndarray:
    """``x`` (scalar or sequence) as a 1-D float64 array; no copy for one already."""
    if type(x) is np.ndarray and x.ndim == 1:
        return farray(x, 1)
    return farray(np.atleast_1d(x), 1)


@_doc
def ujoint_speed(model: int, beta, phi, rho, theta) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Compute the chain's speed ratio, its derivative and the output angle at input angles.

    Parameters
    ----------
    model : int
        Model code (``UJOINT_MODELS``).
    %(chain)s
    theta : array_like
        Input shaft angles, rad.

    Returns
    -------
    ratio : numpy.ndarray
        R = omega_out/omega_in, dimensionless.
    dratio : numpy.ndarray
        The derivative dR/dtheta, 1/rad; times omega_in**2 [(rad/s)**2] it is the output angular
        acceleration [rad/s**2] at constant input speed.
    angle : numpy.ndarray
        Output shaft angle, rad (the exact model only; zeros for the paper models).
    """
    b, ph, rh = _ujoint_chain(beta, phi, rho)
    return _kernels.ujoint.chain_speed(int(model), b, ph, rh, farray(np.atleast_1d(theta), 1))


def ujoint_objective(model: int, kind: int, beta, phi, rho, m: int,
                     grad: bool = True) -> tuple[float, np.ndarray]:
    """Evaluate the objective over ``m`` uniform input angles per revolution, and its gradient.

    Parameters
    ----------
    model : int
        Model code (``UJOINT_MODELS``).
    kind : int
        Objective code (``UJOINT_OBJECTIVES``).
    beta : array_like
        (n,) joint angles, rad.
    phi : array_like
        (n-1,) the paper's phases, rad.
    rho : array_like or None
        (n-1,) plane angles, rad; None: coplanar.
    m : int
        Input angles per revolution.
    grad : bool, default True
        Also compute the gradient.

    Returns
    -------
    f : float
        The objective, dimensionless (mean (R-1)**2, its root, or max R - min R).
    g : numpy.ndarray
        (2n-1,) df/d(beta_1..beta_n, phi_1..phi_(n-1)), 1/rad; zeros when ``grad`` is False.
    """
    b, ph, rh = _ujoint_chain(beta, phi, rho)
    return _kernels.ujoint.chain_objective(int(model), int(kind), b, ph, rh, int(m), int(bool(grad)))


@_doc
def ujoint_equivalent(model: int, beta, phi, rho, tol: float = 1e-7) -> tuple[float, float | None]:
    """Compute the closed-form equivalent angles of a chain.

    Parameters
    ----------
    model : int
        Model code (``UJOINT_MODELS``).
    %(chain)s
    tol : float, default 1e-7
        Tolerance on phi_k - rho_k being a multiple of pi/2, rad.

    Returns
    -------
    beta_e : float
        Equivalent angle from the first-order phasor sum of the model's phasing, rad.
    beta_res : float or None
        Resultant angle of the exact chain, rad, when every phi_k - rho_k is a multiple of
        pi/2 within ``tol``; else None.
    """
    b, ph, rh = _ujoint_chain(beta, phi, rho)
    be, br, st = _kernels.ujoint.chain_equivalent(int(model), b, ph, rh, float(tol))
    defined = kernel_status(UjointStatus, st, "ujoint.chain_equivalent") == UjointStatus.ok
    return float(be), (float(br) if defined else None)


#: columns of ujoint_summaries (fortran/ujoint.f90 chain_summaries)
UJOINT_SUMMARY_COLUMNS = ("objective", "ratio_min", "ratio_max", "dratio_abs_max", "beta_e", "beta_res",
                          "beta_res_status", "dratio_abs_max_at", "ratio_one_at")

#: a chain whose speed ratio stays within this of its range on the grid turns its output uniformly
#: but for round-off (fortran/ujoint.f90 cv_tol): no peak-acceleration angle, R = 1 throughout
UJOINT_CV_TOL = float(_kernels.ujoint.cv_tol)

#: what :func:`ujoint_roots` finds the roots of (fortran/ujoint.f90 root_*): R - 1, d2R/dtheta2
#: (the extremes of the output acceleration), d T_in/d theta (the extremes of the input torque)
UJOINT_ROOTS = {k: int(getattr(_kernels.ujoint, f"root_{k}")) for k in ("ratio_one", "accel_extreme",
                                                                        "torque_extreme")}


@_doc
def ujoint_jet(model: int, beta, phi, rho, theta) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Compute the chain's speed ratio and its first two derivatives in closed form.

    Parameters
    ----------
    model : int
        Model code (``UJOINT_MODELS``).
    %(chain)s
    theta : array_like
        Input shaft angles, rad (from the normal to joint 1's plane).

    Returns
    -------
    ratio : numpy.ndarray
        R = omega_out/omega_in, dimensionless.
    dratio : numpy.ndarray
        The derivative dR/dtheta, 1/rad (times omega_in**2: the output angular acceleration,
        rad/s**2).
    d2ratio : numpy.ndarray
        The second derivative d2R/dtheta2, 1/rad**2 (times omega_in**3: the rate of the output
        acceleration, rad/s**3).
    """
    b, ph, rh = _ujoint_chain(beta, phi, rho)
    return _kernels.ujoint.chain_jet(int(model), b, ph, rh, farray(np.atleast_1d(theta), 1))


@_doc
def ujoint_roots(model: int, what: str, beta, phi, rho, m: int,
                 coef: tuple[float, float] = (0.0, 0.0)) -> np.ndarray:
    """Find every root in one turn of R - 1, of d2R/dtheta2 or of the input torque's derivative.

    Each sign change between neighbours of the grid of ``m`` input angles is refined to 1e-12
    rad (Illinois regula falsi on the closed form of :func:`ujoint_jet`); two roots closer than
    one grid step are not told apart.

    Parameters
    ----------
    model : int
        Model code (``UJOINT_MODELS``).
    what : {'ratio_one', 'accel_extreme', 'torque_extreme'}
        R = 1, the extremes of dR/dtheta, or the extremes of the input torque
        (:func:`ujoint_input_torque`, with ``coef``).
    %(chain)s
    m : int
        Grid points per revolution.
    coef : tuple of float, default (0.0, 0.0)
        For ``'torque_extreme'``: J omega**2 [kg m**2/s**2] and the load torque [N m].

    Returns
    -------
    numpy.ndarray
        The roots, rad in [0, 2 pi) from the normal to joint 1's plane, ascending.
    """
    b, ph, rh = _ujoint_chain(beta, phi, rho)
    roots, count = _kernels.ujoint.chain_roots(int(model), b, ph, rh, int(UJOINT_ROOTS[what]),
                                               np.asarray(coef, dtype=np.float64), int(m))
    return np.array(roots[:count])


@_doc
def ujoint_input_torque(model: int, beta, phi, rho, theta, omega: float, inertia: float,
                        load: float) -> tuple[np.ndarray, np.ndarray]:
    """Compute the input torque that drives the output shaft's inertia and load at constant speed.

    By power balance through massless, frictionless joints, T_in omega_in = (J alpha_out +
    T_load) omega_out, so T_in = (J omega**2 dR/dtheta + T_load) R.

    Parameters
    ----------
    model : int
        Model code (``UJOINT_MODELS``).
    %(chain)s
    theta : array_like
        Input shaft angles, rad.
    omega : float
        Input shaft speed, rad/s.
    inertia : float
        Moment of inertia of the output shaft and its load, kg m**2.
    load : float
        Constant load torque on the output shaft, resisting its rotation, N m.

    Returns
    -------
    torque : numpy.ndarray
        Input torque, N m (positive drives the input shaft).
    dtorque : numpy.ndarray
        Its derivative dT_in/dtheta, N m/rad.
    """
    b, ph, rh = _ujoint_chain(beta, phi, rho)
    return _kernels.ujoint.chain_input_torque(int(model), b, ph, rh, farray(np.atleast_1d(theta), 1),
                                              float(omega), float(inertia), float(load))


#: pass bits of ujoint_summaries (fortran/ujoint.f90 sum_*)
UJOINT_PASSES = {k: int(getattr(_kernels.ujoint, f"sum_{k}")) for k in ("objective", "speed", "equivalent")}


def ujoint_summaries(model: int, kind: int, beta, phi, rho, m: int, tol: float = 1e-7, passes: int = 7,
                     theta0: float = 0.0) -> np.ndarray:
    """Compute the headline figures of many designs of one chain layout in one kernel call.

    Every design shares ``model``, the objective ``kind`` and the grid of ``m`` input angles
    per revolution.  Columns
    (UJOINT_SUMMARY_COLUMNS): the objective (as :func:`ujoint_objective` without gradient),
    min and max of R = omega_out/omega_in on the grid theta_j = 2 pi j/m (as
    :func:`ujoint_speed` there), max |dR/dtheta| [1/rad] over the turn (the grid's largest,
    refined to 1e-12 rad where d2R/dtheta2 changes sign beside it), beta_e and beta_res [rad],
    the status of beta_res (0: defined; as :func:`ujoint_equivalent` with ``tol`` [rad]), the
    input angle of the peak |dR/dtheta| and the first input angle where R = 1 [rad, from the
    normal to joint 1's plane; -1 when R - 1 keeps its sign].
    Each row has the same bits as those single-design calls.  ``passes``: sum of
    UJOINT_PASSES bits (objective: column 0, speed: 1-3 and 7-8, equivalent: 4-6); the columns of a
    pass not asked for are 0 (not computed).

    Parameters
    ----------
    model : int
        Model code (``UJOINT_MODELS``).
    kind : int
        Objective code (``UJOINT_OBJECTIVES``).
    beta : array_like
        (nd, n) joint angles, rad.
    phi : array_like
        (nd, n-1) the paper's phases, rad.
    rho : array_like or None
        (nd, n-1) plane angles, rad; None: coplanar.
    m : int
        Input angles per revolution.
    tol : float, default 1e-7
        Tolerance of beta_res's condition, rad.
    passes : int, default 7
        Sum of ``UJOINT_PASSES`` bits.
    theta0 : float, default 0.0
        The input angle the caller counts from, rad (from the normal to joint 1's plane): the
        peak's angle is the first of its images from it on, the angle of R = 1 the first root
        from it on.

    Returns
    -------
    numpy.ndarray
        (nd, 9), columns ``UJOINT_SUMMARY_COLUMNS`` (objective and R dimensionless,
        dR/dtheta 1/rad, angles rad).

    Raises
    ------
    ValueError
        ``beta`` is not a (designs, joints) array.
    """
    beta = np.asarray(beta, dtype=np.float64)
    if beta.ndim != 2 or beta.shape[1] < 1:
        raise ValueError(f"beta must be (designs, joints), got shape {beta.shape}")
    nd, n = beta.shape
    if nd == 0:
        return np.empty((0, len(UJOINT_SUMMARY_COLUMNS)))
    x = np.empty((nd, 3 * n - 2), dtype=np.float64, order="F")
    x[:, :n] = beta
    x[:, n:2 * n - 1] = phi
    x[:, 2 * n - 1:] = 0.0 if rho is None else rho
    return _kernels.ujoint.chain_summaries(model=int(model), kind=int(kind), n=n, nd=nd, x=x, m=int(m),
                                           tol=float(tol), theta0=float(theta0), passes=int(passes))


def ujoint_geometry(axes) -> tuple[np.ndarray, np.ndarray, UjointStatus]:
    """Compute joint angles and plane angles of a 3-D chain from its shaft directions.

    Parameters
    ----------
    axes : array_like
        (n+1, 3) shaft direction vectors, input shaft first (any length unit, nonzero).

    Returns
    -------
    beta : numpy.ndarray
        (n,) joint angles, rad.
    rho : numpy.ndarray
        (n-1,) angles between the planes of successive joints, rad.
    status : UjointStatus
        ``ok``, ``zero_axis`` (an axis of zero length) or ``right_angle`` (a joint angle of 90
        deg or more); an int, equal to the Fortran code.
    """
    a = farray(np.asarray(axes, dtype=np.float64).T, 2)
    beta, rho, status = _kernels.ujoint.chain_geometry(a)
    return beta, rho, kernel_status(UjointStatus, status, "ujoint.chain_geometry")
