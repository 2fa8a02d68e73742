"""The input boundary, round three (issue 36): every reproducer of the campaign is a test.

Each refusal is exit 2 (or a DeckError) naming the deck, the line and the key, with nothing
written; each fix was checked to fail on the code before it.  The comparison with gfortran's own
namelist reader is tests/test_fortran_reader.py; links are tests/test_output_links.py; resume
records tests/test_optimize_resume_verified.py.
"""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

import driver
from driver._cli import main
from driver._deck import DeckError, read_deck

FOURBAR = """&fourbar
  fixed_link = 12.0, crank = 2.0, coupler = 15.0, rocker = 9.0
  omega = 5.0, step_deg = 60
/
"""


def _refused(tmp_path, capsys, text: str, line: int, key: str, words: str = "") -> str:
    deck = tmp_path / "d.dat"
    deck.write_text(text)
    out = tmp_path / "out"
    assert main([str(deck), "-o", str(out), "-q", "-j", "1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert err[0].startswith(f"error: {deck}:{line}: key '{key}': "), err[0]
    assert words in err[0], err[0]
    assert not out.exists() or not any(out.rglob("*"))
    return err[0]


# ----------------------------------------------------------------------------- 3. r* value

@pytest.mark.parametrize("value,words", [
    ("2* 5", "'2*' followed by a blank or a line end is 2 null value(s) and then '5'"),   # was [5, 5]
    ("2*, 5", "'2*' followed by a comma is 2 null value(s)"),
    ("2*\n    5", "null value"),
    ("7.5, 3.0,\n    ! the point\n    2*", "null value"),   # a comment line between is no separator
])
def test_a_repeat_count_before_a_blank_is_null_values(tmp_path, capsys, value, words):
    text = FOURBAR.replace("step_deg = 60", f"step_deg = 60\n  coupler_point = {value}")
    line = 4 + value[:value.index("*")].count("\n")
    _refused(tmp_path, capsys, text, line, "coupler_point", words)


def test_one_null_then_a_value_is_too_many_for_a_scalar(tmp_path, capsys):
    """gfortran refuses 'crank = 1* 5' (a null value, then 5: two values for one); it was read as 5."""
    _refused(tmp_path, capsys, FOURBAR.replace("crank = 2.0", "crank = 1* 5"), 2, "crank", "null value")


def test_a_repeat_count_glued_to_its_value_still_repeats():
    deck = read_deck("d.dat", text=FOURBAR.replace("step_deg = 60", "step_deg = 60, coupler_point = 2*5"))
    assert deck.groups["fourbar"].values["coupler_point"] == [5, 5]


@pytest.mark.parametrize("text,line,key,words", [
    # gfortran reads a null value at each of these places, the Fortran standard none: refused when
    # the list goes on after it, fine when the list ends there
    ("  coupler_point = 7.5, ! u\n    3.0", 4, "coupler_point", "drop the comma before the comment"),
    ("  coupler_point = ! u, v\n    7.5, 3.0", 4, "coupler_point", "put the first value on the line of the key"),
    ("  coupler_point = 7.5\n    , 3.0", 5, "coupler_point", "end the line before with the comma"),
])
def test_separators_compilers_read_differently_are_refused(tmp_path, capsys, text, line, key, words):
    _refused(tmp_path, capsys, FOURBAR.replace("step_deg = 60", "step_deg = 60\n" + text), line, key, words)


def test_the_same_separators_ending_a_list_are_fine():
    text = FOURBAR.replace("crank = 2.0,", "crank = 2.0,   ! the crank\n ").replace(
        "step_deg = 60", "step_deg = 60\n  coupler_point = 7.5, 3.0\n  , title = 'x'")
    deck = read_deck("d.dat", text=text)
    assert deck.groups["fourbar"].values["crank"] == 2.0
    assert deck.groups["fourbar"].values["coupler_point"] == [7.5, 3.0]


def test_a_quoted_number_is_text(tmp_path, capsys):
    """gfortran refuses crank = '5' (a string for a real); it was read as 5."""
    _refused(tmp_path, capsys, FOURBAR.replace("crank = 2.0", "crank = '5'"), 2, "crank",
             "is in quotes, and a quoted value is text")


def test_a_comment_glued_to_a_value_is_a_comment():
    deck = read_deck("d.dat", text=FOURBAR.replace("crank = 2.0,", "crank = 2.0!the crank\n "))
    assert deck.groups["fourbar"].values["crank"] == 2.0


def test_negative_zero_keeps_its_sign():
    """Fortran reads -0 into a real as -0.0 (f90nml: the integer 0)."""
    import math
    deck = read_deck("d.dat", text=FOURBAR.replace("step_deg = 60", "step_deg = 60, coupler_point = -0, 3"))
    assert math.copysign(1.0, deck.groups["fourbar"].values["coupler_point"][0]) == -1.0


@pytest.mark.parametrize("value,words", [
    (".t", "write .true. or .false."), ("1;2", "semicolon"), ("1q3", "Q exponent"), ("inf", "infinity and NaN"),
])
def test_spellings_gfortran_reads_are_refused_in_words(value, words):
    with pytest.raises(DeckError, match=words):
        read_deck("d.dat", text=FOURBAR.replace("crank = 2.0", f"crank = {value}"))


# ----------------------------------------------------------------------------- 4. budgets

PATH = """&synthesis
  task = 'path'
  target_x = 2.539732, 2.961812, 0.467788, -1.640845, -1.699352
  target_y = 4.978770, 7.379614, 7.194576, 4.811725, 2.397948
  maxiter = 200, popsize = 10, seed = 1, tolerance = 1e-4, length_max = 12
/
"""


@pytest.fixture
def no_search(monkeypatch):
    """A path search that starts is a failure of the test (the refusal must come before it)."""
    from driver.synthesis import _path as pg

    def started(*_a, **_k):
        raise AssertionError("the search started")
    monkeypatch.setattr(pg, "solve", started)
    monkeypatch.setattr(pg, "evaluate", started)


@pytest.mark.parametrize("change,options,key", [
    (("", ""), ["--max-work", "1"], "target_x"),                       # the shipped deck's ~10 s
    (("popsize = 10", "popsize = 10, samples = 100000"), ["--max-work", "1"], "samples"),   # the issue's: 100 000 samples
    (("maxiter = 200", "maxiter = 100000, samples = 100000"), [], "samples"),   # beyond 2 min by default
])
def test_path_synthesis_is_refused_above_the_budget_before_it_starts(tmp_path, capsys, no_search, change, options,
                                                                   key):
    deck = tmp_path / "p.dat"
    deck.write_text(PATH.replace(*change) if change[0] else PATH)
    out = tmp_path / "out"
    assert main([str(deck), "-o", str(out), "-q", *options]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"key '{key}'" in err[0] and "this synthesis is about" in err[0], err
    assert "refused before starting" in err[0]
    assert not out.exists() or not any(out.iterdir())


@pytest.mark.parametrize("body,key", [
    ("task = 'crank_rocker', swing_deg = 60, time_ratio = 1.2, family_points = 100000", "family_points"),
    ("task = 'function', function = 'log10(x)', x_start = 1, x_stop = 2, crank_range_deg = 60, "
     "rocker_range_deg = 90, error_points = 100000, points = 10000", "error_points"),
])
def test_every_synthesis_task_has_its_work_estimated(tmp_path, capsys, body, key):
    deck = tmp_path / "s.dat"
    deck.write_text(f"&synthesis\n  {body}\n/\n")
    assert main([str(deck), "-o", str(tmp_path / "out"), "-q", "--max-work", "0.2"]) == 2
    err = capsys.readouterr().err
    assert f"key '{key}': this synthesis is about" in err and "refused before starting" in err, err


@pytest.mark.parametrize("xs,ys,key,words", [
    ("0, 1, 2, 3", "0, 1, 2, 3", "target_y", "lie on one straight line"),     # the four collinear targets
    ("0, 1, 1, 3", "0, 2, 2, 1", "target_x", "targets 2 and 3 are the same point"),
    ("1, 1, 1", "2, 2, 2", "target_x", "every target is the same point"),
])
def test_degenerate_path_targets_are_refused_with_the_reason(tmp_path, capsys, no_search, xs, ys, key, words):
    deck = tmp_path / "p.dat"
    deck.write_text(f"&synthesis\n  task = 'path'\n  target_x = {xs}\n  target_y = {ys}\n  maxiter = 20\n/\n")
    assert main([str(deck), "-o", str(tmp_path / "out"), "-q"]) == 2
    err = capsys.readouterr().err
    assert f"key '{key}'" in err and words in err, err


def test_a_point_the_curve_passes_twice_at_other_crank_angles_is_no_degenerate_input():
    from driver.synthesis._budget import degenerate_targets
    pts = np.array([[0.0, 0.0], [1.0, 2.0], [0.0, 0.0], [3.0, 1.0]])
    assert degenerate_targets(pts, [0.0, 90.0, 180.0, 270.0]) is None
    assert degenerate_targets(pts, [0.0, 90.0, 360.0, 270.0]) is not None
    assert degenerate_targets(pts, None) is not None
    assert degenerate_targets(np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0 + 1e-6]]), None) is None   # a curve, barely


