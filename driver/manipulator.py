"""&manipulator: robust dimensional synthesis of a planar 2R arm (seed 004, chapter 4).

From a workspace given as points P_i (base A at the origin) the study computes

* the reach conditions |l1 - l2| <= r, l1 + l2 >= R (r, R = min, max d(A, P_i)), the robust
  circle C_rob: l1^2 + l2^2 = mean d^2 (RI2 = sqrt(n) on it), RI1/RI2/RI3 of any design,
  the iso-RI2 ellipse variables (Tables 4.1/4.3) and (l1, l2) pairs on C_rob (Table 4.2);
* the dexterity optimum (l2 = l1 sqrt(2)/2) and manipulability optimum (l1 = l2) on C_rob
  (Table 4.4);
* joint angles and Craig point-mass motor torques at a target point for the chosen designs
  (Tables 4.5-4.7) and along C_rob (Table 4.8; rows where the target is out of reach blank,
  with a note);
* tolerance synthesis: the largest box l +- dl whose positioning error stays within a bound
  (Caro's formulation, closed form and a corner-constrained SLSQP), checked by Monte Carlo.

``mode = 'report'`` applies the report's conventions (shared/notes/manipulator.md sec. 0):
C_rob radius rounded to 3 dp, C = radius^2 for Table 4.2 and round(radius^2, 2) for Table 4.8,
Table 4.5 theta2 printed as the interior angle 180 - acos(c2), Table 4.7 fed with the printed
Table 4.5 angles, Table 4.8 base angle round(atan2(y, x), 2 dp) - theta2.  ``mode = 'exact'``
uses mean d^2 itself, the IK joint angles on the chosen elbow branch at full precision.  In
report mode the .out lists every cell where the two modes differ, and why.

Physics (IK, Jacobian, indices, torques, positioning errors) is in fortran/manipulator.f90.
"""
from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from decimal import ROUND_HALF_UP, Decimal
from typing import Any

import numpy as np
import pandas as pd
from scipy.optimize import minimize

from driver import kernels
from driver.deck import GroupSpec, Key, Params, non_empty, positive
from driver.export import with_units
from driver.limits import Estimate
from driver.study import Figure, Result, keyword_run
from driver.table import Column, fortran_f, render_table

__all__ = ["SPEC", "run", "Workspace", "tolerance_box", "round_half_up", "REASONS", "NOT_REPRODUCIBLE", "TEXT_REASONS",
           "TIDY_NAMES", "TIDY_UNITS", "table_frame"]

STATUS = kernels.MANIPULATOR_STATUS


def _pair_check(v: Any) -> str | None:
    return None if len(v) == 2 else f"needs exactly two values (joint 1, joint 2), got {len(v)}"


def _min_one(v: Any) -> str | None:
    return None if v >= 1 else f"must be at least 1 (got {v})"


def _cross_check(p: Params) -> None:
    """Cross-key checks: every problem a DeckError naming the key."""
    if len(p.points_x) != len(p.points_y):
        raise p.error("points_y", f"gives {len(p.points_y)} coordinates but points_x gives "
                                  f"{len(p.points_x)}; each workspace point needs an x and a y")
    for i, (x, y) in enumerate(zip(p.points_x, p.points_y), 1):
        if x == 0.0 and y == 0.0:
            raise p.error("points_x", f"workspace point {i} is the base (0, 0); points must be "
                                      "at a positive distance from the base")
    if (p.designs_l1 is None) != (p.designs_l2 is None):
        missing = "designs_l2" if p.designs_l2 is None else "designs_l1"
        raise p.error(missing, "designs_l1 and designs_l2 must be given together "
                               "(or neither, for the optimum designs on C_rob)")
    if p.designs_l1 is not None:
        if len(p.designs_l1) != len(p.designs_l2):
            raise p.error("designs_l2", f"gives {len(p.designs_l2)} lengths but designs_l1 gives "
                                        f"{len(p.designs_l1)}")
        if p.design_names is not None and len(p.design_names) != len(p.designs_l1):
            raise p.error("design_names", f"gives {len(p.design_names)} names for "
                                          f"{len(p.designs_l1)} designs")
    elif p.design_names is not None:
        raise p.error("design_names", "only allowed with designs_l1/designs_l2")
    ndes = len(p.designs_l1) if p.designs_l1 is not None else 2
    if p.printed_angles_deg is not None and len(p.printed_angles_deg) != 2 * ndes:
        raise p.error("printed_angles_deg", f"needs theta1, theta2 for each of the {ndes} designs "
                                            f"({2 * ndes} values), got {len(p.printed_angles_deg)}")
    if (p.target_x is None) != (p.target_y is None):
        raise p.error("target_y" if p.target_y is None else "target_x",
                      "target_x and target_y must be given together")
    if p.target_x is not None and p.target_x == 0.0 and p.target_y == 0.0:
        raise p.error("target_x", "the target point is the base (0, 0); no arm posture is defined there")
    n = len(p.points_x)
    if p.ri2_levels is not None:
        for v in p.ri2_levels:
            if not (math.sqrt(n) - 1e-12 <= v < math.sqrt(2 * n)):
                raise p.error("ri2_levels", f"RI2 = {v} is impossible for {n} points: RI2 lies in "
                                            f"[sqrt(n), sqrt(2n)) = [{math.sqrt(n):.4f}, {math.sqrt(2 * n):.4f})")
    if p.sweep_l1_start < 0:
        raise p.error("sweep_l1_start", f"must not be negative (got {p.sweep_l1_start})")
    if p.sweep_count < 0:
        raise p.error("sweep_count", f"must not be negative (got {p.sweep_count}); 0 = up to the C_rob radius")


#: axis labels of summary columns and deck keys (driver.study.column_label): name -> (words, units)
LABELS = {"r_m": ("inner workspace radius r", "m"), "R_m": ("outer workspace radius R", "m"),
          "mean_d2_m2": ("mean squared point distance", "m^2"), "crob_radius_m": ("C_rob radius", "m"),
          "crob_c_m2": ("C_rob l1^2 + l2^2", "m^2"), "ri2_min": ("minimum RI2", "-"),
          "dexterity_l1_m": ("dexterity optimum l1", "m"), "dexterity_l2_m": ("dexterity optimum l2", "m"),
          "manipulability_l1_m": ("manipulability optimum l1", "m"),
          "manipulability_l2_m": ("manipulability optimum l2", "m"),
          "sweep_min_total_torque_Nm": ("least tau1 + tau2 along C_rob", "N m"),
          "sweep_min_l1_m": ("l1 of the least torque", "m"), "sweep_min_l2_m": ("l2 of the least torque", "m"),
          "mass_per_length": ("link mass per length", "kg/m"), "gravity": ("gravity", "m/s^2")}
#: what a sweep summary plots when its deck names no plot_y
SWEEP_PLOT = ("crob_radius_m", "sweep_min_total_torque_Nm", "sweep_min_l1_m", "dexterity_l1_m", "manipulability_l1_m")


