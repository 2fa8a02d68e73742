"""A crank that cannot turn rocks between its limit positions (issue 28): the assembly intervals
from the closed form, the motions out on one assembly branch and back on the other, and the
drawing and animation that show them.

Truth: the closed form of the assembly limits, (r - s)^2 <= |A O_B|^2 = p^2 + q^2 - 2 p q cos(theta)
<= (r + s)^2 (p ground, q crank, r coupler, s rocker), and at a limit B on the line A-O_B
(coupler and rocker in line).  The kernel is asked only for positions; the tests check them by
loop closure and collinearity, not by the code that orders them.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import driver
from conftest import INPUTS
from driver import fourbar
from driver.fourbar import _kernel as fourbar_kernel

OK = fourbar_kernel.FOURBAR_STATUS["ok"]
NO = fourbar_kernel.FOURBAR_STATUS["no_assembly"]


def _closed_form_limit(p: float, q: float, d: float) -> float | None:
    """Crank angle [deg, 0..180] where |A O_B| = d, or None when no crank angle gives it."""
    c = (p * p + q * q - d * d) / (2 * p * q)
    return math.degrees(math.acos(c)) if -1.0 <= c <= 1.0 else None


LINKAGES = [  # (ground, crank, coupler, rocker), Grashof class
    ((10, 6, 7, 8), "non-Grashof triple-rocker"),
    ((8, 6, 2, 7), "Grashof double-rocker"),
    ((8, 7, 6, 2), "rocker-crank"),
    ((10, 2, 7, 8), "crank-rocker"),          # turns: no motions
    ((3, 9, 5, 4), "non-Grashof triple-rocker"),   # rocks through 180 deg
]


@pytest.mark.parametrize("lengths, name", LINKAGES)
def test_assembly_intervals_are_the_closed_form_limits(lengths, name):
    p, q, r, s = lengths
    g = fourbar.grashof(*lengths)
    assert g.name == name
    spans = fourbar.assembly_intervals(*lengths)
    if g.full_crank_rotation:
        assert spans is None
        return
    ext, fold = _closed_form_limit(p, q, r + s), _closed_form_limit(p, q, abs(r - s))
    ends = sorted(abs(x) % 360 for lo_hi in spans for x in lo_hi)
    want = sorted([a for a in (ext, fold) if a is not None] + [360 - a for a in (ext, fold) if a is not None])
    assert np.allclose(sorted(min(e, 360 - e) for e in ends), sorted(min(w, 360 - w) for w in want), atol=1e-9)
    # the kernel assembles inside every interval and nowhere else
    theta = np.linspace(-360.0, 360.0, 14401)
    inside = np.zeros_like(theta, dtype=bool)
    for lo, hi in spans:
        for k in (-1, 0, 1):
            inside |= (theta > lo + 360 * k + 1e-6) & (theta < hi + 360 * k - 1e-6)
    near = np.zeros_like(inside)
    for lo, hi in spans:
        for k in (-1, 0, 1):
            near |= (np.abs(theta - lo - 360 * k) < 1e-6) | (np.abs(theta - hi - 360 * k) < 1e-6)
    _, st = fourbar_kernel.fourbar_exact(np.radians(theta), p, q, r, s, 1.0)
    assert np.all((st[~near] != NO) == inside[~near])
    if len(spans) == 2:   # a Grashof double-rocker or rocker-crank: mirror images about the ground line
        (a, b), (c, d) = spans
        assert c == pytest.approx(360 - b) and d == pytest.approx(360 - a)


@pytest.mark.parametrize("lengths", [(10, 6, 7, 8), (8, 6, 2, 7), (8, 7, 6, 2), (3, 9, 5, 4)])
@pytest.mark.parametrize("branch", ["open", "crossed"])
def test_a_rocking_crank_reverses_at_the_limit_and_changes_branch(lengths, branch):
    params = driver.fourbar.run(fixed_link=lengths[0], crank=lengths[1], coupler=lengths[2], rocker=lengths[3],
                                step_deg=30, branch=branch).params
    p, q, c, s = params.fixed_link, params.crank, params.coupler, params.rocker
    motions = fourbar.rocking_motions(params)
    assert motions and len(motions) == len(fourbar.assembly_intervals(p, q, c, s))
    first = 1 if branch == "open" else -1
    for m in motions:
        n = len(m.theta) // 2
        fwd, back = m.theta[:n], m.theta[n:]
        assert np.all(np.diff(fwd) > 0) and np.all(np.diff(back) < 0)   # out, then back
        assert fwd[0] == pytest.approx(m.lo, abs=1e-4) and fwd[-1] == pytest.approx(m.hi, abs=1e-4)
        assert np.all(m.status == OK)
        A, B = m.out[:, 3:5], m.out[:, 5:7]
        # the crank pin where the crank angle says, every link at its length (loop closure)
        assert np.allclose(A, q * np.column_stack([np.cos(np.radians(m.theta)), np.sin(np.radians(m.theta))]))
        assert np.allclose(np.hypot(*(B - A).T), c, rtol=1e-9)
        assert np.allclose(np.hypot(B[:, 0] - p, B[:, 1]), s, rtol=1e-9)
        # the branch: B left (open) or right (crossed) of the line A -> O_B, out on the deck's, back on the other
        side = np.sign((p - A[:, 0]) * (B[:, 1] - A[:, 1]) - (0 - A[:, 1]) * (B[:, 0] - A[:, 0]))
        interior = np.abs(np.sin(m.out[:, 2])) > 1e-3
        assert np.all(side[:n][interior[:n]] == first) and np.all(side[n:][interior[n:]] == -first)
        assert list(m.branch[:n]) == [first] * n and list(m.branch[n:]) == [-first] * n
        # at each limit the two strokes meet: coupler and rocker in line, |A O_B| = r + s or |r - s|
        for k in (0, n - 1):
            d = math.hypot(p - A[k, 0], A[k, 1])
            assert min(abs(d - (c + s)), abs(d - abs(c - s))) < 1e-6 * p
            u, v = B[k] - A[k], np.array([p, 0.0]) - A[k]
            assert abs(u[0] * v[1] - u[1] * v[0]) < 1e-3 * c * d
        assert np.hypot(*(B[n - 1] - B[n])) < 1e-2 * c   # continuous through the reversal
        assert np.hypot(*(B[-1] - B[0])) < 1e-2 * c       # and the cycle closes


def test_a_turning_crank_has_no_rocking_motion():
    assert fourbar.rocking_motions(driver.run(str(INPUTS / "crank5.dat")).params) is None


@pytest.mark.parametrize("deck", ["nongrashof", "doublerocker"])
def test_the_drawing_rocks_between_the_marked_limit_positions(deck):
    pytest.importorskip("matplotlib")
    r = driver.run(str(INPUTS / f"{deck}.dat"))
    p = r.params
    fig = r.figure("linkage")
    ax = fig.axes[0]
    spans = fourbar.assembly_intervals(p.fixed_link, p.crank, p.coupler, p.rocker)
    limit_lines = [ln for ln in ax.lines if ln.get_linestyle() == "--" and ln.get_color() == "k"]
    assert len(limit_lines) == 2 * len(spans)
    want = sorted(a for lo_hi in spans for a in lo_hi)
    got = []
    for ln in limit_lines:   # O2 -> A -> B -> O4, A at the closed-form limit angle on the crank circle
        x, y = ln.get_data()
        assert (x[0], y[0]) == (0.0, 0.0) and (x[-1], y[-1]) == (p.fixed_link, 0.0)
        assert math.hypot(x[1], y[1]) == pytest.approx(p.crank)
        got.append(math.degrees(math.atan2(y[1], x[1])))
    assert np.allclose(sorted(np.mod(got, 360)), sorted(np.mod(want, 360)), atol=1e-4)
    labels = [t.get_text() for t in ax.texts]
    for a in want:
        assert any(f"{a:.1f}°" in t and t.startswith("limit") for t in labels)
    # the crank pin's path is an arc per motion, never the full circle
    arcs = [ln for ln in ax.lines if ln.get_label().startswith("path of A") or
            (ln.get_color() == "0.55" and ln.get_linestyle() == "-")]
    assert len(arcs) == len(spans)
    for ln, (lo, hi) in zip(arcs, spans):
        ang = np.degrees(np.unwrap(np.arctan2(*ln.get_data()[::-1])))
        assert np.ptp(ang) == pytest.approx(hi - lo, abs=1e-3) and np.ptp(ang) < 359.0
    # both strokes drawn: B's path out (solid) and back (dashed)
    b_paths = [ln for ln in ax.lines if ln.get_color() == "C3"]
    assert {ln.get_linestyle() for ln in b_paths} == {"-", "--"}
    title = fig.get_suptitle()   # the figure's title (the legend has its own panel beside the drawing)
    assert "limit positions" in title and ("separate motions" in title) == (len(spans) > 1)
    assert "/" not in title and ".dat" not in title
