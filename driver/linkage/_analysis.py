"""A ``&linkage`` deck through the kernel: the input positions, the kernel's arrays, the events
(assembly failures, toggles, dead centres) and the tidy long table.

No physics here: fortran/linkage.f90 solves everything; this module names and arranges it."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from driver._deck import Params
from driver.linkage import _kernel as kernel
from driver.linkage._kernel import Analysis, DriverCol, JointCol, LinkageStatus, LinkCol, PointCol, ShakeCol, SlideCol
from driver.linkage._kernel_program import Mechanism
from driver.linkage._spec_model import compile_deck

__all__ = ["Motion", "Event", "inputs", "solve", "events", "tidy_frame", "input_label", "JOINT_WORDS"]

#: what joints A, B, C of each group are (the kernel's JointCol order), by group type
JOINT_WORDS = {
    "rrr": ("{0} (link 1 at its first attachment)", "{1} (link 2 at its second attachment)",
            "{2} (link 1 on link 2)"),
    "rrp": ("{0} (rod at its pivot)", "guide {1} on the block (normal force, couple)", "{2} (rod on block)"),
    "prr": ("guide {0} on the block (normal force, couple)", "{1} (rod at its pivot)", "{2} (block on rod)"),
    "rpr": ("{0} (slotted link at its pivot)", "{1} (block at its pin)", "slot {2}: link 1 on the block "
            "(normal force, couple)"),
    "prp": ("guide {0} on block 1 (normal force, couple)", "guide {1} on block 2 (normal force, couple)",
            "{2} (block 1 on block 2)"),
}


@dataclass
class Motion:
    """The kernel's answer at a deck's inputs: ``x`` the inputs as the deck gives them (deg or
    length), ``xk`` as the kernel takes them (rad or length), and the :class:`Analysis`."""

    mech: Mechanism
    x: np.ndarray
    xk: np.ndarray
    a: Analysis

    @property
    def ok(self) -> np.ndarray:
        """Rows where every group is assembled with known rates."""
        return np.all(self.a.status == LinkageStatus.ok, axis=1)

    @property
    def placed(self) -> np.ndarray:
        """Rows where every group is placed (a toggle is placed)."""
        return np.all((self.a.status == LinkageStatus.ok) | (self.a.status == LinkageStatus.toggle), axis=1)


@dataclass(frozen=True)
class Event:
    """Something that happens to a group over the inputs: ``what`` ('no_assembly', 'toggle',
    'indeterminate', 'dead_centre', 'branch'), the group, and the inputs (first, last) of the
    run of positions where it holds (one input for a dead centre: where its output's rate
    changes sign, interpolated)."""

    what: str
    group: int
    name: str
    first: float
    last: float


def input_label(mech: Mechanism) -> tuple[str, str]:
    """(column name, unit) of the input: theta_deg for a crank, s for an input slider."""
    return ("theta_deg", "deg") if mech.driver == "crank" else ("s_input", "length")


def inputs(p: Params) -> np.ndarray:
    """The deck's input positions, start to stop by step (inclusive)."""
    n = int(math.floor((p.stop - p.start) / p.step + 1e-9)) + 1
    x = p.start + p.step * np.arange(max(n, 1), dtype=np.float64)
    if n > 1 and abs(x[-1] - p.stop) < 1e-9 * max(1.0, abs(p.stop)):
        x[-1] = p.stop
    return x


def solve(p: Params, x: np.ndarray | None = None, mech: Mechanism | None = None) -> Motion:
    """Run the kernel at the deck's inputs.

    Parameters
    ----------
    p : Params
        A validated ``&linkage`` deck.
    x : numpy.ndarray, optional
        Inputs in the deck's units (deg for a crank, length for an input slider), in order;
        default the deck's ``start``..``stop`` by ``step``.
    mech : Mechanism, optional
        The deck's compiled mechanism, when the caller has it.

    Returns
    -------
    Motion
        The inputs and the kernel's arrays (joint forces in the deck's order of each group).
    """
    mech = mech or compile_deck(p)
    x = inputs(p) if x is None else np.asarray(x, dtype=np.float64)
    xk = np.radians(x) if mech.driver == "crank" else x
    a = kernel.analyse(mech, xk)
    prr = [d for d, dy in enumerate(mech.dyads) if dy.kind == "prr"]
    if prr:   # the kernel solves PRR as RRP from its other end: joints back in the deck's order
        j = a.joints.copy()
        for d in prr:
            j[:, 0:3, d], j[:, 3:6, d], j[:, 6:9, d] = a.joints[:, 3:6, d], a.joints[:, 0:3, d], -a.joints[:, 6:9, d]
        a = a._replace(joints=j)
    return Motion(mech, x, xk, a)


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """(first, last) index of each run of True in ``mask``."""
    idx = np.flatnonzero(np.diff(np.concatenate([[0], mask.astype(np.int8), [0]])))
    return [(int(a), int(b) - 1) for a, b in zip(idx[::2], idx[1::2])]


