"""Issue 35, item 5: every Python entry point takes the same inputs and raises the same errors.

``driver.run``, ``driver.run_sweep``, ``driver.compare``, ``driver.optimize.optimize`` and
``driver.synthesis.synthesise`` each take a deck file, a deck's text or a dict of groups (a
DeckSource).  The truth is the deck file itself: its text and its dict give the same answer as
the file, cell for cell.  Bad input is a DeckError (a ValueError and a driver.DriverError) naming
the key; a missing file is a DeckError naming the file; a source of another type a TypeError.
"""
from __future__ import annotations

import f90nml
import pytest

import driver
from conftest import INPUTS
from driver.optimize import optimize
from driver.synthesis import synthesise


def as_dict(path) -> dict:
    """The deck file's groups as a dict, read by f90nml (not the driver's reader)."""
    nml = f90nml.read(str(path))
    return {g: {k: (list(v) if isinstance(v, list) else v) for k, v in vals.items()} for g, vals in nml.items()}


OPT = INPUTS / "optimize_fourbar_design.dat"
SYN = INPUTS / "synthesis_crank_rocker.dat"


@pytest.fixture(scope="module")
def by_file():
    return optimize(OPT, jobs=1)


@pytest.mark.parametrize("form", ["text", "dict"])
def test_optimize_takes_text_and_dicts_and_finds_the_files_optimum(by_file, form):
    source = OPT.read_text() if form == "text" else as_dict(OPT)
    oc = optimize(source, jobs=1)
    assert dict(oc.x) == dict(by_file.x) and oc.fun == by_file.fun and oc.nfev == by_file.nfev


def test_optimize_names_text_outputs_after_the_study(tmp_path):
    oc = optimize(OPT.read_text(), tmp_path, jobs=1)
    assert (tmp_path / "fourbar.out").exists() and oc.name == "fourbar"
    oc = optimize(OPT.read_text(), tmp_path, jobs=1, name="mine")
    assert (tmp_path / "mine.out").exists()


@pytest.mark.parametrize("form", ["text", "dict"])
def test_synthesise_takes_text_and_dicts(form):
    want = synthesise(SYN)
    got = synthesise(SYN.read_text() if form == "text" else as_dict(SYN))
    drop = lambda d: {k: v for k, v in d.items() if k != "title"}   # the title names the deck
    assert drop(got.linkage) == drop(want.linkage) and got.failure == want.failure
    assert got.study_result.summary == want.study_result.summary


@pytest.mark.parametrize("form", ["text", "dict"])
def test_compare_takes_text_and_dicts(form):
    deck = INPUTS / "crank5.dat"
    want = driver.compare(deck)
    got = driver.compare(deck.read_text() if form == "text" else as_dict(deck))
    cols = ["table", "row", "column", "printed", "computed", "status"]
    assert got[cols].equals(want[cols]) and len(got) == 190


def test_run_and_run_sweep_take_the_same_three_forms():
    deck = INPUTS / "crank5_exact.dat"
    outs = [driver.run(s).summary for s in (deck, deck.read_text(), as_dict(deck))]
    assert outs[0] == outs[1] == outs[2]
    sweep = INPUTS / "fourbar_paper_sweep.dat"
    sums = [driver.run_sweep(s, jobs=1).summary.drop(columns=["seconds"], errors="ignore")
            for s in (sweep, sweep.read_text(), as_dict(sweep))]
    assert sums[0].equals(sums[1]) and sums[0].equals(sums[2])


ENTRY_POINTS = [driver.run, driver.run_sweep, driver.compare, optimize, synthesise]


@pytest.mark.parametrize("entry", ENTRY_POINTS, ids=lambda f: f.__name__)
@pytest.mark.parametrize("source", [42, b"&fourbar /", 3.5, None])
def test_a_source_of_another_type_is_a_type_error(entry, source):
    with pytest.raises(TypeError, match="a deck is a path, a deck's text or a dict"):
        entry(source)


@pytest.mark.parametrize("entry", ENTRY_POINTS, ids=lambda f: f.__name__)
def test_a_missing_file_is_a_deck_error_naming_it(entry, tmp_path):
    missing = tmp_path / "no_such_deck.dat"
    with pytest.raises(driver.DeckError, match="no_such_deck.dat: cannot read deck") as e:
        entry(missing)
    assert isinstance(e.value, driver.DriverError) and isinstance(e.value, ValueError)


@pytest.mark.parametrize("entry, groups", [
    (optimize, {"fourbar": {"fixed_link": 12, "crank": -5, "coupler": 15, "rocker": 9, "step_deg": 20},
                "optimize": {"var1": "fourbar.coupler", "lower1": 10, "upper1": 20, "maximize": "mu_min_deg"}}),
    (synthesise, {"synthesis": {"task": "crank_rocker", "swing_deg": -40, "time_ratio": 1.2, "fixed_link": 1}}),
    (driver.run, {"fourbar": {"fixed_link": 12, "crank": -5, "coupler": 15, "rocker": 9, "step_deg": 20}}),
    (driver.compare, {"fourbar": {"fixed_link": 12, "crank": -5, "coupler": 15, "rocker": 9, "step_deg": 20}}),
])
def test_a_bad_value_in_a_dict_is_a_deck_error_naming_the_key(entry, groups):
    with pytest.raises(driver.DeckError) as e:
        entry(groups)
    assert e.value.key in ("crank", "swing_deg")


def test_each_engine_refuses_a_deck_of_another_engine_as_bad_input():
    fb = {"fourbar": {"fixed_link": 12, "crank": 5, "coupler": 15, "rocker": 9, "step_deg": 20}}
    with pytest.raises(driver.DeckError, match="&optimize group"):
        optimize(fb)
    with pytest.raises(driver.DeckError, match="no other group"):
        synthesise(fb)
    with pytest.raises(driver.DeckError, match="optimize"):
        driver.run(OPT.read_text())
