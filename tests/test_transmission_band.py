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
from driver.deck import DeckError

from conftest import INPUTS


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
