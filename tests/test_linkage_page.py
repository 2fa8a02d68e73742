"""The report page of every shipped ``&linkage`` deck, in headless Chromium (Selenium, tests/browser.py):
it renders without an error, animates the mechanism, and what it draws at a frame is the
mechanism of the deck, checked against geometry the page cannot fake:

* the crank: its pin at the crank's length from its pivot, at the frame's crank angle (the label);
* every drawn link is rigid: the distances between its drawn points are the same at every frame,
  and an RRR group's links have the deck's lengths between their joints;
* a block on a ground guide: its pin at the deck's offset from the guide's line (the line through
  the deck's guide point at the deck's angle), the block a rectangle along that line around the pin;
* a block in a slot (RPR): the pin at the deck's offset from the drawn slot, the slot at the deck's
  offset from the lever's pivot.

The page's parts are read from its SVG (their names from the mechanism's frames, their positions
from the page).  Skipped without Chromium, as tests/test_report_page.py is (CI requires it).
"""
from __future__ import annotations

import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))
from conftest import INPUTS, ROOT

pytest.importorskip("matplotlib")

from driver._deck import read_deck
from driver._runner import study_of
from driver.linkage._analysis_frames import animation_frames
from driver.linkage._spec_model import compile_deck

DECKS = sorted(p.stem for p in INPUTS.glob("linkage_*.dat"))
REL = 1e-5   # the page keeps seven significant digits of the drawing's size


@pytest.fixture(scope="module")
def pages(tmp_path_factory):
    out = tmp_path_factory.mktemp("linkage_pages")
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.run([sys.executable, "-m", "driver", *(str(INPUTS / f"{d}.dat") for d in DECKS), "--report",
                           "-q", "-o", str(out)], capture_output=True, text=True, env=env, timeout=900)
    assert proc.returncode == 0, proc.stderr
    return out


def _links(browser) -> dict[str, np.ndarray]:
    """Every drawn link's points (by the link's name), as the page shows them now."""
    got = browser.eval("""(() => { const out = {};
        document.querySelectorAll('.anim [data-link]').forEach(e => { out[e.getAttribute('data-link')] =
            e.tagName === 'line' ? [[+e.getAttribute('x1'), +e.getAttribute('y1')],
                                    [+e.getAttribute('x2'), +e.getAttribute('y2')]]
                                 : e.getAttribute('points').trim().split(/\\s+/).map(p => p.split(',').map(Number)); });
        return {links: out, label: document.querySelector('.anim output').textContent}; })()""")
    return {k: np.array(v, dtype=float) for k, v in got["links"].items()} | {"": got["label"]}


def _move(browser, k: int) -> None:
    browser.eval(f"""(() => {{ const s = document.querySelector('.anim input[type=range]');
        s.value = {k}; s.dispatchEvent(new Event('input')); }})()""")


def _dist_to_line(p: np.ndarray, a: np.ndarray, u: np.ndarray) -> float:
    """Signed distance of p from the line through a along the unit vector u (left +)."""
    return float(u[0] * (p[1] - a[1]) - u[1] * (p[0] - a[0]))


def _drawn_params(deck, summary: Path, browser):
    """The parameters the page draws: the deck's; for a sweep, its marked case's (the case the
    page names, its swept values -- elements of lists too -- read from the summary table the
    sweep wrote and put into the deck's group by hand)."""
    if "sweep" not in deck.groups:
        return study_of(deck)[1]
    import re

    import pandas as pd

    from driver._deck import validate
    from driver.linkage import SPEC
    case = int(re.search(r"Case (\d+),", browser.eval("document.body.textContent")).group(1))
    row = pd.read_csv(summary).set_index("case").loc[case]
    raw = deck.groups["linkage"]
    values = dict(raw.values)
    for col, value in row.items():
        m = re.fullmatch(r"linkage\.(\w+)(?:\((\d+)\))?", str(col))
        if m is None:
            continue
        if m.group(2) is None:
            values[m.group(1)] = float(value)
        else:
            items = list(values[m.group(1)])
            items[int(m.group(2)) - 1] = float(value)
            values[m.group(1)] = items
    return validate(type(raw)(raw.name, values, raw.lines, raw.line), SPEC, deck.path)


