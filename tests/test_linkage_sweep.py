"""&sweep over single elements of list keys (``'linkage.dyad_dims(3)'``): the linkage's batch path
against the same sweep run case by case, and both against each case's own deck (the element put
in its list by hand, summarised as a single run); an element the base deck does not give, and an
element of a key that is no list, refused before anything runs (exit 2, nothing written).

Truth: each case's deck written out with the swept element in place (``dyad_dims`` with its third
number replaced), summarised by the study's own one-deck path, compiled apart from the batch's
affine map of the swept numbers into the kernel's."""
from __future__ import annotations

import numpy as np
import pytest

import driver
from driver._cli import main
from driver.linkage import summarise
from linkage_oracle import params_of

pytest.importorskip("pyarrow")

WATT = """pivots = 'O2', 'O4', 'O6', pivot_xy = 0, 0,   0.30, 0,   0.256, 0.126
  driver_joints = 'O2', 'A', driver_length = 0.10, omega = 10.0, step = 10
  dyads = 'RRR', 'RRR', dyad_joints = 'A', 'O4', 'B',   'C', 'O6', 'D'
  dyad_links = 'coupler', 'rocker', 'link5', 'link6'
  dyad_dims = {dims}, dyad_modes = 1, -1
  points = 'C', point_on = 'rocker', point_uv = -0.15, 0
  scan_points = 90"""
DIMS = (0.35, 0.30, 0.214, 0.189)
LENGTHS = (0.08, 0.10, 0.12)
LINK5 = (0.19, 0.214, 0.24)
COLUMNS = ("stroke", "time_ratio", "mu_min_deg", "mu_max_deg", "omega_peak_link6_rad_s")


def _base(dims=DIMS) -> str:
    """The base deck's text (the Watt II six-bar of inputs/linkage_watt2.dat, kinematics only)."""
    return f"&linkage\n  {WATT.format(dims=', '.join(map(str, dims)))}\n/\n"


@pytest.mark.parametrize("case_outputs", ["none", "all"])
def test_element_sweep_gives_each_case_deck_summary(case_outputs, tmp_path):
    """The batch path (case_outputs 'none') and case by case ('all') sweep driver_length x
    dyad_dims(3); every case's summary equals its own deck's (the element replaced by hand)."""
    s = driver.run_sweep(_base(), grid={"driver_length": list(LENGTHS), "dyad_dims(3)": list(LINK5)},
                         keep="time_ratio > 0", case_outputs=case_outputs, jobs=1)
    assert s.status == 0 and s.n_cases == 9 and s.n_ok == 9
    table = s.summary
    assert list(table["linkage.dyad_dims(3)"]) == [v for _ in LENGTHS for v in LINK5]
    for row in table.itertuples(index=False):
        values = dict(zip(table.columns, row))
        length, link5 = values["linkage.driver_length"], values["linkage.dyad_dims(3)"]
        dims = list(DIMS)
        dims[2] = link5
        text = WATT.format(dims=", ".join(map(repr, dims))).replace("driver_length = 0.10", f"driver_length = {length!r}")
        own = summarise(params_of(text))
        for c in COLUMNS:
            assert values[c] == pytest.approx(own[c], rel=1e-12, abs=1e-12), (values["case"], c)
    # the swept element changes the output's motion (the test can see a wrong element)
    assert len({round(v, 9) for v in table["stroke"]}) == 9


def test_element_sweep_batch_and_case_paths_agree():
    grid = {"driver_length": list(LENGTHS), "dyad_dims(3)": list(LINK5)}
    batch = driver.run_sweep(_base(), grid=grid, keep="time_ratio > 0", case_outputs="none", jobs=1).summary
    cases = driver.run_sweep(_base(), grid=grid, keep="time_ratio > 0", case_outputs="all", jobs=1).summary
    for c in COLUMNS:
        np.testing.assert_array_equal(batch[c].to_numpy(float), cases[c].to_numpy(float))


@pytest.mark.parametrize("key, words", [("linkage.dyad_dims(5)", "element 5 does not exist"),
                                        ("linkage.driver_length(1)", "is not a list key"),
                                        ("linkage.dyad_dims(0)", "from 1"),
                                        ("linkage.no_such_key(2)", "has no key 'no_such_key'")])
