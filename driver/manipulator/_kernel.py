"""The manipulator study's kernel wrappers: manipulator.f90 (IK, Jacobian, indices, Craig torques, positioning errors) and
manipulator_summary.f90 (the batch design summary).

Thin wrappers over the study's modules of the compiled extension (loaded once by
:mod:`driver._fortran`): inputs are converted once to Fortran-ordered float64 (f2py would
otherwise copy C-ordered 2-D arrays silently), nothing is looped in Python, numpy arrays come
back.  Each kernel's physics and units are documented in its Fortran source.
"""
from __future__ import annotations

from enum import IntEnum
from typing import TYPE_CHECKING

import numpy as np

from driver._docs import fill_doc
from driver._fortran import KernelStatus, farray

if TYPE_CHECKING:   # the study's modules of the extension, typed (generated: tools/gen_kernel_stub.py)
    from driver.manipulator import _kernels
else:
    from driver._fortran import _kernels

__all__ = ['ManipulatorStatus', 'Torque', 'Index', 'SummaryParam', 'MANIPULATOR_PASSES', 'MANIPULATOR_STATUS',
           'manipulator_arm_states', 'manipulator_torques', 'manipulator_ik', 'manipulator_design_indices',
           'manipulator_position_errors', 'manipulator_design_summaries', 'MANIPULATOR_SUMMARY_PARAMS',
           'MANIPULATOR_SUMMARY_COLUMNS']


class ManipulatorStatus(KernelStatus):
    """Status of each point of the 2R arm's inverse kinematics (fortran/manipulator.f90 ``st_*``).

    A result of the point, never an error of the call.
    """

    ok = int(_kernels.manipulator.st_ok), "ok"
    unreachable = int(_kernels.manipulator.st_unreachable), "unreachable", "the point lies outside the arm's reach"
    degenerate = int(_kernels.manipulator.st_degenerate), "degenerate", "a link of no length, or the point at the base"


#: the 2R kernels' status codes by name (``MANIPULATOR_STATUS["ok"]``): :class:`ManipulatorStatus`
MANIPULATOR_STATUS: type[ManipulatorStatus] = ManipulatorStatus


# ----------------------------------------------------------------------------- the kernels' column layouts

class Torque(IntEnum):
    """Columns of the joint torques [N m] (:func:`manipulator_torques`, :func:`manipulator_arm_states`).
    """

    TAU1 = 0
    TAU2 = 1


class Index(IntEnum):
    """Columns of :func:`manipulator_design_indices`'s ``ri``.

    The robustness indices RI1, RI2, RI3 (dimensionless).
    """

    RI1 = 0
    RI2 = 1
    RI3 = 2


class SummaryParam(IntEnum):
    """Columns of a :func:`manipulator_design_summaries` design.

    Link lengths l1, l2 [m], the target point [m], mass per length [kg/m], gravity [m/s^2], the
    tolerance bound [m].
    """

    L1 = 0
    L2 = 1
    TARGET_X = 2
    TARGET_Y = 3
    MASS_PER_LENGTH = 4
    GRAVITY = 5
    TOLERANCE_BOUND = 6


_doc = fill_doc(
    arm="""l1, l2 : float or array_like
        Link lengths, m.
    th1, th2 : float or array_like
        Joint angles, rad (th2 relative to link 1).
    qd : array_like, default (1.0, 1.0)
        Joint rates (th1', th2'), rad/s, a pair or (n, 2).
    qdd : array_like, default (1.0, 1.0)
        Joint accelerations (th1'', th2''), rad/s^2, a pair or (n, 2).
    m1, m2 : float or array_like, optional
        Link masses, kg; default ``mass_per_length`` times the length.
    g : float, default 9.8
        Gravitational acceleration along -y, m/s^2.
    mass_per_length : float, default 10.0
        Link mass per unit length for the default masses, kg/m.""",
)


def _col(x, n: int) -> np.ndarray:
    """``x`` (scalar or length-n) broadcast to a contiguous float64 vector of length n."""
    return farray(np.broadcast_to(np.asarray(x, dtype=np.float64), (n,)), 1)


def _pair(x, n: int) -> np.ndarray:
    """``x`` (pair or (n, 2)) broadcast to a Fortran-ordered (n, 2) float64 array."""
    return farray(np.broadcast_to(np.asarray(x, dtype=np.float64), (n, 2)), 2)


_Arrays8 = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]


def _arm_inputs(l1, l2, th1, th2, qd, qdd, m1, m2, mass_per_length: float) -> _Arrays8:
    """Kernel arguments of the 2R routines: every input broadcast to n rows, masses defaulted
    to ``mass_per_length`` times the link length."""
    n = max(np.size(l1), np.size(l2), np.size(th1), np.size(th2))
    l1v, l2v = _col(l1, n), _col(l2, n)
    m1v = _col(mass_per_length * l1v if m1 is None else m1, n)
    m2v = _col(mass_per_length * l2v if m2 is None else m2, n)
    return l1v, l2v, _col(th1, n), _col(th2, n), _pair(qd, n), _pair(qdd, n), m1v, m2v


