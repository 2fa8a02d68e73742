"""The transmission-angle band is a deck key (``transmission_band_deg``, default the paper's
40, 120 deg): the summary's ``meets_transmission_band``, the .out, the figures and the
synthesised linkage's deck use the deck's band, not a hard-coded one.

Truth: for a crank-rocker the transmission angle is extreme where crank and ground are
collinear, cos mu = (b^2 + c^2 - (d -+ a)^2) / (2 b c) (closed form, independent of the kernel).
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import driver
from conftest import INPUTS
from driver._deck import DeckError


def _mu_extremes(d: float, a: float, b: float, c: float) -> tuple[float, float]:
    lo = math.degrees(math.acos((b * b + c * c - (d - a) ** 2) / (2 * b * c)))
    hi = math.degrees(math.acos((b * b + c * c - (d + a) ** 2) / (2 * b * c)))
    return lo, hi


@pytest.mark.parametrize("band", [None, (40.0, 120.0), (30.0, 150.0), (45.0, 100.0)])
@pytest.mark.parametrize("crank", [2.0, 3.0, 4.0, 5.0])
def test_meets_transmission_band_follows_the_deck(crank, band):
    keys = dict(fixed_link=12.0, crank=crank, coupler=15.0, rocker=9.0, step_deg=10)
    if band is not None:
        keys["transmission_band_deg"] = list(band)
    r = driver.fourbar.run(**keys)
    lo_mu, hi_mu = _mu_extremes(12.0, crank, 15.0, 9.0)
    lo, hi = band or (40.0, 120.0)
    assert r.summary["mu_min_deg"] == pytest.approx(lo_mu, abs=1e-6)
    assert r.summary["mu_max_deg"] == pytest.approx(hi_mu, abs=1e-6)
    assert r.summary["meets_transmission_band"] is (lo <= lo_mu and hi_mu <= hi)
    assert "meets_band_40_120" not in r.summary
    assert f"{lo:g}-{hi:g} deg band" in r.text
    assert ("NOT met" in r.text.split(f"{lo:g}-{hi:g} deg band")[1].splitlines()[0]) is not r.summary[
        "meets_transmission_band"]


def test_the_batch_path_uses_the_base_decks_band():
    """A sweep's batch path (one kernel call for many designs) judges by the base deck's band."""
    cranks = np.array([2.0, 3.0, 4.0, 5.0])
    s = driver.run_sweep({"fourbar": dict(fixed_link=12.0, crank=3.0, coupler=15.0, rocker=9.0,
                                          step_deg=10, transmission_band_deg=[30, 150])},
                         grid={"crank": cranks}, case_outputs="none", jobs=1)
    want = []
    for a in cranks:
        lo_mu, hi_mu = _mu_extremes(12.0, a, 15.0, 9.0)
        want.append(30 <= lo_mu and hi_mu <= 150)
    assert s.summary["meets_transmission_band"].tolist() == want
    assert want != [True, False, False, False]   # not the 40-120 answer: the band changed it
    assert "transmission_band_deg        30, 150" in s.text   # the .out states the band it judged by


@pytest.mark.parametrize("value, words", [("40", "two angles"), ("120, 40", "min < max"),
                                          ("-5, 90", "0 <= min"), ("40, 190", "<= 180")])
def test_a_bad_band_is_bad_input(write_deck, value, words):
    path = write_deck("&fourbar\n  fixed_link = 12, crank = 5, coupler = 15, rocker = 9\n"
                      f"  transmission_band_deg = {value}\n/\n")
    with pytest.raises(DeckError) as e:
        driver.run(path)
    assert e.value.key == "transmission_band_deg" and e.value.line == 3 and words in e.value.message


def test_the_curves_figure_shades_the_decks_band():
    pytest.importorskip("matplotlib")
    r = driver.fourbar.run(fixed_link=12.0, crank=3.0, coupler=15.0, rocker=9.0, step_deg=10,
                          transmission_band_deg=[30, 150])
    fig = r.figure("curves")
    ax = fig.axes[1]
    texts = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "30-150 deg band" in texts
    span = [p for p in ax.patches if p.get_label() == "30-150 deg band"][0]
    ys = span.get_path().transformed(span.get_patch_transform()).vertices[:, 1] if hasattr(span, "get_patch_transform") \
        else span.get_xy()[:, 1]
    assert min(ys) == pytest.approx(30.0) and max(ys) == pytest.approx(150.0)


def test_the_synthesised_linkage_carries_the_synthesis_band(tmp_path):
    """synthesis_path asks for 30-150 deg: its linkage deck, summary and figures judge by 30-150."""
    from driver.synthesis import synthesise
    syn = synthesise(INPUTS / "synthesis_path.dat")
    p = syn.params
    assert syn.linkage["transmission_band_deg"] == [p.transmission_min_deg, p.transmission_max_deg]
    assert f"{p.transmission_min_deg:g}-{p.transmission_max_deg:g} deg band" in syn.study_result.text
    assert "/" not in syn.linkage["title"] and "synthesis_path" in syn.linkage["title"]   # no file path in the title


def _parquet_band(path) -> list[float]:
    """The band recorded in a Parquet table's schema metadata (read with pyarrow, not pandas:
    any reader of the file sees it)."""
    import json

    import pyarrow.parquet as pq
    meta = pq.read_schema(path).metadata or {}
    return json.loads(meta[b"PANDAS_ATTRS"])["summary_settings"]["transmission_band_deg"]


@pytest.mark.parametrize("case_outputs, path", [("none", "batch"), ("all", "case")])
def test_the_summary_table_records_the_band_it_was_judged_by(tmp_path, case_outputs, path):
    """The Parquet summary carries the band its meets_transmission_band column used, on both
    engines (batch path and case by case), and the column agrees with that band by the closed form."""
    import pandas as pd
    cranks = [2.0, 3.0, 4.0, 5.0]
    out = tmp_path / "o"
    s = driver.run_sweep({"fourbar": dict(fixed_link=12.0, crank=3.0, coupler=15.0, rocker=9.0, step_deg=10,
                                          transmission_band_deg=[30, 150])},
                         grid={"crank": cranks}, case_outputs=case_outputs, jobs=1, outdir=out, name="bandsweep")
    assert s.batch == (path == "batch")
    f = out / "bandsweep_summary.parquet"
    lo, hi = _parquet_band(f)
    assert (lo, hi) == (30.0, 150.0)
    table = pd.read_parquet(f)
    assert table.attrs["summary_settings"] == {"transmission_band_deg": [30.0, 150.0]}
    for a, met in zip(table["fourbar.crank"], table["meets_transmission_band"]):
        lo_mu, hi_mu = _mu_extremes(12.0, a, 15.0, 9.0)
        assert met is (lo <= lo_mu and hi_mu <= hi)
    assert "transmission_band_deg        30, 150" in (out / "bandsweep.out").read_text()


def test_a_swept_band_is_a_column_not_table_metadata():
    from driver import fourbar
    from driver.sweep._report import summary_settings
    base = {"crank": 3.0, "transmission_band_deg": [30, 150]}
    assert summary_settings(fourbar.STUDY, base) == {"transmission_band_deg": [30.0, 150.0]}
    assert summary_settings(fourbar.STUDY, base, {"transmission_band_deg"}) == {}


def test_shipped_outputs_record_the_band():
    """The committed summary and evals tables of the four-bar sweeps and optimisations state the
    band (the paper's 40-120 deg: their decks give no other)."""
    from conftest import ROOT
    for name in ("fourbar_design_search_summary", "fourbar_paper_sweep_summary",
                 "optimize_fourbar_design_evals", "optimize_crank_rocker_evals"):
        assert _parquet_band(ROOT / "outputs" / f"{name}.parquet") == [40.0, 120.0]
    text = (ROOT / "outputs" / "optimize_fourbar_design.out").read_text()
    assert "transmission_band_deg = 40, 120   (base deck; used by the summary columns)" in text


def test_an_optimisation_states_the_band_it_constrains_by(tmp_path):
    """An optimisation constrained by meets_transmission_band with a 30-150 deg band says so in
    its .out and records the band in its _evals table."""
    from driver.optimize import optimize
    deck = tmp_path / "opt.dat"
    deck.write_text("&fourbar\n fixed_link = 12, crank = 3, coupler = 15, rocker = 9, step_deg = 10\n"
                    " transmission_band_deg = 30, 150\n/\n"
                    "&optimize\n var1 = 'fourbar.crank', lower1 = 1, upper1 = 4\n"
                    " maximize = 'mu_min_deg'\n constraint1 = 'meets_transmission_band'\n"
                    " method = 'grid', grid_count = 7\n/\n")
    oc = optimize(deck, outdir=tmp_path / "o")
    text = (tmp_path / "o" / "opt.out").read_text()
    assert "transmission_band_deg = 30, 150   (base deck; used by the summary columns)" in text
    assert _parquet_band(tmp_path / "o" / "opt_evals.parquet") == [30.0, 150.0]
    assert oc.best is not None