def test_the_estimate_grows_with_what_drives_the_work():
    from driver._deck import read_deck, validate
    from driver.synthesis import SPEC
    from driver.synthesis._budget import estimate

    def seconds(text):
        return estimate(validate(read_deck("p.dat", text=text).groups["synthesis"], SPEC, "p.dat")).seconds
    base = seconds(PATH)
    assert 1.0 < base < 120.0           # the shipped deck runs in about 10 s
    assert seconds(PATH.replace("maxiter = 200", "maxiter = 2000")) > 3 * base
    assert seconds(PATH.replace("popsize = 10", "popsize = 10, samples = 3600")) > 2 * base


def test_an_optimisation_whose_own_design_is_over_the_budget_is_refused_before_it_starts(tmp_path, capsys):
    deck = tmp_path / "o.dat"
    deck.write_text(FOURBAR.replace("step_deg = 60", "step_deg = 1e-3") +
                    "&optimize\n  var1 = 'fourbar.crank', lower1 = 1, upper1 = 3\n  maximize = 'mu_min_deg'\n"
                    "  method = 'grid', grid_count = 3\n/\n")
    assert main([str(deck), "-o", str(tmp_path / "out"), "-q", "-j", "1", "--max-work", "10"]) == 2
    err = capsys.readouterr().err
    assert f"{deck}:3: key 'step_deg': each design of this optimisation (the deck's own design) is about" in err, err


