"""The report page (``--report``) loaded in a real browser: headless Chromium over the DevTools
protocol (tests/headless.py).

One deck of each study, a sweep, an optimisation and a synthesis are run once with --report;
every page is then opened from disk and must: raise no console error or exception, ask for
nothing outside itself, render every figure with a non-empty box, be under the stated size,
print to PDF, and give a screenshot that is not blank.  The animations are checked against
geometry the page cannot fake: at every crank angle the slider selects, the drawn crank pin
lies on the crank circle at that angle (the closed form r(cos t, sin t)), and the drawn coupler
and rocker keep their deck lengths (loop closure); the slider-crank's slider stays on its guide
at the rod's length from the crank pin.

Chromium is Debian's ``chromium`` (.ci/setup installs it); without it these tests are skipped
on a developer machine and fail in CI (CI set), where the page must be tested.
"""
from __future__ import annotations

import io
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))
from conftest import INPUTS, ROOT
from headless import Browser, chromium_path

pytest.importorskip("matplotlib")
pytest.importorskip("pyarrow")

if chromium_path() is None:
    if os.environ.get("CI"):
        pytest.fail("CI must test the report page in Chromium: .ci/setup installs Debian's chromium", pytrace=False)
    pytest.skip("no chromium on PATH (bash .ci/setup installs it)", allow_module_level=True)

from driver._report_page import MAX_PAGE_BYTES

#: a small slider-crank deck (the paper's aluminium rod, coarse mesh): seconds, not minutes
SLIDERCRANK = """! aluminium rod of the paper, coarse mesh for a quick report
&slidercrank
  material = 'aluminium'
  crank_radius = 0.125, rod_length = 0.505
  slider_mass = 0.9, bearing_mass_crank = 0.05, bearing_mass_slider = 0.05
  speeds = 11.52, 29.32
  n_elements = 12, steps_per_rev = 720, revolutions = 2
/
"""

#: deck stem -> what the page must hold (an animation, design-space maps)
PAGES = {"crank5": {"anim": "fourbar"}, "nongrashof": {"anim": "fourbar"},
         "crank5_coupler_point": {"anim": "fourbar"}, "slidercrank_small": {"anim": "slidercrank"},
         "ujoint_option1": {}, "manipulator_case1_report": {}, "robust_example": {},
         "fourbar_paper_sweep": {"anim": "fourbar", "section": "design-space"},
         "optimize_crank_rocker": {"anim": "fourbar", "section": "convergence"},
         "synthesis_path": {"anim": "fourbar", "section": "linkage"}}


@pytest.fixture(scope="module")
def pages(tmp_path_factory):
    out = tmp_path_factory.mktemp("report")
    small = out / "slidercrank_small.dat"
    small.write_text(SLIDERCRANK)
    decks = [str(INPUTS / f"{n}.dat") for n in PAGES if n != "slidercrank_small"] + [str(small)]
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.run([sys.executable, "-m", "driver", *decks, "--report", "-q", "-o", str(out / "out")],
                          capture_output=True, text=True, env=env, timeout=900)
    assert proc.returncode in (0, 1), proc.stderr   # 1: crank5's listing audit is a warning, not a failure
    assert "report page could not be written" not in proc.stderr, proc.stderr
    return out / "out"


@pytest.fixture(scope="module")
def browser():
    with Browser(width=1200, height=900) as b:
        yield b


def _png_pixels(png: bytes) -> np.ndarray:
    import matplotlib.image
    return matplotlib.image.imread(io.BytesIO(png), format="png")


@pytest.mark.parametrize("stem", list(PAGES))
def test_page_renders_offline(pages, browser, stem):
    path = pages / f"{stem}.html"
    assert path.is_file(), sorted(p.name for p in pages.iterdir())
    size = path.stat().st_size
    assert 5_000 < size < MAX_PAGE_BYTES, f"{path.name}: {size} bytes"
    text = path.read_text()
    assert "<link" not in text and not re.search(r"""\b(src|href)\s*=\s*["'](?!#|data:)""", text), \
        "the page must not load anything from outside itself"
    browser.events.clear()
    browser.open(path)
    assert browser.errors() == []
    # every figure and animation has a box on the page
    boxes = browser.eval("""Array.from(document.querySelectorAll('svg.fig, svg.mech')).map(s => {
        const r = s.getBoundingClientRect(); return [s.getAttribute('class'), r.width, r.height]; })""")
    for cls, w, h in boxes:
        assert w > 100 and h > 50, (cls, w, h)
    # each figure drew something: lines/patches/text inside its box
    drawn = browser.eval("""Array.from(document.querySelectorAll('svg.fig')).map(s => {
        const b = s.getBBox(); return [b.width, b.height, s.querySelectorAll('path, use, image, text').length]; })""")
    for w, h, n in drawn:
        assert w > 0 and h > 0 and n > 10, (w, h, n)
    want = PAGES[stem]
    if "section" in want:
        assert browser.eval(f"!!document.getElementById('{want['section']}')")
    assert browser.eval("document.querySelectorAll('svg.mech').length") == (1 if "anim" in want else 0)
    if stem not in ("robust_example",):
        assert len(boxes) >= 1
    # the metadata and the deck are on the page
    assert browser.eval("document.getElementById('run').textContent").count("mechanism-driver") >= 1
    assert browser.eval("document.getElementById('deck').textContent").strip()
    # a screenshot that is not blank: some ink, not one flat colour
    px = _png_pixels(browser.screenshot())
    ink = (px[..., :3].mean(axis=2) < 0.9).mean()
    assert px[..., :3].std() > 0.05 and ink > 0.01, (px[..., :3].std(), ink)
    assert browser.pdf()[:5] == b"%PDF-"


