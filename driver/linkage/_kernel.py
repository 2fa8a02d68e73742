"""The linkage study's kernel wrappers: fortran/linkage.f90 (any planar linkage: kinematics,
kinetostatics, turning-moment energy, batched summaries).

Thin wrappers over the compiled extension (loaded once by :mod:`driver._fortran`): inputs are
converted once to Fortran-ordered arrays, nothing is looped in Python.  The kernel's output
columns are named once, here, by IntEnums (as pymsis names its Fortran columns).
"""
from __future__ import annotations

import weakref
from collections.abc import Callable
from enum import IntEnum, IntFlag
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

from driver._fortran import KernelStatus, farray, kernel_status
from driver.linkage._kernel_program import Mechanism

if TYPE_CHECKING:   # the study's modules of the extension, typed (generated: tools/gen_kernel_stub.py)
    from driver.linkage import _kernels
else:
    from driver._fortran import _kernels

__all__ = ["reusable_call", "LinkageStatus", "CallStatus", "LinkCol", "PointCol", "SlideCol", "JointCol", "DriverCol",
           "ShakeCol", "EnergyCol",
           "SummaryCol", "Want", "Pass", "buffers", "Analysis", "analyse", "table_energy", "summaries", "summary_width",
           "NSUM_LINK", "NSUM_SLIDE", "NSUM_DYAD"]

_K = _kernels.linkage


class LinkageStatus(KernelStatus):
    """Status of a group at an input position (fortran/linkage.f90 ``st_*``).

    A result of the position, never an error of the call.
    """

    ok = int(_K.st_ok), "ok"
    no_assembly = int(_K.st_no_assembly), "cannot be assembled", "the group's two links cannot reach each other"
    toggle = (int(_K.st_toggle), "toggle (velocities unbounded)",
              "the group's two constraint directions are parallel: its rates are unbounded (set to 0)")
    indeterminate = (int(_K.st_indeterminate), "indeterminate",
                     "the group's attachments coincide: its position is not determined")
    unplaced = int(_K.st_unplaced), "not placed", "a link the group attaches to is not placed"


class CallStatus(KernelStatus):
    """Status of a call of analyse (fortran/linkage.f90 ``call_*``)."""

    ok = int(_K.call_ok), "ok"
    bad_args = (int(_K.call_bad_args), "bad arguments",
                "the packed program and the output arrays do not agree (a wrapper's mistake)", True)


class Want(IntFlag):
    """What analyse computes and writes besides the kinematics (bits).

    Bits of fortran/linkage.f90 ``want_*``.  An output not asked for is not written (zero in the
    arrays the wrapper makes); the status of each group is always written.

    ``KINEMATICS`` every kinematic output; ``JOINTS`` the points' positions, velocities and
    accelerations (what pylinkage's kinematics step gives); ``POINTS`` their positions only.
    """

    CONTINUITY = int(_K.want_continuity)
    FORCES = int(_K.want_forces)
    ANGLES = int(_K.want_angles)
    LINK_RATES = int(_K.want_link_rates)
    POINTS = int(_K.want_points)
    POINT_RATES = int(_K.want_point_rates)
    QUALITY = int(_K.want_quality)
    SLIDES = int(_K.want_slides)
    KINEMATICS = int(_K.want_kinematics)
    JOINTS = int(_K.want_points) | int(_K.want_point_rates)


class LinkCol(IntEnum):
    """Columns of a link's kinematics: angle [rad], angular velocity [rad/s], acceleration [rad/s^2]."""

    ANGLE = 0
    OMEGA = 1
    ALPHA = 2


class PointCol(IntEnum):
    """Columns of a point's kinematics [length, length/s, length/s^2]."""

    X = 0
    Y = 1
    VX = 2
    VY = 3
    AX = 4
    AY = 5


class SlideCol(IntEnum):
    """Columns of a slide: displacement along its guide, its rate and acceleration (relative)."""

    S = 0
    V = 1
    A = 2


class JointCol(IntEnum):
    """Columns of a group's joint forces: joints A, B, C each (fx, fy, couple) [N, N m]."""

    AX = 0
    AY = 1
    AQ = 2
    BX = 3
    BY = 4
    BQ = 5
    CX = 6
    CY = 7
    CQ = 8


class DriverCol(IntEnum):
    """Columns of the driver's forces.

    The reaction at its pivot or guide (fx, fy [N], couple [N m]) and the driving torque [N m]
    (crank) or force [N] (slider).
    """

    FX = 0
    FY = 1
    Q = 2
    DRIVE = 3