@pytest.mark.parametrize("stem", DECKS)
def test_page_animates_the_deck_mechanism(pages, browser, stem):
    path = INPUTS / f"{stem}.dat"
    browser.open(pages / f"{stem}.html")
    assert browser.errors() == []
    params = _drawn_params(read_deck(path), pages / f"{stem}_summary.csv", browser)
    mech = compile_deck(params)
    fr = animation_frames(params, None)          # the parts' names and which points each joins
    parts = {link.name: [fr.names[i] for i in link.points] for link in fr.links}
    assert browser.eval("document.querySelectorAll('svg.mech').length") == 1
    n = int(browser.eval("document.querySelector('.anim input[type=range]').max")) + 1
    assert n == fr.n_frames
    crank_pivot = mech.point_names[mech.driver_anchor - 1]
    guides = {g[0]: g for g in mech.guides}
    seen: list[dict] = []
    for k in range(0, n, 11):
        _move(browser, k)
        drawn = _links(browser)
        pos: dict[str, np.ndarray] = {}
        for name, names in parts.items():
            assert name in drawn, (name, sorted(drawn))
            assert len(drawn[name]) == len(names)
            for q, xy in zip(names, drawn[name]):
                if q in pos:   # a joint drawn by two links is one point
                    assert np.allclose(pos[q], xy, atol=REL * 1e-2)
                pos[q] = xy
        # the crank at its length and at the frame's angle
        theta = params.start + 360.0 * k / n
        assert drawn[""] == f"{theta:g}\u00b0"
        a = pos[mech.driver_pin] - pos[crank_pivot]
        assert math.isclose(np.hypot(*a), mech.driver_length, rel_tol=REL)
        assert math.cos(math.atan2(a[1], a[0]) - math.radians(theta)) == pytest.approx(1.0, abs=1e-9)
        for d in mech.dyads:
            a1, a2, j3 = d.joints
            if d.kind == "rrr":   # the deck's link lengths between the group's joints
                assert math.isclose(np.hypot(*(pos[j3] - pos[a1])), d.dims[0], rel_tol=REL)
                assert math.isclose(np.hypot(*(pos[j3] - pos[a2])), d.dims[1], rel_tol=REL)
            elif d.kind in ("rrp", "prr"):   # the rod's length; the pin at its offset from the ground guide
                pivot, gname = (a1, a2) if d.kind == "rrp" else (a2, a1)
                rod, offset = (d.dims[0], d.dims[1]) if d.kind == "rrp" else (d.dims[1], d.dims[0])
                assert math.isclose(np.hypot(*(pos[j3] - pos[pivot])), rod, rel_tol=REL)
                _, glink, gx, gy, ga = guides[gname]
                assert glink == 1
                u = np.array([math.cos(ga), math.sin(ga)])
                size = max(abs(rod), 1.0)
                assert _dist_to_line(pos[j3], np.array([gx, gy]), u) == pytest.approx(offset, abs=REL * size)
                block = drawn[d.links[1] if d.kind == "rrp" else d.links[0]]
                edges = np.diff(np.vstack([block, block[:1]]), axis=0)
                along = edges @ u
                across = edges @ np.array([-u[1], u[0]])
                assert np.allclose(np.minimum(abs(along), abs(across)), 0.0, atol=REL * size)   # a rectangle on u
                c = block.mean(axis=0)
                assert (c - pos[j3]) @ u == pytest.approx(0.0, abs=REL * size)   # around the pin
            elif d.kind == "rpr":   # the pin at its offset from the drawn slot, the slot at its offset from the pivot
                slot = drawn[f"guide {j3} on {d.links[0]}"]
                u = (slot[1] - slot[0]) / np.hypot(*(slot[1] - slot[0]))
                assert abs(_dist_to_line(pos[a2], slot[0], u)) == pytest.approx(abs(d.dims[1]), abs=REL)
                assert abs(_dist_to_line(pos[a1], slot[0], u)) == pytest.approx(abs(d.dims[0]), abs=REL)
        seen.append(pos)
    # every drawn part is rigid (links, blocks, slots): the distances between its points never change
    for name, names in parts.items():
        for i in range(len(names)):
            for j in range(i + 1, len(names)):
                ds = [np.hypot(*(s[names[i]] - s[names[j]])) for s in seen]
                assert max(ds) - min(ds) <= REL * max(max(ds), 1e-300) * 10, (name, names[i], names[j])
    # the mechanism moves
    assert len({tuple(np.round(s[mech.driver_pin], 9)) for s in seen}) == len(seen)
