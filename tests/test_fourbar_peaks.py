"""Peak coupler and rocker speeds of the batch summary (fortran/fourbar_summary.f90 ``peaks``)
against a dense brute-force oracle, and the kernel's passes.

The oracle is written apart from the kernel: the loop closed by intersecting the coupler and
rocker circles, the angular velocities from the two velocity equations (dotted with the rocker
and the coupler directions), evaluated with numpy on a grid of 0.002 deg over the whole crank
range.  The kernel scans coarsely (6 deg) and refines to 1 deg (and below) only where its test
says an extremum may hide, and finds each root of the acceleration by Newton steps; it must
never report a peak below the oracle's largest sampled speed (a missed extremum), and what it
reports must be the oracle's speed at the reported crank angle.
Linkages are drawn by hypothesis: any proportions, and near-toggle ones (coupler and rocker
lengths within a relative 1e-10..1e-2 of a toggle), with the transmission angle kept at least
1e-4 deg from 0 and 180 deg (closer, a toggle hides in the rounding of the closed-form count).
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from driver import fourbar
from driver.fourbar import _kernel as fourbar_kernel

PASSES = fourbar_kernel.FOURBAR_PASSES
ALL = PASSES["transmission"] | PASSES["rocker"] | PASSES["peaks"]
DENSE = ALL | PASSES["dense_scan"]       # the previous search: every 1 deg grid point


def oracle_speeds(p: float, q: float, r: float, s: float, theta: np.ndarray, branch: int
                  ) -> tuple[np.ndarray, np.ndarray]:
    """Coupler and rocker angular velocity [rad/s] at unit crank speed, crank angles theta [rad]."""
    ax, ay = q * np.cos(theta), q * np.sin(theta)
    dx, dy = p - ax, -ay
    d = np.hypot(dx, dy)
    a = (r * r - s * s + d * d) / (2 * d)
    h = np.sqrt(np.maximum(r * r - a * a, 0.0))
    bx = ax + a * dx / d - branch * h * dy / d
    by = ay + a * dy / d + branch * h * dx / d
    t3 = np.arctan2(by - ay, bx - ax)
    t4 = np.arctan2(by, bx - p)
    # q w2 e2' + r w3 e3' = s w4 e4' (e' the unit normal): dotted with e4 and with e3
    with np.errstate(divide="ignore", invalid="ignore"):
        w3 = -q * np.sin(t4 - theta) / (r * np.sin(t4 - t3))
        w4 = q * np.sin(t3 - theta) / (s * np.sin(t3 - t4))
    return w3, w4


def summary(p, q, r, s, lo, hi, branch, passes=ALL) -> np.ndarray:
    return fourbar_kernel.fourbar_summaries(np.array([[p, q, r, s, 1.0, lo, hi, branch]]), passes)[0]


def check_peaks(p, q, r, s, lo, hi, branch) -> None:
    row = summary(p, q, r, s, lo, hi, branch)
    assume(row[1] == 1 and row[2] >= 1.0 and row[13] == 0)   # assembled throughout, no toggle: peaks exist
    # a transmission angle of 0 or 180 deg within rounding is a toggle the closed-form count may
    # miss (the speeds are 0/0 there): near-toggle means down to 1e-4 deg
    assume(row[3] > 1e-4 and row[5] < 180.0 - 1e-4)
    theta = np.radians(np.linspace(lo, hi, max(2, int((hi - lo) / 0.002) + 1)))
    w_coupler, w_rocker = oracle_speeds(p, q, r, s, theta, branch)
    assume(np.isfinite(w_coupler).all() and np.isfinite(w_rocker).all())
    for w, col in ((w_rocker, 14), (w_coupler, 16)):
        dense = np.abs(w).max()
        peak, at = row[col], row[col + 1]
        assert abs(peak) >= dense * (1 - 1e-7) - 1e-9 * max(1.0, q / r, q / s), (
            f"missed extremum: kernel |peak| {abs(peak)!r} < oracle {dense!r} (column {col})")
        wk = oracle_speeds(p, q, r, s, np.radians([at]), branch)[0 if col == 16 else 1][0]
        assert peak == pytest.approx(wk, rel=1e-6, abs=1e-9), f"peak {peak} at {at} deg, oracle there {wk}"


lengths = st.floats(0.3, 10.0)


@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(p=lengths, q=lengths, r=lengths, s=lengths, lo=st.floats(-360.0, 360.0), span=st.floats(1.0, 360.0),
       branch=st.sampled_from([1, -1]), full=st.booleans())
def test_peaks_never_below_dense_oracle(p, q, r, s, lo, span, branch, full):
    if full:
        lo, span = 0.0, 360.0
    check_peaks(p, q, r, s, lo, lo + span, branch)


@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(q=st.floats(0.5, 3.0), extra=st.floats(0.5, 9.0), log_eps=st.floats(-10.0, -2.0), share=st.floats(0.2, 0.8),
       outer=st.booleans(), branch=st.sampled_from([1, -1]))
def test_peaks_near_toggle(q, extra, log_eps, share, outer, branch):
    """Crank-rockers whose coupler and rocker come within eps of collinear (p + q = (r + s)(1 - eps),
    or |r - s| = (p - q)(1 - eps)): the transmission angle nearly 0 or 180 deg, sharp peaks."""
    p, eps = q + extra, 10.0 ** log_eps
    if outer:
        total = (p + q) / (1 - eps)
        r, s = share * total, (1 - share) * total
    else:
        gap = (p - q) * (1 - eps)
        r = gap + 0.1 + 10 * share
        s = r - gap
    check_peaks(p, q, r, s, 0.0, 360.0, branch)


def test_refined_scan_finds_a_peak_the_1deg_scan_missed():
    """A crossed linkage whose transmission angle comes within 3.4e-4 deg of 0 at 360 deg, over
    [113.3, 400.3] deg: the coupler's peak (-1.3717 rad/s at 359.815 deg) is a spike narrower
    than 1 deg.  The previous 1 deg scan reported 0.547 rad/s at the range's end; the refined
    scan finds the spike (the oracle's dense maximum)."""
    p, q, r, s = 9.007532785525626, 2.5943456204226627, 9.920232906457937, 16.333420071126117
    lo, hi = 113.29737213558315, 400.3473357989953
    theta = np.radians(np.linspace(lo, hi, 500001))
    w = oracle_speeds(p, q, r, s, theta, -1)[0]
    new, old = summary(p, q, r, s, lo, hi, -1), summary(p, q, r, s, lo, hi, -1, DENSE)
    assert new[3] < 1e-3 and new[13] == 0
    assert new[16] == pytest.approx(w[np.abs(w).argmax()], rel=1e-7) == pytest.approx(-1.37172, abs=1e-5)
    assert new[17] == pytest.approx(359.8147, abs=1e-3)
    assert old[16] == pytest.approx(0.547094, abs=1e-6)     # what the 1 deg scan reported


@pytest.fixture(scope="module")
def shipped() -> np.ndarray:
    """The parameter rows of the shipped design search (inputs/fourbar_design_search.dat)."""
    c, k, r = np.meshgrid(np.linspace(1, 7, 25), np.linspace(6, 20, 64), np.linspace(4, 16, 64), indexing="ij")
    m = np.empty((c.size, 8), order="F")
    m[:, 0], m[:, 1], m[:, 2], m[:, 3], m[:, 4], m[:, 5], m[:, 6], m[:, 7] = 12, c.ravel(), k.ravel(), r.ravel(), 5, 0, 360, 1
    return m


def test_shipped_search_peaks_as_the_1deg_scan_except_near_toggle(shipped):
    """On the 102 400 shipped linkages the refined search gives the 1 deg scan's peaks wherever
    that scan found the extremum: the same speeds to 1e-11 relative (the roots are Newton's from
    the scan's own brackets or from 6 deg ones, so not the same last bits) and the same crank
    angles to 1e-8 deg (roots to about 1e-12 rad); every other column the same bits.  The only
    larger differences are 5 linkages whose transmission angle touches 0 deg at the range's end
    (toggle at 0/360 deg within rounding), where the 1 deg scan reported 0 (no extremum found)
    and the refined one a peak by the toggle -- none passes the deck's filter."""
    new = fourbar_kernel.fourbar_summaries(shipped, ALL)
    old = fourbar_kernel.fourbar_summaries(shipped, DENSE)
    assert np.array_equal(new[:, :14], old[:, :14]) and np.array_equal(new[:, 18], old[:, 18])
    speed, at = new[:, [14, 16]], new[:, [15, 17]]
    far = (np.abs(speed - old[:, [14, 16]]) > 1e-11 * np.abs(old[:, [14, 16]])) | (np.abs(at - old[:, [15, 17]]) > 1e-8)
    differ = np.flatnonzero(far.any(axis=1))
    assert differ.tolist() == [19470, 49400, 51271, 52835, 85027]
    assert (new[differ, 3] < 1e-5).all() and (np.abs(new[differ, 14]) > np.abs(old[differ, 14])).all()
    assert (speed != old[:, [14, 16]]).any()   # (the comparison is not of one computation with itself)


def test_shipped_search_peaks_against_the_oracle(shipped):
    """Every 16th shipped linkage (6 400) against the oracle written apart from the kernel: no
    reported peak below the oracle's largest speed on a 0.25 deg grid (a missed extremum), and each
    reported peak the oracle's speed at the reported crank angle (crank speed 5 rad/s)."""
    rows = shipped[::16]
    res = fourbar_kernel.fourbar_summaries(rows, ALL)
    has = (res[:, 1] == 1) & (res[:, 2] >= 1.0) & (res[:, 13] == 0) & (res[:, 3] > 1e-4) & (res[:, 5] < 180.0 - 1e-4)
    assert has.sum() > 3000
    p, q, r, s = (rows[has, j][:, None] for j in range(4))
    omega = rows[has, 4]
    theta = np.radians(np.linspace(0.0, 360.0, 1441))[None, :]
    w_coupler, w_rocker = oracle_speeds(p, q, r, s, theta, 1)
    for w, col, which in ((w_rocker, 14, 1), (w_coupler, 16, 0)):
        peak, at = res[has, col], res[has, col + 1]
        assert (np.abs(peak) >= omega * np.abs(w).max(axis=1) * (1 - 1e-9)).all()
        there = omega * oracle_speeds(p, q, r, s, np.radians(at)[:, None], 1)[which][:, 0]
        np.testing.assert_allclose(peak, there, rtol=1e-9, atol=1e-12)


def test_passes_compute_only_their_columns_with_the_same_bits(shipped):
    """Each pass alone gives its columns with the bits of all passes together; the columns of a
    pass not asked for are 0 (not computed)."""
    rows = shipped[::7]
    rng = np.random.default_rng(3)
    other = np.asfortranarray(np.column_stack([rng.uniform(0.3, 10, (4000, 4)), rng.uniform(-5, 5, 4000),
                                               rng.uniform(-400, 400, 4000), rng.uniform(-400, 400, 4000),
                                               rng.choice([1.0, -1.0], 4000)]))
    always = [0, 1, 2, 13]
    cols = {PASSES["transmission"]: [3, 4, 5, 6], PASSES["rocker"]: [7, 8, 9, 10, 11, 12, 18],
            PASSES["peaks"]: [14, 15, 16, 17]}
    for params in (rows, other):
        full = fourbar_kernel.fourbar_summaries(params, ALL)
        for bits in range(8):
            res = fourbar_kernel.fourbar_summaries(params, bits)
            mine = always + [c for b, cs in cols.items() if bits & b for c in cs]
            rest = [c for c in range(19) if c not in mine]
            assert np.array_equal(res[:, mine], full[:, mine]), bits
            assert not res[:, rest].any(), bits


def test_summarise_batch_wanted_columns(shipped):
    base = {"fixed_link": 12.0, "crank": 3.0, "coupler": 15.0, "rocker": 9.0, "omega": 5.0, "start_deg": 0.0,
            "stop_deg": 360.0, "branch": "open"}
    cols = {"crank": shipped[:3000, 1], "coupler": shipped[:3000, 2], "rocker": shipped[:3000, 3]}
    full = fourbar.summarise_batch(base, cols, detail=True)
    assert set(full.columns) == {c for c, p in fourbar.BATCH_PASSES.items() if p != ("forces",)}
    for wanted in (["mu_min_deg"], ["rocker_swing_deg", "meets_transmission_band"], ["coupler_omega_peak_at_deg"], []):
        part = fourbar.summarise_batch(base, cols, wanted=wanted)
        assert list(part.columns) == [c for c in full.columns if c in wanted] and len(part) == 3000
        for c in wanted:
            assert part[c].equals(full[c]), c
