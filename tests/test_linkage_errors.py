"""Bad &linkage decks: exit status 2 with the deck's file, line and key, and nothing written;
Grübler refusals (a link placed twice, a group locked to one link, a link never placed), unknown
and not-yet-placed points, absurd position counts refused before anything is allocated; assembly
failures and dead centres named with the input and the group."""
from __future__ import annotations

import pytest

from driver._cli import main
from driver.linkage import run
from driver.linkage._analysis import events, solve
from linkage_oracle import params_of

FOURBAR = """&linkage
  pivots = 'O2', 'O4'
  pivot_xy = 0, 0, 12, 0
  driver_joints = 'O2', 'A', driver_length = 5
  step = 10
  dyads = 'RRR'
  dyad_joints = 'A', 'O4', 'B'
  dyad_links = 'coupler', 'rocker'
  dyad_dims = 15, 9
/
"""


@pytest.mark.parametrize("old,new,line,key,words", [
    ("'A', 'O4', 'B'", "'A', 'O5', 'B'", 7, "dyad_joints", "unknown point 'O5'"),
    ("dyad_links = 'coupler', 'rocker'", "dyad_links = 'crank', 'rocker'", 8, "dyad_links",
     "placed twice"),
    ("dyad_links = 'coupler', 'rocker'", "dyad_links = 'coupler', 'rocker'\n  points = 'P'\n  point_on = 'arm'\n"
     "  point_uv = 1, 1", 10, "point_on", "which no group places"),
    ("'A', 'O4', 'B'", "'O2', 'O4', 'B'", 7, "dyad_joints", "both ends to the 'ground'"),
    ("dyad_dims = 15, 9", "dyad_dims = 15, 9, 4", 9, "dyad_dims", "give pairs of numbers"),
    ("dyad_dims = 15, 9", "dyad_dims = 15, -9", 9, "dyad_dims", "must be positive"),
    ("step = 10", "step = 1e-6", 5, "step", "input positions"),
    ("step = 10", "step = 10, stop = -5", 5, "step", "steps away from stop"),
    ("dyads = 'RRR'", "dyads = 'RRX'", 6, "dyads", "is not one of"),
    ("pivot_xy = 0, 0, 12, 0", "pivot_xy = 0, 0, 12", 3, "pivot_xy", "pairs"),
    ("step = 10", "step = 10\n  mass = 1, 2", 6, "mass", "force analysis"),
    ("'A', 'O4', 'B'", "'A', 'O4', 'O2'", 7, "dyad_joints", "given twice"),
])
def test_bad_deck_exits_2_with_file_line_key(old, new, line, key, words, tmp_path, capsys):
    deck = tmp_path / "bad.dat"
    text = FOURBAR.replace(old, new)
    assert text != FOURBAR
    deck.write_text(text)
    out = tmp_path / "out"
    assert main([str(deck), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert f"bad.dat:{line}: key '{key}'" in err, err
    assert words in err, err
    assert not out.exists() or not any(out.iterdir())


def test_a_group_on_a_point_of_a_link_placed_later_is_refused_in_order():
    with pytest.raises(ValueError, match="not placed yet"):
        params_of("pivots='O2','O4','O6', pivot_xy=0,0, 3,0, 1,2\ndriver_joints='O2','A', driver_length=1, step=10\n"
                  "dyads='RRR','RRR', dyad_joints='C','O6','D', 'A','O4','B', "
                  "dyad_links='l5','l6','coupler','rocker', dyad_dims=2,2, 3.5,3\n"
                  "points='C', point_on='rocker', point_uv=-1,0")


def test_absurd_position_count_is_refused_before_allocating(tmp_path, capsys):
    """A range of 1e14 positions is refused by the deck check (nothing computed, nothing written)."""
    deck = tmp_path / "huge.dat"
    deck.write_text(FOURBAR.replace("step = 10", "step = 1e-9, stop = 1e5"))
    assert main([str(deck), "-o", str(tmp_path / "o")]) == 2
    assert "input positions" in capsys.readouterr().err


def test_budget_refuses_a_run_too_large_for_memory(tmp_path, capsys):
    deck = tmp_path / "big.dat"
    deck.write_text(FOURBAR.replace("step = 10", "step = 0.0001, stop = 360"))
    assert main([str(deck), "-o", str(tmp_path / "o"), "--max-memory", "64M"]) == 2
    err = capsys.readouterr().err
    assert "big.dat" in err and "key 'step'" in err and "refused before allocating" in err


def test_assembly_failures_toggles_and_dead_centres_are_named():
    """A Grashof double-rocker driven by its crank: the group cannot be assembled over part of the
    turn; the toggle limits and the rocker's dead centres are named with the input and the group."""
    p = params_of("pivots='O2','O4', pivot_xy=0,0, 8,0\ndriver_joints='O2','A', driver_length=6, step=1\n"
                  "dyads='RRR', dyad_joints='A','O4','B', dyad_links='coupler','rocker', dyad_dims=2,7")
    m = solve(p)
    evs = events(m)
    fails = [e for e in evs if e.what == "no_assembly"]
    assert fails and all(e.name == "RRR B" and e.group == 1 for e in fails)
    # the limit angles: |A O4| = l1 + l2 = 9 and = l2 - l1 = 5 (cosine rule), the crank beyond them fails
    import math
    lim = [math.degrees(math.acos((36 + 64 - d * d) / 96)) for d in (9.0, 5.0)]
    lo, hi = sorted(lim)                      # 38.62 and 78.58 deg: assembled in between
    assert (fails[0].first, fails[0].last) == (0.0, math.floor(lo))
    assert fails[1].first == math.ceil(hi)
    r = run(p)
    assert "cannot be assembled" in r.text and "group 1 (RRR B)" in r.text
    assert r.warnings and "group 1, RRR B" in r.warnings[0]


def test_slider_crank_dead_centres_are_the_closed_form():
    p = params_of("pivots='O2', pivot_xy=0,0, guides='bore', guide_xy=0,0, guide_deg=0\n"
                  "driver_joints='O2','A', driver_length=1, step=0.5\n"
                  "dyads='RRP', dyad_joints='A','bore','B', dyad_links='rod','piston', dyad_dims=4,0")
    dc = [e for e in events(solve(p)) if e.what == "dead_centre"]
    assert [round(e.first, 6) for e in dc][:2] == [0.0, 180.0]