def test_a_library_warning_reaches_the_terminal_in_words(tmp_path, capfd, monkeypatch):
    import warnings

    import driver._runner as runner
    real = runner.run_study

    def noisy(*a, **k):
        import numpy as np
        with np.errstate(over="warn"):
            np.exp(np.array([1000.0]))                 # numpy's own RuntimeWarning, from numpy
        warnings.warn_explicit("the step is poorly scaled", UserWarning, "/x/site-packages/scipy/optimize/_y.py", 7)
        return real(*a, **k)
    monkeypatch.setattr("driver._dispatch.run_study", noisy)
    deck = tmp_path / "d.dat"
    deck.write_text(FOURBAR)
    with warnings.catch_warnings():
        warnings.simplefilter("default")
        assert main([str(deck), "-o", str(tmp_path / "out"), "-q"]) == 0
    err = capfd.readouterr().err.strip().splitlines()
    assert any("warned while the deck ran (RuntimeWarning: overflow encountered in exp)" in e for e in err), err
    assert any("scipy warned while the deck ran (UserWarning: the step is poorly scaled)" in e for e in err), err
    assert all(e.startswith(f"warning: {deck}: ") for e in err), err


# ----------------------------------------------------------------------------- 6. the Python API

API_BASE = dict(fixed_link=12.0, crank=5.0, coupler=15.0, rocker=9.0, omega=5.0, step_deg=20)