SPEC = GroupSpec(
    name="manipulator",
    doc="2R manipulator robust design: C_rob, RI2, dexterity/manipulability optima, torques, tolerances",
    check=_cross_check,
    keys={
        "title": Key("str", default="", doc="case title echoed in the .out"),
        "mode": Key("str", default="exact", choices=("exact", "report"),
                    doc="'report' reproduces the report's tables with its conventions"),
        "points_x": Key("floats", required=True, check=non_empty, units="m",
                        doc="x of the workspace points P_i (base A at the origin)"),
        "points_y": Key("floats", required=True, check=non_empty, units="m", doc="y of the workspace points"),
        "designs_l1": Key("floats", check=positive, units="m",
                          doc="l1 of the designs for Tables 4.5-4.7 and tolerances (default: optima on C_rob)"),
        "designs_l2": Key("floats", check=positive, units="m", doc="l2 of the designs"),
        "design_names": Key("strs", doc="names of the designs (default Design 1, ...)"),
        "printed_angles_deg": Key("floats", units="deg",
                                  doc="report mode: theta1, theta2 per design as printed in Table 4.5; "
                                      "Table 4.7 is computed from them"),
        "target_x": Key("float", units="m", doc="torque target point x (default: first workspace point)"),
        "target_y": Key("float", units="m", doc="torque target point y"),
        "elbow": Key("int", default=1, choices=(1, -1), doc="IK branch: +1 theta2 >= 0, -1 theta2 <= 0"),
        "joint_rates": Key("floats", default=[1.0, 1.0], check=_pair_check, units="rad/s",
                           doc="joint rates (theta1', theta2') for the torques"),
        "joint_accels": Key("floats", default=[1.0, 1.0], check=_pair_check, units="rad/s^2",
                            doc="joint accelerations (theta1'', theta2'')"),
        "gravity": Key("float", default=9.8, check=positive, units="m/s^2", doc="g, along -y"),
        "mass_per_length": Key("float", default=10.0, check=positive, units="kg/m",
                               doc="link mass per unit length (m_i = value * l_i)"),
        "crob_l1": Key("floats", check=positive, units="m",
                       doc="l1 values of the (l1, l2) pairs on C_rob (Table 4.2); default 1, 2, ... below the radius"),
        "ri2_levels": Key("floats", doc="RI2 values of the iso-RI2 ellipse table (Table 4.1); default sqrt(n)"),
        "sweep_l1_start": Key("float", default=0.0, units="m", doc="first l1 of the sweep along C_rob (Table 4.8)"),
        "sweep_l1_step": Key("float", default=0.25, check=positive, units="m", doc="l1 step of the sweep"),
        "sweep_count": Key("int", default=0, doc="rows of the sweep; 0 = up to the C_rob radius"),
        "tolerance_bound": Key("float", default=0.01, units="m",
                               check=lambda v: positive(v) or ("below 1e-9 m the tolerance box underflows"
                                                               if v < 1e-9 else None),
                               doc="largest allowed positioning error epsilon"),
        "error_measure": Key("str", default="global", choices=("global", "per_point"),
                             doc="'global': ||J_x dl||_2 over all points stacked (Caro); "
                                 "'per_point': error at every single point"),
        "mc_samples": Key("int", default=100000,
                          check=lambda v: _min_one(v) or ("at most 10^8 samples (memory)" if v > 10**8 else None),
                          doc="Monte Carlo samples in the tolerance box"),
        "mc_seed": Key("int", default=2005, doc="seed of the Monte Carlo sampler"),
    },
)


# ----------------------------------------------------------------------------- helpers

def round_half_up(x: float, d: int) -> float:
    """``x`` rounded to ``d`` decimals, half away from zero (as the report's printed values)."""
    q = Decimal(1).scaleb(-d)
    return float(Decimal(float(x)).quantize(q, rounding=ROUND_HALF_UP))


@dataclass
class Workspace:
    """Workspace points and the quantities derived from them (lengths in m)."""

    x: np.ndarray
    y: np.ndarray

    @property
    def n(self) -> int:
        return int(self.x.size)

    @property
    def d2(self) -> np.ndarray:
        """Squared distances d^2(A, P_i) [m^2]."""
        return self.x ** 2 + self.y ** 2

    @property
    def r(self) -> float:
        """min d(A, P_i) [m]."""
        return float(np.sqrt(self.d2.min()))

    @property
    def R(self) -> float:
        """max d(A, P_i) [m]."""
        return float(np.sqrt(self.d2.max()))

    @property
    def mean_d2(self) -> float:
        """mean d^2 = l1^2 + l2^2 on C_rob [m^2] (eq. 4.12)."""
        return float(self.d2.mean())


@dataclass
class Conv:
    """Which conventions to use: the report's (``report=True``) or the correct ones."""

    report: bool
    ws: Workspace

    @property
    def radius(self) -> float:
        """C_rob radius [m]: rounded to 3 dp in the report."""
        r = math.sqrt(self.ws.mean_d2)
        return round_half_up(r, 3) if self.report else r

    @property
    def c_pairs(self) -> float:
        """l1^2 + l2^2 for Table 4.2 and the optima: radius^2 (report) or mean d^2."""
        return self.radius ** 2 if self.report else self.ws.mean_d2

    @property
    def c_sweep(self) -> float:
        """l1^2 + l2^2 for Table 4.8: round(radius^2, 2) in the report (51.49)."""
        return round_half_up(self.radius ** 2, 2) if self.report else self.ws.mean_d2


@dataclass
class Table:
    """A rendered table: title, columns, cell values (full precision), trailers, notes."""

    key: str
    title: str
    columns: list[Column]
    rows: list[list[Any]]
    trailers: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    labels: list[str] = field(default_factory=list)

    def lines(self) -> list[str]:
        out = [self.title, "-" * len(self.title)]
        out += render_table(self.columns, self.rows, self.trailers or None)
        out += [f"  note: {n}" for n in self.notes]
        return out + [""]

    def cells(self) -> dict[tuple[int, str], str]:
        """Printed text of every cell, keyed by (row, header)."""
        out = {}
        for i, row in enumerate(self.rows):
            for col, v in zip(self.columns, row):
                out[(i, col.header.strip())] = col.cell(v)
        return out


def _design_list(p: Params, conv: Conv) -> tuple[list[str], np.ndarray, np.ndarray]:
    """Names and lengths [m] of the designs: from the deck or the optima on C_rob."""
    if p.designs_l1 is not None:
        names = p.design_names or [f"Design {i + 1}" for i in range(len(p.designs_l1))]
        return list(names), np.array(p.designs_l1, float), np.array(p.designs_l2, float)
    opt = optima(conv.c_pairs)
    l1 = np.array([opt["dexterity"][0], opt["manipulability"][0]])
    l2 = np.array([opt["dexterity"][1], opt["manipulability"][1]])
    if conv.report:  # Table 4.4 prints 2 dp and Tables 4.5-4.7 use the printed lengths
        l1 = np.array([round_half_up(v, 2) for v in l1])
        l2 = np.array([round_half_up(v, 2) for v in l2])
    return ["Dexterity", "Workspace"], l1, l2


def optima(c: float) -> dict[str, tuple[float, float]]:
    """Optimum designs on l1^2 + l2^2 = c [m^2]: dexterity l2 = l1 sqrt(2)/2, manipulability l1 = l2."""
    return {"dexterity": (math.sqrt(2 * c / 3), math.sqrt(c / 3)),
            "manipulability": (math.sqrt(c / 2), math.sqrt(c / 2))}


# ----------------------------------------------------------------------------- tolerance synthesis

