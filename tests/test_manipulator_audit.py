"""2R manipulator and robust-design-example defects found by the independent audit; each test
failed before its fix.

Independent truths: the reach conditions of a 2R arm (|l1 - l2| <= d <= l1 + l2); Craig's
closed-form point-mass torques written out here (not the kernel); the closed-form tolerance
box dl = eps / (sqrt2 RI2); the deck values themselves; a quadratic's stationary point.
"""
from __future__ import annotations

import math
import re

import pytest

from conftest import INPUTS
from driver import manipulator
from driver._cli import main
from driver._deck import read_deck
from driver._runner import run_study
from driver._table import significant

CASE1 = ("  points_x = 1, 2, 3, 4\n  points_y = 5, 7, 7, 6\n  target_x = 1, target_y = 5\n"
         "  mc_samples = 2000\n")


def _run(write_deck, group: str, body: str):
    deck = read_deck(write_deck(f"! audit deck\n&{group}\n" + body + "\n/\n"))
    return run_study(deck, None, [], False).result


def _block(text: str, title: str) -> list[str]:
    lines = text.split(title)[1].split("\n\n")[0].splitlines()
    return lines[3:]   # after the underline and the column header


def test_unreachable_workspace_gets_no_tolerance_box(write_deck):
    """Points at d = 1 and 10: the dexterity optimum on C_rob has l1 + l2 < 10 and cannot reach
    (10, 0); before, the IK status was dropped and a box with verdict 'ok yes' was printed."""
    res = _run(write_deck, "manipulator", "  points_x = 1, 10, points_y = 0, 0, mc_samples = 2000")
    rows = _block(res.text, "Tolerance synthesis")
    verdicts = []
    for line in rows[:2]:
        l1, l2 = (float(v) for v in line.split()[1:3])
        bad = [k + 1 for k, d in enumerate((1.0, 10.0)) if not abs(l1 - l2) <= d <= l1 + l2]
        if not bad:
            assert line.split()[11] == "yes"
        else:
            listed = ", ".join(f"{k} ({(1, 10)[k - 1]}, 0; d = {(1, 10)[k - 1]} m)" for k in bad)
            assert f"no box: the design cannot reach workspace point(s) {listed}" in line
            assert " yes" not in line
        verdicts.append(bool(bad))
    assert verdicts == [True, False]          # dexterity (5.80, 4.10) cannot, manipulability can
    assert any("no box" in w for w in res.warnings)


def test_horizontal_arm_gravity_zero(write_deck):
    """g = 0 is an arm in a horizontal plane: accepted, and the torques are Craig's without the
    gravity terms."""
    res = _run(write_deck, "manipulator", CASE1 + "  gravity = 0, joint_rates = 1.5, -0.5, "
                                                  "joint_accels = 2, 1")
    t45 = manipulator.table_frame(res.tidy, "4.5")
    t47 = manipulator.table_frame(res.tidy, "4.7")
    for (_, a), (_, b) in zip(t45.iterrows(), t47.iterrows()):
        l1, l2, m1, m2 = a["l1_m"], a["l2_m"], a["m1_kg"], a["m2_kg"]
        q2 = math.radians(a["theta2_deg"])
        qd1, qd2, qa1, qa2 = 1.5, -0.5, 2.0, 1.0
        c2, s2 = math.cos(q2), math.sin(q2)
        tau1 = (m2 * l2 ** 2 * (qa1 + qa2) + m2 * l1 * l2 * c2 * (2 * qa1 + qa2) + (m1 + m2) * l1 ** 2 * qa1
                - m2 * l1 * l2 * s2 * qd2 ** 2 - 2 * m2 * l1 * l2 * s2 * qd1 * qd2)
        tau2 = m2 * l1 * l2 * c2 * qa1 + m2 * l1 * l2 * s2 * qd1 ** 2 + m2 * l2 ** 2 * (qa1 + qa2)
        assert b["tau1_Nm"] == pytest.approx(tau1, rel=1e-12)
        assert b["tau2_Nm"] == pytest.approx(tau2, rel=1e-12)


def test_exact_mode_prints_significant_digits(write_deck):
    """tolerance_bound = 1e-6 printed as 0.000000 before; g = 3.71 as 3.7; Table 4.5 lengths as
    5.61 / 3.97 while the torques used 5.6125 / 3.9686."""
    res = _run(write_deck, "manipulator", CASE1 + "  tolerance_bound = 1e-6, gravity = 3.71")
    row = _block(res.text, "Tolerance synthesis")[0].split()
    ri2 = float(row[3])
    assert float(row[4]) == pytest.approx(1e-6 / (math.sqrt(2) * ri2), rel=1e-5) and float(row[4]) > 0
    t45 = _block(res.text, "Table 4.5  Torque parameters")[0].split()
    c = 47.25                                  # mean d^2 of the four points
    assert t45[1] == significant(math.sqrt(2 * c / 3), 6) == "5.61249"
    assert t45[2] == significant(math.sqrt(c / 3), 6)
    assert t45[5] == "3.71000"


