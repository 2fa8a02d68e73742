"""Bad input for &manipulator and &robust_example: exit 2, nothing written, message names the
deck file, line and key (through the CLI)."""
from __future__ import annotations

import re

import pytest

from driver._cli import main

BASE = {
    "points_x": "1, 2, 3, 4",
    "points_y": "5, 7, 7, 6",
    "mc_samples": "1000",
}


def deck(tmp_path, **changes) -> str:
    keys = dict(BASE)
    keys.update(changes)
    body = "\n".join(f"  {k} = {v}" for k, v in keys.items() if v is not None)
    path = tmp_path / "bad.dat"
    path.write_text(f"! bad deck\n&manipulator\n{body}\n/\n")
    return str(path)


def line_of(path: str, key: str) -> int:
    for n, text in enumerate(open(path).read().splitlines(), 1):
        if re.match(rf"\s*{key}\s*=", text):
            return n
    return 2


CASES = [
    ("points_x", dict(points_x=","), "empty entry"),
    ("points_x", dict(points_x="1, 'a', 3, 4"), "not a number"),
    ("points_y", dict(points_y="5, 7, 7"), "each workspace point needs an x and a y"),
    ("points_x", dict(points_x="0, 2, 3, 4", points_y="0, 7, 7, 6"), "is the base"),
    ("target_x", dict(target_x="50", target_y="50"), "out of reach of every design"),
    ("designs_l1", dict(designs_l1="1, 5.61", designs_l2="1, 3.97"), "violates the reach conditions"),
    ("designs_l2", dict(designs_l1="5.61, 4.86", designs_l2="3.97"), "designs_l1 gives 2"),
    ("designs_l2", dict(designs_l1="5.61"), "must be given together"),
    ("designs_l1", dict(designs_l1="-5.61", designs_l2="3.97"), "must be positive"),
    ("ri2_levels", dict(ri2_levels="1.5"), "impossible"),
    ("joint_rates", dict(joint_rates="1, 1, 1"), "exactly two"),
    ("mode", dict(mode="'paper'"), "is not one of"),
    ("elbow", dict(elbow="2"), "is not one of"),
    ("printed_angles_deg", dict(printed_angles_deg="34.81, 61.53"), "needs theta1, theta2"),
    ("tolerance_bound", dict(tolerance_bound="0"), "must be positive"),
    ("mc_samples", dict(mc_samples="0"), "at least 1"),
    ("sweep_l1_start", dict(sweep_l1_start="10"), "beyond the C_rob radius"),
    ("sweep_count", dict(sweep_count="-1"), "must not be negative"),
    ("target_y", dict(target_x="1"), "must be given together"),
]


@pytest.mark.parametrize("key,changes,message", CASES, ids=[c[0] + ":" + c[2] for c in CASES])
def test_bad_manipulator_input(tmp_path, capsys, key, changes, message):
    path = deck(tmp_path, **changes)
    out = tmp_path / "out"
    rc = main([path, "-o", str(out), "-q"])
    err = capsys.readouterr().err
    assert rc == 2, err
    assert not out.exists() or not any(out.iterdir())
    assert f"{path}:{line_of(path, key)}: key '{key}'" in err
    assert message in err
    assert "Traceback" not in err


def test_missing_points(tmp_path, capsys):
    path = tmp_path / "bad.dat"
    path.write_text("&manipulator\n  mode = 'exact'\n/\n")
    assert main([str(path), "-o", str(tmp_path / "o")]) == 2
    assert "key 'points_x': missing" in capsys.readouterr().err


def test_partly_unreachable_target_marks_rows(tmp_path, capsys):
    """A target that some designs reach and others do not: marked rows, never NaN."""
    path = deck(tmp_path, designs_l1="5.61, 3.2", designs_l2="3.97, 6.7", target_x="2.5", target_y="1",
                points_x="3, 4", points_y="3, 4")
    out = tmp_path / "out"
    rc = main([path, "-o", str(out), "-q"])
    assert rc == 0, capsys.readouterr().err
    text = (out / "bad.out").read_text()
    assert "target out of reach of this design" in text
    assert "nan" not in text.lower()


ROBUST = """&robust_example
  dual_targets = 10, 15, 20
  dual_y = {dual_y}
  taguchi_targets = 10, 15, 20
  taguchi_offsets = -0.5, 0, 0.5
  taguchi_y = {taguchi_y}
/
"""


@pytest.mark.parametrize("dual_y,taguchi_y,key,message", [
    ("1, 2, 3, 4, 5", ", ".join(["1"] * 18), "dual_y", "do not split"),
    (", ".join(["1", "2"] * 3), ", ".join(["1"] * 17), "taguchi_y", "do not split"),
    (", ".join(["1"] * 6), ", ".join(["1", "2"] * 9), "dual_y", "all equal"),
    ("1, x, 3", "1", "dual_y", "not a number"),
])
def test_bad_robust_example_input(tmp_path, capsys, dual_y, taguchi_y, key, message):
    path = tmp_path / "bad.dat"
    path.write_text(ROBUST.format(dual_y=dual_y, taguchi_y=taguchi_y))
    rc = main([str(path), "-o", str(tmp_path / "o"), "-q"])
    err = capsys.readouterr().err
    assert rc == 2, err
    assert f"key '{key}'" in err and message in err
    assert not (tmp_path / "o").exists()
