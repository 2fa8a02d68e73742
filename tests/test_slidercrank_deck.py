"""&slidercrank decks through the CLI: bad input is a DeckError (exit 2, nothing written, file:line
and key named), good decks write fixed-format tables, buckling is reported in words."""
from __future__ import annotations

import math
import re
from pathlib import Path

import pytest

from driver._cli import main
from driver._deck import read_deck, validate
from driver.slidercrank import SPEC, run

SMALL = """! small aluminium case
&slidercrank
  material = 'aluminium'
  speeds = 11.52, 29.32
  n_elements = 4
  steps_per_rev = 360, revolutions = 2
/
"""


def _write(tmp_path: Path, text: str, name: str = "case.dat") -> Path:
    deck = tmp_path / name
    deck.write_text(text)
    return deck


def _run_cli(tmp_path: Path, deck: Path, *extra: str) -> tuple[int, Path]:
    out = tmp_path / "out"
    return main([str(deck), "-o", str(out), "-q", *extra]), out


def _params(tmp_path: Path, text: str):
    deck = _write(tmp_path, text)
    return validate(read_deck(deck).groups["slidercrank"], SPEC, deck)


BAD = [
    # (replacement lines inserted into the group, key expected in the message, words expected)
    ("crank_radius = 0.6", "crank_radius", "cannot turn"),
    ("crank_radius = 0.505", "crank_radius", "not shorter than the rod"),
    ("area = 0.0", "area", "must be positive"),
    ("second_moment = -2e-11", "second_moment", "must be positive"),
    ("density = 0", "density", "must be positive"),
    ("youngs_modulus = -7e10", "youngs_modulus", "must be positive"),
    ("slider_mass = -0.9", "slider_mass", "must be positive"),
    ("slider_mass = 0", "slider_mass", "must be positive"),
    ("bearing_mass_slider = -0.05", "bearing_mass_slider", "must not be negative"),
    ("steps_per_rev = 100", "steps_per_rev", "too coarse"),
    ("material = 'titanium'", "material", "is not one of"),
    ("speeds = 29.32, 0.0", "speeds", "must be positive"),
    ("n_elements = 0", "n_elements", "between 1 and"),
    ("damping_ratio = 1.5", "damping_ratio", "fraction"),
]


@pytest.mark.parametrize("line, key, words", BAD)
def test_bad_input_is_a_deck_error(tmp_path, capsys, line, key, words):
    k = line.split("=")[0].strip()
    if f"  {k} = " in SMALL:      # replace the line of a key that SMALL already gives
        text = re.sub(rf"  {k} = [^\n]*\n", f"  {line}\n", SMALL)
    else:
        text = SMALL.replace("  n_elements = 4\n", f"  n_elements = 4\n  {line}\n")
    deck = _write(tmp_path, text)
    rc, out = _run_cli(tmp_path, deck)
    err = capsys.readouterr().err
    assert rc == 2
    assert not out.exists() or not any(out.iterdir())
    lineno = next(i for i, l in enumerate(text.splitlines(), 1) if l.strip().startswith(line.split("=")[0].strip()))
    assert f"{deck}:{lineno}" in err
    assert f"key '{key}'" in err
    assert words in err


def test_time_step_message_explains_the_criterion(tmp_path, capsys):
    deck = _write(tmp_path, SMALL.replace("material = 'aluminium'", "material = 'low_carbon_steel'")
                  .replace("steps_per_rev = 360", "steps_per_rev = 400"))
    rc, _ = _run_cli(tmp_path, deck)
    err = capsys.readouterr().err
    assert rc == 2
    # low-carbon steel: first bending 478 rad/s; at 11.52 rad/s 20 steps per bending period need 830 per revolution
    w_bend = math.pi ** 2 * math.sqrt(18.96e10 * 4.9620e-10 / (7800 * 7.8965e-5 * 0.505 ** 4))
    need = math.ceil(20 * w_bend / 11.52)
    assert f"steps_per_rev >= {need}" in err
    assert "steps per period of the first bending mode" in err


def test_custom_section_needs_every_key(tmp_path, capsys):
    text = SMALL.replace("material = 'aluminium'", "area = 27e-6, density = 2660, youngs_modulus = 7.17e10, "
                                                   "section_depth = 3e-3")
    deck = _write(tmp_path, text)
    rc, _ = _run_cli(tmp_path, deck)
    err = capsys.readouterr().err
    assert rc == 2 and "key 'second_moment'" in err and f"{deck}:2" in err


def test_simeon_benchmark_needs_its_geometry(tmp_path, capsys):
    deck = _write(tmp_path, SMALL.replace("n_elements = 4", "n_elements = 4, start = 'simeon1996'"))
    rc, _ = _run_cli(tmp_path, deck)
    assert rc == 2 and "key 'start'" in capsys.readouterr().err


