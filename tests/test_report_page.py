"""The report page (``--report``) loaded in a real browser: headless Chromium driven by Selenium
and Debian's chromium-driver (tests/browser.py, one browser per session).

One deck of each study, a sweep, an optimisation and a synthesis are run once with --report
(tests/report_runs.py: the shipped decks' runs are shared with tests/test_shipped_pages.py);
every page is then opened from disk and must: raise no console error or exception, ask for
nothing outside itself, render every figure with a non-empty box, print to PDF, and give a
screenshot that is not blank.  The animations are checked against geometry the page cannot
fake: at every crank angle the slider selects, the drawn crank pin lies on the crank circle at
that angle (the closed form r(cos t, sin t)), and the drawn coupler and rocker keep their deck
lengths (loop closure); the slider-crank's slider stays on its guide at the rod's length from
the crank pin, its rod bowed by the run's deflection; a balancing four-bar's counterweights
ride at their radius and angle; a path synthesis's targets lie on the coupler point's path.

Without selenium, chromium or chromedriver these tests are skipped on a developer machine and
fail in CI (CI set), where the page must be tested.
"""
from __future__ import annotations

import io
import math
import re
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))
from conftest import INPUTS

pytest.importorskip("matplotlib")
pytest.importorskip("pyarrow")

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

#: a single Hooke joint: its output angle has a closed form, tan(theta_out) = cos(beta) tan(theta)
UJOINT_ONE = """! one Hooke joint at 30 deg
&ujoint
  beta = 30.0
  rpm = 30.0
/
"""

#: a small nonlinear rod (the paper's aluminium, 8 elements): buckled at 29.32 rad/s in seconds
SLIDERCRANK_NL = """! aluminium rod of the paper, nonlinear, coarse mesh for a quick report
&slidercrank
  material = 'aluminium'
  speeds = 11.52, 29.32
  n_elements = 8
  steps_per_rev = 720, revolutions = 4
  damping_ratio = 0.02
  model = 'nonlinear'
/
"""

#: deck stem -> what the page must hold (an animation, design-space maps)
PAGES = {"crank5": {"anim": "fourbar"}, "nongrashof": {"anim": "fourbar"},
         "crank5_coupler_point": {"anim": "fourbar"}, "slidercrank_small": {"anim": "slidercrank"},
         "ujoint_option1": {"anim": "ujoint"}, "ujoint_one": {"anim": "ujoint"},
         "manipulator_case1_report": {"anim": "manipulator"}, "robust_example": {},
         "fourbar_paper_sweep": {"anim": "fourbar", "section": "best"},
         "optimize_crank_rocker": {"anim": "fourbar", "section": "optimum"},
         "synthesis_path": {"anim": "fourbar", "section": "linkage"}, "slidercrank_nl_small": {"anim": "slidercrank"},
         "fourbar_forces_balanced": {"anim": "fourbar"}}
WRITTEN = {"slidercrank_small": SLIDERCRANK, "ujoint_one": UJOINT_ONE, "slidercrank_nl_small": SLIDERCRANK_NL}


@pytest.fixture(scope="module")
def pages(report_runs):
    """Every page of PAGES written (the session's runs), and the folder holding them."""
    for name in PAGES:
        report_runs.get(name, WRITTEN.get(name))
    return report_runs.root / "out"


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
    """The animation's parts as drawn: every link's points (by name) and every pin or dot (by name)."""
    return browser.eval("""(() => { const r = document.querySelector('.anim');
        const xy = s => s.trim().split(/\\s+/).map(p => p.split(',').map(Number));
        const links = {}, dots = {};
        r.querySelectorAll('[data-link]').forEach(e => { links[e.getAttribute('data-link')] = {
            visible: e.style.visibility, tag: e.tagName,
            points: e.tagName === 'line' ? [[+e.getAttribute('x1'), +e.getAttribute('y1')],
                                            [+e.getAttribute('x2'), +e.getAttribute('y2')]]
                                         : xy(e.getAttribute('points') || '')}; });
        r.querySelectorAll('[data-point]').forEach(e => { dots[e.getAttribute('data-point')] =
            [+e.getAttribute('cx'), +e.getAttribute('cy')]; });
        return {label: r.querySelector('output').textContent, links: links, dots: dots,
                note: r.querySelector("[data-role='note']").style.visibility}; })()""")


def _move(browser, k: int) -> None:
    browser.eval(f"""(() => {{ const s = document.querySelector('.anim input[type=range]');
        s.value = {k}; s.dispatchEvent(new Event('input')); }})()""")


