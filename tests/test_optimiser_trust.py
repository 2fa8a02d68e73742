"""Issue 24's reproducers, each against a closed form or a brute force written here (not the optimiser).

1. A feasible optimum exceeding a bound by a rounding error is feasible within the stated
   tolerance: the least torque demand on C_rob of a workspace whose optimum sits where C_rob meets
   the reach condition l1 + l2 = R -- closed form (R -+ sqrt(2 c - R^2)) / 2.
2. The manipulator's signed sum tau1 + tau2 is named for what it is; the demand |tau1| + |tau2|
   and the peak max |tau_i| are columns of their own (identities on the joint torques).
3. polish = .true. after differential evolution improves the best member to the optimum a
   multi-start SLSQP finds, and says so.
4. Equalities (a == b) and a max-min objective (epigraph): on the shipped crank-rocker deck every
   start that is a crank-rocker (Grashof, crank shortest: checked here by hand) reaches the optimum.
"""
from __future__ import annotations

import math

import pytest

from conftest import ROOT
from driver.optimize import optimize

REPRO_1 = """&manipulator
 points_x = -4, -2, 1, -3
 points_y = 2, 5, 4, -1
 designs_l1 = 2.5, designs_l2 = 3.5
 target_x = -3, target_y = -1
 mc_samples = 1000
/
&optimize
 var1 = 'manipulator.designs_l1', lower1 = 0.5, upper1 = 8.0
 var2 = 'manipulator.designs_l2', lower2 = 0.5, upper2 = 8.0
 minimize = 'abs(design_1_tau1_Nm) + abs(design_1_tau2_Nm)'
 constraint1 = 'abs(design_l1_m - design_l2_m) <= r_m'
 constraint2 = 'design_l1_m + design_l2_m >= R_m'
 constraint3 = 'design_crob_residual_m2 <= 1e-6'
 constraint4 = 'design_crob_residual_m2 >= -1e-6'
 method = 'slsqp', starts = 8, seed = 5
/
"""


def _manip_run(points, l1, l2, target):
    from driver import manipulator
    from driver._deck import RawGroup, validate
    values = {"points_x": [p[0] for p in points], "points_y": [p[1] for p in points], "designs_l1": [l1],
              "designs_l2": [l2], "target_x": target[0], "target_y": target[1], "mc_samples": 200}
    return manipulator.run(validate(RawGroup("manipulator", values, {}, 1), manipulator.SPEC, "x.dat")).summary


def test_a_feasible_optimum_is_not_rejected_by_a_rounding_error(tmp_path):
    path = tmp_path / "r1.dat"
    path.write_text(REPRO_1)
    oc = optimize(path, tmp_path / "out", jobs=1)
    assert oc.success, oc.message
    # workspace distances^2 20, 29, 17, 10: mean c = 19, R = sqrt(29); the optimum is the corner of
    # the reachable arc of C_rob, l1 + l2 = R and l1^2 + l2^2 = c
    c, R = 19.0, math.sqrt(29.0)
    l1 = (R - math.sqrt(2 * c - R * R)) / 2
    assert oc.x["manipulator.designs_l1"] == pytest.approx(l1, abs=2e-6)          # 1.192582
    assert oc.x["manipulator.designs_l2"] == pytest.approx(R - l1, abs=2e-6)
    assert oc.fun == pytest.approx(585.598, abs=2e-3)                             # the audit's value
    # brute force: along the reachable arc of C_rob, away from the corner, the demand only rises
    points = [(-4, 2), (-2, 5), (1, 4), (-3, -1)]
    t0 = math.atan2(R - l1, l1)
    demand = []
    for k in range(1, 41):
        t = t0 - k * 0.002       # l1 grows, l2 shrinks: l1 + l2 > R (reachable)
        s = _manip_run(points, math.sqrt(c) * math.cos(t), math.sqrt(c) * math.sin(t), (-3, -1))
        demand.append(abs(s["design_1_tau1_Nm"]) + abs(s["design_1_tau2_Nm"]))
    assert oc.fun <= min(demand)
    text = (tmp_path / "out" / "r1.out").read_text()
    assert "Result: CONVERGED" in text and "tolerance" in text


