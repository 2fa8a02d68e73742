"""Bad input: one message naming the deck, the line and the key; exit status 2; nothing written."""
from __future__ import annotations

import pytest

from conftest import GOOD_DECK as GOOD
from driver._cli import main


@pytest.mark.parametrize("change,line,key,words", [
    (("&fourbar", "&fourbarr"), 2, None, "unknown group &fourbarr"),
    (("  omega = 5.0", "  omegaa = 5.0"), 6, "omegaa", "unknown key"),
    (("  rocker = 9.0\n", ""), 2, "rocker", "missing"),
    (("crank = 5.0", "crank = -5.0"), 3, "crank", "must be positive"),
    (("crank = 5.0", "crank = 0"), 3, "crank", "must be positive"),
    (("coupler = 15.0", "coupler = 'long'"), 4, "coupler", "not a number"),
    (("coupler = 15.0", "coupler = abc"), 4, "coupler", "not a number"),
    (("step_deg = 20", "step_deg = 0"), 7, "step_deg", "must not be 0"),
    (("step_deg = 20", "step_deg = 20\n  method = 'magic'"), 8, "method", "not one of"),
    (("step_deg = 20", "step_deg = 2.5\n  method = 'listing'"), 7, "step_deg", "whole degrees"),
    (("step_deg = 20", "step_deg = 20\n  coupler_point = 1, 2, 3"), 8, "coupler_point", "two numbers"),
])
def test_bad_deck(change, line, key, words, tmp_path, capsys):
    deck = tmp_path / "bad.dat"
    deck.write_text(GOOD.replace(*change, 1))
    out = tmp_path / "out"
    assert main([str(deck), "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1
    assert err[0].startswith(f"error: {deck}:{line}: ")
    if key:
        assert f"key '{key}'" in err[0]
    assert words in err[0]
    assert not out.exists() or not any(out.iterdir())


def test_legacy_deck_errors_name_line_and_key(tmp_path, capsys):
    deck = tmp_path / "old.dat"
    deck.write_text("12 5 15 9\nfive\n20\n")
    assert main([str(deck), "-o", str(tmp_path / "o")]) == 2
    # 'five' makes it not a legacy deck of numbers; with a number missing it is:
    deck.write_text("12 5 15\n5\n20\n")
    capsys.readouterr()
    assert main([str(deck), "-o", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert f"{deck}:1: key 'rocker'" in err


def test_several_decks_each_on_their_own(tmp_path, capsys):
    good = tmp_path / "good.dat"
    good.write_text(GOOD)
    bad = tmp_path / "bad.dat"
    bad.write_text(GOOD.replace("crank = 5.0", "crank = -1"))
    out = tmp_path / "out"
    assert main([str(bad), str(good), "-o", str(out), "-q"]) == 2
    assert (out / "good.out").exists()
    assert not (out / "bad.out").exists()
    assert main([str(good), "-o", str(out), "-q"]) == 0


def test_two_study_groups_in_one_deck_is_an_error(tmp_path, capsys):
    deck = tmp_path / "two.dat"
    deck.write_text(GOOD + GOOD.replace("! a good deck\n", ""))
    assert main([str(deck), "-o", str(tmp_path)]) == 2
    assert "given twice" in capsys.readouterr().err


def test_missing_file(tmp_path, capsys):
    assert main([str(tmp_path / "nope.dat"), "-o", str(tmp_path)]) == 2
    assert "cannot read deck" in capsys.readouterr().err