def _corner_patterns(l: int) -> np.ndarray:
    """The 2^(l-1) sign patterns of a box's corners up to an overall sign."""
    return np.array([(1.0,) + s for s in itertools.product((1.0, -1.0), repeat=l - 1)])


def tolerance_box(blocks: np.ndarray, eps: float, measure: str = "global") -> dict[str, Any]:
    """Largest tolerance box (Caro 2005, eq. 2.45) for sensitivity blocks ``blocks`` (k, 2, l).

    Feasible region: ||J_x du||_2 <= eps (``global``, J_x = blocks stacked) or
    max_i ||J_xi du||_2 <= eps (``per_point``), for every corner du = s * u of the box.
    Maximises prod u_i with SLSQP over all 2^(l-1) corner patterns; for l = 2 the closed form
    u_i = eps / sqrt(2 S_ii (1 + |rho|)) of the binding corner is returned alongside.
    Returns dict(u=SLSQP half-widths, closed=closed form or None, converged, message).
    """
    k, _, l = blocks.shape
    pats = _corner_patterns(l)
    mats = [blocks.reshape(2 * k, l).T @ blocks.reshape(2 * k, l)] if measure == "global" \
        else [b.T @ b for b in blocks]

    def worst(u: np.ndarray) -> np.ndarray:
        return np.array([(s * u) @ S @ (s * u) for S in mats for s in pats])

    closed = None
    if l == 2:
        cand = []
        for S in mats:
            rho = abs(S[0, 1]) / math.sqrt(S[0, 0] * S[1, 1])
            cand.append(eps / np.sqrt(2 * np.diag(S) * (1 + rho)))
        # with several constraints (per point) the symmetric S_ii = 1 case keeps u1 = u2
        closed = min(cand, key=lambda u: float(np.prod(u)))
        closed = closed * min(1.0, eps / math.sqrt(worst(closed).max()))
    scale = eps / math.sqrt(max(m.trace() for m in mats))     # work with v = u / scale ~ 1
    res = minimize(lambda v: -np.sum(np.log(v)), np.full(l, 0.5), method="SLSQP",
                   jac=lambda v: -1.0 / v,
                   constraints=[{"type": "ineq", "fun": lambda v: 1.0 - worst(v * scale) / eps ** 2}],
                   bounds=[(1e-9, None)] * l, options={"ftol": 1e-13, "maxiter": 500})
    res.x = res.x * scale
    return {"u": np.asarray(res.x), "closed": closed, "converged": bool(res.success),
            "message": str(res.message)}


def _sensitivity_blocks(th1: np.ndarray, th2: np.ndarray) -> np.ndarray:
    """J_xi = [[c1, c12], [s1, s12]] per workspace point (eq. 2.23), shape (k, 2, 2)."""
    return np.stack([np.stack([np.cos(th1), np.cos(th1 + th2)], -1),
                     np.stack([np.sin(th1), np.sin(th1 + th2)], -1)], 1)


# ----------------------------------------------------------------------------- tables

def _t41(p: Params, conv: Conv) -> Table:
    n = conv.ws.n
    levels = p.ri2_levels or [math.sqrt(n)]
    rows = []
    for v in levels:
        a1 = 1.0 / v
        a2 = 1.0 / math.sqrt(2 * n - v * v)
        rows.append([None, v, n, a1, a1, a2, a2])
    cols = [Column("No.", "s", 4), Column("RI2", "f", 8, 4), Column("n", "i", 4), Column("a1", "f", 8, 4),
            Column("b2", "f", 8, 4), Column("a2", "f", 8, 4), Column("b1", "f", 8, 4)]
    for i, r in enumerate(rows):
        r[0] = f"{i + 1}."
    note = (f"iso-RI2 ellipses (4.14)-(4.17) in the 45-deg frame L1 = (l1+l2)/sqrt2, L2 = (l1-l2)/sqrt2: "
            f"L1^2/a^2 + L2^2/b^2 = c with c = sum d^2 = {conv.ws.d2.sum():g} m^2")
    return Table("4.1", "Table 4.1/4.3  Ellipse variables", cols, rows, notes=[note])


def _t42(p: Params, conv: Conv) -> Table:
    c, radius = conv.c_pairs, conv.radius
    l1s = p.crob_l1 or [float(v) for v in range(int(math.floor(radius)), 0, -1)]
    rows, trailers = [], []
    valid = [v for v in l1s if v < math.sqrt(c)]
    ri = kernels.manipulator_design_indices(conv.ws.x, conv.ws.y, valid, [math.sqrt(c - v * v) for v in valid]) \
        if valid else None
    j = 0
    for i, v in enumerate(l1s):
        if v >= math.sqrt(c):
            rows.append([f"{i + 1}.", None, v, None, None])
            trailers.append(f"l1 >= C_rob radius {radius:.3f}: no l2 on C_rob")
            continue
        l2 = math.sqrt(c - v * v)
        ok = bool(ri[2][j])
        rows.append([f"{i + 1}.", float(ri[0][j, 1]), v, l2, "yes" if ok else "no"])
        trailers.append("" if ok else "violates the reach conditions (4.4)")
        j += 1
    cols = [Column("No.", "s", 4), Column("RI2", "f", 8, 4), Column("l1", "f", 8, 3), Column("l2", "f", 8, 3),
            Column("reach", "s", 6)]
    eq = f"{radius:.3f}^2" if conv.report else f"{c:g}"
    return Table("4.2", "Table 4.2  Pairs (l1, l2) on C_rob (RI2 = sqrt(n))", cols, rows, trailers,
                 notes=[f"equation used: l2 = sqrt({eq} - l1^2)"])


def _t44(p: Params, conv: Conv) -> Table:
    opt = optima(conv.c_pairs)
    d = 2 if conv.report else 4
    ri = kernels.manipulator_design_indices(conv.ws.x, conv.ws.y, [opt["dexterity"][0], opt["manipulability"][0]],
                                            [opt["dexterity"][1], opt["manipulability"][1]])
    rows = []
    for j, (name, key) in enumerate((("Dexterity", "dexterity"), ("Workspace", "manipulability"))):
        l1, l2 = opt[key]
        rows.append([name, l1, l2, float(ri[0][j, 1]), "yes" if ri[2][j] else "no"])
    cols = [Column("Criterion", "s", 10), Column("l1opt", "f", 8, d), Column("l2opt", "f", 8, d),
            Column("RI2", "f", 8, 4), Column("reach", "s", 6)]
    notes = ["Dexterity: l2 = l1 sqrt(2)/2 on C_rob, Workspace (manipulability w = l1 l2 |s2|): l1 = l2"]
    return Table("4.4", "Table 4.4  Optimum dimensions on C_rob", cols, rows, notes=notes)


def _target(p: Params, ws: Workspace) -> tuple[float, float]:
    if p.target_x is not None:
        return float(p.target_x), float(p.target_y)
    return float(ws.x[0]), float(ws.y[0])


