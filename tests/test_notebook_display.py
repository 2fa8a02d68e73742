"""In a notebook a Result, a sweep's outcome and an optimisation's outcome show themselves as
their report page's content (``_repr_html_``, as pandas and matplotlib objects do), made by the
page's own templates: the same figures, the same headline table (names in words, numbers as the
.out prints them), the animation with its script, and none of the page around them.
"""
from __future__ import annotations

import re
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))
pytest.importorskip("matplotlib")
pytest.importorskip("pyarrow")

import driver
from conftest import INPUTS


def _rows(html: str, section: str) -> list[tuple[str, str, str]]:
    """The (tooltip, name, value) rows of a section's key-value table."""
    body = re.search(rf'<section id="{section}">(.*?)</section>', html, re.S).group(1)
    return re.findall(r'<tr><th(?: title="([^"]*)")?>(.*?)</th><td>(.*?)</td></tr>', body)


def test_a_result_shows_its_page_content(tmp_path):
    r = driver.run(str(INPUTS / "fourbar_forces_balanced.dat"))
    html = r._repr_html_()
    assert html.lstrip().startswith('<div class="mechanism-driver">')
    assert "<html" not in html and "<body" not in html and 'id="deck"' not in html
    assert len(re.findall(r'<svg[^>]*class="fig"', html)) == len(r.figures)
    assert len(re.findall(r'<svg[^>]*class="mech"', html)) == 1
    assert html.count("<script>") == 1   # the animation's script travels with it
    # the same headline table as the page's, made by the same code: words, units, .out decimals
    page = (driver.write(r, tmp_path, report=True)[-1]).read_text()
    assert _rows(html, "summary") == _rows(page, "summary")
    rows = {tip: value for tip, _, value in _rows(html, "summary")}
    assert rows["torque_mean_Nm"] == "0.0000" and rows["shaking_force_peak_N"] == "0.0000"   # round-off reads zero
    names = {tip: name for tip, name, _ in _rows(html, "summary")}
    assert names["mu_min_deg"] == "minimum transmission angle [deg]"


def test_a_sweep_outcome_shows_its_maps_and_table():
    s = driver.run_sweep({"fourbar": {"fixed_link": 12, "crank": 3, "coupler": 15, "rocker": 9, "step_deg": 20}},
                         grid={"crank": [2, 3, 4], "coupler": [12, 14, 16]}, jobs=1)
    html = s._repr_html_()
    assert html is not None and 'id="design-space"' in html and 'id="summary-table"' in html
    assert len(re.findall(r'<svg[^>]*class="fig"', html)) >= 1 and "<html" not in html
    # the table's headers are words, the swept key's own name its tooltip
    assert 'title="fourbar.crank">crank length [length units]</th>' in html


def test_an_optimisation_outcome_shows_its_convergence_and_optimum(tmp_path):
    from driver.optimize import optimize
    deck = tmp_path / "opt.dat"
    deck.write_text("&fourbar fixed_link = 12, crank = 3, coupler = 15, rocker = 9, omega = 5, step_deg = 10 /\n"
                    "&optimize\nvar1 = 'fourbar.coupler', lower1 = 10, upper1 = 20\n"
                    "maximize = 'rocker_swing_deg'\nmethod = 'slsqp', starts = 1\n/\n")
    oc = optimize(deck, tmp_path / "out", jobs=1)
    html = oc._repr_html_()
    assert html is not None and 'id="convergence"' in html and 'id="optimum"' in html
    assert len(re.findall(r'<svg[^>]*class="mech"', html)) == 1            # the optimum's linkage, animated
    assert 'aria-label="opt_convergence: convergence"' in html


def test_an_outcome_without_a_renderer_falls_back_to_its_repr():
    from driver._outcome import Outcome
    assert Outcome()._repr_html_() is None


def test_the_fragment_runs_in_a_browser(browser, tmp_path):
    """The fragment, put in a bare page as a notebook puts it: its animation moves, no error."""
    r = driver.run(str(INPUTS / "crank5.dat"))
    page = tmp_path / "nb.html"
    page.write_text("<!DOCTYPE html><html><head><meta charset='utf-8'></head><body>" + r._repr_html_()
                    + "</body></html>")
    browser.open(page)
    assert browser.errors() == []
    before = browser.eval("document.querySelector('.anim [data-point=A]').getAttribute('cx')")
    browser.eval("""(() => { const s = document.querySelector('.anim input[type=range]');
        s.value = 40; s.dispatchEvent(new Event('input')); })()""")
    assert browser.eval("document.querySelector('.anim [data-point=A]').getAttribute('cx')") != before