def test_the_signed_torque_sum_is_not_a_demand():
    s = _manip_run([(-3, 1), (-1, 4), (2, 3)], 3.0, 2.6, (-3, 1))
    t1, t2 = s["design_1_tau1_Nm"], s["design_1_tau2_Nm"]
    assert s["design_tau_sum_signed_Nm"] == pytest.approx(-1041.78, abs=0.01)     # the audit's value
    assert s["design_tau_sum_signed_Nm"] == pytest.approx(t1 + t2, rel=1e-12)
    assert s["design_torque_demand_Nm"] == pytest.approx(abs(t1) + abs(t2), rel=1e-12)
    assert s["design_peak_torque_Nm"] == pytest.approx(max(abs(t1), abs(t2)), rel=1e-12)
    assert t1 < 0 and t2 < 0          # both motors push against gravity the other way: demand = |sum|
    assert "design_total_torque_Nm" not in s


def test_an_old_column_name_is_answered_with_the_new_one(tmp_path):
    from driver._deck import DeckError
    text = (ROOT / "inputs" / "optimize_manipulator_torque.dat").read_text()
    path = tmp_path / "old.dat"
    path.write_text(text.replace("minimize = 'design_torque_demand_Nm'", "minimize = 'design_total_torque_Nm'"))
    with pytest.raises(DeckError, match="design_tau_sum_signed_Nm"):
        optimize(path, None, jobs=1)


POLISH = """&fourbar
  fixed_link = 8.0, crank = 2.0, coupler = 8.0, rocker = 6.0, omega = 1.0, step_deg = 5
/
&optimize
  var1 = 'fourbar.crank',   lower1 = 0.5, upper1 = 6.0
  var2 = 'fourbar.coupler', lower2 = 1.0, upper2 = 16.0
  var3 = 'fourbar.rocker',  lower3 = 1.0, upper3 = 16.0
  maximize = 'mu_min_deg'
  constraint1 = 'grashof_class == "crank-rocker"'
  constraint2 = 'rocker_swing_deg >= 45'
  constraint3 = 'rocker_swing_deg <= 55'
  constraint4 = 'mu_max_deg <= 130'
  {method}
/
"""


def test_polish_after_evolution_reaches_the_local_optimum_and_says_so(tmp_path):
    de = tmp_path / "de.dat"
    de.write_text(POLISH.format(method="method = 'differential_evolution', seed = 1, polish = .true."))
    ls = tmp_path / "ls.dat"
    ls.write_text(POLISH.format(method="method = 'slsqp', starts = 8, tol = 1e-8"))
    a = optimize(de, tmp_path / "a", jobs=1)
    b = optimize(ls, tmp_path / "b", jobs=1)
    assert a.success and b.success
    assert a.method.polish is not None and a.method.polish["record"] is not None
    assert a.fun == pytest.approx(b.fun, abs=1e-4)
    line = next(l for l in (tmp_path / "a" / "de.out").read_text().splitlines() if "polish ......" in l)
    assert "improved mu_min_deg from" in line
    # the member it started from is worse: the evolution alone stops short
    start = float(line.split("from ")[1].split()[0])
    assert start < a.fun


def _crank_rocker_by_hand(ground: float, crank: float, coupler: float, rocker: float) -> bool:
    links = sorted([ground, crank, coupler, rocker])
    return crank == links[0] and links[0] + links[3] < links[1] + links[2]


def test_every_crank_rocker_start_reaches_the_optimum_of_the_shipped_deck(tmp_path):
    oc = optimize(ROOT / "inputs" / "optimize_crank_rocker.dat", None, jobs=1)
    assert oc.success
    starts = oc.method.starts
    inside = [r for r in starts if _crank_rocker_by_hand(10.0, *r["x0"])]
    assert len(inside) >= 3
    assert all(r["reached"] for r in inside)
    # equalities met within the stated tolerance, 1e-7 x max(1, |a|, |b|)
    s = oc.check.summary
    assert abs(s["rocker_swing_deg"] - 60.0) <= 1e-7 * 60.0
    assert abs(s["time_ratio"] - 1.25) <= 1e-7 * 1.25


def _crank_rocker_deck(tmp_path, swing: float, q: float):
    path = tmp_path / "cr.dat"
    path.write_text(f"&synthesis\n task = 'crank_rocker', swing_deg = {swing}, time_ratio = {q}\n fixed_link = 10.0\n/\n")
    return path


