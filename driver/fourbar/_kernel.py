"""The fourbar study's kernel wrappers: fourbar.f90 (closed-loop and listing kinematics, coupler
point), fourbar_summary.f90 (the batch summary) and fourbar_forces.f90 (joint forces,
Berkof-Lowen balancing, the force summary).

Thin wrappers over the study's modules of the compiled extension (loaded once by
:mod:`driver._fortran`): inputs are converted once to Fortran-ordered float64 (f2py would
otherwise copy C-ordered 2-D arrays silently), nothing is looped in Python, numpy arrays come
back.  Each kernel's physics and units are documented in its Fortran source.
"""
from __future__ import annotations

from enum import IntEnum
from typing import TYPE_CHECKING

import numpy as np

from driver._fortran import KernelStatus, farray

if TYPE_CHECKING:   # the study's modules of the extension, typed (generated: tools/gen_kernel_stub.py)
    from driver.fourbar import _kernels
else:
    from driver._fortran import _kernels

__all__ = ['FourbarStatus', 'State', 'Listing', 'Point', 'Force', 'Prop', 'Counterweight', 'ForceParam', 'Summary',
           'SummaryParam', 'FOURBAR_PASSES', 'fourbar_listing', 'fourbar_exact', 'fourbar_coupler_point',
           'fourbar_summaries', 'fourbar_joint_forces', 'fourbar_berkof_lowen', 'fourbar_force_summaries',
           'FOURBAR_FORCE_SUMMARY_COLUMNS', 'FOURBAR_SUMMARY_COLUMNS', 'FOURBAR_GRASHOF', 'FOURBAR_STATUS',
           'fourbar_link_stresses']


class FourbarStatus(KernelStatus):
    """Status of each crank angle of the four-bar kernels (fortran/fourbar.f90 ``st_*``).

    A result of the position, never an error of the call.
    """

    ok = int(_kernels.fourbar.st_ok), "ok"
    no_assembly = int(_kernels.fourbar.st_no_assembly), "cannot assemble", "the loop does not close at this crank angle"
    toggle = int(_kernels.fourbar.st_toggle), "toggle", "coupler and rocker in line: the velocities are unbounded"
    indeterminate = int(_kernels.fourbar.st_indeterminate), "indeterminate", "the crank pin A lies on the rocker pivot O4"


#: the four-bar kernels' status codes by name (``FOURBAR_STATUS["no_assembly"]``): :class:`FourbarStatus`
FOURBAR_STATUS: type[FourbarStatus] = FourbarStatus


# ----------------------------------------------------------------------------- the kernels' column layouts
# Each kernel array's columns, named once (as pymsis names its model's outputs): ``out[:, State.XB]``.

class State(IntEnum):
    """Columns of :func:`fourbar_exact`'s states.

    Angles [rad], pin positions [length], angular velocities [rad/s] and accelerations [rad/s^2] of
    the coupler and the rocker, each named after its link (docs/fourbar.md, "Names").
    """

    COUPLER_ANGLE = 0
    ROCKER_ANGLE = 1
    TRANSMISSION_ANGLE = 2
    XA = 3
    YA = 4
    XB = 5
    YB = 6
    COUPLER_OMEGA = 7
    ROCKER_OMEGA = 8
    COUPLER_ALPHA = 9
    ROCKER_ALPHA = 10


class Listing(IntEnum):
    """Columns of :func:`fourbar_listing`'s table.

    Crank angle, epsl, phi, beta [whole deg, truncated], pin positions [length], omr, oms [rad/s]
    (single precision, as printed).
    """

    THETA = 0
    EPSL = 1
    PHI = 2
    BETA = 3
    XA = 4
    YA = 5
    XB = 6
    YB = 7
    OMR = 8
    OMS = 9


class Point(IntEnum):
    """Columns of :func:`fourbar_coupler_point`.

    Position [length], velocity [length/s] and acceleration [length/s^2] of a point fixed to the
    coupler.
    """

    X = 0
    Y = 1
    VX = 2
    VY = 3
    AX = 4
    AY = 5


