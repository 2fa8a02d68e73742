"""The linkage study's kernel wrappers: fortran/linkage.f90 (any planar linkage: kinematics,
kinetostatics, turning-moment energy, batched summaries).

Thin wrappers over the compiled extension (loaded once by :mod:`driver._fortran`): inputs are
converted once to Fortran-ordered arrays, nothing is looped in Python.  The kernel's output
columns are named once, here, by IntEnums (as pymsis names its Fortran columns).
"""
from __future__ import annotations

import weakref
from collections.abc import Callable
from enum import IntEnum
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

from driver._fortran import KernelStatus, farray
from driver.linkage._kernel_program import Mechanism

if TYPE_CHECKING:   # the study's modules of the extension, typed (generated: tools/gen_kernel_stub.py)
    from driver.linkage import _kernels
else:
    from driver._fortran import _kernels

__all__ = ["reusable_call", "LinkageStatus", "LinkCol", "PointCol", "SlideCol", "JointCol", "DriverCol", "ShakeCol", "EnergyCol",
           "SummaryCol", "Want", "Analysis", "analyse", "table_energy", "summaries", "summary_width",
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


class Want(IntEnum):
    """What analyse computes besides the kinematics (bits)."""

    CONTINUITY = int(_K.want_continuity)
    FORCES = int(_K.want_forces)


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


def analyse(mech: Mechanism, x: np.ndarray, forces: bool | None = None, continuity: bool = True) -> Analysis:
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

    Returns
    -------
    Analysis
        The kernel's arrays (see :class:`Analysis`).
    """
    x = farray(np.atleast_1d(x), 1)
    want = (int(Want.CONTINUITY) if continuity else 0) | (int(Want.FORCES) if (mech.forces if forces is None
                                                                                else forces) else 0)
    i, r = mech.integers(), mech.reals()
    n, nl, npt, nd, ns = x.shape[0], len(mech.links), len(mech.points), len(mech.dyads), mech.nslides
    bufs = [np.zeros(shape, order="F") for shape in ((n, 3, nl), (n, 6, npt), (n, 3, ns), (n, nd))]
    st = np.zeros((n, nd), dtype=np.int32, order="F")
    _fill_ground(mech, bufs[0], bufs[1])
    nf = n if want & int(Want.FORCES) else 1     # no forces asked: one unused row
    fbufs = [np.zeros(shape, order="F") for shape in ((nf, 9, nd), (nf, 4), (nf, 3))]
    out = _K.analyse(x, i["idrv"], r["rdrv"], i["ipts"], r["rpts"],
                     i["igd"], r["rgd"], i["idy"], r["rdy"], r["rl"], r["grav"], i["ild"], r["rld"], r["rtq"],
                     i["ift"], r["tab"], r["rft"], want, bufs[0], bufs[1], bufs[2], bufs[3], st, fbufs[0],
                     fbufs[1], fbufs[2])
    a = Analysis(*out)
    if nf < n:   # no force analysis: zero-size force arrays, not garbage
        a = a._replace(joints=np.zeros((0, 9, nd)),
                       driver=np.zeros((0, 4)), shaking=np.zeros((0, 3)))
    if not mech.slides:
        a = a._replace(slides=a.slides[:, :, :0])
    return a


#: the ground columns of a reused output buffer: name -> (weak reference to the buffer, what they hold)
_GROUND: dict[str, tuple[weakref.ref, tuple]] = {}


def _fill_ground(mech: Mechanism, lk: np.ndarray, pk: np.ndarray) -> None:
    """Write the ground's columns of the output buffers (the kernel leaves them: constant), unless
    the buffer is the very array an earlier call filled with exactly these (a reused spare:
    the weak reference proves it is the same living object, whose ground columns nothing else
    writes)."""
    ground = tuple((j, u, v) for j, (_, link, u, v) in enumerate(mech.points) if link == 1)
    for name, buf, contents in (("lk", lk, ()), ("pk", pk, ground)):
        held = _GROUND.get(name)
        if held is not None and held[0]() is buf and held[1] == contents:
            continue
        if name == "lk":
            buf[:, :, 0] = 0.0
        else:
            for j, u, v in ground:
                buf[:, 0, j] = u
                buf[:, 1, j] = v
                buf[:, 2:, j] = 0.0
        _GROUND[name] = (weakref.ref(buf), contents)


def reusable_call(mech: Mechanism, x: np.ndarray, forces: bool | None = None,
                  continuity: bool = True) -> Callable[[], tuple]:
    """Make a call of the kernel on fixed inputs and output arrays made once.

    For benchmarks: the cost of the kernel itself, its outputs reused as the four-bar's
    ``out=`` buffers are.

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

    Returns
    -------
    callable
        ``call()`` runs the kernel and returns its raw outputs (the arrays of :class:`Analysis`).
    """
    x = farray(np.atleast_1d(x), 1)
    want = (int(Want.CONTINUITY) if continuity else 0) | (int(Want.FORCES) if (mech.forces if forces is None
                                                                                else forces) else 0)
    i, r = mech.integers(), mech.reals()
    n, nl, npt, nd, ns = x.shape[0], len(mech.links), len(mech.points), len(mech.dyads), mech.nslides
    nf = n if want & int(Want.FORCES) else 1
    bufs = [np.zeros(shape, order="F") for shape in ((n, 3, nl), (n, 6, npt), (n, 3, ns), (n, nd))]
    st = np.zeros((n, nd), dtype=np.int32, order="F")
    fbufs = [np.zeros(shape, order="F") for shape in ((nf, 9, nd), (nf, 4), (nf, 3))]
    _fill_ground(mech, bufs[0], bufs[1])
    args: tuple[Any, ...] = (x, i["idrv"], r["rdrv"], i["ipts"], r["rpts"], i["igd"], r["rgd"], i["idy"], r["rdy"], r["rl"],
            r["grav"], i["ild"], r["rld"], r["rtq"], i["ift"], r["tab"], r["rft"], want, *bufs, st, *fbufs)
    kernel: Any = _K.analyse
    return lambda: kernel(*args)


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


def summaries(mech: Mechanism, numbers: np.ndarray, nscan: int, periodic: bool, forces: bool | None = None) -> np.ndarray:
    """Summarise many designs of one mechanism in one kernel call.

    Parameters
    ----------
    mech : Mechanism
        The mechanism (its integer program is shared by every design).
    numbers : numpy.ndarray
        (designs, numbers + 3): each design's :meth:`Mechanism.numbers`, then the scan's first
        input, span [rad or length] and the coefficient of speed fluctuation.
    nscan : int
        Scan points of the cycle.
    periodic : bool
        A crank's cycle (no end point) or a slider's range (both ends).
    forces : bool, optional
        Include the kinetostatic figures (default: when the mechanism has bodies).

    Returns
    -------
    numpy.ndarray
        (designs, :func:`summary_width`) rows (fortran/linkage.f90 summaries, :class:`SummaryCol`).
    """
    i = mech.integers()
    want = int(Want.CONTINUITY) | (int(Want.FORCES) if (mech.forces if forces is None else forces) else 0)
    return _K.summaries(farray(numbers, 2), len(mech.links), mech.nslides, mech.reals()["tab"].shape[0], i["idrv"],
                        i["ipts"], i["igd"], i["idy"], i["ild"], i["ift"], int(nscan), int(bool(periodic)),
                        np.array(mech.output, dtype=np.int32), want, summary_width(mech))