def _design_angles(p: Params, conv: Conv, l1: np.ndarray, l2: np.ndarray) -> dict[str, np.ndarray]:
    """Joint angles [deg] of the designs at the target: printed (Table 4.5) and used for torques."""
    tx, ty = _target(p, conv.ws)
    th1, th2, st = kernels.manipulator_ik(l1, l2, tx, ty, p.elbow)
    t1, t2 = np.degrees(th1), np.degrees(th2)
    if conv.report:
        shown2 = 180.0 - np.abs(t2)             # interior angle between the links
        shown1 = t1
        if p.printed_angles_deg is not None:
            used = np.array(p.printed_angles_deg, float).reshape(-1, 2)
        else:
            used = np.array([[round_half_up(a, 2), round_half_up(b, 2)] for a, b in zip(shown1, shown2)])
        used1, used2 = used[:, 0], used[:, 1]
    else:
        shown1, shown2, used1, used2 = t1, t2, t1, t2
    return {"shown1": shown1, "shown2": shown2, "used1": used1, "used2": used2, "status": st}


def _torque_tables(p: Params, conv: Conv) -> tuple[Table, Table, Table, dict[str, Any]]:
    names, l1, l2 = _design_list(p, conv)
    ang = _design_angles(p, conv, l1, l2)
    tx, ty = _target(p, conv.ws)
    ok = ang["status"] == STATUS["ok"]
    if not ok.any():
        raise p.error("target_x", f"target point ({tx:g}, {ty:g}) is out of reach of every design "
                                  f"(d = {math.hypot(tx, ty):.4f} m); choose a point inside |l1-l2| <= d <= l1+l2")
    mpl, g = p.mass_per_length, p.gravity
    m1, m2 = mpl * l1, mpl * l2
    tau = kernels.manipulator_torques(l1, l2, np.radians(ang["used1"]), np.radians(ang["used2"]),
                                      p.joint_rates, p.joint_accels, m1, m2, g)
    why = "target out of reach of this design"
    r45, r46, r47, tr = [], [], [], []
    for i, name in enumerate(names):
        good = bool(ok[i])
        a1 = float(ang["shown1"][i]) if good else None
        a2 = float(ang["shown2"][i]) if good else None
        r45.append([name, l1[i], l2[i], m1[i], m2[i], g, a1, a2])
        r46.append([name, l1[i], l2[i], a1, a2, *p.joint_rates, *p.joint_accels])
        r47.append([name, l1[i], l2[i], float(tau[i, 0]) if good else None, float(tau[i, 1]) if good else None])
        tr.append("" if good else why)
    cols45 = [Column("Design", "s", 10), Column("l1", "f", 6, 2), Column("l2", "f", 6, 2), Column("m1", "f", 6, 1),
              Column("m2", "f", 6, 1), Column("g", "f", 5, 1), Column("theta1", "f", 8, 2), Column("theta2", "f", 8, 2)]
    cols46 = [Column("Design", "s", 10), Column("l1", "f", 6, 2), Column("l2", "f", 6, 2), Column("theta1", "f", 8, 2),
              Column("theta2", "f", 8, 2), Column("th1'", "f", 6, 2), Column("th2'", "f", 6, 2),
              Column("th1''", "f", 6, 2), Column("th2''", "f", 6, 2)]
    cols47 = [Column("Design", "s", 10), Column("l1", "f", 6, 2), Column("l2", "f", 6, 2), Column("tau1", "f", 10, 3),
              Column("tau2", "f", 10, 3)]
    n45 = [f"target P = ({tx:g}, {ty:g}) m, m_i = {mpl:g} l_i kg, angles in deg"]
    if conv.report:
        n45.append("theta2 printed as the interior angle 180 - acos(c2) (report convention)")
    n47 = [f"torques [N m], Craig point-mass model (2.52)/(2.53), rates {p.joint_rates} rad/s, "
           f"accelerations {p.joint_accels} rad/s^2"]
    if conv.report:
        src = "printed_angles_deg of the deck" if p.printed_angles_deg is not None else "Table 4.5 rounded to 2 dp"
        n47.append(f"joint angles fed in as printed ({src}), the interior angle used as theta2")
    rad1, rad2 = np.radians(ang["used1"]), np.radians(ang["used2"])
    fx = l1 * np.cos(rad1) + l2 * np.cos(rad1 + rad2)
    fy = l1 * np.sin(rad1) + l2 * np.sin(rad1 + rad2)
    miss = np.hypot(fx - tx, fy - ty)
    for i, name in enumerate(names):
        if ok[i] and miss[i] > 1e-6:
            n47.append(f"{name}: the joint angles used put the end effector at ({fx[i]:.3f}, {fy[i]:.3f}), "
                       f"{miss[i]:.3f} m from the target")
    used = {"names": names, "l1": l1, "l2": l2, "m1": m1, "m2": m2, "tau": tau, "ok": ok, "fk_miss": miss,
            "used1": ang["used1"], "used2": ang["used2"], "shown1": ang["shown1"], "shown2": ang["shown2"]}
    return (Table("4.5", "Table 4.5  Torque parameters", cols45, r45, tr, n45),
            Table("4.6", "Table 4.6  Torque parameters (continued): rates [rad/s], accelerations [rad/s^2]",
                  cols46, r46, tr),
            Table("4.7", "Table 4.7  Motor torques", cols47, r47, tr, n47), used)


def _designs_table(p: Params, conv: Conv) -> Table:
    """Robustness indices of the designs and their manipulability/condition number at the target."""
    names, l1, l2 = _design_list(p, conv)
    ri, sumc2, reach = kernels.manipulator_design_indices(conv.ws.x, conv.ws.y, l1, l2)
    tx, ty = _target(p, conv.ws)
    th1, th2, st = kernels.manipulator_ik(l1, l2, tx, ty, p.elbow)
    _, w, kappa, _ = kernels.manipulator_arm_states(l1, l2, th1, th2)
    rows, trailers = [], []
    for i, name in enumerate(names):
        ok = st[i] == STATUS["ok"]
        rows.append([name, l1[i], l2[i], float(ri[i, 0]) if ri[i, 0] > 0 else None, float(ri[i, 1]),
                     float(ri[i, 2]), float(w[i]) if ok else None, float(kappa[i]) if ok and kappa[i] > 0 else None,
                     "yes" if reach[i] else "no"])
        trailers.append("" if ok else "target out of reach of this design")
    cols = [Column("Design", "s", 10), Column("l1", "f", 8, 4), Column("l2", "f", 8, 4), Column("RI1", "f", 9, 3),
            Column("RI2", "f", 8, 5), Column("RI3", "f", 8, 5), Column("w", "f", 9, 4), Column("kappa", "f", 8, 4),
            Column("reach", "s", 6)]
    notes = ["RI1 = sigma_max/sigma_min (blank where sigma_min = 0), "
             "RI2 = sigma_max (2.25), RI3 = sigma_max + ||J_x||_F (2.26)",
             f"w = |det J| [m^2] and kappa = cond(J) of the arm Jacobian (4.18) at the target ({tx:g}, {ty:g}), "
             "IK joint angles"]
    return Table("designs", "Designs: robustness indices and dexterity measures", cols, rows, trailers, notes)


def _sweep_l1(p: Params, conv: Conv) -> np.ndarray:
    if p.sweep_count > 0:
        return p.sweep_l1_start + p.sweep_l1_step * np.arange(p.sweep_count)
    top = math.sqrt(conv.c_sweep)
    n = int(math.floor((top - p.sweep_l1_start) / p.sweep_l1_step + 1e-9)) + 1
    if n < 1:
        raise p.error("sweep_l1_start", f"{p.sweep_l1_start:g} m is beyond the C_rob radius {top:.4f} m: the sweep "
                                        "along C_rob would be empty (give a smaller start or a sweep_count)")
    return p.sweep_l1_start + p.sweep_l1_step * np.arange(n)