class Force(IntEnum):
    """Columns of :func:`fourbar_joint_forces`.

    Input torque [N m], the force on each pin (x, y) [N], the shaking force (x, y) [N] and moment
    about O2 [N m].
    """

    INPUT_TORQUE = 0
    F_O2_X = 1
    F_O2_Y = 2
    F_A_X = 3
    F_A_Y = 4
    F_B_X = 5
    F_B_Y = 6
    F_O4_X = 7
    F_O4_Y = 8
    SHAKING_X = 9
    SHAKING_Y = 10
    SHAKING_MOMENT = 11


class Prop(IntEnum):
    """The 18 link and load properties of the force kernels.

    Masses [kg], inertias about the centres of mass [kg m^2], centre-of-mass distances [m] and
    angles [rad] of crank, coupler and rocker (each ``+ 0``, ``+ 1``, ``+ 2`` from its first),
    gravity [m/s^2], load torque on the rocker [N m], load force at the coupler point (x, y) [N],
    the point's u, v [m].
    """

    MASS = 0
    INERTIA = 3
    COM_DISTANCE = 6
    COM_ANGLE = 9
    GRAVITY = 12
    LOAD_TORQUE = 13
    LOAD_FORCE_X = 14
    LOAD_FORCE_Y = 15
    POINT_U = 16
    POINT_V = 17


#: the number of link and load properties (the length of a ``props`` array)
N_PROPS = Prop.POINT_V + 1


class Counterweight(IntEnum):
    """The six results of :func:`fourbar_berkof_lowen`.

    Crank counterweight mass x radius [kg m] and angle [rad], the rocker's the same, the two
    counterweight masses [kg].
    """

    CRANK_MR = 0
    CRANK_ANGLE = 1
    ROCKER_MR = 2
    ROCKER_ANGLE = 3
    CRANK_MASS = 4
    ROCKER_MASS = 5


class ForceParam(IntEnum):
    """The 31 columns of a :func:`fourbar_force_summaries` design.

    The lengths p, q, r, s [m], omega [rad/s], alpha [rad/s^2], the crank range [deg], branch, the 18
    :class:`Prop` (from ``PROPS``), the speed fluctuation, the balance flag and the two
    counterweight radii [m].
    """

    P = 0
    Q = 1
    R = 2
    S = 3
    OMEGA = 4
    ALPHA = 5
    START_DEG = 6
    STOP_DEG = 7
    BRANCH = 8
    PROPS = 9
    SPEED_FLUCTUATION = 27
    BALANCE = 28
    CRANK_CW_RADIUS = 29
    ROCKER_CW_RADIUS = 30


#: the number of columns of a force-summary design
N_FORCE_PARAMS = ForceParam.ROCKER_CW_RADIUS + 1


class Summary(IntEnum):
    """Columns of :func:`fourbar_summaries` (fortran/fourbar_summary.f90).

    Named as the summary's (``FOURBAR_SUMMARY_COLUMNS``): angles in deg, speeds in rad/s, flags 0/1.
    """

    GRASHOF = 0
    ASSEMBLABLE = 1
    ASSEMBLED_FRACTION = 2
    MU_MIN_DEG = 3
    MU_MIN_AT_DEG = 4
    MU_MAX_DEG = 5
    MU_MAX_AT_DEG = 6
    ROCKER_MIN_DEG = 7
    ROCKER_MIN_AT_DEG = 8
    ROCKER_MAX_DEG = 9
    ROCKER_MAX_AT_DEG = 10
    ROCKER_SWING_DEG = 11
    ROCKER_TURNS = 12
    TOGGLES_IN_RANGE = 13
    ROCKER_OMEGA_PEAK_RAD_S = 14
    ROCKER_OMEGA_PEAK_AT_DEG = 15
    COUPLER_OMEGA_PEAK_RAD_S = 16
    COUPLER_OMEGA_PEAK_AT_DEG = 17
    TIME_RATIO = 18


class SummaryParam(IntEnum):
    """The 8 columns of a :func:`fourbar_summaries` design, named as the deck keys they take.

    Lengths [length], crank speed [rad/s], the crank range [deg], branch (+1 open, -1 crossed).
    """

    FIXED_LINK = 0
    CRANK = 1
    COUPLER = 2
    ROCKER = 3
    OMEGA = 4
    START_DEG = 5
    STOP_DEG = 6
    BRANCH = 7


