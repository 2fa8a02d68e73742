"""The input boundary, round three (issue 36): every reproducer of the campaign is a test.

Each refusal is exit 2 (or a DeckError) naming the deck, the line and the key, with nothing
written; each fix was checked to fail on the code before it.  The comparison with gfortran's own
namelist reader is tests/test_fortran_reader.py; links are tests/test_output_links.py; resume
records tests/test_optimize_resume_verified.py.
"""
from __future__ import annotations

import pytest

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