def events(m: Motion) -> list[Event]:
    """Assembly failures, toggles and indeterminate positions of each group (runs of inputs),
    and the dead centres: the inputs where a group's output comes to rest and turns back (a
    slide's rate or its follower link's angular velocity changes sign; linearly interpolated)."""
    out: list[Event] = []
    st = m.a.status
    for d, dy in enumerate(m.mech.dyads):
        for what, code in (("no_assembly", LinkageStatus.no_assembly), ("toggle", LinkageStatus.toggle),
                           ("indeterminate", LinkageStatus.indeterminate)):
            for a, b in _runs(st[:, d] == code):
                out.append(Event(what, d + 1, dy.name, float(m.x[a]), float(m.x[b])))
        rate, accel = _follower_rate(m, d)
        ok = st[:, d] == LinkageStatus.ok
        w = m.mech.omega
        scale = math.radians(1.0) if m.mech.driver == "crank" else 1.0   # input unit -> kernel unit
        for k in range(len(m.x) - 1):
            if not (ok[k] and ok[k + 1]):
                continue
            r0, r1 = rate[k], rate[k + 1]
            if r0 == 0.0 and k > 0:
                continue
            if r0 == 0.0 or r0 * r1 < 0.0:
                h = m.x[k + 1] - m.x[k]
                t = 0.0 if r0 == 0.0 else _hermite_root(r0, r1, accel[k] / w * h * scale if w else 0.0,
                                                         accel[k + 1] / w * h * scale if w else 0.0)
                xc = float(m.x[k] + t * h)
                out.append(Event("dead_centre", d + 1, dy.name, xc, xc))
    return out


def _hermite_root(r0: float, r1: float, d0: float, d1: float) -> float:
    """Where the cubic Hermite interpolant on [0, 1] (end values r0, r1 of opposite signs, end
    slopes d0, d1 per unit of the interval) is zero; the linear zero when it has none inside."""
    a = 2 * r0 - 2 * r1 + d0 + d1
    b = -3 * r0 + 3 * r1 - 2 * d0 - d1
    roots = [z.real for z in np.roots([a, b, d0, r0]) if abs(z.imag) < 1e-12 and -1e-12 <= z.real <= 1 + 1e-12]
    lin = r0 / (r0 - r1)
    return float(min(roots, key=lambda z: abs(z - lin))) if roots else float(lin)


def _follower_rate(m: Motion, d: int) -> tuple[np.ndarray, np.ndarray]:
    """The rate whose sign change is a dead centre of group d, and its time derivative: its
    slide's rate (RRP, PRR, PRP's second block), the slotted link's angular velocity relative to
    its pivot's link (RPR), else the second link's angular velocity relative to the link its
    second attachment is on (RRR)."""
    dy = m.mech.dyads[d]
    L = m.a.links
    if dy.kind == "rpr":
        carrier = m.mech.points[dy.a1 - 1][1] - 1
        return L[:, LinkCol.OMEGA, dy.k1 - 1] - L[:, LinkCol.OMEGA, carrier], \
            L[:, LinkCol.ALPHA, dy.k1 - 1] - L[:, LinkCol.ALPHA, carrier]
    if dy.slide:
        j = dy.slide - 1 + (1 if dy.kind == "prp" else 0)
        return m.a.slides[:, SlideCol.V, j], m.a.slides[:, SlideCol.A, j]
    carrier = m.mech.points[dy.a2 - 1][1] - 1
    return L[:, LinkCol.OMEGA, dy.k2 - 1] - L[:, LinkCol.OMEGA, carrier], \
        L[:, LinkCol.ALPHA, dy.k2 - 1] - L[:, LinkCol.ALPHA, carrier]