def _self_holding() -> object:
    a = np.empty(1, dtype=object)
    a[0] = a
    return a


@pytest.mark.parametrize("key,value,expected", [
    ("crank", lambda: np.longdouble(5.5), 5.5),                                    # was RecursionError
    ("coupler_point", lambda: np.array([7.5, 3.0], dtype=np.longdouble), [7.5, 3.0]),
    ("crank", lambda: np.array(np.longdouble(5.5)), 5.5),
    ("coupler_point", lambda: np.array([np.longdouble(7.5), 3.0], dtype=object), [7.5, 3.0]),
    ("crank", lambda: np.float16(5.5), 5.5),
])
def test_numpy_floats_of_every_precision_are_numbers(key, value, expected):
    r = driver.run({"fourbar": dict(API_BASE, **{key: value()})})
    assert r.ok and r.params[key] == expected


@pytest.mark.parametrize("key,value,words", [
    ("crank", lambda: np.clongdouble(5.0), "is a complex number"),                 # was RecursionError
    ("coupler_point", lambda: np.array([1, 2], dtype=np.clongdouble), "is a complex number"),
    ("crank", lambda: np.longdouble('1e4000'), "not a finite number"),             # beyond a double
    ("coupler_point", lambda: _self_holding(), "a list inside a list"),            # an object array holding itself
    ("coupler_point", lambda: np.array([[1.0], 2.0], dtype=object), "a list inside a list"),
    ("title", lambda: np.bytes_(b'x'), "is bytes"),
    ("crank", lambda: np.datetime64('2020-01-01'), "is a date"),
])
def test_numpy_values_that_are_no_deck_values_are_refused_naming_the_key(key, value, words):
    with pytest.raises(DeckError, match=words) as info:
        driver.run({"fourbar": dict(API_BASE, **{key: value()})})
    assert info.value.key == key


@pytest.mark.parametrize("source", [
    {"fourbar": API_BASE},                                                    # was AttributeError: 'dict' ... 'stop_deg'
    API_BASE,
    "&fourbar fixed_link = 12, crank = 5, coupler = 15, rocker = 9, step_deg = 20 /",
])
def test_a_study_run_takes_a_deck_positionally_as_driver_run_does(source):
    r = driver.fourbar.run(source)
    want = driver.run({"fourbar": API_BASE})
    assert r.ok and r.study == "fourbar" and r.name == "fourbar"
    assert r.summary["mu_min_deg"] == want.summary["mu_min_deg"]


def test_a_study_run_given_something_else_says_what_to_pass():
    with pytest.raises(TypeError, match=r"fourbar.run\(\) takes the deck's keys as keyword arguments"):
        driver.fourbar.run(5)
    with pytest.raises(TypeError, match="mixes groups"):
        driver.fourbar.run({"fourbar": API_BASE, "crank": 5})
    with pytest.raises(DeckError, match=r"a &ujoint group in a deck given to fourbar.run\(\)"):
        driver.fourbar.run({"ujoint": {"beta": [15.0]}})


# ----------------------------------------------------------------------------- 5. names from anywhere

NAMES = ["a\x1b]0;pwned\x07b", "x\u202egnp.exe", "\x1b[2J\x1b[31mred", "zw\u200bsp", "c1\x9bx", "ls\u2028ps"]


@pytest.mark.parametrize("stem", NAMES)
def test_a_deck_name_with_control_or_bidi_characters_is_refused_and_shown_escaped(tmp_path, capfd, stem):
    """ESC/OSC sequences and right-to-left overrides in a deck's file name reached the terminal,
    the .out and the report page raw (a bidi override spoofed the page title)."""
    deck = tmp_path / f"{stem}.dat"
    deck.write_text(FOURBAR)
    out = tmp_path / "out"
    assert main([str(deck), "-o", str(out), "--report", "--plot"]) == 2
    cap = capfd.readouterr()
    err = cap.err.strip().splitlines()
    assert len(err) == 1 and "the deck's file name holds" in err[0] and "rename it" in err[0], err
    from driver._names import unsafe
    assert not unsafe((cap.out + cap.err).replace("\n", "")), "a raw control or bidi character reached the terminal"
    assert not out.exists() or not any(out.iterdir())