def _t48(p: Params, conv: Conv) -> tuple[Table, dict[str, Any]]:
    c = conv.c_sweep
    tx, ty = _target(p, conv.ws)
    dt = math.hypot(tx, ty)
    l1 = _sweep_l1(p, conv)
    inside = l1 <= math.sqrt(c) + 1e-12
    l2 = np.sqrt(np.where(inside, c - np.minimum(l1, math.sqrt(c)) ** 2, 0.0))
    safe1, safe2 = np.where(l1 > 0, l1, 1.0), np.where(l2 > 0, l2, 1.0)
    th1, th2, st = kernels.manipulator_ik(safe1, safe2, tx, ty, p.elbow)
    st = np.where((l1 > 0) & (l2 > 0) & inside, st, STATUS["degenerate"])
    t2 = np.degrees(th2)
    t1 = round_half_up(math.degrees(math.atan2(ty, tx)), 2) - t2 if conv.report else np.degrees(th1)
    mpl, g = p.mass_per_length, p.gravity
    m1, m2 = mpl * l1, mpl * l2
    tau = kernels.manipulator_torques(safe1, safe2, np.radians(t1), np.radians(t2), p.joint_rates,
                                      p.joint_accels, m1, m2, g)
    ri = kernels.manipulator_design_indices(conv.ws.x, conv.ws.y, safe1, safe2)
    rows, trailers = [], []
    for i in range(l1.size):
        ok = st[i] == STATUS["ok"]
        if not inside[i]:
            rows.append([f"{i + 1}.", l1[i], None, m1[i], None, g, None, None, None, None])
            trailers.append("l1 beyond the C_rob radius")
            continue
        row = [f"{i + 1}.", l1[i], l2[i], m1[i], m2[i], g]
        if ok:
            row += [float(t1[i]), float(t2[i]), float(tau[i, 0]), float(tau[i, 1])]
            trailers.append("" if ri[2][i] else "violates the workspace reach conditions")
        else:
            row += [None] * 4
            trailers.append(f"target out of reach: |l1-l2| = {abs(l1[i] - l2[i]):.3f} > d = {dt:.3f}"
                            if abs(l1[i] - l2[i]) > dt else
                            (f"target out of reach: l1+l2 < d = {dt:.3f}" if l1[i] > 0 and l2[i] > 0
                             else "a zero link length: no posture"))
        rows.append(row)
    cols = [Column("No.", "s", 4), Column("l1", "f", 6, 2), Column("l2", "f", 6, 2), Column("m1", "f", 7, 2),
            Column("m2", "f", 7, 2), Column("g", "f", 5, 1), Column("theta1", "f", 8, 2), Column("theta2", "f", 8, 2),
            Column("tau1", "f", 10, 3), Column("tau2", "f", 10, 3)]
    eqs = f"l2 = sqrt({c:g} - l1^2)"
    notes = [f"target P = ({tx:g}, {ty:g}) m, {eqs}; blank rows: the target is out of reach (as in the report)"]
    if conv.report:
        notes.append(f"report convention: theta2 = +acos(c2), theta1 = "
                     f"{round_half_up(math.degrees(math.atan2(ty, tx)), 2):.2f} - theta2 (does not reach P)")
    r1, r2 = np.radians(t1), np.radians(t2)
    miss = np.hypot(safe1 * np.cos(r1) + safe2 * np.cos(r1 + r2) - tx, safe1 * np.sin(r1) + safe2 * np.sin(r1 + r2) - ty)
    good = (st == STATUS["ok"]) & inside
    if good.any() and miss[good].max() > 1e-6:
        notes.append(f"the tabulated angles miss the target by {miss[good].min():.3f} to {miss[good].max():.3f} m (FK)")
    data = {"l1": l1, "l2": l2, "m1": m1, "m2": m2, "t1": t1, "t2": t2, "tau": tau, "ok": (st == STATUS["ok"]) & inside,
            "reach_all": ri[2].astype(bool) & inside}
    return Table("4.8", "Table 4.8  Torques for other arm lengths along C_rob", cols, rows, trailers, notes), data


def _tolerance(p: Params, ws: Workspace, names: list[str], l1: np.ndarray, l2: np.ndarray) -> tuple[Table, list[dict]]:
    eps = p.tolerance_bound
    rng = np.random.default_rng(p.mc_seed)
    unit = rng.uniform(-1.0, 1.0, size=(p.mc_samples, 2))
    col = 0 if p.error_measure == "global" else 1
    rows, out = [], []
    for i, name in enumerate(names):
        th1, th2, st = kernels.manipulator_ik(l1[i], l2[i], ws.x, ws.y, p.elbow)
        blocks = _sensitivity_blocks(th1, th2)
        box = tolerance_box(blocks, eps, p.error_measure)
        dl = box["closed"] if box["closed"] is not None else box["u"]
        corners = np.array([[1, 1], [1, -1], [-1, 1], [-1, -1]], float) * dl
        worst = kernels.manipulator_position_errors(th1, th2, corners)[:, col].max()
        err = kernels.manipulator_position_errors(th1, th2, unit * dl)[:, col]
        ri2 = math.sqrt(ws.n + abs(np.cos(th2).sum()))
        rec = {"name": name, "l1": float(l1[i]), "l2": float(l2[i]), "ri2": ri2, "dl1": float(dl[0]),
               "dl2": float(dl[1]), "slsqp_dl1": float(box["u"][0]), "slsqp_dl2": float(box["u"][1]),
               "converged": box["converged"], "worst_corner": float(worst), "mc_max": float(err.max()),
               "mc_p99": float(np.percentile(err, 99.0))}
        out.append(rec)
        rows.append([name, rec["l1"], rec["l2"], ri2, rec["dl1"], rec["dl2"], rec["slsqp_dl1"], rec["slsqp_dl2"],
                     rec["worst_corner"], rec["mc_max"], rec["mc_p99"], "yes" if rec["mc_max"] <= eps * (1 + 1e-12) else "NO"])
    cols = [Column("Design", "s", 10), Column("l1", "f", 7, 3), Column("l2", "f", 7, 3), Column("RI2", "f", 7, 4),
            Column("dl1", "f", 9, 6), Column("dl2", "f", 9, 6), Column("dl1 SLSQP", "f", 10, 6),
            Column("dl2 SLSQP", "f", 10, 6), Column("worst corner", "f", 12, 6), Column("MC max", "f", 9, 6),
            Column("MC p99", "f", 9, 6), Column("ok", "s", 3)]
    meas = ("global error ||J_x dl||_2 over all points (Caro)" if col == 0 else "largest error at a single point")
    notes = [f"bound epsilon = {eps:g} m on the {meas}; box l_i +- dl_i; closed form dl = eps/(sqrt2 RI2)"
             if col == 0 else f"bound epsilon = {eps:g} m on the {meas}; closed form dl = eps/sqrt(2(1 + max|c2_i|))",
             f"Monte Carlo: {p.mc_samples} uniform samples in the box (seed {p.mc_seed}), joint angles held at the "
             f"nominal IK ({'elbow +1' if p.elbow > 0 else 'elbow -1'})"]
    return Table("tol", "Tolerance synthesis (Caro 2005, eq. 2.45)", cols, rows, notes=notes), out