def tidy_frame(m: Motion) -> pd.DataFrame:
    """The tidy long table: one row per input, element and quantity (element, quantity, value,
    unit); rows of a position where an element is not defined are left out."""
    mech, a = m.mech, m.a
    xname, xunit = input_label(mech)
    forces = mech.forces
    ang = "deg"
    pieces: list[pd.DataFrame] = []
    n = len(m.x)
    placed_rows = m.placed
    ok_rows = m.ok

    def add(element: str, quantity: str, values: np.ndarray, unit: str, mask: np.ndarray) -> None:
        if not mask.any():
            return
        pieces.append(pd.DataFrame({xname: m.x[mask], "element": element, "quantity": quantity,
                                    "value": np.asarray(values, dtype=np.float64)[mask], "unit": unit}))

    for i, name in enumerate(mech.links[1:], start=1):
        add(name, "angle", np.degrees(a.links[:, LinkCol.ANGLE, i]), ang, placed_rows)
        add(name, "omega", a.links[:, LinkCol.OMEGA, i], "rad/s", ok_rows)
        add(name, "alpha", a.links[:, LinkCol.ALPHA, i], "rad/s^2", ok_rows)
    for j, (name, link, _, _) in enumerate(mech.points):
        if link == 1:
            continue
        for col, q, unit in ((PointCol.X, "x", "length"), (PointCol.Y, "y", "length")):
            add(name, q, a.points[:, col, j], unit, placed_rows)
        for col, q, unit in ((PointCol.VX, "vx", "length/s"), (PointCol.VY, "vy", "length/s"),
                             (PointCol.AX, "ax", "length/s^2"), (PointCol.AY, "ay", "length/s^2")):
            add(name, q, a.points[:, col, j], unit, ok_rows)
    for j, (name, _, _) in enumerate(mech.slides):
        add(name, "slide", a.slides[:, SlideCol.S, j], "length", placed_rows)
        add(name, "slide_rate", a.slides[:, SlideCol.V, j], "length/s", ok_rows)
        add(name, "slide_acceleration", a.slides[:, SlideCol.A, j], "length/s^2", ok_rows)
    for d, dy in enumerate(mech.dyads):
        q = "transmission_angle" if dy.kind == "rrr" else "pressure_angle"
        add(dy.name, q, np.degrees(a.quality[:, d]), "deg", placed_rows)
        add(dy.name, "status", a.status[:, d].astype(np.float64), "1", np.ones(n, bool))
        if forces:
            for letter, c0 in (("A", JointCol.AX), ("B", JointCol.BX), ("C", JointCol.CX)):
                add(dy.name, f"F{letter}_x", a.joints[:, c0, d], "N", ok_rows)
                add(dy.name, f"F{letter}_y", a.joints[:, c0 + 1, d], "N", ok_rows)
                if dy.kind != "rrr":
                    add(dy.name, f"F{letter}_couple", a.joints[:, c0 + 2, d], "N m", ok_rows)
    if forces:
        drive = "torque" if mech.driver == "crank" else "force"
        add("driver", f"driving_{drive}", a.driver[:, DriverCol.DRIVE], "N m" if drive == "torque" else "N", ok_rows)
        add("driver", "reaction_x", a.driver[:, DriverCol.FX], "N", ok_rows)
        add("driver", "reaction_y", a.driver[:, DriverCol.FY], "N", ok_rows)
        add("frame", "shaking_force_x", a.shaking[:, ShakeCol.FX], "N", ok_rows)
        add("frame", "shaking_force_y", a.shaking[:, ShakeCol.FY], "N", ok_rows)
        add("frame", "shaking_moment", a.shaking[:, ShakeCol.M], "N m", ok_rows)
    frame = pd.concat(pieces, ignore_index=True) if pieces else pd.DataFrame(
        {xname: [], "element": [], "quantity": [], "value": [], "unit": []})
    frame.attrs["units"] = {xname: xunit, "value": "see the unit column"}
    return frame