def test_an_output_folder_with_a_bidi_override_is_refused(tmp_path, capfd):
    deck = tmp_path / "d.dat"
    deck.write_text(FOURBAR)
    out = tmp_path / "o\u202ex"
    assert main([str(deck), "-o", str(out)]) == 2
    cap = capfd.readouterr()
    assert "\\u202e, RIGHT-TO-LEFT OVERRIDE" in cap.err and "\u202e" not in cap.err + cap.out
    assert not out.exists() or not any(out.iterdir())


def test_an_api_name_with_an_escape_writes_nothing(tmp_path):
    from driver._atomic import UnsafeName
    r = driver.run({"fourbar": API_BASE}, name="x\x1b[31m")
    with pytest.raises(UnsafeName, match="holds a control character"):
        driver.write(r, tmp_path / "o", formats=["csv"], json=True)
    assert not (tmp_path / "o").exists() or not any((tmp_path / "o").iterdir())


@pytest.mark.parametrize("char", ["\u202e", "\u2066", "\x1b", "\u200f"])
def test_the_same_characters_are_refused_in_a_deck_title_too(tmp_path, capsys, char):
    _refused(tmp_path, capsys, FOURBAR.replace("step_deg = 60", f"step_deg = 60, title = 'a{char}b'"), 3, "title",
             "printable characters only")


def test_shown_escapes_and_bounds_a_name():
    from driver._names import shown
    assert shown("a\x1b]0;x\x07b") == "a\\x1b]0;x\\x07b"
    assert shown("r\u202el") == "r\\u202el"
    assert shown("Ünïcødé ok") == "Ünïcødé ok"
    long = shown("n" * 75_000)
    assert len(long) <= 200 and "(74" in long and long.startswith("nnn") and long.endswith("nnn")


