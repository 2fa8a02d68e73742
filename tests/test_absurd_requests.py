"""Absurd requests are refused promptly (exit 2, the key named, nothing written), before any
allocation: the budget of driver._limits, repeat counts and list lengths before expansion, sweep
case counts; numerical failures reached from bad input are deck errors in words."""
from __future__ import annotations

import re
import tracemalloc

import pytest

from conftest import INPUTS
from driver import _limits as limits
from driver._cli import main


def _deck(tmp_path, base: str, edits: list[tuple[str, str]], add: str = "") -> str:
    text = (INPUTS / base).read_text()
    for pattern, repl in edits:
        text, n = re.subn(pattern, repl, text, count=1, flags=re.M)
        assert n == 1, pattern
    if add:
        text = re.sub(r"^(&\w+.*)$", lambda m: m.group(1) + "\n  " + add, text, count=1, flags=re.M)
    path = tmp_path / base
    path.write_text(text)
    return str(path)


def _drop(key: str) -> tuple[str, str]:
    """Remove ``key = value`` (up to the next comma-separated key or the end of the line)."""
    return (rf"\b{key}\s*=\s*[^=!\n]*?(?=,\s*\w+\s*=|\s*!|$)", "")


ABSURD = [
    # (deck, edits, added line, key named)
    ("crank5_exact.dat", [(r"step_deg\s*=\s*[\d.]+", "step_deg = 1e-4")], "", "step_deg"),
    ("crank5_exact.dat", [(r"step_deg\s*=\s*[\d.]+", "step_deg = 1e15, start_deg = -1e15")], "", "start_deg"),
    ("crank5_exact.dat", [], "coupler_point = 99999999999*1", "coupler_point"),
    ("ujoint_option1.dat", [_drop("n_starts")], "n_starts = 1e5", "n_starts"),
    ("ujoint_analyse.dat", [], "table_step = 1e-6", "table_step"),
    ("ujoint_analyse.dat", [], "table_step = 4.9e-324", "table_step"),
    # a denormal crank speed overflowed the time-step check (found by the fuzz campaign)
    ("slidercrank_aluminium.dat", [(r"speeds\s*=\s*11\.52", "speeds = 4.9e-324")], "", "speeds"),
    ("ujoint_option1.dat", [], "n_grid = 1e9", "n_grid"),
    ("slidercrank_aluminium.dat", [(r"steps_per_rev\s*=\s*\d+", "steps_per_rev = 1e9")], "", "steps_per_rev"),
    ("slidercrank_aluminium.dat", [(r"speeds\s*=\s*[\d., ]+", "speeds = 100000*11.52")], "", "speeds"),
    ("manipulator_case1_report.dat", [(r"mc_samples\s*=\s*\d+", "mc_samples = 1e8")], "", "mc_samples"),
    ("manipulator_case1_report.dat", [], "sweep_count = 1e9", "sweep_count"),
    ("manipulator_case1_report.dat", [], "sweep_l1_step = 4.9e-324", "sweep_l1_step"),
    ("manipulator_case1_report.dat", [(r"points_x\s*=\s*[\d, ]+", "points_x = 1000000*1.5")], "", "points_x"),
    # one axis of 10^8 values on a batch sweep (10^10 cases are allowed there) ran out of memory
    # building the axis (found by the fuzz campaign)
    ("manipulator_design_search.dat", [(r"count2\s*=\s*141", "count2 = 1e8")], "", "count2"),
]


#: what a refusal may allocate in Python/numpy (the absurd requests would need GBs)
MAX_PEAK = 200 * 2**20


def _run_traced(argv: list[str]) -> tuple[int, int]:
    """The command line's exit status and the peak of memory traced while it ran [bytes]."""
    tracemalloc.start()
    try:
        rc = main(argv)
        return rc, tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


@pytest.mark.parametrize("base,edits,add,key", ABSURD)
def test_absurd_request_is_refused_promptly(base, edits, add, key, tmp_path, capsys):
    deck = _deck(tmp_path, base, edits, add)
    out = tmp_path / "out"
    rc, peak = _run_traced([deck, "-o", str(out), "-q"])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2, err
    assert len(err) == 1 and err[0].startswith(f"error: {deck}:"), err
    assert f"key '{key}'" in err[0], err[0]
    assert peak < MAX_PEAK, f"{peak / 2**20:.0f} MiB allocated before refusing"   # refused before the work
    assert not out.exists()


def test_budget_message_names_estimate_and_how_to_raise_it(tmp_path, capsys):
    deck = _deck(tmp_path, "ujoint_option1.dat", [], "n_grid = 1e9")
    assert main([deck, "-o", str(tmp_path / "o"), "-q"]) == 2
    err = capsys.readouterr().err
    assert "GiB of memory" in err and "--max-memory" in err and "1e+09 grid angles" in err


def test_limits_can_be_raised_and_lowered(tmp_path, capsys):
    deck = str(INPUTS / "crank5_exact.dat")
    assert main([deck, "-o", str(tmp_path / "a"), "-q", "--max-work", "1e-6"]) == 2
    assert "--max-work" in capsys.readouterr().err
    assert main([deck, "-o", str(tmp_path / "b"), "-q", "--max-memory", "1K"]) == 2
    assert "--max-memory" in capsys.readouterr().err
    assert main([deck, "-o", str(tmp_path / "c"), "-q", "--max-memory", "64G", "--max-work", "1h"]) == 0
    assert limits.ENV_MEMORY not in __import__("os").environ   # the process's setting is restored
    with pytest.raises(SystemExit) as exc:
        main([deck, "--max-memory", "lots"])
    assert exc.value.code == 2