class ShakeCol(IntEnum):
    """Columns of the shaking force (x, y) [N] and moment about the origin [N m]."""

    FX = 0
    FY = 1
    M = 2


class EnergyCol(IntEnum):
    """Columns of table_energy's result."""

    MEAN_TORQUE = 0
    ENERGY_FLUCTUATION = 1
    FLYWHEEL_INERTIA = 2
    AT_MAX = 3
    AT_MIN = 4
    WORK = 5
    TORQUE_MAX = 6
    TORQUE_MIN = 7


class SummaryCol(IntEnum):
    """The head columns of a summary row (fortran/linkage.f90 summaries).

    Angles in rad, inputs in rad (crank) or length (slider).
    """

    ASSEMBLED_FRACTION = 0
    NOT_ASSEMBLED = 1
    TOGGLES = 2
    OUTPUT_MIN = 3
    OUTPUT_MIN_AT = 4
    OUTPUT_MAX = 5
    OUTPUT_MAX_AT = 6
    STROKE = 7
    TIME_RATIO = 8
    MU_MIN = 9
    MU_MAX = 10
    PRESSURE_MAX = 11
    TORQUE_PEAK = 12
    TORQUE_PEAK_AT = 13
    TORQUE_MEAN = 14
    TORQUE_RMS = 15
    SHAKING_FORCE_PEAK = 16
    SHAKING_MOMENT_PEAK = 17
    ENERGY_FLUCTUATION = 18
    FLYWHEEL_INERTIA = 19
    MU_MIN_AT = 20
    MU_MAX_AT = 21


NSUM_HEAD = int(_K.nsum_head)
NSUM_LINK, NSUM_SLIDE, NSUM_DYAD = int(_K.nsum_link), int(_K.nsum_slide), int(_K.nsum_dyad)
assert NSUM_HEAD == len(SummaryCol)


class Analysis(NamedTuple):
    """The kernel's answer at n inputs (positions first).

    Attributes
    ----------
    links : numpy.ndarray
        (n, 3, links) by :class:`LinkCol` (the ground first).
    points : numpy.ndarray
        (n, 6, points) by :class:`PointCol`.
    slides : numpy.ndarray
        (n, 3, slides) by :class:`SlideCol`.
    quality : numpy.ndarray
        (n, groups) transmission or pressure angle [rad].
    status : numpy.ndarray
        (n, groups) :class:`LinkageStatus`.
    joints : numpy.ndarray
        (n, 9, groups) by :class:`JointCol` (no rows without the force analysis).
    driver : numpy.ndarray
        (n, 4) by :class:`DriverCol` (no rows without the force analysis).
    shaking : numpy.ndarray
        (n, 3) by :class:`ShakeCol` (no rows without the force analysis).
    """

    links: np.ndarray
    points: np.ndarray
    slides: np.ndarray
    quality: np.ndarray
    status: np.ndarray
    joints: np.ndarray
    driver: np.ndarray
    shaking: np.ndarray


def buffers(mech: Mechanism, n: int, forces: bool | None = None) -> tuple[np.ndarray, ...]:
    """Make the output arrays of :func:`analyse` once, to pass as its ``out`` call after call.

    Parameters
    ----------
    mech : Mechanism
        The compiled mechanism.
    n : int
        Inputs per call.
    forces : bool, optional
        Room for the kinetostatics (default: when the mechanism has bodies).

    Returns
    -------
    tuple of numpy.ndarray
        The kernel's eight output arrays (Fortran order), zero; the ground's columns filled.
    """
    nl, npt, nd, ns = len(mech.links), len(mech.points), len(mech.dyads), mech.nslides
    nf = n if (mech.forces if forces is None else forces) else 1     # no forces: one unused row
    bufs = [np.zeros(shape, order="F") for shape in ((n, 3, nl), (n, 6, npt), (n, 3, ns), (n, nd))]
    bufs.append(np.zeros((n, nd), dtype=np.int32, order="F"))
    bufs += [np.zeros(shape, order="F") for shape in ((nf, 9, nd), (nf, 4), (nf, 3))]
    _fill_ground(mech, bufs[0], bufs[1])
    return tuple(bufs)