# ----------------------------------------------------------------------------- differences between modes

REASONS = {
    ("4.2", "l2"): "report uses C = (radius rounded to 3 dp)^2 instead of mean d^2",
    ("4.2", "RI2"): "follows from l2",
    ("4.4", "l1opt"): "report prints 2 dp and uses the rounded radius",
    ("4.4", "l2opt"): "report prints 2 dp and uses the rounded radius",
    ("4.5", "theta2"): "report prints the interior angle 180 - acos(c2); exact gives the joint angle",
    ("4.5", "theta1"): "deck printed angle differs from the IK (report slip) or follows theta2",
    ("4.6", "theta2"): "as Table 4.5",
    ("4.6", "theta1"): "as Table 4.5",
    ("4.7", "tau1"): "report feeds the printed (rounded, interior-angle) Table 4.5 angles into (2.52)",
    ("4.7", "tau2"): "report feeds the printed (rounded, interior-angle) Table 4.5 angles into (2.53)",
    ("4.8", "l2"): "report uses C = round(radius^2, 2) instead of mean d^2",
    ("4.8", "m2"): "follows from l2",
    ("4.8", "theta1"): "report uses theta1 = round(atan2(y,x), 2) - theta2, which does not reach the target",
    ("4.8", "theta2"): "follows from l2 (C = round(radius^2, 2))",
    ("4.8", "tau1"): "follows from the report's theta1 and l2",
    ("4.8", "tau2"): "follows from the report's theta1 and l2",
}


#: printed cells of chapter 4 that the report's own data and formulas do not give:
#: (table, row label, column, printed) -> why.  The report uses them as inputs further on.
NOT_REPRODUCIBLE = {
    ("4.4", "Dexterity", "l1opt", "5.85"): "case 2 dexterity optimum l1 = sqrt(2C/3) = 5.859 prints 5.86; 5.85 "
                                            "(a truncation) was read off Fig. 4.10",
    ("4.4", "Dexterity", "l2opt", "4.16"): "case 2 dexterity optimum l2 = l1 sqrt(2)/2 = 4.143 prints 4.14; no "
                                            "variant of the formulas gives 4.16 (read off Fig. 4.10)",
    ("4.5", "1.", "theta1", "34.81"): "the report's own IK at P = (1, 5) gives 35.50 for (5.61, 3.97); 34.81 = "
                                       "78.00 - beta, a slip in the base angle",
    ("4.6", "1.", "theta1", "34.81"): "as Table 4.5 (the same printed angle)",
}

#: why the exact mode departs from values the report prints in its text (quantity -> why)
TEXT_REASONS = {
    "crob_c_sweep": "report uses C = round(radius^2, 2) = 51.49 instead of mean d^2 = 51.5",
    "min_total_torque": "follows from Table 4.8: with angles that reach the target the smallest total torque "
                        "is another design",
    "min_total_l1": "follows from Table 4.8 (chapter 5 minimum)",
    "min_total_l2": "follows from Table 4.8 (chapter 5 minimum)",
}

#: tidy-table column of each .out column header
TIDY_NAMES = {"l1": "l1_m", "l2": "l2_m", "m1": "m1_kg", "m2": "m2_kg", "g": "g_m_s2",
              "theta1": "theta1_deg", "theta2": "theta2_deg", "tau1": "tau1_Nm", "tau2": "tau2_Nm",
              "l1opt": "l1_m", "l2opt": "l2_m", "RI2": "ri2", "n": "n", "a1": "a1", "b2": "b2",
              "a2": "a2", "b1": "b1", "reach": "reach", "th1'": "theta1_rate_rad_s",
              "th2'": "theta2_rate_rad_s", "th1''": "theta1_acc_rad_s2",
              "th2''": "theta2_acc_rad_s2", "RI1": "ri1", "RI3": "ri3",
              "w": "manipulability_m2", "kappa": "condition_number"}


def _differences(report: list[Table], exact: list[Table]) -> list[str]:
    """Every cell whose printed text differs between the two modes, with the reason."""
    lines = []
    for a, b in zip(report, exact):
        ca, cb = a.cells(), b.cells()
        for key in sorted(set(ca) | set(cb)):
            va, vb = ca.get(key, "(none)"), cb.get(key, "(none)")
            if va != vb:
                why = REASONS.get((a.key, key[1]), "follows from the cells above")
                lines.append(f"  Table {a.key:<4} row {key[0] + 1:>2} {key[1]:<7} report {va or '(blank)':>10}"
                             f"  exact {vb or '(blank)':>10}  {why}")
    return lines


# ----------------------------------------------------------------------------- run

def _tables(p: Params, conv: Conv) -> tuple[list[Table], dict[str, Any], dict[str, Any]]:
    t45, t46, t47, used = _torque_tables(p, conv)
    t48, sweep = _t48(p, conv)
    return [_t41(p, conv), _t42(p, conv), _t44(p, conv), _designs_table(p, conv), t45, t46, t47, t48], used, sweep


def _header(p: Params, ws: Workspace, conv: Conv) -> list[str]:
    tx, ty = _target(p, ws)
    pts = ", ".join(f"({x:g}, {y:g})" for x, y in zip(ws.x, ws.y))
    lines = ["2R manipulator robust design (seed 004, chapter 4)", "=" * 50]
    if p.title:
        lines.append(f"case: {p.title}")
    lines += [f"deck: {p.path.name}", f"mode: {p.mode}" + ("  (report's conventions, shared/notes/manipulator.md)"
                                                        if conv.report else "  (correct IK, exact constants)"),
              f"workspace points [m]: {pts}  (n = {ws.n})",
              f"target point [m]: ({tx:g}, {ty:g})   elbow branch: {p.elbow:+d}",
              f"joint rates [rad/s]: {p.joint_rates}   joint accelerations [rad/s^2]: {p.joint_accels}",
              f"g = {p.gravity:g} m/s^2   mass per length = {p.mass_per_length:g} kg/m",
              f"tolerance bound = {p.tolerance_bound:g} m ({p.error_measure})   Monte Carlo samples = {p.mc_samples}",
              "",
              "Workspace and robust circle",
              "---------------------------",
              f"  d^2(A,P_i) [m^2]: {', '.join(f'{v:g}' for v in ws.d2)}",
              f"  r = min d = {fortran_f(ws.r, None, 4)} m   R = max d = {fortran_f(ws.R, None, 4)} m",
              f"  reach conditions (4.4): |l1 - l2| <= {fortran_f(ws.r, None, 4)},  l1 + l2 >= {fortran_f(ws.R, None, 4)}",
              f"  C_rob: l1^2 + l2^2 = mean d^2 = {ws.mean_d2:g} m^2, radius {fortran_f(math.sqrt(ws.mean_d2), None, 5)} m"
              f" (report: {fortran_f(round_half_up(math.sqrt(ws.mean_d2), 3), None, 3)})",
              f"  RI2 on C_rob = sqrt(n) = {fortran_f(math.sqrt(ws.n), None, 4)}",
              ""]
    if conv.report:
        lines.insert(-1, f"  report constants: C = radius^2 = {conv.c_pairs:.6f} (Table 4.2, optima), "
                         f"C = round(radius^2, 2) = {conv.c_sweep:.2f} (Table 4.8)")
    return lines