@_doc
def manipulator_arm_states(l1, l2, th1, th2, qd=(1.0, 1.0), qdd=(1.0, 1.0), m1=None, m2=None,
                           g: float = 9.8, mass_per_length: float = 10.0,
                           out: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None = None):
    """Compute Jacobian, manipulability, condition number and torques of 2R configurations.

    Inputs broadcast to n rows.

    Parameters
    ----------
    %(arm)s
    out : tuple of numpy.ndarray, optional
        (jac, w, kappa, tau) Fortran-ordered float64 buffers of the shapes returned, reused
        across calls (large fresh arrays cost page faults that can exceed the kernel's own
        time); overwritten and returned.

    Returns
    -------
    jac : numpy.ndarray
        (n, 4): J11, J12, J21, J22 of eq. 4.18, m.
    w : numpy.ndarray
        (n,) manipulability |det J|, m^2.
    kappa : numpy.ndarray
        (n,) condition number sigma_max/sigma_min, dimensionless (0 where J is singular).
    tau : numpy.ndarray
        (n, 2) joint torques, N m.

    Raises
    ------
    ValueError
        ``out`` of the wrong shapes, type or order (f2py would work on hidden copies).
    """
    args = _arm_inputs(l1, l2, th1, th2, qd, qdd, m1, m2, mass_per_length)
    n = args[0].shape[0]
    shapes = ((n, 4), (n,), (n,), (n, 2))
    if out is None:
        out = (np.empty(shapes[0], dtype=np.float64, order="F"), np.empty(shapes[1], dtype=np.float64, order="F"),
               np.empty(shapes[2], dtype=np.float64, order="F"), np.empty(shapes[3], dtype=np.float64, order="F"))
    elif len(out) != 4 or not all(isinstance(a, np.ndarray) and a.flags.f_contiguous and a.dtype == np.float64
                                  and a.shape == shp for a, shp in zip(out, shapes)):
        raise ValueError(f"out must be four Fortran-ordered float64 arrays of shapes {shapes}; "
                         "f2py would otherwise work on hidden copies")
    return _kernels.manipulator.arm_states(*args, float(g), *out)


@_doc
def manipulator_torques(l1, l2, th1, th2, qd=(1.0, 1.0), qdd=(1.0, 1.0), m1=None, m2=None,
                        g: float = 9.8, mass_per_length: float = 10.0) -> np.ndarray:
    """Compute the joint torques of Craig's point-mass 2R arm (report eqs 2.52/2.53).

    Parameters
    ----------
    %(arm)s

    Returns
    -------
    numpy.ndarray
        (n, 2) joint torques, N m.
    """
    return _kernels.manipulator.craig_torques(*_arm_inputs(l1, l2, th1, th2, qd, qdd, m1, m2, mass_per_length),
                                              float(g))


def manipulator_ik(l1, l2, x, y, branch: int = 1) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Solve the inverse kinematics of 2R arms for target points on one elbow branch.

    Parameters
    ----------
    l1, l2 : float or array_like
        Link lengths, m.
    x, y : float or array_like
        Target points, m (base at the origin).
    branch : int, default 1
        Elbow branch: +1 gives th2 >= 0, -1 gives th2 <= 0.

    Returns
    -------
    th1, th2 : numpy.ndarray
        Joint angles, rad (0 where the status is not ok).
    status : numpy.ndarray
        Per row: 0 ok, 1 out of reach, 2 degenerate (zero link or target at the base).
    """
    n = max(np.size(l1), np.size(l2), np.size(x), np.size(y))
    return _kernels.manipulator.inverse_kin(_col(l1, n), _col(l2, n), _col(x, n), _col(y, n),
                                            int(branch))


def manipulator_design_indices(x, y, l1, l2) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Compute the robustness indices of designs for the workspace points.

    Parameters
    ----------
    x, y : array_like
        Workspace points, m.
    l1, l2 : float or array_like
        Link lengths of the nd designs, m.

    Returns
    -------
    ri : numpy.ndarray
        (nd, 3): RI1 = sigma_max/sigma_min (0 when sigma_min = 0), RI2 = sigma_max
        (eq. 2.25), RI3 = sigma_max + ||J_x||_F, all dimensionless (J_x the sensitivity of
        the positions to the link lengths).
    sum_c2 : numpy.ndarray
        (nd,) sum of cos(th2_i) over the points, dimensionless.
    reach : numpy.ndarray
        (nd,) 1 when the design reaches every point, else 0.
    """
    x, y = farray(np.atleast_1d(x), 1), farray(np.atleast_1d(y), 1)
    nd = max(np.size(l1), np.size(l2))
    return _kernels.manipulator.design_indices(x, y, _col(l1, nd), _col(l2, nd))