@pytest.mark.parametrize("value, digits, text", [(3.71, 6, "3.71000"), (3.5355339e-7, 6, "3.53553E-07"),
                                                 (0.0, 6, "0.00000"), (9.9999996, 6, "10.0000"),
                                                 (-2.5e-4, 3, "-0.000250"), (123456789.0, 4, "1.235E+08"),
                                                 (2.0e10, 3, "2.00E+10")])
def test_significant(value, digits, text):
    assert significant(value, digits) == text


def test_report_prints_the_texts_precision_of_the_optimum():
    """(4.76) prints l1 = l2 = 5.074 where Table 4.4 prints 5.07."""
    deck = read_deck(INPUTS / "manipulator_case2_report.dat")
    res = run_study(deck, None, [], False).result
    assert "workspace l1 = l2 = 5.074" in res.text
    assert "     5.07      5.07" in res.text           # Table 4.4 stays as printed


def test_printed_angles_in_exact_mode_is_an_error(write_deck, capsys):
    deck = write_deck("&manipulator\n" + CASE1 + "  printed_angles_deg = 34.81, 61.53, 20.33, 63.28\n/\n")
    assert main([str(deck), "-o", str(deck.parent / "o")]) == 2
    err = capsys.readouterr().err
    assert "key 'printed_angles_deg'" in err and "mode = 'report'" in err


def test_blank_kappa_says_why(write_deck):
    """Target at l1 + l2 from the base: the arm is stretched, J singular, kappa infinite."""
    res = _run(write_deck, "manipulator", "  points_x = 2, 4, points_y = 0, 0, designs_l1 = 3, designs_l2 = 2\n"
                                          "  target_x = 5, target_y = 0, mc_samples = 2000")
    row = _block(res.text, "Designs: robustness indices")[0]
    assert "kappa blank: J is singular" in row


# ----------------------------------------------------------------------------- robust example

ROBUST = """  dual_targets = {targets}
  dual_y = {dual}
  taguchi_targets = 10, 15, 20
  taguchi_offsets = -0.5, 0.5
  taguchi_y = {tag}"""


def _robust(write_deck, targets: str, dual_means, tag_means, spread):
    """Two replicates per cell: mean +- spread, so std = spread * sqrt2 (Table 2.2), and the two
    noise offsets' row means mean -+ spread (Table 2.5).  Full double precision in the deck."""
    dual = ", ".join(f"{m - s!r}, {m + s!r}" for m, s in zip(dual_means, spread))
    tag = ", ".join(f"{m - s!r}, {m - s!r}, {m + s!r}, {m + s!r}" for m, s in zip(tag_means, spread))
    return _run(write_deck, "robust_example", ROBUST.format(targets=targets, dual=dual, tag=tag))


def test_robust_example_repeated_targets_are_a_deck_error(write_deck, capsys):
    deck = write_deck("&robust_example\n" + ROBUST.format(targets="10, 10, 20", dual="1, 2, 1, 3, 2, 2.5",
                                                          tag=", ".join(["1"] * 12)) + "\n/\n")
    assert main([str(deck), "-o", str(deck.parent / "o")]) == 2
    err = capsys.readouterr().err
    assert "key 'dual_targets'" in err and "3 distinct targets" in err


def test_robust_example_no_minimum_is_said_in_words(write_deck):
    """ln(std) with a maximum in the middle (b2 < 0) has no minimum; ln(std) linear in t is flat."""
    res = _robust(write_deck, "10, 15, 20", [2.0, 3.0, 2.0], [2.0, 3.0, 2.0], [0.1, 0.4, 0.1])
    assert re.search(r"\(2\.9\) no t_min: b2 = -[\d.e-]+ < 0, the fitted quadratic has a maximum at t = 15\.000",
                     res.text)
    assert res.summary["tmin_dual_response"] is None
    res = _robust(write_deck, "10, 15, 20", [2.0, 3.0, 2.0], [2.0, 3.0, 2.0],
                  [0.1, 0.1 * math.exp(1.0), 0.1 * math.exp(2.0)])
    assert "(2.9) no t_min: the fitted quadratic is flat" in res.text
    assert "(2.13) no t_min: the fitted quadratic is flat" in res.text
