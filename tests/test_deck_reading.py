"""The deck reader never silently misreads: each case f90nml alone would read wrongly is either
the right value or a deck error naming file, line, key (and column where it helps); exit 2."""
from __future__ import annotations

import os
import warnings

import pytest

from conftest import GOOD_DECK as GOOD
from driver._cli import main
from driver._deck import MAX_DECK_BYTES, MAX_VALUES, DeckError, read_deck


def _raw(text, tmp_path, name="d.dat", mode="w"):
    p = tmp_path / name
    if mode == "wb":
        p.write_bytes(text)
    else:
        p.write_text(text)
    return p


@pytest.mark.parametrize("change,line,key,words", [
    # a Unicode minus pasted from a PDF was dropped (omega ran as +5)
    (("omega = 5.0", "omega = \u22125.0"), 6, None, ["column 11", "U+2212", "MINUS SIGN", "ASCII '-'"]),
    (("crank = 5.0", "crank = 5.0\u00a0"), 3, None, ["U+00A0"]),
    (("rocker = 9.0", "rocker = 9.0\x01"), 5, None, ["U+0001", "control"]),
    # '/' inside a value ended the group: step 360 and omega silently defaulted
    (("step_deg = 20", "step_deg = 360/7, omega = 3.0"), 7, None, ["text after the closing '/'", "360/7"]),
    (("/\n", "/ extra\n"), 8, None, ["text after the closing '/'", "extra"]),
    (("/\n", "/\n/\n"), 9, None, ["closes no group"]),
    (("! a good deck", "junk line"), 1, None, ["text outside a namelist group"]),
    # array subscripts were ignored: element_counts(2) = 1, 2, 4 ran [1]
    (("crank = 5.0", "crank(2) = 5.0"), 3, "crank", ["array subscripts are not supported"]),
    (("crank = 5.0", "crank%a = 5.0"), 3, "crank", ["derived-type components"]),
    # a key given twice silently kept the last value
    (("omega = 5.0", "omega = 5.0, omega = 6.0"), 6, "omega", ["given twice", "line 6 and on line 6"]),
    (("step_deg = 20", "step_deg = 20\n  crank = 4"), 8, "crank", ["given twice", "on line 3 and on line 8"]),
    # repeat counts are refused before anything is expanded
    (("omega = 5.0", "omega = 99999999999*1"), 6, "omega", ["repeat count", "before anything is expanded"]),
    (("omega = 5.0", "omega = 10001*1.0"), 6, "omega", ["repeat count 10001*"]),
    (("omega = 5.0", "omega = " + "1, " * 10001), 6, "omega", ["10001 values"]),
    # f90nml's own failures: the line and key, never an exception name
    (("omega = 5.0", "omega = 5.0 (1"), 6, None, []),
    (("omega = 5.0", "omega = 'open"), 6, None, ["string not closed"]),
    (("/\n", ""), 2, None, ["not closed"]),
    (("step_deg = 20", "step_deg = 20\n&sweep"), 8, None, ["not closed", "before '&sweep'"]),
    (("&fourbar", "&fourbar\n 5.0, "), 3, None, ["value without a key"]),
])
def test_misread_is_a_deck_error(change, line, key, words, tmp_path, capsys):
    deck = _raw(GOOD.replace(*change, 1), tmp_path, "bad.dat")
    out = tmp_path / "out"
    assert main([str(deck), "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert err[0].startswith(f"error: {deck}:{line}: "), err[0]
    if key:
        assert f"key '{key}'" in err[0]
    for w in words:
        assert w in err[0], err[0]
    for bad in ("Error:", "AssertionError", "IndexError", "StopIteration", "Traceback", "Warning"):
        assert bad not in err[0]
    assert not out.exists()


def test_bom_crlf_and_cr_are_read(tmp_path):
    ref = read_deck(_raw(GOOD, tmp_path, "ref.dat")).groups["fourbar"]
    for name, data in [("bom.dat", b"\xef\xbb\xbf" + GOOD.encode()),
                       ("crlf.dat", GOOD.replace("\n", "\r\n").encode()),
                       ("bomcrlf.dat", b"\xef\xbb\xbf" + GOOD.replace("\n", "\r\n").encode()),
                       ("cr.dat", GOOD.replace("\n", "\r").encode())]:
        got = read_deck(_raw(data, tmp_path, name, "wb")).groups["fourbar"]
        assert got.values == ref.values and got.lines == ref.lines, name


def test_unicode_in_comments_and_strings_is_fine(tmp_path):
    deck = GOOD.replace("! a good deck", "! Kurbel \u2212 Schwinge \u00b0").replace(
        "step_deg = 20", "step_deg = 20   ! \u00b5m \u2212")
    g = read_deck(_raw(deck, tmp_path)).groups["fourbar"]
    assert g.values["omega"] == 5.0 and g.values["step_deg"] == 20


def test_values_read_exactly(tmp_path):
    g = read_deck(_raw(GOOD.replace("omega = 5.0", "omega = -5.0, step_deg = 360").replace(
        "  step_deg = 20\n", ""), tmp_path)).groups["fourbar"]
    assert g.values["omega"] == -5.0 and g.values["step_deg"] == 360
    g = read_deck(_raw(GOOD.replace("omega = 5.0", "omega = 3*2.5"), tmp_path)).groups["fourbar"]
    assert g.values["omega"] == [2.5, 2.5, 2.5]
    # a list continued on the next line, '/' inside a string, and '&end' as the terminator
    text = "&fourbar\n crank = 1,\n   2, 3\n method = 'a/b'\n&end\n"
    g = read_deck(_raw(text, tmp_path)).groups["fourbar"]
    assert g.values["crank"] == [1, 2, 3] and g.values["method"] == "a/b"
    assert g.lines == {"crank": 2, "method": 4}


def test_no_warning_reaches_the_terminal(tmp_path, capfd):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(DeckError):
            read_deck(_raw("&fourbar\n crank = 1 2 = 3\n/\n", tmp_path))
    assert capfd.readouterr().err == ""


def test_not_a_regular_file_or_too_large(tmp_path, capsys):
    fifo = tmp_path / "fifo.dat"
    os.mkfifo(fifo)
    with pytest.raises(DeckError, match="not a regular file"):
        read_deck(fifo)   # would block for ever if it were opened
    with pytest.raises(DeckError, match="is a folder"):
        read_deck(tmp_path)
    big = _raw(GOOD + "!" * MAX_DECK_BYTES, tmp_path, "big.dat")
    with pytest.raises(DeckError, match=f"larger than {MAX_DECK_BYTES}"):
        read_deck(big)
    binary = _raw(b"&fourbar\n crank = \xff\xfe\n/\n", tmp_path, "bin.dat", "wb")
    with pytest.raises(DeckError, match="bin.dat:2: column 10: byte 0xff is not UTF-8"):
        read_deck(binary)
    assert MAX_VALUES == 10_000