def manipulator_position_errors(th1, th2, dl) -> np.ndarray:
    """Compute the positioning errors of an arm for link-length errors.

    Parameters
    ----------
    th1, th2 : array_like
        Joint angles at the workspace points, rad.
    dl : array_like
        (ns, 2) link-length errors, m.

    Returns
    -------
    numpy.ndarray
        (ns, 2), m: column 0 the global norm over all points stacked (Caro), column 1 the
        largest error at a single point.
    """
    th1, th2 = farray(np.atleast_1d(th1), 1), farray(np.atleast_1d(th2), 1)
    return _kernels.manipulator.position_errors(th1, th2, farray(dl, 2))


#: columns of the parameter matrix of :func:`manipulator_design_summaries` by name: :class:`SummaryParam`
MANIPULATOR_SUMMARY_PARAMS = tuple(c.name.lower() for c in SummaryParam)
#: columns of its result (fortran/manipulator_summary.f90)
MANIPULATOR_SUMMARY_COLUMNS = ("ri1", "ri2", "ri3", "sum_c2", "reach", "target_status", "theta1_deg", "theta2_deg",
                               "tau1", "tau2", "reaches_points", "dl1", "dl2", "mc_max")


#: pass bits of manipulator_design_summaries (fortran/manipulator_summary.f90 ds_*)
MANIPULATOR_PASSES = {k: int(getattr(_kernels.manipulator_summary, f"ds_{k}")) for k in
                      ("indices", "target", "tolerance")}


def manipulator_design_summaries(x, y, params, branch: int = 1, rates=(1.0, 1.0, 1.0, 1.0),
                                 measure: str = "global", unit=None, passes: int = 7) -> np.ndarray:
    """Summarise nd 2R arm designs for the workspace points in one kernel call.

    Result columns MANIPULATOR_SUMMARY_COLUMNS: RI1 (0 where sigma_min = 0), RI2, RI3, sum c2,
    reach (1/0, conditions 4.4), IK status at the target (MANIPULATOR_STATUS), theta1, theta2
    there [deg], tau1, tau2 [N m] (0 unless the status is ok), reaches_points (1 when the IK
    reaches every workspace point), tolerance half-widths dl1, dl2 [m] and the Monte Carlo
    maximum error [m] (the last three 0 unless reaches_points).  ``passes``: sum of
    MANIPULATOR_PASSES bits (indices: columns 0-4, target: 5-9, tolerance: 10-13); the
    columns of a pass not asked for are 0 (not computed).

    Parameters
    ----------
    x, y : array_like
        Workspace points, m.
    params : numpy.ndarray
        (nd, 7), columns ``MANIPULATOR_SUMMARY_PARAMS``: l1, l2 [m] (positive), the target
        point x, y [m], mass per length [kg/m], g [m/s^2] along -y, tolerance bound [m].
    branch : int, default 1
        The IK elbow branch (+1/-1).
    rates : array_like, default (1.0, 1.0, 1.0, 1.0)
        (th1', th2' [rad/s], th1'', th2'' [rad/s^2]).
    measure : {'global', 'per_point'}, default 'global'
        The positioning-error measure.
    unit : numpy.ndarray, optional
        (ns, 2) Monte Carlo samples in [-1, 1]^2 (the box is unit * dl); default one sample
        at (1, 1).
    passes : int, default 7
        Sum of ``MANIPULATOR_PASSES`` bits.

    Returns
    -------
    numpy.ndarray
        (nd, 14), columns ``MANIPULATOR_SUMMARY_COLUMNS`` (indices dimensionless, angles deg,
        torques N m, half-widths and errors m).

    Raises
    ------
    ValueError
        ``params`` without 7 columns or ``unit`` not (ns >= 1, 2).
    """
    x, y = farray(np.atleast_1d(x), 1), farray(np.atleast_1d(y), 1)
    params = farray(params, 2)
    if params.shape[1] != len(MANIPULATOR_SUMMARY_PARAMS):
        raise ValueError(f"params must have {len(MANIPULATOR_SUMMARY_PARAMS)} columns, got {params.shape[1]}")
    unit = farray(np.ones((1, 2)) if unit is None else unit, 2)
    if unit.shape[1] != 2 or unit.shape[0] < 1:
        raise ValueError(f"unit must have shape (ns >= 1, 2), got {unit.shape}")
    return _kernels.manipulator_summary.design_summaries(
        x, y, params, int(branch), farray(np.asarray(rates, dtype=np.float64).ravel(), 1),
        {"global": 0, "per_point": 1}[measure], unit, int(passes))