def test_bad_element_refused_before_anything_runs(key, words, tmp_path, capsys):
    deck = tmp_path / "bad.dat"
    deck.write_text(_base() + f"&sweep\n  key1 = '{key}', values1 = 0.2, 0.22\n  case_outputs = 'none', "
                              "keep = 'time_ratio > 0'\n/\n")
    out = tmp_path / "out"
    assert main([str(deck), "-q", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert words in err and "bad.dat:" in err, err
    assert not out.exists() or not any(out.iterdir())


def test_shipped_sweep_rows_are_their_own_decks():
    """The committed summary of inputs/linkage_watt2_sweep.dat (outputs/, equal to a fresh run by
    test_outputs_fresh): a corner, an inner and a refused design each equal the base deck with
    driver_length and link5 replaced by hand, summarised as a single run (masses, gravity and the
    output torque included, so the force columns are checked too); the keep rule holds row by row."""
    import pandas as pd

    from conftest import INPUTS, ROOT
    text = (INPUTS / "linkage_watt2_sweep.dat").read_text()
    body = text.split("&linkage", 1)[1].split("\n/", 1)[0]
    table = pd.read_csv(ROOT / "outputs" / "linkage_watt2_sweep_summary.csv")
    assert len(table) == 121 and (table["status"] == "ok").all()
    assert list(table["kept"]) == [bool(f == 1.0 and m >= 35) for f, m in
                                   zip(table["assembled_fraction"], table["mu_min_deg"])]
    assert table["kept"].any() and not table["kept"].all()
    refused = int(np.argmax(~table["kept"].to_numpy(bool)))
    for i in (0, 60, refused, 120):
        row = table.iloc[i]
        length, link5 = float(row["linkage.driver_length"]), float(row["linkage.dyad_dims(3)"])
        own = summarise(params_of(body.replace("driver_length = 0.10", f"driver_length = {length!r}")
                                  .replace("0.35, 0.30,   0.214, 0.189", f"0.35, 0.30,   {link5!r}, 0.189")))
        for c in ("stroke", "time_ratio", "mu_min_deg", "torque_peak", "shaking_force_peak_N", "flywheel_inertia_kgm2"):
            assert row[c] == pytest.approx(own[c], rel=1e-12, abs=1e-12), (i, c)


def test_large_sweep_validates_each_value_once(tmp_path, monkeypatch):
    """Above FULL_VALIDATION cases the sweep validates every value of every axis alone before
    anything runs (driver.sweep._spec.validate_sweep, which refuses a bad one); the batch path's
    own check (driver.sweep._plan.batch_plan) then skips those values instead of validating them
    a second time (0.1-0.5 ms each: a 1000 x 1000 sweep validated 2000 values twice).  Counted:
    the deck validations each module makes while planning an 80 x 80 sweep."""
    from driver._deck import read_deck
    from driver.sweep import _plan, _spec
    calls = {"spec": 0, "plan": 0}
    for mod, name in ((_spec, "spec"), (_plan, "plan")):
        def counted(*a, _real=mod.validate, _name=name, **k):
            calls[_name] += 1
            return _real(*a, **k)
        monkeypatch.setattr(mod, "validate", counted)
    deck = tmp_path / "big.dat"
    deck.write_text(_base() + "&sweep\n  key1 = 'linkage.driver_length', start1 = 0.06, stop1 = 0.12, count1 = 80\n"
                              "  key2 = 'linkage.dyad_dims(3)', start2 = 0.19, stop2 = 0.24, count2 = 80\n"
                              "  case_outputs = 'none', keep = 'time_ratio > 0'\n/\n")
    plan = _plan.plan_sweep(read_deck(deck), tmp_path / "out", [], False)
    assert plan.grid.n == 6400 > _spec.FULL_VALIDATION and plan.batch is not None
    assert calls["spec"] >= 160                      # each of the 2 x 80 values, before anything runs
    assert calls["plan"] <= 2, calls                 # the &sweep group and the base deck, not the values again
    assert plan.batch.single_errors == {"linkage.driver_length": {}, "linkage.dyad_dims(3)": {}}
    assert not plan.batch.coupled_errors
