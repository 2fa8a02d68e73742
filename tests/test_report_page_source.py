"""The report page is built from templates with autoescaping, and its animation is generic
(no browser needed).

* No Python string of the package holds HTML or SVG markup (an element's tag): markup lives in
  ``driver/_report_page/templates/`` only.  A self-check shows the detector finds each form.
* What a deck or a run says (a title, a warning, a deck line) reaches the page escaped: a
  ``<script>`` in them stays text.
* The shared animation code (the frames' data class, the page's animation module, its template
  and script) names no mechanism: a study's frames are all it draws.
* A study's frames are checked when they are made: shapes, indices, labels, segments.
"""
from __future__ import annotations

import ast
import re
from pathlib import Path

import numpy as np
import pytest

from conftest import ROOT

PACKAGE = ROOT / "driver"
TEMPLATES = PACKAGE / "_report_page" / "templates"

#: an element's opening or closing tag, of the elements a page or an SVG drawing is made of
TAG = re.compile(r"<\s*/?\s*(html|head|body|main|header|nav|section|div|span|p|pre|table|thead|tbody|tr|td|th|ul|ol|li|"
                 r"a|details|summary|figure|figcaption|h[1-6]|meta|title|style|script|link|img|br|input|button|label|"
                 r"output|svg|g|line|circle|path|polyline|polygon|rect|text|use|defs)(\s|/|>|$)", re.IGNORECASE)
#: words that name a kind of mechanism or one of its parts
KINDS = re.compile(r"rocker|slider|crank|coupler|four.?bar|shaft|yoke|joint\b|manipulator|ujoint|piston|\barm\b",
                   re.IGNORECASE)


def _docstrings(tree: ast.AST) -> set[int]:
    """ids of the docstring nodes of ``tree``."""
    out = set()
    for node in ast.walk(tree):
        body = getattr(node, "body", None)
        if isinstance(body, list) and body and isinstance(body[0], ast.Expr) \
                and isinstance(body[0].value, ast.Constant) and isinstance(body[0].value.value, str):
            out.add(id(body[0].value))
    return out


def markup_in_strings(source: str) -> list[tuple[int, str]]:
    """(line, text) of every string literal (f-string parts included, docstrings not) of
    ``source`` that holds an HTML or SVG tag."""
    tree = ast.parse(source)
    skip = _docstrings(tree)
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in skip \
                and TAG.search(node.value):
            found.append((node.lineno, node.value[:60]))
    return found


def test_the_detector_finds_markup_in_every_form():
    assert markup_in_strings('x = "<td>" + v + "</td>"')
    assert markup_in_strings('x = f"<polyline points=\\"{d}\\" fill=\\"none\\"/>"')
    assert markup_in_strings("x = '</section>'")
    assert markup_in_strings('x = "<svg"')
    assert not markup_in_strings('"""A docstring may say <table> and <stem>.html."""\nx = "a < b, <stem>.out"')


def test_no_markup_is_built_in_python():
    """Every tag of the report page is in a template: no Python string of the package holds one."""
    found = {str(p.relative_to(ROOT)): hits for p in sorted(PACKAGE.rglob("*.py"))
             if (hits := markup_in_strings(p.read_text()))}
    assert found == {}


def test_the_page_is_rendered_with_autoescaping():
    """Text from a deck or a run cannot become markup: it is escaped wherever the page shows it."""
    from driver._report_page._blocks import KeyValues, Page, Pre, Section, Table, Text, Warnings
    from driver._report_page._render import environment, render_page
    assert environment().autoescape is True
    evil = "</pre><script>alert(1)</script><b onmouseover=x>"
    page = Page(evil, evil, [Section("s", evil, [Text(evil), Pre(evil), KeyValues([(evil, evil, evil)]),
                                                 Table([evil], [[evil]], evil), Warnings([evil])])],
                {"tool": evil, "date": evil})
    html = render_page(page)
    assert "<script>alert" not in html and "<b onmouseover" not in html
    assert html.count("&lt;script&gt;alert(1)&lt;/script&gt;") >= 10


def test_a_deck_title_reaches_the_page_as_text(tmp_path):
    """A run whose deck title holds markup: the page shows it as text (the figures' SVG escapes it too)."""
    import driver
    from driver._outcome import RunOutcome
    from driver._report_page import page
    r = driver.fourbar.run(fixed_link=12, crank=5, coupler=15, rocker=9, step_deg=30,
                           title="<script>alert('x')</script>")
    html = page(RunOutcome(result=r))
    assert "<script>alert" not in html and "&lt;script&gt;alert" in html


def _longest_run(text: str, ch: str) -> int:
    return max((len(m) for m in re.findall(f"{re.escape(ch)}+", text)), default=0)


