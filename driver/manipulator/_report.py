"""A &manipulator run: the .out text (header, tables, chapter 5 comparisons, report-mode
differences), the long tidy table, the summary and the figures."""
from __future__ import annotations

import math
from decimal import Decimal
from typing import TYPE_CHECKING, Any

import numpy as np

from driver._deck import Params
from driver._result import Figure, Result, Tidy
from driver._runner import study_run
from driver._table import fortran_f
from driver.manipulator import _kernel as kernel
from driver.manipulator._analysis import (
    SIGNIFICANT,
    Conv,
    Workspace,
    design_list,
    design_status,
    design_torque_columns,
    optima,
    round_half_up,
    sweep_columns,
    target_point,
    workspace_columns,
)
from driver.manipulator._kernel import Torque
from driver.manipulator._spec import SPEC
from driver.manipulator._tables import TIDY_NAMES, Table, mode_differences, report_tables, tolerance_table

if TYPE_CHECKING:   # annotations only: pandas is imported when a table is built
    import pandas as pd

    from driver._mechanism import MechanismFrames

__all__ = ["run", "TIDY_UNITS", "table_frame", "animation_frames"]


def _header(p: Params, ws: Workspace, conv: Conv) -> list[str]:
    tx, ty = target_point(p, ws)
    pts = ", ".join(f"({x:g}, {y:g})" for x, y in zip(ws.x, ws.y))
    lines = ["2R manipulator robust design ([Ma'arif 2006], chapter 4)", "=" * 50]
    if p.title:
        lines.append(f"case: {p.title}")
    lines += [f"deck: {p.path.name}", f"mode: {p.mode}" + ("  (report's conventions, docs/manipulator.md)"
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


def _tidy(tables: list[Table], tol: list[dict], sweep: dict, used: dict) -> Tidy:
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
        # a box with a reason (e.g. the design cannot reach a target) has only its lengths
        pairs = [("l1_m", "l1"), ("l2_m", "l2")]
        if not rec.get("reason"):
            pairs += [("ri2", "ri2"), ("dl1_m", "dl1"), ("dl2_m", "dl2"), ("worst_corner_m", "worst_corner"),
                      ("mc_max_m", "mc_max"), ("mc_p99_m", "mc_p99")]
        for name, key in pairs:
            add("tolerance", k, rec["name"], name, rec[key])
    return Tidy(records=recs, columns=["table", "row", "label", "quantity", "value", "unit"],
                units={"row": "1", "value": "see unit column"})


def table_frame(tidy: pd.DataFrame, table: str) -> pd.DataFrame:
    """Return one table of the long tidy frame in its printed, wide shape.

    Parameters
    ----------
    tidy : pandas.DataFrame
        A run's tidy table (``table, row, label, quantity, value, unit``).
    table : str
        The table's number, e.g. ``'4.8'``.

    Returns
    -------
    pandas.DataFrame
        A row per printed row (row, label, then a column per quantity in printed order, in
        the units of the tidy ``unit`` column); NaN where the printed cell is blank.
    """
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
    s = workspace_columns(p, ws, conv)
    for i, name in enumerate(used["names"]):
        key = name.lower().replace(" ", "_")
        s[f"{key}_tau1_Nm"] = float(used["tau"][i, Torque.TAU1]) if used["ok"][i] else None
        s[f"{key}_tau2_Nm"] = float(used["tau"][i, Torque.TAU2]) if used["ok"][i] else None
    for rec in tol:
        key = rec["name"].lower().replace(" ", "_")
        s[f"{key}_dl_m"] = rec["dl1"]
        s[f"{key}_mc_max_m"] = rec["mc_max"]
        s[f"{key}_reaches_workspace"] = not rec["reason"]
    # design measures of the first design (what an &optimize deck varies: designs_l1, designs_l2)
    l1, l2 = float(used["l1"][0]), float(used["l2"][0])
    ri, _, reach = kernel.manipulator_design_indices(ws.x, ws.y, [l1], [l2])
    s.update({"design_l1_m": l1, "design_l2_m": l2, "design_ri1": float(ri[0, 0]) if ri[0, 0] > 0 else None,
              "design_ri2": float(ri[0, 1]), "design_ri3": float(ri[0, 2]),
              "design_ri2_excess": float(ri[0, 1]) - math.sqrt(ws.n),
              "design_reaches_all": bool(reach[0]), "design_crob_residual_m2": l1 * l1 + l2 * l2 - ws.mean_d2,
              **design_torque_columns(used["tau"][0, 0], used["tau"][0, 1], bool(used["ok"][0])),
              "design_status": design_status(bool(reach[0]), bool(used["ok"][0]), float(ri[0, 0]))})
    s.update(sweep_columns(sweep))
    return s


@study_run(SPEC)
def run(params: Params, progress: bool = False) -> Result:
    """Synthesise a planar 2R arm robustly for a workspace of points (the report's chapter 4).

    Reach conditions, the robust circle C_rob and the RI1/RI2/RI3 indices, the dexterity and
    manipulability optima, joint angles and motor torques at a target point, and tolerance
    synthesis checked by Monte Carlo (see :mod:`driver.manipulator`).  Lengths in m, angles in
    degrees, joint rates in rad/s, torques in N m.

    Examples
    --------
    >>> import driver
    >>> r = driver.manipulator.run(points_x=[0.5, 1.0, 1.5], points_y=[1.0, 0.5, 1.0])
    >>> round(r.summary["crob_radius_m"], 6), r.summary["design_status"]
    (1.384437, 'ok')
    """
    p = params
    ws = Workspace(np.array(p.points_x, float), np.array(p.points_y, float))
    conv = Conv(p.mode == "report", ws)
    _check_designs(p, ws, conv)
    tables, used, sweep = report_tables(p, conv)
    tol_table, tol = tolerance_table(p, ws, used["names"], used["l1"], used["l2"])
    if not conv.report:
        for t in tables + [tol_table]:
            t.significant(SIGNIFICANT)
    warnings = []
    for rec in tol:
        if rec["reason"]:
            warnings.append(f"design {rec['name']}: {rec['reason']}")
            continue
        if not rec["converged"] or abs(rec["opt_dl1"] * rec["opt_dl2"] / (rec["dl1"] * rec["dl2"]) - 1) > 1e-6:
            warnings.append(f"design {rec['name']}: largest box ({rec['opt_dl1']:.6g}, {rec['opt_dl2']:.6g}) "
                            f"does not match the closed form ({rec['dl1']:.6g}, {rec['dl2']:.6g})")
    lines = _header(p, ws, conv)
    for t in tables:
        lines += t.lines()
    lines += tol_table.lines()
    lines += _claims(used, sweep)
    if conv.report:
        exact_tables, _, _ = report_tables(p, Conv(False, ws))
        diff = mode_differences(tables, exact_tables)
        lines += ["Cells where mode = 'report' and mode = 'exact' differ", "-" * 52]
        lines += diff or ["  none"]
        lines += [""]
        lines += _design_notes(p, conv, used)
    if warnings:
        lines += ["Warnings", "--------"] + [f"  {w}" for w in warnings] + [""]
    tidy = _tidy(tables, tol, sweep, used)
    figures = [Figure("design_space", lambda: _figures().design_space_figure(p, ws, conv, used)),
               Figure("torque_crob", lambda: _figures().torque_figure(sweep, conv, p.title or p.path.stem))]
    return Result(text="\n".join(lines).rstrip() + "\n", tidy=tidy, summary=_summary(p, ws, conv, used, sweep, tol),
                  warnings=warnings, figures=figures)


def _check_designs(p: Params, ws: Workspace, conv: Conv) -> None:
    """Deck designs must satisfy the reach conditions (4.4): DeckError otherwise."""
    if p.designs_l1 is None:
        return
    _, l1, l2 = design_list(p, conv)
    ri = kernel.manipulator_design_indices(ws.x, ws.y, l1, l2)
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
                exponent = Decimal(repr(float(pa[i, j]))).as_tuple().exponent
                assert isinstance(exponent, int)   # a finite number's ('n'/'N'/'F' are NaN and inf)
                half = 0.5 * 10.0 ** exponent   # half a printed unit
                if used["ok"][i] and abs(pa[i, j] - used[key][i]) > half + 1e-9:
                    lines.append(f"  design {name}: printed theta{j + 1} = {pa[i, j]:g} deg but the report's IK gives "
                                 f"{used[key][i]:.2f} deg (not reproducible; used as printed for Table 4.7)")
    if lines:
        lines = ["Printed inputs that the report's own formulas do not give", "-" * 58] + lines + [""]
    return lines


def _figures():
    """The study's figure module, imported when a figure is drawn (matplotlib is the optional [plot] extra)."""
    from driver.manipulator import _figures as figures
    return figures


def animation_frames(params: Params, result: Result | None = None, n: int = 180) -> MechanismFrames:
    """The 2R arm of each design at the workspace points, for the report page's animation
    (:class:`driver._mechanism.MechanismFrames`): the joint angles from the kernel's inverse
    kinematics (:func:`~driver.manipulator.kernel.manipulator_ik`, the deck's elbow branch) at
    each point, moving linearly in joint space from one point to the next; a design that cannot
    reach a point is not drawn there.  The designs are the deck's, else the optima on C_rob."""
    from driver._mechanism import Link, MechanismFrames  # the page's animation only
    ws = Workspace(np.array(params.points_x, float), np.array(params.points_y, float))
    names_d, l1s, l2s = design_list(params, Conv(params.mode == "report", ws))
    m = ws.n
    steps = max(4, n // max(1, len(l1s) * m))        # frames per move from one point to the next
    px, py = np.append(ws.x, ws.x[0]), np.append(ws.y, ws.y[0])   # a tour of the points, back to the first
    pts: list[list[np.ndarray]] = []
    labels: list[str] = []
    segments: list[tuple[int, int]] = []
    for name, l1, l2 in zip(names_d, l1s, l2s):
        th1, th2, st = kernel.manipulator_ik(l1, l2, px, py, params.elbow)
        q = np.where((st == 0)[:, None], np.column_stack([th1, th2]), np.nan)
        if np.isfinite(q).all():   # each move the short way round (the angles are modulo a turn)
            q = np.unwrap(q, axis=0)
        start = len(labels)
        for i in range(m):
            for j in range(steps):
                t = j / steps
                a, b = (1.0 - t) * q[i] + t * q[i + 1]
                elbow = l1 * np.array([math.cos(a), math.sin(a)])
                pts.append([elbow, elbow + l2 * np.array([math.cos(a + b), math.sin(a + b)])])
                where = (f"at P{i + 1} ({ws.x[i]:g}, {ws.y[i]:g})" if j == 0 else
                         f"P{i + 1} \u2192 P{(i + 1) % m + 1} (joint angles interpolated)")
                labels.append(f"{name} (l\u2081 = {l1:g} m, l\u2082 = {l2:g} m) {where}")
        segments.append((start, len(labels)))
    arm = np.array(pts)
    fixed = np.vstack([[0.0, 0.0], np.column_stack([ws.x, ws.y])])
    names = ("A", "elbow", "tip", *(f"P{i + 1}" for i in range(m)))
    points = np.concatenate([np.broadcast_to(fixed[:1], (len(arm), 1, 2)), arm,
                             np.broadcast_to(fixed[1:], (len(arm), m, 2))], axis=1)
    return MechanismFrames(
        names=names, points=points, links=(Link("link 1", (0, 1)), Link("link 2", (1, 2))), labels=tuple(labels),
        ground=(0,), joints=(1,), markers=(2, *range(3, 3 + m)), paths=(2,), segments=tuple(segments),
        periodic=False, frame_name="pose", units="m",
        caption=f"Each design's arm at the workspace points P1..P{m} (inverse kinematics from the kernel, elbow "
                f"branch {params.elbow:+d}), moving linearly in joint space between them.",
        invalid_note="the design cannot reach this point")