def test_small_deck_writes_tables_and_csv(tmp_path, capsys):
    deck = _write(tmp_path, SMALL)
    rc, out = _run_cli(tmp_path, deck, "--csv")
    assert rc == 0
    text = (out / "case.out").read_text()
    assert "Table 1" in text and "Table 2" in text
    assert "nan" not in text.lower() and "*" * 4 not in text
    # Table 2: 37 rows 0..360 deg, one column per speed
    rows = [l for l in text.splitlines() if re.match(r"^\s+\d+\.0\s+-?\d", l)]
    assert len(rows) == 37 and len(rows[0].split()) == 3
    csv = (out / "case.csv").read_text().splitlines()
    assert csv[0].startswith("material,omega_rad_s,n_elements,crank_angle_deg")
    assert len(csv) == 1 + 2 * 361


def test_summary_and_euler_warning(tmp_path):
    res = run(_params(tmp_path, SMALL))
    s = res.summary
    assert s["omega_1_rad_s"] == 11.52 and s["omega_2_rad_s"] == 29.32
    # peak tension in the crank-end region near TDC, compression near BDC
    assert s["peak_tensile_2_microstrain"] > 0 > s["peak_compressive_2_microstrain"]
    assert min(s["peak_tensile_2_deg"], 360 - s["peak_tensile_2_deg"]) < 5
    assert abs(s["peak_compressive_2_deg"] - 180) < 5
    # aluminium at 29.32 rad/s: compression exceeds the weak-axis Euler load (ratio > 1) -> warning
    assert s["euler_ratio_2"] > 1.0 > s["euler_ratio_1"]
    assert any("29.32 rad/s" in w and "Euler load" in w for w in res.warnings)
    assert not s["buckled"]


def test_geometric_stiffness_reports_buckling_in_words(tmp_path):
    text = SMALL.replace("n_elements = 4", "n_elements = 8, geometric_stiffness = .true.")
    res = run(_params(tmp_path, text))
    assert res.failure is None
    assert res.summary["buckled_2"] and not res.summary["buckled_1"]
    assert "peak_tensile_2_microstrain" not in res.summary
    line = next(l for l in res.text.splitlines() if l.strip().startswith("29.32"))
    assert re.search(r"(STATIC INSTABILITY|LIMIT L/20) at theta2 = \d+\.\d\d deg \(revolution \d\)", line)
    assert set(res.tidy["omega_rad_s"]) == {11.52}


def test_convergence_table(tmp_path):
    text = SMALL.replace("n_elements = 4", "element_counts = 1, 2, 4, 8").replace("11.52, 29.32", "29.32")
    res = run(_params(tmp_path, text))
    lines = res.text.splitlines()
    k = next(i for i, l in enumerate(lines) if l.startswith("Table 3"))
    rows = [l.split() for l in lines[k:] if re.match(r"^\s+[1248]\s+\d", l)]
    assert [int(r[0]) for r in rows] == [1, 2, 4, 8]
    tens = [float(r[2]) for r in rows]
    assert tens == sorted(tens)


def test_simeon_deck_end_state(tmp_path):
    text = """&slidercrank
  crank_radius = 0.15, rod_length = 0.30, area = 64e-6, second_moment = 3.41333333e-10
  density = 7870, youngs_modulus = 2.0e11, section_depth = 0.008
  slider_mass = 0.075552, bearing_mass_crank = 0, bearing_mass_slider = 0
  speeds = 150, n_elements = 8, steps_per_rev = 4189, end_time = 0.1
  damping_ratio = 0, start = 'simeon1996', benchmark = 'simeon1996'
/
"""
    res = run(_params(tmp_path, text))
    row = next(l for l in res.text.splitlines() if "(q1)" in l)
    assert abs(float(row.split()[-1])) < 0.5        # percentage difference from Simeon's q1
    row = next(l for l in res.text.splitlines() if "(q4)" in l)
    assert abs(float(row.split()[-1])) < 0.5


def test_progress_bar_quiet_when_disabled(tmp_path, capsys):
    run(_params(tmp_path, SMALL), progress=False)
    assert capsys.readouterr().err == ""


def test_deck_keys_override_the_named_material(tmp_path):
    text = SMALL.replace("material = 'aluminium'", "material = 'aluminium', second_moment = 1.8225e-10") \
        .replace("steps_per_rev = 360", "steps_per_rev = 1000")     # stiffer in bending: finer steps
    res = run(_params(tmp_path, text))
    line = next(l for l in res.text.splitlines() if "second moment I" in l)
    assert "1.8225e-10" in line and "(deck)" in line
    assert "(Table 1a)" in next(l for l in res.text.splitlines() if "section area A" in l)
    # 9 x 3 mm bar with its strong axis in plane (I = 3 * 9^3 / 12 mm^4): the Euler load is 9 times
    # larger and the rigid-body compression unchanged, so the ratio drops by exactly 9
    weak = run(_params(tmp_path, SMALL)).summary["euler_ratio_2"]
    assert res.summary["euler_ratio_2"] == pytest.approx(weak / 9, rel=1e-12)


def test_progress_bar_runs_when_enabled(tmp_path, capsys):
    run(_params(tmp_path, SMALL), progress=True)
    assert "slidercrank" in capsys.readouterr().err