def analyse(mech: Mechanism, x: np.ndarray, forces: bool | None = None, continuity: bool = True,
            outputs: Want = Want.KINEMATICS, out: tuple[np.ndarray, ...] | None = None) -> Analysis:
    """Solve the mechanism at inputs ``x``: kinematics, and forces when it has bodies.

    Parameters
    ----------
    mech : Mechanism
        The compiled mechanism (:func:`driver.linkage._spec_model.compile_deck`).
    x : numpy.ndarray
        Inputs in order: crank angles [rad] or slides [length].
    forces : bool, optional
        Run the kinetostatics (default: when the mechanism has bodies).
    continuity : bool, default True
        Follow each group's assembly through change points (fortran/linkage.f90).
    outputs : Want, default Want.KINEMATICS
        The kinematic outputs to write (:class:`Want` bits ``ANGLES``, ``LINK_RATES``,
        ``POINTS``, ``POINT_RATES``, ``QUALITY``, ``SLIDES``); the others are not written (zero
        in arrays made here).  Everything is computed either way: this saves the stores.
    out : tuple of numpy.ndarray, optional
        Output arrays made by :func:`buffers` for this mechanism and ``len(x)`` inputs, reused
        (no allocation; the result's arrays are views of them).

    Returns
    -------
    Analysis
        The kernel's arrays (see :class:`Analysis`).
    """
    x = farray(x if type(x) is np.ndarray and x.ndim == 1 else np.atleast_1d(x), 1)
    do_forces = mech.forces if forces is None else forces
    want = (_CONTINUITY if continuity else 0) | (_FORCES if do_forces else 0) | (int(outputs) & _KINEMATICS)
    iprog, rprog = mech.program()
    n = x.shape[0]
    bufs = buffers(mech, n, do_forces) if out is None else out
    if bufs[0].shape[0] != n or (do_forces and bufs[5].shape[0] != n):
        raise ValueError(f"out: buffers for {bufs[0].shape[0]} inputs{'' if bufs[5].shape[0] > 1 else ' without forces'}"
                         f", called with {n}{' and forces' if do_forces else ''}")
    if out is not None:
        _fill_ground(mech, bufs[0], bufs[1])
    lk, pk, sk, qa, st, fk, fd, sh, info = _K.analyse(x, iprog, rprog, want, bufs[0], bufs[1], bufs[2], bufs[3], bufs[4],
                                                      bufs[5], bufs[6], bufs[7])
    if info:
        kernel_status(CallStatus, info, "linkage.analyse")
    if not do_forces:   # no force analysis: zero-size force arrays, not an unused row
        fk, fd, sh = fk[:0], fd[:0], sh[:0]
    return Analysis(lk, pk, sk if mech.slides else sk[:, :, :0], qa, st, fk, fd, sh)


#: the want bits as plain ints (no enum arithmetic per call)
_CONTINUITY, _FORCES, _KINEMATICS = int(Want.CONTINUITY), int(Want.FORCES), int(Want.KINEMATICS)


#: the ground columns of output buffers: id -> (weak reference to the buffer, what they hold)
_GROUND: dict[int, tuple[weakref.ref, tuple]] = {}


def _fill_ground(mech: Mechanism, lk: np.ndarray, pk: np.ndarray) -> None:
    """Write the ground's columns of the output buffers (the kernel leaves them: constant), unless
    the buffer is the very array an earlier call filled with exactly these (the weak reference
    proves it is the same living object, whose ground columns nothing else writes)."""
    ground = mech.ground_points()
    for buf, contents in ((lk, ("links",)), (pk, ground)):
        held = _GROUND.get(id(buf))
        if held is not None and held[0]() is buf and held[1] == contents:
            continue
        if buf is lk:
            buf[:, :, 0] = 0.0
        else:
            for j, u, v in ground:
                buf[:, 0, j] = u
                buf[:, 1, j] = v
                buf[:, 2:, j] = 0.0
        for key in [k for k, (ref, _) in _GROUND.items() if ref() is None]:
            del _GROUND[key]
        _GROUND[id(buf)] = (weakref.ref(buf), contents)


def reusable_call(mech: Mechanism, x: np.ndarray, forces: bool | None = None, continuity: bool = True,
                  outputs: Want = Want.KINEMATICS) -> Callable[[], tuple[np.ndarray, ...]]:
    """Make a call of the kernel on fixed inputs, its arguments prepared once.

    For benchmarks and callers that call again and again: the arguments :func:`analyse` would
    pass (the packed program, the want bits, output arrays made once by :func:`buffers`) bound
    once, as the four-bar's ``out=`` buffers are; each call is the Fortran call and its status
    check, nothing else.

    Parameters
    ----------
    mech : Mechanism
        The compiled mechanism.
    x : numpy.ndarray
        Inputs [rad or length].
    forces : bool, optional
        Run the kinetostatics (default: when the mechanism has bodies).
    continuity : bool, default True
        Follow each group's assembly.
    outputs : Want, default Want.KINEMATICS
        The outputs written (see :func:`analyse`).

    Returns
    -------
    callable
        ``call()`` runs the kernel and returns its output arrays (those of :class:`Analysis`,
        the force arrays with one unused row without forces).
    """
    x = farray(np.atleast_1d(x), 1)
    do_forces = mech.forces if forces is None else forces
    bufs = buffers(mech, x.shape[0], do_forces)
    iprog, rprog = mech.program()
    want = (_CONTINUITY if continuity else 0) | (_FORCES if do_forces else 0) | (int(outputs) & _KINEMATICS)
    args: tuple[Any, ...] = (x, iprog, rprog, want, *bufs)
    kernel: Callable[..., tuple[Any, ...]] = _K.analyse

    def call() -> tuple[np.ndarray, ...]:
        res = kernel(*args)
        if res[8]:
            kernel_status(CallStatus, int(res[8]), "linkage.analyse")
        return tuple(res[:8])

    return call