def _parts(browser) -> dict:
    return browser.eval("""(() => { const r = document.querySelector('.anim');
        const g = s => r.querySelector("[data-part='" + s + "']");
        const num = (e, a) => parseFloat(e.getAttribute(a));
        const c = g('crank'), A = g('A'), B = g('B'), k = g('coupler'), o = g('out'), blk = g('block');
        return {theta: r.querySelector('output').textContent,
                crank: [num(c,'x1'), num(c,'y1'), num(c,'x2'), num(c,'y2')],
                A: [num(A,'cx'), num(A,'cy')], B: [num(B,'cx'), num(B,'cy')],
                coupler: k.getAttribute('points'), rod: k.getAttribute('d'), visible: k.style.visibility,
                out: o ? [num(o,'x1'), num(o,'y1'), num(o,'x2'), num(o,'y2')] : null,
                block: blk ? [num(blk,'x') + num(blk,'width') / 2, num(blk,'y') + num(blk,'height') / 2] : null,
                note: r.querySelector("[data-part='note']").style.visibility}; })()""")


def _move(browser, k: int) -> None:
    browser.eval(f"""(() => {{ const s = document.querySelector('.anim input[type=range]');
        s.value = {k}; s.dispatchEvent(new Event('input')); }})()""")


@pytest.mark.parametrize("stem, lengths", [
    ("crank5", dict(ground=12.0, crank=5.0, coupler=15.0, rocker=9.0)),
    ("nongrashof", dict(ground=10.0, crank=6.0, coupler=7.0, rocker=8.0, rocking=True)),
    ("slidercrank_small", dict(crank=0.125, rod=0.505)),
])
def test_animation_follows_the_slider(pages, browser, stem, lengths):
    if stem == "slidercrank_small":   # the run's midpoint deflection at its fastest speed, in metres
        import driver
        tidy = driver.run(SLIDERCRANK, name="slidercrank_small").tidy
        fast = tidy[tidy["omega_rad_s"] == tidy["omega_rad_s"].max()]
        ang = np.mod(fast["crank_angle_deg"].to_numpy(), 360.0)
        mid = fast["midpoint_deflection_mm"].to_numpy() * 1e-3
        order = np.argsort(ang)
        lengths = dict(lengths, mid=(ang[order], mid[order]), scale=0.06 * 0.505 / np.abs(mid).max())
    browser.events.clear()
    browser.open(pages / f"{stem}.html")
    n = int(browser.eval("document.querySelector('.anim input[type=range]').max")) + 1
    seen = []
    for k in (0, n // 8, n // 3, n // 2, (3 * n) // 4):
        _move(browser, k)
        p = _parts(browser)
        if lengths and lengths.get("rocking"):   # the frame's crank angle, then the stroke and branch
            theta = float(browser.eval(f"JSON.parse(document.querySelector('.anim script[type=\\'application/json\\']')"
                                       f".textContent).theta[{k}]"))
            assert p["theta"].startswith(f"{theta:.0f}\u00b0 ") and "assembly" in p["theta"]
        else:
            theta = 360.0 * k / n
            assert p["theta"] == f"{theta:.0f}\u00b0"
        seen.append(p)
        if lengths is None:
            continue
        a = np.array(p["A"])
        r = lengths["crank"]
        # the crank pin where the crank angle says (closed form), the crank drawn to it
        assert np.allclose(a, [r * math.cos(math.radians(theta)), r * math.sin(math.radians(theta))], atol=1e-4 * r)
        assert np.allclose(p["crank"][2:], a) and np.allclose(p["crank"][:2], [0.0, 0.0])
        b = np.array(p["B"])
        if "rocker" in lengths:   # loop closure of the drawn linkage: every link keeps its length
            assert p["visible"] == "visible"
            assert math.isclose(np.hypot(*(b - a)), lengths["coupler"], rel_tol=1e-4)
            assert math.isclose(np.hypot(b[0] - lengths["ground"], b[1]), lengths["rocker"], rel_tol=1e-4)
            assert np.allclose(p["out"], [lengths["ground"], 0.0, *b])
        else:                     # the slider on its guide, the rod at its length
            assert abs(b[1]) < 1e-9 and math.isclose(np.hypot(*(b - a)), lengths["rod"], rel_tol=1e-4)
            assert np.allclose(p["block"], b, atol=1e-6)
            # the rod drawn from A to B, bowed by its midpoint deflection (magnified as the caption says)
            nums = [float(v) for v in re.findall(r"-?[0-9.]+(?:e-?[0-9]+)?", p["rod"])]
            start, ctrl, end = np.array(nums[:2]), np.array(nums[2:4]), np.array(nums[4:6])
            assert np.allclose(start, a) and np.allclose(end, b)
            mid_drawn = 0.25 * start + 0.5 * ctrl + 0.25 * end   # the quadratic Bezier at t = 1/2
            chord = (b - a) / np.hypot(*(b - a))
            off = mid_drawn - 0.5 * (a + b)
            bow = float(chord[0] * off[1] - chord[1] * off[0])   # signed distance to the left of A->B
            assert bow == pytest.approx(lengths["scale"] * np.interp(theta, *lengths["mid"], period=360.0),
                                        abs=1e-6 * lengths["rod"])
    # the drawing changes with the slider
    assert len({tuple(p["A"]) for p in seen}) == len(seen)
    assert browser.errors() == []
    if lengths and lengths.get("rocking"):
        # the non-Grashof linkage cannot turn: it rocks between its closed-form limit angles, out
        # on the open assembly and back on the crossed, always assembled (no "cannot be assembled")
        F = browser.eval("JSON.parse(document.querySelector(\".anim script[type='application/json']\").textContent)")
        g, a, b, c = (lengths[k] for k in ("ground", "crank", "coupler", "rocker"))
        limit = math.degrees(math.acos((g * g + a * a - (b + c) ** 2) / (2 * g * a)))
        th = np.array(F["theta"])
        assert th.max() == pytest.approx(limit, abs=1e-4) and th.min() == pytest.approx(-limit, abs=1e-4)
        top = int(np.argmax(th))
        assert np.all(np.diff(th[:top + 1]) > 0) and np.all(np.diff(th[top + 1:]) < 0)   # reverses once, at the limit
        assert all("open" in f for f in F["phase"][:top + 1]) and all("crossed" in f for f in F["phase"][top + 1:])
        states = []
        for k in range(0, n, 3):
            _move(browser, k)
            q = _parts(browser)
            states.append(q["note"])
            A, B = np.array(q["A"]), np.array(q["B"])
            assert math.isclose(np.hypot(*(B - A)), b, rel_tol=1e-4)
            assert math.isclose(np.hypot(B[0] - g, B[1]), c, rel_tol=1e-4)
        assert set(states) == {"hidden"}
        limits = browser.eval("document.querySelectorAll(\".anim [data-part='limit']\").length")
        assert limits == 2


def test_play_button_moves_the_mechanism(pages, browser):
    browser.events.clear()
    browser.open(pages / "crank5.html")
    before = _parts(browser)["A"]
    browser.eval("document.querySelector('.anim button').click()")
    browser.eval("new Promise(r => setTimeout(r, 400))")
    after = _parts(browser)
    browser.eval("document.querySelector('.anim button').click()")
    assert after["A"] != before and after["theta"] != "0\u00b0"
    assert browser.errors() == []


def test_published_comparison_on_the_page(pages, browser):
    """crank5 reproduces the paper's Lampiran 3: the page lists its cells and counts them."""
    from driver._compare import compare
    expected = compare(INPUTS / "crank5.dat")
    browser.events.clear()
    browser.open(pages / "crank5.html")
    text = browser.eval("document.getElementById('published').textContent")
    assert f"{len(expected)} published cells compared" in text
    for table in expected["table"].unique():
        assert table in text


def test_result_write_report(tmp_path, browser):
    """The Python API writes the same page: driver.write(result, ..., report=True)."""
    import driver
    r = driver.run(str(INPUTS / "crank2.dat"))
    written = driver.write(r, tmp_path, report=True)
    page = tmp_path / "crank2.html"
    assert page in written
    browser.events.clear()
    browser.open(page)
    assert browser.errors() == []
    assert browser.eval("document.querySelectorAll('svg.mech').length") == 1
    assert browser.eval("document.querySelectorAll('svg.fig').length") == len(r.figures)
