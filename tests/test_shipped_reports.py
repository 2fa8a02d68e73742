"""Every shipped deck's figures and report page, as a reader meets them.

Each deck in inputs/ is run once per session with --report (tests/report_runs.py), then:

* every figure its files and page hold keeps all its text inside the canvas, laid out by
  matplotlib's own renderer as ``savefig`` lays it out (tick labels, legends, annotations,
  colour-bar labels), and no title, axis label, legend entry or colour-bar label shows a column
  or key name instead of words (``mu_min_deg``, ``fourbar.crank``: tests/figure_checks.py);
* no cell of its page's tables prints round-off or a negative zero (``6.35529e-14``, ``-0``)
  where the ``.out`` prints 0.000;
* its page keeps the size docs/report.md promises (PAGE_BYTES), loads nothing from outside
  itself (no external reference in the file; the browser's network log holds the page alone),
  raises no console error, gives every figure and the animation a box, draws every figure's text
  legibly (no font under LEGIBLE_PX pixels at a 1200-pixel window), and its screenshot in
  headless Chromium is not blank.
"""
from __future__ import annotations

import io
import re
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))
pytest.importorskip("matplotlib")
pytest.importorskip("pyarrow")

from figure_checks import figure_problems
from report_runs import SHIPPED, outcome_figures

#: the largest page of a shipped deck [bytes] (docs/report.md states it; the figures are SVG, a
#: scatter of many points an image inside them)
PAGE_BYTES = 600_000
#: the smallest font size of a figure's text on the page [CSS px] at a 1200-pixel window: 7 pt
#: tick labels at the page's least 94 px per inch of figure are 9.1 px
LEGIBLE_PX = 8.5
#: JavaScript: per figure of the page, its accessible name and the smallest font size [CSS px]
#: of its texts as drawn (the text's font size times the scale from the figure to the screen)
SMALLEST_FONT = """Array.from(document.querySelectorAll('svg.fig')).map(s => {
    const sizes = Array.from(s.querySelectorAll('text')).map(t => {
        const m = t.getScreenCTM(); const k = Math.sqrt(Math.abs(m.a * m.d - m.b * m.c));
        return parseFloat(getComputedStyle(t).fontSize) * k; }).filter(v => v > 0);
    return [s.getAttribute('aria-label'), sizes.length ? Math.min(...sizes) : 1e9]; })"""


@pytest.mark.slow
@pytest.mark.parametrize("stem", SHIPPED)
def test_shipped_figures_keep_their_text_inside_and_in_words(report_runs, stem):
    run = report_runs.get(stem)
    figures = outcome_figures(run.outcome)
    problems = []
    for name, draw, names in figures:
        fig = draw()
        problems += [f"{name}: {p}" for p in figure_problems(fig, names)]
    assert not problems, "\n".join(problems)


#: a table cell that prints round-off or a negative zero instead of the .out's zero
ROUND_OFF = re.compile(r"^-?\d(?:\.\d+)?e-(?:1[2-9]|[2-9]\d|\d{3})$|^-0(?:\.0*)?$")


@pytest.mark.slow
@pytest.mark.parametrize("stem", SHIPPED)
def test_shipped_page_tables_print_no_round_off(report_runs, stem):
    """Every cell of the page's tables (headline figures, summary, history, tidy table) prints a
    number to the precision its table states: round-off such as 6.35529e-14 N of a balanced
    linkage's shaking force, or -0, is the .out's 0.0000 on the page too."""
    run = report_runs.get(stem)
    html = re.sub(r"<(svg|script)\b.*?</\1>", "", run.page.read_text(), flags=re.S)
    cells = re.findall(r"<td>([^<]*)</td>", html)
    bad = [c for c in cells if ROUND_OFF.match(c.strip())]
    assert not bad, f"{run.page.name}: {bad[:10]}"


def _png_pixels(png: bytes) -> np.ndarray:
    import matplotlib.image
    return matplotlib.image.imread(io.BytesIO(png), format="png")


@pytest.mark.slow
@pytest.mark.parametrize("stem", SHIPPED)
def test_shipped_page_in_chromium(report_runs, browser, stem):
    run = report_runs.get(stem)
    size = run.page.stat().st_size
    assert 5_000 < size < PAGE_BYTES, f"{run.page.name}: {size} bytes (docs/report.md promises < {PAGE_BYTES})"
    text = run.page.read_text()
    assert "<link" not in text and not re.search(r"""\b(src|href)\s*=\s*["'](?!#|data:)""", text), \
        "the page must not load anything from outside itself"
    browser.size(1200, 900)
    browser.open(run.page)
    assert browser.errors() == []
    asked = [u for u in browser.requests() if not u.startswith("data:")]   # data: URLs are the page's own images
    assert asked == [run.page.resolve().as_uri()], f"the page asked for more than itself: {asked}"
    boxes = browser.eval("""Array.from(document.querySelectorAll('svg.fig, svg.mech')).map(s => {
        const r = s.getBoundingClientRect(); return [s.getAttribute('class'), r.width, r.height]; })""")
    for cls, w, h in boxes:
        assert w > 100 and h > 50, (cls, w, h)
    n_figs = browser.eval("document.querySelectorAll('svg.fig').length")
    assert n_figs == text.count('<figure class="plot"')
    for label, px in browser.eval(SMALLEST_FONT):   # every figure's text readable at this window
        assert px >= LEGIBLE_PX, f"{label}: text at {px:.1f} px"
    px = _png_pixels(browser.screenshot())
    ink = (px[..., :3].mean(axis=2) < 0.9).mean()
    assert px[..., :3].std() > 0.05 and ink > 0.01, (px[..., :3].std(), ink)


@pytest.mark.slow
def test_a_narrow_window_scrolls_a_figure_instead_of_shrinking_it(report_runs, browser):
    """At a 640-pixel window the manipulator's 11-inch design-space figure keeps its least size
    (its box scrolls sideways) and its text stays legible."""
    run = report_runs.get("manipulator_case1_report")
    browser.size(640, 900)
    try:
        browser.open(run.page)
        first = browser.eval("""(() => { const s = document.querySelector('svg.fig');
            return [s.getBoundingClientRect().width, s.parentElement.parentElement.scrollWidth,
                    s.parentElement.parentElement.clientWidth]; })()""")
        width, scroll, client = first
        smallest = browser.eval(SMALLEST_FONT)[0][1]
        assert width >= 11.0 * 94 - 1 and scroll > client and smallest >= LEGIBLE_PX, (first, smallest)
        # a click shows it on the whole window
        browser.eval("document.querySelector('figure.plot a.zoomin').click()")
        assert browser.eval("getComputedStyle(document.querySelector('figure.plot')).position") == "fixed"
        assert browser.errors() == []
    finally:
        browser.size(1200, 900)