def test_sizes_and_durations_parse():
    assert limits.parse_size("4G") == 4 * 2**30 and limits.parse_size("512MB") == 512e6
    assert limits.parse_size("1.5e9") == 1.5e9
    assert limits.parse_seconds("10min") == 600 and limits.parse_seconds("2h") == 7200
    for bad in ("", "-1G", "4Q", "nan"):
        with pytest.raises(ValueError):
            limits.parse_size(bad)


@pytest.mark.parametrize("deck", sorted(p.name for p in INPUTS.glob("*.dat")))
def test_every_shipped_deck_is_within_the_default_budget(deck):
    """The estimates refuse nothing the tool ships (a sweep: its base deck)."""
    from driver._deck import read_deck
    from driver._runner import study_of
    d = read_deck(INPUTS / deck)
    groups = {n: g for n, g in d.groups.items() if n not in ("sweep", "optimize", "synthesis")}
    if not groups:
        pytest.skip("no study group")
    module, params = study_of(type(d)(d.path, groups))
    est = limits.check(module, params)
    assert est is not None and est.bytes < 2**30 and est.seconds < 120, est


def test_sweep_too_many_cases_is_refused_before_building_them(tmp_path, capsys):
    deck = tmp_path / "grid.dat"
    deck.write_text((INPUTS / "crank5_exact.dat").read_text() + (
        "&sweep key1 = 'fourbar.crank', start1 = 1, stop1 = 5, count1 = 1000\n"
        "       key2 = 'fourbar.coupler', start2 = 10, stop2 = 20, count2 = 1000\n"
        "       key3 = 'fourbar.rocker', start3 = 5, stop3 = 15, count3 = 1000 /\n"))
    rc, peak = _run_traced([str(deck), "-o", str(tmp_path / "o"), "-q"])
    assert rc == 2
    assert peak < MAX_PEAK, f"{peak / 2**20:.0f} MiB allocated before refusing"
    err = capsys.readouterr().err
    assert "1000000000 cases" in err and "key 'key1'" in err


def test_sweep_axis_of_too_many_values_is_refused_before_allocating(tmp_path, capsys):
    """count1 = 1e8 would build 10^8 Python floats (about 3 GB) before the grid's size is checked."""
    deck = tmp_path / "axis.dat"
    deck.write_text((INPUTS / "crank5_exact.dat").read_text() +
                    "&sweep key1 = 'fourbar.crank', start1 = 1, stop1 = 5, count1 = 1e8, case_outputs = 'none' /\n")
    rc, peak = _run_traced([str(deck), "-o", str(tmp_path / "o"), "-q"])
    assert rc == 2
    assert peak < MAX_PEAK, f"{peak / 2**20:.0f} MiB allocated before refusing"
    err = capsys.readouterr().err
    assert "key 'count1'" in err and "100000000 values on one axis" in err
    assert not (tmp_path / "o").exists()


def test_sweep_case_beyond_budget_refuses_the_sweep(tmp_path, capsys):
    deck = tmp_path / "sw.dat"
    deck.write_text((INPUTS / "crank5_exact.dat").read_text()
                    + "&sweep key1 = 'fourbar.step_deg', values1 = 10, 1e-4 /\n")
    assert main([str(deck), "-o", str(tmp_path / "o"), "-q", "-j", "1"]) == 2
    err = capsys.readouterr().err
    assert "key 'values1'" in err and "case 2" in err and "--max-" in err
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("base,edits,add,words", [
    ("crank5.dat", [(r"fixed_link\s*=\s*[\d.]+", "fixed_link = 1"), (r"crank\s*=\s*[\d.]+", "crank = 1"),
                    (r"coupler\s*=\s*[\d.]+", "coupler = 1"), (r"rocker\s*=\s*[\d.]+", "rocker = 1")], "",
     "key 'method': the listing's formulas divide 0 by 0"),
    ("crank5_exact.dat", [(r"fixed_link\s*=\s*[\d.]+", "fixed_link = 1e400")], "", "not a finite number"),
    ("slidercrank_aluminium.dat", [], "youngs_modulus = 4.9e-324", ""),
    ("robust_example.dat", [(r"taguchi_targets\s*=\s*[\d, ]+", "taguchi_targets = 10, 10, 10")], "", ""),
    ("robust_example.dat", [(r"dual_targets\s*=\s*[\d, ]+", "dual_targets = 15, 15, 15")], "", ""),
])
def test_numerical_failure_is_a_deck_error_in_words(base, edits, add, words, tmp_path, capsys):
    deck = _deck(tmp_path, base, edits, add)
    out = tmp_path / "out"
    rc = main([deck, "-o", str(out), "-q"])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2, err
    assert len(err) == 1 and err[0].startswith(f"error: {deck}:"), err
    assert words in err[0]
    for bad in ("Traceback", "run failed", "nan", "LinAlgError", "ZeroDivisionError"):
        assert bad not in err[0].replace("finite number", ""), err[0]
    assert not out.exists()