#: unit of every tidy quantity ('1' dimensionless, 'bool' 1 = yes / 0 = no)
TIDY_UNITS = {"l1_m": "m", "l2_m": "m", "m1_kg": "kg", "m2_kg": "kg", "g_m_s2": "m/s^2", "theta1_deg": "deg",
              "theta2_deg": "deg", "tau1_Nm": "N m", "tau2_Nm": "N m", "ri1": "1", "ri2": "1", "ri3": "1",
              "n": "1", "a1": "1", "b1": "1", "a2": "1", "b2": "1", "reach": "bool",
              "theta1_rate_rad_s": "rad/s", "theta2_rate_rad_s": "rad/s", "theta1_acc_rad_s2": "rad/s^2",
              "theta2_acc_rad_s2": "rad/s^2", "manipulability_m2": "m^2", "condition_number": "1",
              "dl1_m": "m", "dl2_m": "m", "worst_corner_m": "m", "mc_max_m": "m", "mc_p99_m": "m"}


def _tidy(tables: list[Table], tol: list[dict], sweep: dict, used: dict) -> pd.DataFrame:
    """One long tidy frame for every table: table, row, label, quantity, value, unit.

    A blank printed cell (e.g. angles of a design that cannot reach the target) has no row,
    so no cell is empty; ``reach`` is 1 (yes) or 0 (no).  :func:`table_frame` gives one
    table back in its printed (wide) shape.
    """
    recs = []

    def add(table: str, row: int, label: str, name: str, v: Any) -> None:
        if v is None or (isinstance(v, float) and not math.isfinite(v)):
            return
        if name == "reach":
            v = 1.0 if v == "yes" else 0.0
        recs.append((table, row, label, name, float(v), TIDY_UNITS[name]))

    for t in tables:
        for i, row in enumerate(t.rows):
            label = str(row[0]).rstrip(".")
            for col, v in zip(t.columns[1:], row[1:]):
                add(t.key, i + 1, label, TIDY_NAMES.get(col.header.strip(), col.header.strip()), v)
    for k, rec in enumerate(tol, start=1):
        for name, key in (("l1_m", "l1"), ("l2_m", "l2"), ("ri2", "ri2"), ("dl1_m", "dl1"), ("dl2_m", "dl2"),
                          ("worst_corner_m", "worst_corner"), ("mc_max_m", "mc_max"), ("mc_p99_m", "mc_p99")):
            add("tolerance", k, rec["name"], name, rec[key])
    frame = pd.DataFrame.from_records(recs, columns=["table", "row", "label", "quantity", "value", "unit"])
    return with_units(frame, {"row": "1", "value": "see unit column"})


def table_frame(tidy: pd.DataFrame, table: str) -> pd.DataFrame:
    """One table of the long tidy frame in its printed shape: a row per printed row (row,
    label, then a column per quantity in printed order; NaN where the printed cell is blank)."""
    part = tidy[tidy["table"] == table]
    if part.empty:
        known = ", ".join(dict.fromkeys(tidy["table"]))
        raise KeyError(f"no table {table!r} (tables: {known})")
    wide = part.pivot(index=["row", "label"], columns="quantity", values="value")
    wide = wide[list(dict.fromkeys(part["quantity"]))].reset_index()
    wide.columns.name = None
    wide.attrs["units"] = {"row": "1", "label": "", **{q: TIDY_UNITS[q] for q in wide.columns[2:]}}
    return wide


def _summary(p: Params, ws: Workspace, conv: Conv, used: dict, sweep: dict, tol: list[dict]) -> dict[str, Any]:
    opt = optima(conv.c_pairs)
    s: dict[str, Any] = {"mode": p.mode, "n_points": ws.n, "r_m": ws.r, "R_m": ws.R, "mean_d2_m2": ws.mean_d2,
                         "crob_radius_m": conv.radius, "crob_c_m2": conv.c_pairs, "ri2_min": math.sqrt(ws.n),
                         "dexterity_l1_m": opt["dexterity"][0], "dexterity_l2_m": opt["dexterity"][1],
                         "manipulability_l1_m": opt["manipulability"][0], "manipulability_l2_m": opt["manipulability"][1]}
    for i, name in enumerate(used["names"]):
        key = name.lower().replace(" ", "_")
        s[f"{key}_tau1_Nm"] = float(used["tau"][i, 0]) if used["ok"][i] else None
        s[f"{key}_tau2_Nm"] = float(used["tau"][i, 1]) if used["ok"][i] else None
    for rec in tol:
        key = rec["name"].lower().replace(" ", "_")
        s[f"{key}_dl_m"] = rec["dl1"]
        s[f"{key}_mc_max_m"] = rec["mc_max"]
    # design measures of the first design (what an &optimize deck varies: designs_l1, designs_l2)
    l1, l2 = float(used["l1"][0]), float(used["l2"][0])
    ri, _, reach = kernels.manipulator_design_indices(ws.x, ws.y, [l1], [l2])
    s.update({"design_l1_m": l1, "design_l2_m": l2, "design_ri1": float(ri[0, 0]) if ri[0, 0] > 0 else None,
              "design_ri2": float(ri[0, 1]), "design_ri3": float(ri[0, 2]),
              "design_ri2_excess": float(ri[0, 1]) - math.sqrt(ws.n),
              "design_reaches_all": bool(reach[0]), "design_crob_residual_m2": l1 * l1 + l2 * l2 - ws.mean_d2,
              "design_total_torque_Nm": float(used["tau"][0].sum()) if used["ok"][0] else None})
    tot = np.where(sweep["ok"], sweep["tau"].sum(1), np.inf)
    if np.isfinite(tot).any():
        k = int(np.argmin(tot))
        s.update({"sweep_min_total_torque_Nm": float(tot[k]), "sweep_min_l1_m": float(sweep["l1"][k]),
                  "sweep_min_l2_m": float(sweep["l2"][k]), "sweep_min_row": k + 1,
                  "sweep_min_reaches_workspace": bool(sweep["reach_all"][k])})
    return s


def estimate(params: Params) -> Estimate:
    """Memory and work of a run from the keys alone (driver.limits): the Monte Carlo check holds
    mc_samples x points errors (about 64 bytes and 50 ns each), every row of the C_rob sweep is a
    small design evaluation (about 2 ms), the designs tables a few us per design and point."""
    p = params
    pts = max(len(p.points_x), len(p.points_y))
    designs = len(p.designs_l1 or []) + len(p.crob_l1 or []) + 10
    mc = Estimate(64.0 * p.mc_samples * pts, 5e-8 * p.mc_samples * pts, "mc_samples", "mc_samples",
                  f"{p.mc_samples} Monte Carlo samples x {pts} points")
    if p.sweep_count > 0:
        rows = float(p.sweep_count)
    else:   # up to the C_rob radius, bounded by the workspace's size
        reach = max(math.hypot(x, y) for x, y in zip(p.points_x, p.points_y)) if pts else 1.0
        try:
            rows = (10.0 * reach + 10.0) / p.sweep_l1_step + 1.0
        except (OverflowError, ZeroDivisionError):
            rows = math.inf
    sweep = Estimate(2000.0 * rows, 2e-3 * rows, "sweep_count" if p.sweep_count > 0 else "sweep_l1_step",
                     "sweep_count" if p.sweep_count > 0 else "sweep_l1_step", f"{rows:.4g} sweep rows")
    tables = Estimate(1e4 * designs * pts + 5e6, 5e-6 * designs * pts, "points_x", "points_x", "")
    return mc + sweep + tables


