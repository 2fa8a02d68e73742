"""&manipulator deck keys: the group's SPEC, its cross-key checks, axis labels and the run's
cost estimate from the keys alone (driver._limits)."""
from __future__ import annotations

import math
from typing import Any

from driver._deck import GroupSpec, Key, Params, non_empty, non_negative, positive
from driver._limits import Estimate
from driver._study import contract_doc

__all__ = ["SPEC", "LABELS", "SWEEP_PLOT", "SWEEP_BEST", "estimate"]


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
    if p.text_optimum_decimals is not None and p.mode != "report":
        raise p.error("text_optimum_decimals", "applies only to mode = 'report'")
    if p.printed_angles_deg is not None and len(p.printed_angles_deg) == 2 * ndes and p.mode != "report":
        raise p.error("printed_angles_deg", "applies only to mode = 'report' (the report's printed Table 4.5 "
                                            "angles); mode = 'exact' takes the joint angles from the inverse "
                                            "kinematics: remove the key or set mode = 'report'")
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


#: axis labels of summary columns and deck keys (driver._output.column_label): name -> (words, units)
LABELS = {"r_m": ("inner workspace radius $r$", "m"), "R_m": ("outer workspace radius $R$", "m"),
          "mean_d2_m2": ("mean squared point distance $\\overline{d^2}$", "m$^2$"),
          "crob_radius_m": ("$C_{rob}$ radius", "m"),
          "crob_c_m2": ("$C_{rob}$: $l_1^2 + l_2^2$", "m$^2$"), "ri2_min": ("minimum $RI_2$", "-"),
          "dexterity_l1_m": ("dexterity optimum $l_1$", "m"), "dexterity_l2_m": ("dexterity optimum $l_2$", "m"),
          "manipulability_l1_m": ("manipulability optimum $l_1$", "m"),
          "manipulability_l2_m": ("manipulability optimum $l_2$", "m"),
          "sweep_min_tau_sum_signed_Nm": ("least signed $\\tau_1 + \\tau_2$ along $C_{rob}$ (the report's total torque)",
                                          "N m"),
          "sweep_min_l1_m": ("$l_1$ of the least torque", "m"), "sweep_min_l2_m": ("$l_2$ of the least torque", "m"),
          "mass_per_length": ("link mass per length", "kg/m"), "gravity": ("gravity $g$", "m/s$^2$"),
          "design_l1_m": ("design $l_1$", "m"), "design_l2_m": ("design $l_2$", "m"),
          "design_ri1": ("design $RI_1$", "-"), "design_ri2": ("design $RI_2$", "-"), "design_ri3": ("design $RI_3$", "-"),
          "design_ri2_excess": ("design $RI_2 - \\sqrt{n}$", "-"),
          "design_crob_residual_m2": ("design $l_1^2 + l_2^2 - \\overline{d^2}$", "m$^2$"),
          "design_tau_sum_signed_Nm": ("design signed $\\tau_1 + \\tau_2$ at the target (not a demand)", "N m"),
          "design_torque_demand_Nm": ("design torque demand $|\\tau_1| + |\\tau_2|$ at the target", "N m"),
          "design_peak_torque_Nm": ("design peak joint torque $\\max(|\\tau_1|, |\\tau_2|)$ at the target", "N m"),
          "designs_l1": ("design link length $l_1$", "m"), "designs_l2": ("design link length $l_2$", "m")}
#: summary columns renamed (old -> new): a deck naming an old one is told the new name
RENAMED = {"design_total_torque_Nm": "design_tau_sum_signed_Nm (signed; the demand is design_torque_demand_Nm)",
           "sweep_min_total_torque_Nm": "sweep_min_tau_sum_signed_Nm"}
#: which way a summary column is better (the design-space maps star the best kept design)
SWEEP_BEST = {"design_torque_demand_Nm": "min", "design_peak_torque_Nm": "min", "design_ri2": "min",
              "design_ri2_excess": "min", "sweep_min_tau_sum_signed_Nm": "min"}
#: what a sweep summary plots when its deck names no plot_y
#: (a design sweep's constant columns are skipped: its plot shows the design_* columns)
SWEEP_PLOT = ("design_torque_demand_Nm", "design_ri2", "crob_radius_m", "sweep_min_tau_sum_signed_Nm", "sweep_min_l1_m",
              "dexterity_l1_m", "manipulability_l1_m")


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
        "gravity": Key("float", default=9.8, check=non_negative, units="m/s^2",
                       doc="g, along -y; 0 for an arm moving in a horizontal plane"),
        "text_optimum_decimals": Key("int", check=lambda v: None if 0 <= v <= 6 else "must be 0 to 6",
                                     doc="report mode: decimals of the optima as the report's text prints "
                                         "them (e.g. 3 for (4.76) l1 = l2 = 5.074; Table 4.4 prints 2)"),
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


@contract_doc
def estimate(params: Params) -> Estimate:
    """Estimate the memory and work of a run from the keys alone, before it allocates.

    The Monte Carlo check holds
    mc_samples x points errors (about 64 bytes and 50 ns each), every row of the C_rob sweep is a
    small design evaluation (about 2 ms), the designs tables a few us per design and point.

    %(estimate)s
    """
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
    if p.crob_l1:
        crob = Estimate(0.0, 0.0)
    else:   # Table 4.2 lists l1 = floor(radius), ..., 1 along C_rob; the radius grows with the workspace
        far = "points_x" if max(map(abs, p.points_x)) >= max(map(abs, p.points_y)) else "points_y"
        reach = max(math.hypot(x, y) for x, y in zip(p.points_x, p.points_y)) if pts else 1.0
        rows = 2.0 * reach + 2.0
        crob = Estimate(1000.0 * rows, 1e-4 * rows, far, far, f"about {rows:.4g} C_rob rows (workspace size)")
    return mc + sweep + tables + crob