def table_energy(theta: np.ndarray, torque: np.ndarray, cs: float, omega: float) -> np.ndarray:
    """Energy of a turning-moment diagram (torque linear between the given angles).

    Parameters
    ----------
    theta : numpy.ndarray
        Crank angles of one cycle, ascending [rad].
    torque : numpy.ndarray
        Torque at each angle [N m].
    cs : float
        Coefficient of speed fluctuation [1].
    omega : float
        Mean crank speed [rad/s].

    Returns
    -------
    numpy.ndarray
        (8,) by :class:`EnergyCol`: mean torque [N m], energy fluctuation [J], flywheel inertia
        [kg m^2], angles of the energy's maximum and minimum [rad], the cycle's work [J], largest
        and smallest torque [N m].
    """
    return _K.table_energy(farray(theta, 1), farray(torque, 1), float(cs), float(omega))


def summary_width(mech: Mechanism) -> int:
    """Count the columns of a summary row.

    Parameters
    ----------
    mech : Mechanism
        The compiled mechanism.

    Returns
    -------
    int
        Head columns, then per moving link, per slide and per group.
    """
    return NSUM_HEAD + NSUM_LINK * (len(mech.links) - 1) + NSUM_SLIDE * mech.nslides + NSUM_DYAD * len(mech.dyads)


class Pass(IntFlag):
    """The passes of :func:`summaries` (fortran/linkage.f90 ``pass_*``).

    The output's extremes (stroke, time ratio), the transmission and pressure angles, the links'
    and slides' peaks, the forces.  A pass not run leaves its columns 0; the others are the same
    whichever run.
    """

    OUTPUT = int(_K.pass_output)
    QUALITY = int(_K.pass_quality)
    PEAKS = int(_K.pass_peaks)
    FORCES = int(_K.pass_forces)
    ALL = int(_K.pass_output) | int(_K.pass_quality) | int(_K.pass_peaks) | int(_K.pass_forces)


def summaries(mech: Mechanism, numbers: np.ndarray, nscan: int, periodic: bool, forces: bool | None = None,
              passes: Pass = Pass.ALL) -> np.ndarray:
    """Summarise many designs of one mechanism in one kernel call.

    Parameters
    ----------
    mech : Mechanism
        The mechanism (its integer program is shared by every design).
    numbers : numpy.ndarray
        (designs, numbers + 3): each design's :meth:`Mechanism.numbers`, then the scan's first
        input, span [rad or length] and the coefficient of speed fluctuation (C order: a
        design's numbers contiguous, as the kernel reads them).
    nscan : int
        Scan points of the cycle.
    periodic : bool
        A crank's cycle (no end point) or a slider's range (both ends).
    forces : bool, optional
        Include the kinetostatic figures (default: when the mechanism has bodies).
    passes : Pass, default Pass.ALL
        The passes to run (:class:`Pass`).

    Returns
    -------
    numpy.ndarray
        (designs, :func:`summary_width`) rows (fortran/linkage.f90 summaries, :class:`SummaryCol`).
    """
    i = mech.integers()
    want = int(Want.CONTINUITY) | (int(Want.FORCES) if (mech.forces if forces is None else forces) else 0)
    prm = farray(np.ascontiguousarray(numbers, dtype=np.float64).T, 2)   # (numbers, designs), no copy
    res = _K.summaries(prm, len(mech.links), mech.nslides, mech.reals()["tab"].shape[0], i["idrv"],
                       i["ipts"], i["igd"], i["idy"], i["ild"], i["ift"], int(nscan), int(bool(periodic)),
                       np.array(mech.output, dtype=np.int32), want, int(passes), summary_width(mech))
    return res.T