def _frames(browser) -> int:
    return int(browser.eval("document.querySelector('.anim input[type=range]').max")) + 1


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
    browser.open(pages / f"{stem}.html")
    n = _frames(browser)
    seen = []
    r = lengths["crank"]
    for k in (0, n // 8, n // 3, n // 2, (3 * n) // 4):
        _move(browser, k)
        p = _parts(browser)
        crank = np.array(p["links"]["crank"]["points"])
        a = np.array(p["dots"]["A"])
        # the crank from its pivot at the origin to the pin A, at the crank's length
        assert np.allclose(crank[0], [0.0, 0.0]) and np.allclose(crank[1], a)
        assert math.isclose(np.hypot(*a), r, rel_tol=1e-5)
        theta = math.degrees(math.atan2(a[1], a[0]))
        if lengths.get("rocking"):   # the frame's crank angle, then the stroke and branch
            assert p["label"].startswith(f"{theta:.0f}\u00b0 ") and "assembly" in p["label"]
        else:                        # the crank turns through the frames evenly, as the label says
            assert p["label"] == f"{360.0 * k / n:.0f}\u00b0"
            assert math.isclose(math.cos(math.radians(theta - 360.0 * k / n)), 1.0, abs_tol=1e-9)
        seen.append(p)
        b = np.array(p["dots"]["B"])
        if "rocker" in lengths:   # loop closure of the drawn linkage: every link keeps its length
            coupler, rocker = p["links"]["coupler"], p["links"]["rocker"]
            assert coupler["visible"] == "visible"
            assert np.allclose(coupler["points"], [a, b])
            assert math.isclose(np.hypot(*(b - a)), lengths["coupler"], rel_tol=1e-5)
            assert math.isclose(np.hypot(b[0] - lengths["ground"], b[1]), lengths["rocker"], rel_tol=1e-5)
            assert np.allclose(rocker["points"], [[lengths["ground"], 0.0], b])
        else:                     # the slider on its guide, the rod at its length
            assert abs(b[1]) < 1e-9 and math.isclose(np.hypot(*(b - a)), lengths["rod"], rel_tol=1e-5)
            block = np.array(p["links"]["slider"]["points"])
            assert p["links"]["slider"]["tag"] == "polygon" and np.allclose(block.mean(axis=0), b, atol=1e-6)
            # the rod drawn from A to B through its nodes, its middle node off the chord by the midpoint
            # deflection (magnified as the caption says), to the left of A->B
            rod = np.array(p["links"]["connecting rod"]["points"])
            assert np.allclose(rod[0], a) and np.allclose(rod[-1], b) and len(rod) % 2 == 1
            chord = (b - a) / np.hypot(*(b - a))
            off = rod[len(rod) // 2] - 0.5 * (a + b)
            bow = float(chord[0] * off[1] - chord[1] * off[0])
            assert bow == pytest.approx(lengths["scale"] * np.interp(theta % 360.0, *lengths["mid"], period=360.0),
                                        abs=1e-6 * lengths["rod"])
    # the drawing changes with the slider
    assert len({tuple(p["dots"]["A"]) for p in seen}) == len(seen)
    assert browser.errors() == []
    if lengths.get("rocking"):
        # the non-Grashof linkage cannot turn: it rocks between its closed-form limit angles, out
        # on the open assembly and back on the crossed, always assembled (no "cannot be assembled")
        g, a, b, c = (lengths[k] for k in ("ground", "crank", "coupler", "rocker"))
        limit = math.degrees(math.acos((g * g + a * a - (b + c) ** 2) / (2 * g * a)))
        th, phase, states = [], [], []
        for k in range(n):
            _move(browser, k)
            q = _parts(browser)
            A, B = np.array(q["dots"]["A"]), np.array(q["dots"]["B"])
            th.append(math.degrees(math.atan2(A[1], A[0])))
            phase.append(q["label"])
            states.append(q["note"])
            assert math.isclose(np.hypot(*(B - A)), b, rel_tol=1e-5)
            assert math.isclose(np.hypot(B[0] - g, B[1]), c, rel_tol=1e-5)
        th = np.array(th)
        assert th.max() == pytest.approx(limit, abs=1e-3) and th.min() == pytest.approx(-limit, abs=1e-3)
        top = int(np.argmax(th))
        assert np.all(np.diff(th[:top + 1]) > 0) and np.all(np.diff(th[top + 1:]) < 0)   # reverses once, at the limit
        assert all("open" in f for f in phase[:top + 1]) and all("crossed" in f for f in phase[top + 1:])
        assert set(states) == {"hidden"}
        limits = browser.eval("Array.from(document.querySelectorAll(\".anim [data-role='guide'] title\"))"
                              ".filter(t => t.textContent.startsWith('limit position')).length")
        assert limits == 2


def test_ujoint_animation_turns_the_output_as_the_closed_form(pages, browser):
    """One Hooke joint at 30 deg: the page's output deviation at every frame is the closed form
    atan(cos(beta) tan(theta)) - theta (about its mean, zero over a turn); the shafts keep their length."""
    browser.open(pages / "ujoint_one.html")
    n = _frames(browser)
    beta = math.radians(30.0)
    for k in range(0, n, 7):
        _move(browser, k)
        p = _parts(browser)
        theta = 2 * math.pi * k / n
        closed = math.degrees(math.atan2(math.cos(beta) * math.sin(theta), math.cos(theta)) - theta)
        closed = (closed + 180.0) % 360.0 - 180.0
        m = re.fullmatch(r"(\d+)\u00b0, output ([+-]\d+\.\d\d)\u00b0 from uniform rotation", p["label"])
        assert m and int(m.group(1)) == round(math.degrees(theta)), p["label"]
        assert float(m.group(2)) == pytest.approx(closed, abs=0.0051)
        for shaft in ("input shaft", "output shaft"):
            assert p["links"][shaft]["visible"] == "visible"
    assert browser.errors() == []


def test_manipulator_animation_reaches_each_workspace_point(pages, browser):
    """The deck's designs (l1, l2) = (5.61, 3.97) and (4.86, 4.86): at each frame that says 'at Pi' the
    drawn tip is the workspace point and the links keep their lengths (inverse kinematics checked
    by forward kinematics on the page)."""
    browser.open(pages / "manipulator_case1_report.html")
    points = {1: (1, 5), 2: (2, 7), 3: (3, 7), 4: (4, 6)}
    reached = set()
    for k in range(_frames(browser)):
        _move(browser, k)
        p = _parts(browser)
        m = re.search(r"l\u2081 = ([0-9.]+) m, l\u2082 = ([0-9.]+) m\) at P(\d)", p["label"])
        if not m:
            continue
        l1, l2, i = float(m.group(1)), float(m.group(2)), int(m.group(3))
        elbow, tip = np.array(p["dots"]["elbow"]), np.array(p["dots"]["tip"])
        assert np.allclose(tip, points[i], atol=1e-6)
        assert math.isclose(np.hypot(*elbow), l1, rel_tol=1e-6) and math.isclose(np.hypot(*(tip - elbow)), l2, rel_tol=1e-6)
        reached.add((l1, i))
    assert reached == {(l1, i) for l1 in (5.61, 4.86) for i in points}
    assert browser.errors() == []


def test_every_mechanism_moves_by_the_same_script(pages):
    """The four-bar, the slider-crank, the shaft chain and the arm are animated by one script, the
    same text on every page (templates/animation.js), and the page names no mechanism."""
    scripts = set()
    for stem in ("crank5", "slidercrank_small", "ujoint_option1", "manipulator_case1_report"):
        html = (pages / f"{stem}.html").read_text()
        found = re.findall(r"<script>(.*?)</script>", html, re.S)
        assert len(found) == 1, stem
        scripts.add(found[0])
    assert len(scripts) == 1


def test_play_button_moves_the_mechanism(pages, browser):
    browser.open(pages / "crank5.html")
    before = _parts(browser)["dots"]["A"]
    browser.eval("document.querySelector('.anim button').click()")
    browser.wait(400)
    after = _parts(browser)
    browser.eval("document.querySelector('.anim button').click()")
    assert after["dots"]["A"] != before and after["label"] != "0\u00b0"
    assert browser.errors() == []


def test_published_comparison_on_the_page(pages, browser):
    """crank5 reproduces the paper's Lampiran 3: the page lists its cells and counts them."""
    from driver._compare import compare
    expected = compare(INPUTS / "crank5.dat")
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
    browser.open(page)
    assert browser.errors() == []
    assert browser.eval("document.querySelectorAll('svg.mech').length") == 1
    assert browser.eval("document.querySelectorAll('svg.fig').length") == len(r.figures)


def test_nonlinear_rod_is_drawn_through_its_nodes_as_the_run_left_them(pages, browser):
    """The nonlinear deck's rod is no rigid bar: at each frame its middle node (the midspan node
    of the 8-element mesh) lies off the chord by the midspan deflection the run's tidy table
    records at that crank angle (a separate record of the kernel's), at the scale the caption
    states, to the left of A->B; the rod runs from A to B through its interior nodes."""
    import driver
    tidy = driver.run(SLIDERCRANK_NL, name="slidercrank_nl_small").tidy
    fast = tidy[tidy["omega_rad_s"] == tidy["omega_rad_s"].max()]
    ang = np.mod(fast["crank_angle_deg"].to_numpy(), 360.0)
    mid = fast["midspan_nonlinear_mm"].to_numpy() * 1e-3
    order = np.argsort(ang)
    browser.open(pages / "slidercrank_nl_small.html")
    caption = browser.eval("document.querySelector('.anim p.caption').textContent")
    m = re.search(r"magnified ([0-9.e+]+) times", caption)
    scale = float(m.group(1)) if m else 1.0
    assert m or "drawn at true scale" in caption, caption
    n = _frames(browser)
    bows = []
    for k in range(0, n, 9):
        _move(browser, k)
        p = _parts(browser)
        a, b = np.array(p["dots"]["A"]), np.array(p["dots"]["B"])
        rod = np.array(p["links"]["connecting rod"]["points"])
        assert len(rod) == 9 and np.allclose(rod[0], a) and np.allclose(rod[-1], b)
        chord = (b - a) / np.hypot(*(b - a))
        off = rod[4] - 0.5 * (a + b)
        bow = float(chord[0] * off[1] - chord[1] * off[0])
        want = scale * np.interp(360.0 * k / n, ang[order], mid[order], period=360.0)
        assert bow == pytest.approx(want, abs=2e-3 * scale * np.abs(mid).max() + 1e-7)
        bows.append(bow)
    assert np.ptp(bows) > 0.05 * 0.505   # a visibly bending rod, not a rigid bar
    assert browser.errors() == []


def test_balancing_linkage_keeps_its_centre_of_mass_with_the_drawn_counterweights(pages, browser):
    """fourbar_forces_balanced: the Berkof-Lowen counterweights drawn on the page are where the
    force balance puts them: the centre of mass of the three links (deck masses at their deck
    centre-of-mass offsets, from the drawn pins) and the two drawn counterweights does not move
    over the turn (a shaking force of zero), and each counterweight keeps its radius from its
    pivot."""
    import driver
    from driver.fourbar._analysis_forces import counterweights
    params = driver.run(str(INPUTS / "fourbar_forces_balanced.dat")).params
    cw = counterweights(params)
    m, d, off = [0.5, 1.2, 0.9], [0.05, 0.175, 0.125], np.radians([0.0, 10.0, 0.0])
    g = 0.30
    browser.open(pages / "fourbar_forces_balanced.html")
    n = _frames(browser)

    def at(p0, p1, dist, angle):
        u = (p1 - p0) / np.hypot(*(p1 - p0))
        rot = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
        return p0 + dist * rot @ u

    coms = []
    for k in range(0, n, 10):
        _move(browser, k)
        p = _parts(browser)
        a, b = np.array(p["dots"]["A"]), np.array(p["dots"]["B"])
        o2, o4 = np.zeros(2), np.array([g, 0.0])
        c2 = np.array(next(v for name, v in p["dots"].items() if name.startswith("crank counterweight")))
        c4 = np.array(next(v for name, v in p["dots"].items() if name.startswith("rocker counterweight")))
        assert np.hypot(*c2) == pytest.approx(cw.radius[0], rel=1e-5)
        assert np.hypot(*(c4 - o4)) == pytest.approx(cw.radius[1], rel=1e-5)
        links = [at(o2, a, d[0], off[0]), at(a, b, d[1], off[1]), at(o4, b, d[2], off[2])]
        total = sum(mi * ri for mi, ri in zip(m, links)) + cw.mass[0] * c2 + cw.mass[1] * c4
        coms.append(total / (sum(m) + sum(cw.mass)))
    coms = np.array(coms)
    assert np.ptp(coms, axis=0).max() < 1e-5 * g   # the drawing's 7 digits; unbalanced it moves ~1e-2 g
    assert browser.errors() == []


def test_synthesis_targets_lie_on_the_drawn_coupler_path(pages, browser):
    """synthesis_path: the page draws the task's target points (squares) in the linkage's frame,
    and each lies on the coupler point's drawn path within the synthesis's structural error."""
    browser.open(pages / "synthesis_path.html")
    marks = browser.eval("""Array.from(document.querySelectorAll(".anim [data-role='mark']")).map(r =>
        [+r.getAttribute('x') + r.getAttribute('width') / 2, +r.getAttribute('y') + r.getAttribute('height') / 2])""")
    assert len(marks) == 5
    path = browser.eval("""Array.from(document.querySelectorAll(".anim [data-role='path']"))
        .filter(e => e.querySelector('title').textContent === 'path of P')
        .map(e => e.getAttribute('points').trim().split(/\\s+/).map(q => q.split(',').map(Number)))""")
    pts = np.vstack([np.array(seg) for seg in path])
    size = np.ptp(pts, axis=0).max()
    for x, y in marks:
        gap = np.min(np.hypot(pts[:, 0] - x, pts[:, 1] - y))
        assert gap < 0.02 * size, (x, y, gap, size)
    assert browser.errors() == []