def _mu_deg(a: float, b: float, c: float, d: float) -> tuple[float, float]:
    """Transmission-angle extremes of a crank-rocker by the law of cosines (crank along the ground)."""
    mu = lambda x: math.degrees(math.acos((b * b + c * c - x * x) / (2 * b * c)))
    return mu(d - a), mu(d + a)


def _swing_deg(a: float, b: float, c: float, d: float) -> float:
    """Rocker swing between the folded and extended dead centres (law of cosines at O_B)."""
    ang = lambda x: math.acos((c * c + d * d - x * x) / (2 * c * d))
    return math.degrees(ang(b + a) - ang(b - a))


def test_time_ratio_one_has_no_interior_optimum_and_a_usable_member_is_returned(tmp_path):
    from driver.synthesis import synthesise
    syn = synthesise(_crank_rocker_deck(tmp_path, 30.0, 1.0))
    assert syn.failure is None
    assert any("no interior optimum" in w and "75.000000" in w for w in syn.warnings)   # 90 - swing/2
    a, b, c, d = (syn.linkage[k] for k in ("crank", "coupler", "rocker", "fixed_link"))
    assert min(a, b, c) >= 0.05 * d * (1 - 1e-9)                 # usable: every link >= 5 % of the ground
    assert _swing_deg(a, b, c, d) == pytest.approx(30.0, abs=1e-6)
    lo, hi = _mu_deg(a, b, c, d)
    q = min(lo, 180 - hi)
    assert 70.0 < q < 75.0                                         # below the limit, approaching it
    assert "WARNING: no interior optimum" in syn.text


@pytest.mark.parametrize("swing, q", [(60.0, 3.5), (170.0, 1.2)])
def test_a_poor_best_transmission_angle_is_named(tmp_path, swing, q):
    from driver.synthesis import synthesise
    syn = synthesise(_crank_rocker_deck(tmp_path, swing, q))
    a, b, c, d = (syn.linkage[k] for k in ("crank", "coupler", "rocker", "fixed_link"))
    lo, hi = _mu_deg(a, b, c, d)
    assert min(lo, 180 - hi) < 30.0                                # by hand: the design is poor
    assert any(w.startswith("poor design: transmission angle") for w in syn.warnings)
    assert "WARNING: poor design" in syn.text


def test_json_records_of_optimisation_synthesis_and_sweep(tmp_path):
    import json

    from driver._cli import main
    decks = [ROOT / "inputs" / n for n in ("optimize_manipulator_torque.dat", "synthesis_crank_rocker.dat",
                                           "fourbar_paper_sweep.dat")]
    assert main([*map(str, decks), "-o", str(tmp_path), "-q", "--json"]) == 0
    opt = json.loads((tmp_path / "optimize_manipulator_torque.json").read_text())
    assert opt["engine"] == "optimize" and opt["ok"] is True
    opt = opt["optimize"]
    assert opt["success"] is True and opt["status"] == 0 and opt["nfev"] > 0 and opt["nit"] > 0
    assert opt["x_names"] == ["manipulator.designs_l1", "manipulator.designs_l2"]
    l1, l2 = opt["x"]
    eq = opt["constraints"][1]
    assert eq["kind"] == "equality" and eq["met"] is True
    assert eq["value"] == pytest.approx(l1 * l1 + l2 * l2, rel=1e-12)          # its left side, recomputed
    assert abs(eq["value"] - 47.25) <= eq["tolerance"] == pytest.approx(1e-7 * 47.25)
    assert eq["margin"] == pytest.approx(-abs(l1 * l1 + l2 * l2 - 47.25), abs=1e-12)
    syn = json.loads((tmp_path / "synthesis_crank_rocker.json").read_text())
    assert syn["ok"] is True and syn["synthesis"]["linkage"]["crank"] == pytest.approx(4.126, abs=1e-3)
    sw = json.loads((tmp_path / "fourbar_paper_sweep.json").read_text())
    assert sw["engine"] == "sweep" and sw["sweep"]["rows"] == 4 and sw["sweep"]["swept_keys"] == ["fourbar.crank"]