def fourbar_listing(p: float, q: float, r: float, s: float, omega: float,
                    start: int, step: int, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Run the published listing's program (single precision, as printed).

    Parameters
    ----------
    p, q, r, s : float
        Ground, crank, coupler and rocker length, in one length unit.
    omega : float
        Crank speed, rad/s.
    start, step : int
        First crank angle and step, whole deg.
    n : int
        Rows.

    Returns
    -------
    table : numpy.ndarray
        (n, 10): crank angle i [deg], epsl, phi, beta [whole deg, truncated], xa, ya, xb, yb
        [length], omr, oms [rad/s].
    status : numpy.ndarray
        (n,): 0 ok, 1 not assemblable, 2 velocities divide by zero.
    """
    table, status = _kernels.fourbar.listing_table(p, q, r, s, omega, int(start), int(step), int(n))
    return table, status


def fourbar_exact(theta: np.ndarray, p: float, q: float, r: float, s: float, omega: float,
                  alpha: float = 0.0, branch: int = 1, out: np.ndarray | None = None,
                  status: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Solve the closed loop at the given crank angles: positions, velocities, accelerations.

    Parameters
    ----------
    theta : numpy.ndarray
        Crank angles, rad.
    p, q, r, s : float
        Ground, crank, coupler and rocker length, in one length unit.
    omega : float
        Crank angular velocity, rad/s.
    alpha : float, default 0.0
        Crank angular acceleration, rad/s^2.
    branch : int, default 1
        +1 open, -1 crossed.
    out : numpy.ndarray, optional
        (n, 11) Fortran-ordered float64 buffer to reuse; overwritten.
    status : numpy.ndarray, optional
        (n,) int32 buffer to reuse; overwritten.

    Returns
    -------
    out : numpy.ndarray
        (n, 11): coupler angle, rocker angle, transmission angle [rad]; xa, ya, xb, yb
        [length]; coupler and rocker angular velocity [rad/s]; coupler and rocker angular
        acceleration [rad/s^2].
    status : numpy.ndarray
        (n,): 0 ok, 1 cannot be assembled, 2 toggle (velocities unbounded, returned as 0),
        3 indeterminate (A on O4).

    Raises
    ------
    ValueError
        A buffer of the wrong shape, type or order (f2py would work on a hidden copy).
    """
    theta = farray(np.atleast_1d(theta), 1)
    n = theta.shape[0]
    if out is None:
        out = np.empty((n, 11), order="F")
    elif not (out.flags.f_contiguous and out.dtype == np.float64 and out.shape == (n, 11)):
        raise ValueError("out must be a Fortran-ordered float64 array of shape (n, 11); "
                         "f2py would otherwise work on a hidden copy")
    if status is None:
        status = np.empty(n, dtype=np.int32)
    elif not (status.dtype == np.int32 and status.shape == (n,)):
        raise ValueError("status must be an int32 array of shape (n,)")
    return _kernels.fourbar.exact_states(theta, p, q, r, s, omega, alpha, int(branch), out, status)


#: columns of fourbar_summaries by name (fortran/fourbar_summary.f90): :class:`Summary`
FOURBAR_SUMMARY_COLUMNS = tuple(c.name.lower() for c in Summary)
#: class codes of fourbar_summaries (fortran/fourbar_summary.f90 gr_*): Grashof's classes, the
#: change-point ones (cp_), and the chains that cannot move (no_chain: no position exists;
#: flat_chain: the longest link equals the other three together)
FOURBAR_GRASHOF = {int(getattr(_kernels.fourbar_summary, f"gr_{k}")): k for k in
                   ("double_crank", "crank_rocker", "rocker_crank", "double_rocker", "triple_rocker",
                    "cp_double_crank", "cp_crank_rocker", "cp_rocker_crank", "cp_double_rocker",
                    "no_chain", "flat_chain")}


#: pass bits of fourbar_summaries (fortran/fourbar_summary.f90 pass_*); 'dense_scan' with
#: 'peaks' is the previous peak search (every 1 deg grid point), the baseline of bench and tests
FOURBAR_PASSES = {k: int(getattr(_kernels.fourbar_summary, f"pass_{k}")) for k in
                  ("transmission", "rocker", "peaks", "dense_scan")}


def fourbar_summaries(params: np.ndarray, passes: int = 7) -> np.ndarray:
    """Compute the headline figures of many four-bars in one kernel call.

    Parameters
    ----------
    params : numpy.ndarray
        (n, 8): fixed link p, crank q, coupler r, rocker s [length], crank speed [rad/s],
        first and last crank angle of the range [deg], branch (+1 open, -1 crossed).
    passes : int, default 7
        Sum of ``FOURBAR_PASSES`` bits; the columns of a pass not asked for are 0 (not
        computed), the others have the same bits whichever passes run (default: all three).

    Returns
    -------
    numpy.ndarray
        (n, 19), columns ``FOURBAR_SUMMARY_COLUMNS`` (angles in deg, speeds in rad/s, flags
        0/1; figures that do not exist are 0 -- mask them with 'assemblable' and
        'toggles_in_range').

    Raises
    ------
    ValueError
        ``params`` does not have 8 columns.
    """
    params = farray(params, 2)
    if params.shape[1] != 8:
        raise ValueError(f"params must have 8 columns, got {params.shape[1]}")
    return _kernels.fourbar_summary.summaries(params, int(passes))


def fourbar_coupler_point(theta: np.ndarray, states: np.ndarray, status: np.ndarray, q: float,
                          omega: float, alpha: float, u: float, v: float) -> np.ndarray:
    """Compute position, velocity and acceleration of a point fixed to the coupler.

    Parameters
    ----------
    theta : numpy.ndarray
        Crank angles, rad.
    states, status : numpy.ndarray
        The ``fourbar_exact`` results at ``theta``.
    q : float
        Crank length [length].
    omega : float
        Crank angular velocity, rad/s.
    alpha : float
        Crank angular acceleration, rad/s^2.
    u, v : float
        The point: u along A->B and v to its left [length].

    Returns
    -------
    numpy.ndarray
        (n, 6): x, y [length], vx, vy [length/s], ax, ay [length/s^2]; zero where the
        linkage is not placed.
    """
    theta = farray(np.atleast_1d(theta), 1)
    return _kernels.fourbar.coupler_point(theta, q, omega, alpha, u, v, farray(states, 2),
                                          np.asarray(status, dtype=np.int32))


def fourbar_joint_forces(states: np.ndarray, status: np.ndarray, p: float, q: float, r: float, s: float,
                         omega: float, alpha: float, props: np.ndarray) -> np.ndarray:
    """Compute joint forces, input torque and shaking from ``fourbar_exact`` results.

    Parameters
    ----------
    states, status : numpy.ndarray
        The ``fourbar_exact`` results (same omega and alpha).
    p, q, r, s : float
        Ground, crank, coupler and rocker length, m.
    omega : float
        Crank angular velocity, rad/s.
    alpha : float
        Crank angular acceleration, rad/s^2.
    props : numpy.ndarray
        (18,): masses [kg], inertias about the centres of mass [kg m^2], com distances [m]
        and angles [rad] of crank, coupler, rocker; gravity [m/s^2] (along -y); load torque
        on the rocker [N m]; load force at the coupler point [N]; the point's u, v [m].

    Returns
    -------
    numpy.ndarray
        (n, 12): input torque [N m]; F_O2, F_A, F_B, F_O4 (x, y) [N]; shaking force (x, y)
        [N]; shaking moment about O2 [N m] (fortran/fourbar_forces.f90).  Zero where status
        is not ok.

    Raises
    ------
    ValueError
        ``props`` does not have 18 values.
    """
    props = np.ascontiguousarray(props, dtype=np.float64)
    if props.shape != (N_PROPS,):
        raise ValueError(f"props must have {N_PROPS} values, got shape {props.shape}")
    return _kernels.fourbar_forces.joint_forces(farray(states, 2), np.asarray(status, dtype=np.int32),
                                                p, q, r, s, omega, alpha, props)


def fourbar_berkof_lowen(q: float, r: float, s: float, props: np.ndarray,
                         radii: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
    """Compute the Berkof-Lowen counterweights on crank and rocker that cancel the shaking force.

    Parameters
    ----------
    q, r, s : float
        Crank, coupler and rocker length, m.
    props : numpy.ndarray
        (18,) link and load properties, as for ``fourbar_joint_forces``.
    radii : tuple of float
        Counterweight radii on crank and rocker, m.

    Returns
    -------
    props : numpy.ndarray
        (18,) properties of the balanced linkage.
    cw : numpy.ndarray
        (6,): crank counterweight mass x radius [kg m] and angle [rad], rocker the same, the
        two counterweight masses [kg].
    """
    return _kernels.fourbar_forces.berkof_lowen(q, r, s, np.asarray(props, dtype=np.float64),
                                                np.asarray(radii, dtype=np.float64))


def fourbar_link_stresses(states: np.ndarray, status: np.ndarray, p: float, q: float, r: float, s: float,
                          alpha: float, props: np.ndarray, forces: np.ndarray, section: np.ndarray) -> np.ndarray:
    """Compute the peak normal stress in each moving link from the joint forces.

    Each link is a straight prismatic bar between its pins carrying the loads of the force
    analysis's free body where they act (pin forces, driver and load torques, its inertia force
    and weight at its centre of mass, the load force at the coupler point); the peak of
    |N|/A + |M|/Z along it (fortran/fourbar_forces.f90 ``link_stresses``).

    Parameters
    ----------
    states, status : numpy.ndarray
        The ``fourbar_exact`` results.
    p, q, r, s : float
        Ground, crank, coupler and rocker length, m.
    alpha : float
        Crank angular acceleration, rad/s^2.
    props : numpy.ndarray
        (18,) link and load properties, as for ``fourbar_joint_forces``.
    forces : numpy.ndarray
        (n, 12) ``fourbar_joint_forces`` of the same states and props.
    section : numpy.ndarray
        (6,): the section areas of crank, coupler, rocker [m^2], then their elastic section
        moduli for in-plane bending [m^3].

    Returns
    -------
    numpy.ndarray
        (n, 3): the peak normal stress in crank, coupler and rocker [Pa]; zero where the status
        is not ok.

    Raises
    ------
    ValueError
        ``section`` does not have 6 positive values.
    """
    section = np.ascontiguousarray(section, dtype=np.float64)
    if section.shape != (6,) or not np.all(section > 0):
        raise ValueError(f"section must be 6 positive values (areas, moduli), got {section!r}")
    return _kernels.fourbar_forces.link_stresses(farray(states, 2), np.asarray(status, dtype=np.int32), p, q, r, s,
                                                 alpha, np.asarray(props, dtype=np.float64), farray(forces, 2),
                                                 section)


#: columns of fourbar_force_summaries (fortran/fourbar_forces.f90 force_summaries)
FOURBAR_FORCE_SUMMARY_COLUMNS = ("defined_fraction", "torque_peak_Nm", "torque_peak_at_deg", "torque_mean_Nm",
                                 "torque_rms_Nm", "F_O2_peak_N", "F_A_peak_N", "F_B_peak_N", "F_O4_peak_N",
                                 "shaking_force_peak_N", "shaking_moment_peak_Nm", "energy_fluctuation_J",
                                 "flywheel_inertia_kgm2")


def fourbar_force_summaries(params: np.ndarray) -> np.ndarray:
    """Compute the force summaries of many four-bars in one kernel call.

    Parameters
    ----------
    params : numpy.ndarray
        (n, 31): p, q, r, s [m], omega [rad/s], alpha [rad/s^2], first and last crank angle
        [deg], branch (+1/-1), the 18 props of ``fourbar_joint_forces``, speed fluctuation
        [dimensionless], balance flag (1 = Berkof-Lowen counterweights first), counterweight
        radii [m].

    Returns
    -------
    numpy.ndarray
        (n, 13), columns ``FOURBAR_FORCE_SUMMARY_COLUMNS`` (units in their names: N, N m, J,
        kg m^2, deg).

    Raises
    ------
    ValueError
        ``params`` does not have 31 columns.
    """
    params = farray(params, 2)
    if params.shape[1] != N_FORCE_PARAMS:
        raise ValueError(f"params must have {N_FORCE_PARAMS} columns, got {params.shape[1]}")
    return _kernels.fourbar_forces.force_summaries(params)
