"""The tables of a &manipulator run (Tables 4.1-4.8 of [Ma'arif 2006], the designs' indices and
the tolerance boxes), and the cells where the report's conventions and the exact ones differ."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from driver._deck import Params
from driver._table import Column, fortran_f, render_table
from driver.manipulator import _kernel as kernel
from driver.manipulator._analysis import (
    STATUS,
    Conv,
    Workspace,
    design_angles,
    design_list,
    optima,
    percentile,
    round_half_up,
    sensitivity_blocks,
    sweep_l1_values,
    target_point,
    tolerance_box,
)
from driver.manipulator._kernel import Index, Torque

__all__ = ["Table", "REASONS", "NOT_REPRODUCIBLE", "TEXT_REASONS", "TIDY_NAMES"]


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

    def significant(self, digits: int) -> Table:
        """The same table with every fixed-decimal number column printed to ``digits`` significant
        digits (outside report mode); returns self."""
        self.columns = [Column(c.header, "g", c.width, digits, c.sep) if c.kind == "f" else c
                        for c in self.columns]
        return self

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
    ri = kernel.manipulator_design_indices(conv.ws.x, conv.ws.y, valid, [math.sqrt(c - v * v) for v in valid]) \
        if valid else None
    j = 0
    for i, v in enumerate(l1s):
        if v >= math.sqrt(c):
            rows.append([f"{i + 1}.", None, v, None, None])
            trailers.append(f"l1 >= C_rob radius {radius:.3f}: no l2 on C_rob")
            continue
        l2 = math.sqrt(c - v * v)
        assert ri is not None   # v is valid, so there are valid designs
        ok = bool(ri[2][j])
        rows.append([f"{i + 1}.", float(ri[0][j, Index.RI2]), v, l2, "yes" if ok else "no"])
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
    ri = kernel.manipulator_design_indices(conv.ws.x, conv.ws.y, [opt["dexterity"][0], opt["manipulability"][0]],
                                            [opt["dexterity"][1], opt["manipulability"][1]])
    rows = []
    for j, (name, key) in enumerate((("Dexterity", "dexterity"), ("Workspace", "manipulability"))):
        l1, l2 = opt[key]
        rows.append([name, l1, l2, float(ri[0][j, Index.RI2]), "yes" if ri[2][j] else "no"])
    cols = [Column("Criterion", "s", 10), Column("l1opt", "f", 8, d), Column("l2opt", "f", 8, d),
            Column("RI2", "f", 8, 4), Column("reach", "s", 6)]
    notes = ["Dexterity: l2 = l1 sqrt(2)/2 on C_rob, Workspace (manipulability w = l1 l2 |s2|): l1 = l2"]
    if conv.report and p.text_optimum_decimals is not None:
        k = p.text_optimum_decimals
        txt = lambda v: fortran_f(round_half_up(v, k), None, k)
        notes.append(f"the report's text prints the optima to {k} dp: dexterity l1 = {txt(opt['dexterity'][0])}, "
                     f"l2 = {txt(opt['dexterity'][1])}; workspace l1 = l2 = {txt(opt['manipulability'][0])}")
    return Table("4.4", "Table 4.4  Optimum dimensions on C_rob", cols, rows, notes=notes)


def _torque_tables(p: Params, conv: Conv) -> tuple[Table, Table, Table, dict[str, Any]]:
    names, l1, l2 = design_list(p, conv)
    ang = design_angles(p, conv, l1, l2)
    tx, ty = target_point(p, conv.ws)
    ok = ang["status"] == STATUS["ok"]
    if not ok.any():
        raise p.error("target_x", f"target point ({tx:g}, {ty:g}) is out of reach of every design "
                                  f"(d = {math.hypot(tx, ty):.4f} m); choose a point inside |l1-l2| <= d <= l1+l2")
    mpl, g = p.mass_per_length, p.gravity
    m1, m2 = mpl * l1, mpl * l2
    tau = kernel.manipulator_torques(l1, l2, np.radians(ang["used1"]), np.radians(ang["used2"]),
                                      p.joint_rates, p.joint_accels, m1, m2, g)
    why = "target out of reach of this design"
    r45, r46, r47, tr = [], [], [], []
    for i, name in enumerate(names):
        good = bool(ok[i])
        a1 = float(ang["shown1"][i]) if good else None
        a2 = float(ang["shown2"][i]) if good else None
        r45.append([name, l1[i], l2[i], m1[i], m2[i], g, a1, a2])
        r46.append([name, l1[i], l2[i], a1, a2, *p.joint_rates, *p.joint_accels])
        r47.append([name, l1[i], l2[i], float(tau[i, Torque.TAU1]) if good else None,
                    float(tau[i, Torque.TAU2]) if good else None])
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
    names, l1, l2 = design_list(p, conv)
    ri, sumc2, reach = kernel.manipulator_design_indices(conv.ws.x, conv.ws.y, l1, l2)
    tx, ty = target_point(p, conv.ws)
    th1, th2, st = kernel.manipulator_ik(l1, l2, tx, ty, p.elbow)
    _, w, kappa, _ = kernel.manipulator_arm_states(l1, l2, th1, th2)
    rows, trailers = [], []
    for i, name in enumerate(names):
        ok = st[i] == STATUS["ok"]
        rows.append([name, l1[i], l2[i], float(ri[i, Index.RI1]) if ri[i, Index.RI1] > 0 else None,
                     float(ri[i, Index.RI2]), float(ri[i, Index.RI3]), float(w[i]) if ok else None,
                     float(kappa[i]) if ok and kappa[i] > 0 else None, "yes" if reach[i] else "no"])
        trailers.append("target out of reach of this design" if not ok else
                        "" if kappa[i] > 0 else "kappa blank: J is singular at the target (arm stretched "
                                                "or folded, w = 0), so cond(J) is infinite")
    cols = [Column("Design", "s", 10), Column("l1", "f", 8, 4), Column("l2", "f", 8, 4), Column("RI1", "f", 9, 3),
            Column("RI2", "f", 8, 5), Column("RI3", "f", 8, 5), Column("w", "f", 9, 4), Column("kappa", "f", 8, 4),
            Column("reach", "s", 6)]
    notes = ["RI1 = sigma_max/sigma_min (blank where sigma_min = 0), "
             "RI2 = sigma_max (2.25), RI3 = sigma_max + ||J_x||_F (2.26)",
             f"w = |det J| [m^2] and kappa = cond(J) of the arm Jacobian (4.18) at the target ({tx:g}, {ty:g}), "
             "IK joint angles"]
    return Table("designs", "Designs: robustness indices and dexterity measures", cols, rows, trailers, notes)


def table_4_8(p: Params, conv: Conv) -> tuple[Table, dict[str, Any]]:
    c = conv.c_sweep
    tx, ty = target_point(p, conv.ws)
    dt = math.hypot(tx, ty)
    l1 = sweep_l1_values(p, conv)
    inside = l1 <= math.sqrt(c) + 1e-12
    l2 = np.sqrt(np.where(inside, c - np.minimum(l1, math.sqrt(c)) ** 2, 0.0))
    safe1, safe2 = np.where(l1 > 0, l1, 1.0), np.where(l2 > 0, l2, 1.0)
    th1, th2, st = kernel.manipulator_ik(safe1, safe2, tx, ty, p.elbow)
    st = np.where((l1 > 0) & (l2 > 0) & inside, st, STATUS["degenerate"])
    t2 = np.degrees(th2)
    t1 = round_half_up(math.degrees(math.atan2(ty, tx)), 2) - t2 if conv.report else np.degrees(th1)
    mpl, g = p.mass_per_length, p.gravity
    m1, m2 = mpl * l1, mpl * l2
    tau = kernel.manipulator_torques(safe1, safe2, np.radians(t1), np.radians(t2), p.joint_rates,
                                      p.joint_accels, m1, m2, g)
    ri = kernel.manipulator_design_indices(conv.ws.x, conv.ws.y, safe1, safe2)
    rows, trailers = [], []
    for i in range(l1.size):
        ok = st[i] == STATUS["ok"]
        if not inside[i]:
            rows.append([f"{i + 1}.", l1[i], None, m1[i], None, g, None, None, None, None])
            trailers.append("l1 beyond the C_rob radius")
            continue
        row = [f"{i + 1}.", l1[i], l2[i], m1[i], m2[i], g]
        if ok:
            row += [float(t1[i]), float(t2[i]), float(tau[i, Torque.TAU1]), float(tau[i, Torque.TAU2])]
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


def tolerance_table(p: Params, ws: Workspace, names: list[str], l1: np.ndarray, l2: np.ndarray) -> tuple[Table, list[dict]]:
    eps = p.tolerance_bound
    rng = np.random.default_rng(p.mc_seed)
    unit = rng.uniform(-1.0, 1.0, size=(p.mc_samples, 2))
    col = 0 if p.error_measure == "global" else 1
    rows, out = [], []
    trailers = []
    for i, name in enumerate(names):
        th1, th2, st = kernel.manipulator_ik(l1[i], l2[i], ws.x, ws.y, p.elbow)
        bad = np.flatnonzero(st != STATUS["ok"])
        if bad.size:
            d = np.hypot(ws.x[bad], ws.y[bad])
            pts = ", ".join(f"{k + 1} ({ws.x[k]:g}, {ws.y[k]:g}; d = {dk:.4g} m)" for k, dk in zip(bad, d))
            why = (f"no box: the design cannot reach workspace point(s) {pts}; it reaches "
                   f"{abs(l1[i] - l2[i]):.4g} <= d <= {l1[i] + l2[i]:.4g} m")
            out.append({"name": name, "l1": float(l1[i]), "l2": float(l2[i]), "ri2": None, "dl1": None,
                        "dl2": None, "opt_dl1": None, "opt_dl2": None, "converged": False,
                        "worst_corner": None, "mc_max": None, "mc_p99": None, "reason": why})
            rows.append([name, float(l1[i]), float(l2[i])] + [None] * 8 + ["-"])
            trailers.append(why)
            continue
        blocks = sensitivity_blocks(th1, th2)
        box = tolerance_box(blocks, eps, p.error_measure)
        dl = box["closed"] if box["closed"] is not None else box["u"]
        corners = np.array([[1, 1], [1, -1], [-1, 1], [-1, -1]], float) * dl
        worst = kernel.manipulator_position_errors(th1, th2, corners)[:, col].max()
        err = kernel.manipulator_position_errors(th1, th2, unit * dl)[:, col]
        ri2 = math.sqrt(ws.n + abs(np.cos(th2).sum()))
        rec = {"name": name, "l1": float(l1[i]), "l2": float(l2[i]), "ri2": ri2, "dl1": float(dl[0]),
               "dl2": float(dl[1]), "opt_dl1": float(box["u"][0]), "opt_dl2": float(box["u"][1]),
               "converged": box["converged"], "worst_corner": float(worst), "mc_max": float(err.max()),
               "mc_p99": percentile(err, 99.0), "reason": ""}
        out.append(rec)
        trailers.append("")
        rows.append([name, rec["l1"], rec["l2"], ri2, rec["dl1"], rec["dl2"], rec["opt_dl1"], rec["opt_dl2"],
                     rec["worst_corner"], rec["mc_max"], rec["mc_p99"], "yes" if rec["mc_max"] <= eps * (1 + 1e-12) else "NO"])
    cols = [Column("Design", "s", 10), Column("l1", "f", 7, 3), Column("l2", "f", 7, 3), Column("RI2", "f", 7, 4),
            Column("dl1", "f", 9, 6), Column("dl2", "f", 9, 6), Column("dl1 opt", "f", 10, 6),
            Column("dl2 opt", "f", 10, 6), Column("worst corner", "f", 12, 6), Column("MC max", "f", 9, 6),
            Column("MC p99", "f", 9, 6), Column("ok", "s", 3)]
    meas = ("global error ||J_x dl||_2 over all points (Caro)" if col == 0 else "largest error at a single point")
    notes = [f"bound epsilon = {eps:g} m on the {meas}; box l_i +- dl_i; closed form dl = eps/(sqrt2 RI2)"
             if col == 0 else f"bound epsilon = {eps:g} m on the {meas}; closed form dl = eps/sqrt(2(1 + max|c2_i|))",
             "dl opt: the largest box over every corner constraint, found apart from the closed form (docs/manipulator.md)",
             f"Monte Carlo: {p.mc_samples} uniform samples in the box (seed {p.mc_seed}), joint angles held at the "
             f"nominal IK ({'elbow +1' if p.elbow > 0 else 'elbow -1'})"]
    return Table("tol", "Tolerance synthesis (Caro 2005, eq. 2.45)", cols, rows, trailers, notes=notes), out


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


def mode_differences(report: list[Table], exact: list[Table]) -> list[str]:
    """Every cell whose printed text differs between the two modes, with the reason."""
    lines = []
    for a, b in zip(report, exact):
        ca = a.cells()
        cb = {(i, col.header.strip()): col.cell(v) for i, row in enumerate(b.rows)
              for col, v in zip(a.columns, row)}     # exact values at the report's printed digits
        for key in sorted(set(ca) | set(cb)):
            va, vb = ca.get(key, "(none)"), cb.get(key, "(none)")
            if va != vb:
                why = REASONS.get((a.key, key[1]), "follows from the cells above")
                lines.append(f"  Table {a.key:<4} row {key[0] + 1:>2} {key[1]:<7} report {va or '(blank)':>10}"
                             f"  exact {vb or '(blank)':>10}  {why}")
    return lines


# ----------------------------------------------------------------------------- run

def report_tables(p: Params, conv: Conv) -> tuple[list[Table], dict[str, Any], dict[str, Any]]:
    t45, t46, t47, used = _torque_tables(p, conv)
    t48, sweep = table_4_8(p, conv)
    tables = [_t41(p, conv), _t42(p, conv), _t44(p, conv), _designs_table(p, conv), t45, t46, t47, t48]
    return tables, used, sweep