@pytest.mark.parametrize("where", ["key", "group", "swept key", "choice"])
def test_a_75_kB_name_in_a_deck_is_bounded_in_the_message(tmp_path, capsys, where):
    """A deck naming a 75 000-character key, group, swept key or choice value: the one error
    line shows the name cut in the middle to NAME_CHARS characters (it echoed all 75 kB)."""
    from driver._names import NAME_CHARS
    t = "t" * 75_000
    base = "fixed_link = 12, crank = 5, coupler = 15, rocker = 9, step_deg = 30"
    text = {"key": f"&fourbar {base}, {t} = 1 /\n", "group": f"&{t} a = 1 /\n",
            "swept key": f"&sweep key1 = 'fourbar.{t}', values1 = 1, 2 /\n&fourbar {base} /\n",
            "choice": f"&fourbar {base}, branch = '{t}' /\n"}[where]
    deck = tmp_path / "d.dat"
    deck.write_text(text)
    assert main([str(deck), "-o", str(tmp_path / "out"), "-q", "-j", "1"]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and len(err) < 1000, len(err)
    assert max(len(m) for m in re.findall("t+", err)) <= NAME_CHARS


# ----------------------------------------------------------------------------- 7. the sweep's part

def test_a_large_sweep_validates_every_case_before_any_runs(tmp_path, capsys):
    """6 161 cases: every value of each axis is valid alone and every corner is valid, but one
    inner case (start_deg 200, stop_deg 150) is not; it ran the others, wrote, and exited 2."""
    start = [str(i) for i in range(100)]
    start[50] = "200"
    stop = [str(300 + i) for i in range(60)]
    stop.insert(30, "150")
    deck = tmp_path / "big.dat"
    deck.write_text("&fourbar fixed_link = 12, crank = 5, coupler = 15, rocker = 9, omega = 5, step_deg = 90 /\n"
                    f"&sweep\n  key1 = 'fourbar.start_deg', values1 = {', '.join(start)}\n"
                    f"  key2 = 'fourbar.stop_deg', values2 = {', '.join(stop)}\n  case_outputs = 'none'\n/\n")
    out = tmp_path / "out"
    assert main([str(deck), "-o", str(out), "-q", "-j", "1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "start_deg = 200" in err[0] and "stop_deg = 150" in err[0], err
    assert not out.exists() or not any(out.iterdir())


def test_a_sweep_record_part_cut_in_half_is_redone_and_said(tmp_path, capsys):
    """The optimiser's resume says how many records it did not believe and why; the sweep's
    redid a part cut in half without a word ('resume: 3 of 4 cases complete, 1 to run')."""
    deck = tmp_path / "sw.dat"
    deck.write_text("&fourbar fixed_link = 12, crank = 5, coupler = 15, rocker = 9, omega = 5, step_deg = 90 /\n"
                    "&sweep\n  key1 = 'fourbar.crank', values1 = 2, 3, 4, 5\n  chunk = 1\n/\n")
    out = tmp_path / "out"
    assert main([str(deck), "-o", str(out), "-q", "-j", "1"]) == 0
    part = sorted((out / "sw.sweep").glob("part-*"))[0]
    part.write_bytes(part.read_bytes()[: part.stat().st_size // 2])
    capsys.readouterr()
    assert main([str(deck), "-o", str(out), "-j", "1", "--resume"]) == 0
    said = capsys.readouterr().err
    assert any("1 " in line and "redone" in line and "because" in line for line in said.splitlines()), said


# ----------------------------------------------------------------------------- 7. messages in words

def test_a_non_finite_table_value_is_said_in_words():
    """The message printed the format 'FNone.3' and the float 'nan'."""
    from driver._table import TableValueError, fortran_f
    for value, words in ((float("nan"), "a value that is not a number"), (float("-inf"), "-infinity")):
        with pytest.raises(TableValueError) as info:
            fortran_f(value, None, 3)
        assert str(info.value) == f"{words} cannot be written in a column of 3 decimals"
        assert "None" not in str(info.value) and "nan" not in str(info.value)
    with pytest.raises(TableValueError, match=r"cannot be written in an F10\.4 column"):
        fortran_f(float("inf"), 10, 4)


def test_a_nan_bound_for_a_table_is_said_in_words(monkeypatch):
    import dataclasses

    from driver import fourbar
    from driver._runner import CaseFailure, compute, study_of
    run = fourbar.STUDY.run

    def with_nan(params, progress=False):
        result = run(params, progress)
        return dataclasses.replace(result, text=result.text + "   nan\n")
    study = dataclasses.replace(fourbar.STUDY, run=with_nan)
    _, params = study_of(read_deck("d.dat", text=FOURBAR))
    with pytest.raises(CaseFailure) as info:
        compute(study, params)
    assert "a value that is not a number would be written on line" in info.value.message
    assert "'nan'" not in info.value.message


def test_a_numerical_failure_never_blames_a_key_the_deck_does_not_have(monkeypatch):
    import dataclasses

    from driver import _runner, fourbar
    _, params = _runner.study_of(read_deck("d.dat", text=FOURBAR))
    assert "method" not in params.given
    study = dataclasses.replace(fourbar.STUDY, blame=lambda p, exc: ("method", "the listing divides 0 by 0"))
    monkeypatch.setattr(_runner, "load_study", lambda group: study)
    e = _runner.numerical_error(params, ZeroDivisionError("x"))
    assert e.key is None and e.line == params.line
    assert "key 'method' is not in the deck: its default, 'exact', applies" in e.message
    given = dataclasses.replace(fourbar.STUDY, blame=lambda p, exc: ("crank", "too short"))
    monkeypatch.setattr(_runner, "load_study", lambda group: given)
    assert _runner.numerical_error(params, ZeroDivisionError("x")).key == "crank"


@pytest.mark.parametrize("key, line", [("com_distance", "com_distance = 0.05, 0.175, 0.125"),
                                       ("counterweight_radius", "balance = 'force', counterweight_radius = 0.05, 0.1")])
def test_a_unit_mismatch_ratio_is_said_in_a_few_digits(tmp_path, capsys, key, line):
    """A centre of mass 0.05 m from a 1e-140 m crank printed the ratio as a 138-digit number."""
    deck = tmp_path / "units.dat"
    deck.write_text("&fourbar fixed_link = 0.30, crank = 1e-140, coupler = 0.35, rocker = 0.25, omega = 20,\n"
                    "  method = 'exact', step_deg = 10, mass = 0.5, 1.2, 0.9,\n"
                    f"  {line} /\n")
    assert main([str(deck), "-o", str(tmp_path / "out"), "-q"]) == 2
    err = capsys.readouterr().err
    assert key in err and "times" in err, err
    assert not re.search(r"\d{12}", err), err      # no run of 138 digits
    assert re.search(r"\d(\.\d+)?e\+13\d times", err), err    # the ratio, to 3 significant digits


@pytest.mark.parametrize("deck_name, rel", [("optimize_crank_rocker", True), ("synthesis_function_log", False)])
def test_an_engine_and_its_json_record_are_put_in_place_together(tmp_path, capsys, monkeypatch, deck_name, rel):
    """An optimisation (or synthesis) whose --json record could not be written (a full disk) put
    its .out and .optimum files in place all the same; relative output folders did not join the
    engine's own set either.  Now the deck fails with none of its files in place."""
    import driver._record

    def full_disk(outcome, stem):
        raise OSError(28, "No space left on device", str(stem) + ".json")
    monkeypatch.setattr(driver._record, "write_record", full_disk)
    src = Path(__file__).resolve().parents[1] / "inputs" / f"{deck_name}.dat"
    deck = tmp_path / src.name
    deck.write_text(src.read_text())
    out = tmp_path / "out"
    monkeypatch.chdir(tmp_path)
    code = main([deck.name if rel else str(deck), "-o", "out" if rel else str(out), "-q", "--json", "-j", "1"])
    assert code != 0
    assert "no space left on the device" in capsys.readouterr().err
    assert not out.exists() or not [p.name for p in out.iterdir() if not p.name.endswith(".journal.jsonl")]


@pytest.mark.parametrize("jobs", ["1", "2"])
def test_a_library_warning_in_a_sweep_worker_reaches_the_terminal_in_words(tmp_path, capfd, monkeypatch, jobs):
    """A SciPy or NumPy warning raised inside a sweep's worker process went to the terminal raw
    (Python's 'file:line: RuntimeWarning: ...'); now each kind comes back with its chunk's result
    and is said once, in words, as a warning of the sweep."""
    import warnings

    from driver.sweep import _chunks

    original = _chunks.CHUNK_FUNCTIONS["cases"]

    def noisy(work, span):
        with np.errstate(over="warn"):
            np.exp(np.array([1000.0]))
        return original(work, span)
    monkeypatch.setitem(_chunks.CHUNK_FUNCTIONS, "cases", noisy)   # forked workers inherit it
    deck = tmp_path / "sw.dat"
    deck.write_text("&fourbar fixed_link = 12, crank = 5, coupler = 15, rocker = 9, omega = 5, step_deg = 90 /\n"
                    "&sweep\n  key1 = 'fourbar.crank', values1 = 2, 3, 4, 5\n  chunk = 1\n/\n")
    with warnings.catch_warnings():
        warnings.simplefilter("default")
        assert main([str(deck), "-o", str(tmp_path / "out"), "-q", "-j", jobs]) == 0
    err = capfd.readouterr().err
    assert "RuntimeWarning: overflow" not in err.replace("(RuntimeWarning: overflow", ""), err   # no raw line
    worded = [e for e in err.splitlines() if "warned while the deck ran (RuntimeWarning: overflow" in e]
    assert len(worded) == 1, err