def test_a_75_kB_title_and_name_are_bounded_on_the_page(tmp_path):
    """Issue 36 item 7: a 75 kB design name made a 10 MB page.  A deck's 75 000-character
    title and a run's 75 000-character name: the page's title, subtitle, captions, figures and
    notebook display show each at most NAME_CHARS characters (cut in the middle, saying how
    many were left out), every other line (the deck echo, the .out) at most LINE_CHARS; the page
    grows by less than 20 kB over the same run with a one-letter title."""
    import driver
    from driver._names import NAME_CHARS
    from driver._outcome import RunOutcome
    from driver._report_page import page
    from driver._report_page._render import LINE_CHARS
    base = dict(fixed_link=12.0, crank=5.0, coupler=15.0, rocker=9.0, step_deg=30)
    sizes = []
    for title in ("t", "t" * 75_000):
        deck = tmp_path / f"d{len(title)}.dat"
        deck.write_text(f"&fourbar fixed_link = 12, crank = 5, coupler = 15, rocker = 9, step_deg = 30, "
                        f"title = '{title}' /\n")
        r = driver.run(str(deck))
        html = page(RunOutcome(result=r), driver.read_deck(deck))
        sizes.append(len(html.encode()))
    head = html[: html.index("<main>")]
    assert _longest_run(head, "t") <= NAME_CHARS and "characters) ..." in head
    for svg in re.findall(r"<svg.*?</svg>", html, flags=re.S):
        assert _longest_run(svg, "t") <= NAME_CHARS
    assert _longest_run(html, "t") <= LINE_CHARS
    assert sizes[1] - sizes[0] < 20_000, sizes
    # a name given in Python: the notebook's display of the run
    small = driver.run({"fourbar": base}, name="n")._repr_html_()
    big = driver.run({"fourbar": base}, name="n" * 75_000)._repr_html_()
    assert _longest_run(big, "n") <= LINE_CHARS and len(big) - len(small) < 20_000
    heads = re.findall(r"<(?:h[1-6]|figcaption|summary)[^>]*>(.*?)</", big, flags=re.S)
    assert heads and all(_longest_run(h, "n") <= NAME_CHARS for h in heads)
    assert all(len(i) <= 60 for i in re.findall(r'id="(anim-[^"]*)"', big))


def _code(path: Path) -> str:
    """The code of a Python file without its docstrings and comments."""
    tree = ast.parse(path.read_text())
    for node in ast.walk(tree):
        body = getattr(node, "body", None)
        if isinstance(body, list) and body and isinstance(body[0], ast.Expr) \
                and isinstance(body[0].value, ast.Constant) and isinstance(body[0].value.value, str):
            body[0].value.value = ""
    return ast.unparse(tree)


def test_the_shared_animation_names_no_mechanism():
    """The frames' data class and the page's animation (module, template, script) know points,
    links, guides and paths, not four-bars, slider-cranks, shaft chains or arms."""
    texts = {"driver/_mechanism.py": _code(PACKAGE / "_mechanism.py"),
             "driver/_report_page/_animation.py": _code(PACKAGE / "_report_page" / "_animation.py"),
             "templates/animation.html.j2": (TEMPLATES / "animation.html.j2").read_text(),
             "templates/animation.js": (TEMPLATES / "animation.js").read_text()}
    for name, text in texts.items():
        assert not KINDS.search(text), (name, KINDS.search(text))
    assert KINDS.search(_code(PACKAGE / "fourbar" / "_report.py"))   # the detector reads the studies' words


def test_the_animation_hook_is_declared_by_the_studies_with_a_mechanism():
    from driver._mechanism import MechanismFrames
    from driver._study import registered
    have = {name for name, s in registered().items() if s.animation is not None}
    assert have == {"fourbar", "slidercrank", "ujoint", "manipulator", "linkage"}
    import driver
    r = driver.run(str(ROOT / "inputs" / "crank5.dat"))
    frames = registered()["fourbar"].animation(r.params, r, 36)
    assert isinstance(frames, MechanismFrames) and frames.n_frames == 36


def test_frames_are_checked_when_made():
    from driver._mechanism import Guide, Link, MechanismFrames
    pts = np.zeros((3, 2, 2))
    pts[:, 1] = [[1, 0], [0, 1], [-1, 0]]
    ok = MechanismFrames(("O", "A"), pts, (Link("bar", (0, 1)),), ("0", "1", "2"), ground=(0,), paths=(1,))
    assert ok.valid.all() and ok.runs() == [(0, 3)] and ok.closed_paths()
    with pytest.raises(ValueError, match="n_frames, n_points, 2"):
        MechanismFrames(("O", "A"), np.zeros((3, 2)), (), ("0", "1", "2"))
    with pytest.raises(ValueError, match="one per frame"):
        MechanismFrames(("O", "A"), pts, (), ("0", "1"))
    with pytest.raises(ValueError, match="point index"):
        MechanismFrames(("O", "A"), pts, (Link("bar", (0, 2)),), ("0", "1", "2"))
    with pytest.raises(ValueError, match="at least two points"):
        Link("bar", (0,))
    with pytest.raises(ValueError, match="segments"):
        MechanismFrames(("O", "A"), pts, (), ("0", "1", "2"), segments=((0, 2),))
    with pytest.raises(ValueError, match="finite"):
        Guide(np.array([[0.0, 0.0], [np.nan, 1.0]]), "guide")
    gone = pts.copy()
    gone[1, 1] = np.nan      # a frame where A does not exist: paths stop there, and do not close
    frames = MechanismFrames(("O", "A"), gone, (Link("bar", (0, 1)),), ("0", "1", "2"), paths=(1,))
    assert frames.valid.tolist() == [True, False, True] and frames.runs() == [] and not frames.closed_paths()
    with pytest.raises(ValueError, match="fixed pivot"):
        MechanismFrames(("O", "A"), gone, (), ("0", "1", "2"), ground=(1,))