@keyword_run
def run(params: Params, progress: bool = False) -> Result:
    """Run one &manipulator deck (see the module docstring)."""
    p = params
    ws = Workspace(np.array(p.points_x, float), np.array(p.points_y, float))
    conv = Conv(p.mode == "report", ws)
    _check_designs(p, ws, conv)
    tables, used, sweep = _tables(p, conv)
    tol_table, tol = _tolerance(p, ws, used["names"], used["l1"], used["l2"])
    warnings = []
    for rec in tol:
        if not rec["converged"] or abs(rec["slsqp_dl1"] * rec["slsqp_dl2"] / (rec["dl1"] * rec["dl2"]) - 1) > 1e-6:
            warnings.append(f"design {rec['name']}: SLSQP box ({rec['slsqp_dl1']:.6g}, {rec['slsqp_dl2']:.6g}) "
                            f"does not match the closed form ({rec['dl1']:.6g}, {rec['dl2']:.6g})")
    lines = _header(p, ws, conv)
    for t in tables:
        lines += t.lines()
    lines += tol_table.lines()
    lines += _claims(used, sweep)
    if conv.report:
        exact_tables, _, _ = _tables(p, Conv(False, ws))
        diff = _differences(tables, exact_tables)
        lines += ["Cells where mode = 'report' and mode = 'exact' differ", "-" * 52]
        lines += diff or ["  none"]
        lines += [""]
        lines += _design_notes(p, conv, used)
    if warnings:
        lines += ["Warnings", "--------"] + [f"  {w}" for w in warnings] + [""]
    tidy = _tidy(tables, tol, sweep, used)
    figures = [Figure("design_space", lambda: _fig_design(p, ws, conv, used)),
               Figure("torque_crob", lambda: _fig_torque(sweep, conv, p.title or p.path.stem))]
    return Result(text="\n".join(lines).rstrip() + "\n", tidy=tidy, summary=_summary(p, ws, conv, used, sweep, tol),
                  warnings=warnings, figures=figures)


def _check_designs(p: Params, ws: Workspace, conv: Conv) -> None:
    """Deck designs must satisfy the reach conditions (4.4): DeckError otherwise."""
    if p.designs_l1 is None:
        return
    _, l1, l2 = _design_list(p, conv)
    ri = kernels.manipulator_design_indices(ws.x, ws.y, l1, l2)
    for i in np.flatnonzero(ri[2] == 0):
        raise p.error("designs_l1", f"design {i + 1} (l1 = {l1[i]:g}, l2 = {l2[i]:g}) violates the reach "
                                    f"conditions |l1 - l2| <= r = {ws.r:.4f} and l1 + l2 >= R = {ws.R:.4f}: "
                                    "it cannot reach every workspace point")


def _claims(used: dict, sweep: dict) -> list[str]:
    lines = ["Chapter 5 comparisons", "---------------------"]
    tot = used["tau"].sum(1)
    for i, name in enumerate(used["names"]):
        if used["ok"][i]:
            lines.append(f"  {name:<10} total torque tau1 + tau2 = {fortran_f(tot[i], None, 3)} N m")
    if used["ok"].sum() > 1:
        k = int(np.argmin(np.where(used["ok"], tot, np.inf)))
        lines.append(f"  lowest total torque among the designs: {used['names'][k]}")
    t = np.where(sweep["ok"], sweep["tau"].sum(1), np.inf)
    if np.isfinite(t).any():
        k = int(np.argmin(t))
        lines.append(f"  smallest total torque along C_rob: {fortran_f(t[k], None, 3)} N m at row {k + 1} "
                     f"(l1 = {sweep['l1'][k]:.2f}, l2 = {sweep['l2'][k]:.2f})"
                     + ("" if sweep["reach_all"][k] else "; this design violates the workspace reach conditions"))
        okw = np.where(sweep["reach_all"] & sweep["ok"], t, np.inf)
        if np.isfinite(okw).any() and int(np.argmin(okw)) != k:
            j = int(np.argmin(okw))
            lines.append(f"  smallest among rows that reach the whole workspace: {fortran_f(t[j], None, 3)} N m at "
                         f"row {j + 1} (l1 = {sweep['l1'][j]:.2f}, l2 = {sweep['l2'][j]:.2f})")
    return lines + [""]


def _design_notes(p: Params, conv: Conv, used: dict) -> list[str]:
    """Report mode: deck inputs that are the report's unreproducible printed values."""
    lines = []
    opt = optima(conv.c_pairs)
    if p.designs_l1 is not None:
        for i, name in enumerate(used["names"]):
            for key in ("dexterity", "manipulability"):
                o = [round_half_up(v, 2) for v in opt[key]]
                close = abs(used["l1"][i] - opt[key][0]) < 0.05 and abs(used["l2"][i] - opt[key][1]) < 0.05
                if close and (abs(used["l1"][i] - o[0]) > 1e-9 or abs(used["l2"][i] - o[1]) > 1e-9):
                    lines.append(f"  design {name} ({used['l1'][i]:g}, {used['l2'][i]:g}) is not the computed {key} "
                                 f"optimum ({o[0]:.2f}, {o[1]:.2f}); the report read it off its figure")
    if p.printed_angles_deg is not None:
        pa = np.array(p.printed_angles_deg, float).reshape(-1, 2)
        for i, name in enumerate(used["names"]):
            for j, key in ((0, "shown1"), (1, "shown2")):
                half = 0.5 * 10.0 ** Decimal(repr(float(pa[i, j]))).as_tuple().exponent  # half a printed unit
                if used["ok"][i] and abs(pa[i, j] - used[key][i]) > half + 1e-9:
                    lines.append(f"  design {name}: printed theta{j + 1} = {pa[i, j]:g} deg but the report's IK gives "
                                 f"{used[key][i]:.2f} deg (not reproducible; used as printed for Table 4.7)")
    if lines:
        lines = ["Printed inputs that the report's own formulas do not give", "-" * 58] + lines + [""]
    return lines


# ----------------------------------------------------------------------------- figures

def _fig_design(p: Params, ws: Workspace, conv: Conv, used: dict):
    from driver.plotting import manipulator_design_space
    field_l = np.linspace(0.05, ws.R + 1.0, 161)
    L1, L2 = np.meshgrid(field_l, field_l)
    ri = kernels.manipulator_design_indices(ws.x, ws.y, L1.ravel(), L2.ravel())[0][:, 1].reshape(L1.shape)
    levels = p.ri2_levels or [math.sqrt(ws.n)]
    return manipulator_design_space(ws.r, ws.R, math.sqrt(conv.c_pairs), L1, L2, ri, float(ws.d2.sum()), ws.n,
                                    levels, optima(conv.c_pairs), used["names"], used["l1"], used["l2"],
                                    title=p.title or p.path.stem)


def _fig_torque(sweep: dict, conv: Conv, title: str = ""):
    from driver.plotting import manipulator_torque_crob
    return manipulator_torque_crob(sweep["l1"], np.where(sweep["ok"], sweep["tau"][:, 0], np.nan),
                                   np.where(sweep["ok"], sweep["tau"][:, 1], np.nan), conv.c_sweep,
                                   violates=sweep["ok"] & ~sweep["reach_all"], title=title)
