"""Batched four-bar summaries (fortran/fourbar_summary.f90) against independent truth.

* a brute-force oracle: the exact state kernel on a 0.01 deg grid (limit angles inserted),
  transmission angle from |A O_B| in closed form, rocker angle unwrapped along each placed
  run of the grid, speed peaks as the grid maximum -- no candidate points, no refinement;
* the single-case summary (``summarise``, what a run prints) equals the batch row for every
  column, for random linkages of every Grashof class, both branches, partial ranges,
  toggle and non-assemblable ones (hypothesis);
* Grashof class against the Python rule, input errors named by key.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from driver._deck import DeckError, Params
from driver.fourbar import SPEC, grashof, limit_angles, summarise, summarise_batch
from driver.fourbar import _kernel as fourbar_kernel

OK, TOG = fourbar_kernel.FOURBAR_STATUS["ok"], fourbar_kernel.FOURBAR_STATUS["toggle"]


def params(**kw) -> Params:
    """A validated-looking &fourbar Params (defaults of the SPEC, lengths from kw)."""
    vals = {k: spec.default for k, spec in SPEC.keys.items()}
    vals.update(kw)
    return Params("fourbar", Path("test.dat"), vals, {}, 1)


def oracle(p, q, r, s, lo=0.0, hi=360.0, branch=1, omega=1.0, step=0.01):
    """Brute-force summary on a fine grid (test oracle only)."""
    lims = [a + 360.0 * k for a in limit_angles(p, q, r, s) for k in range(-2, 3)]
    grid = np.unique(np.concatenate([np.arange(lo, hi, step), [hi], [t for t in lims if lo <= t <= hi]]))
    out, stt = fourbar_kernel.fourbar_exact(np.radians(grid), p, q, r, s, omega, 0.0, branch)
    placed = (stt == OK) | (stt == TOG)
    d = np.hypot(p - q * np.cos(np.radians(grid)), q * np.sin(np.radians(grid)))
    eps = 1e-9 * (p + q + r + s)   # the limit angles themselves are assemblable (rounded in limit_angles)
    dplaced = (d >= abs(r - s) - eps) & (d <= r + s + eps)
    d = np.clip(d, abs(r - s), r + s)
    mu = np.degrees(np.arccos(np.clip((r * r + s * s - d * d) / (2 * r * s), -1, 1)))
    res = {"assemblable": placed.any()}
    if not placed.any():
        return res
    res["mu_min_deg"], res["mu_max_deg"] = mu[dplaced].min(), mu[dplaced].max()
    # placed runs of the grid; rocker unwrapped along each (a full turn joins its last and first run)
    idx = np.flatnonzero(placed)
    runs = np.split(idx, np.flatnonzero(np.diff(idx) > 1) + 1)
    if len(runs) > 1 and hi - lo == 360.0 and placed[0] and placed[-1]:
        runs = [np.concatenate([runs[-1], runs[0]])] + runs[1:-1]
    res["runs"] = len(runs)
    u = np.unwrap(out[runs[0], 1])
    res["rocker_swing_deg"] = math.degrees(u.max() - u.min())
    res["rocker_min_deg"] = math.degrees(u.min()) % 360.0
    res["rocker_max_deg"] = math.degrees(u.max()) % 360.0
    ok = stt == OK
    if ok.all():
        for name, col in (("rocker_omega_peak_rad_s", 8), ("coupler_omega_peak_rad_s", 7)):
            k = np.argmax(np.abs(out[:, col]))
            res[name] = out[k, col]
        if hi - lo == 360.0 and res["rocker_swing_deg"] < 359.0:
            # crank angles of the rocker's extremes on the grid: the strokes' shares of the turn
            turn = (grid[runs[0][np.argmax(u)]] - grid[runs[0][np.argmin(u)]]) % 360.0
            res["time_ratio"] = max(turn, 360.0 - turn) / min(turn, 360.0 - turn)
    res["assembled_fraction"] = placed.mean()
    return res


def circ(a, b):
    """Circular distance between angles [deg]."""
    return abs((a - b + 180.0) % 360.0 - 180.0)


CASES = [  # (p, q, r, s) of every Grashof class
    (12, 2, 15, 9), (12, 5, 15, 9), (12, 5.9, 15, 9),      # crank-rockers (the last near a toggle)
    (2, 5, 4.5, 4), (3, 7, 6, 5),                           # double-cranks
    (8, 6, 2, 7), (8, 7, 6, 2),                             # Grashof double-rocker, rocker-crank
    (10, 6, 7, 8), (5, 4, 4.5, 3),                          # non-Grashof triple-rockers
    (4, 2, 4, 2),                                           # change point
]


@pytest.mark.parametrize("branch", [1, -1])
@pytest.mark.parametrize("lengths", CASES)
def test_batch_against_brute_force(lengths, branch):
    p, q, r, s = lengths
    f = summarise_batch(params(fixed_link=p, crank=q, coupler=r, rocker=s,
                               branch="open" if branch > 0 else "crossed"), detail=True).iloc[0]
    o = oracle(p, q, r, s, branch=branch)
    assert f["assemblable"] == o["assemblable"]
    assert f["grashof_class"] == grashof(p, q, r, s).name
    assert f["mu_min_deg"] == pytest.approx(o["mu_min_deg"], abs=1e-3)   # sqrt-steep at a limit angle
    assert f["mu_max_deg"] == pytest.approx(o["mu_max_deg"], abs=1e-3)
    assert f["assembled_fraction"] == pytest.approx(o["assembled_fraction"], abs=1e-4)
    if o["runs"] == 1 and not f["rocker_turns_fully"]:
        assert f["rocker_swing_deg"] == pytest.approx(o["rocker_swing_deg"], abs=1e-4)
        assert circ(f["rocker_min_deg"], o["rocker_min_deg"]) < 1e-4
        assert circ(f["rocker_max_deg"], o["rocker_max_deg"]) < 1e-4
    if f["rocker_turns_fully"]:
        assert o["rocker_swing_deg"] >= 360.0 - 1e-6
    if "rocker_omega_peak_rad_s" in o:
        assert not f["toggle_in_range"]
        for name in ("rocker_omega_peak_rad_s", "coupler_omega_peak_rad_s"):
            # the grid maximum is below the true peak by at most ~curvature * (0.005 deg)^2
            assert f[name] == pytest.approx(o[name], rel=1e-6, abs=1e-9)
            assert abs(f[name]) >= abs(o[name]) * (1 - 1e-12)
    else:
        assert f["toggle_in_range"] and math.isnan(f["rocker_omega_peak_rad_s"])
    if "time_ratio" in o:   # a full turn with the rocker oscillating: strokes of 180 +- alpha
        assert f["time_ratio"] >= 1.0
        assert f["time_ratio"] == pytest.approx(o["time_ratio"], abs=2e-4)
    else:
        assert math.isnan(f["time_ratio"])


def test_time_ratio_of_the_closed_form_crank_rocker_family():
    """Every crank-rocker of the textbook family (driver/synthesis/_crank_rocker.py, built for a
    swing and a time ratio in closed form) has exactly that time ratio in the batch summary."""
    from driver.synthesis import _crank_rocker as cr
    for swing, q in ((60.0, 1.25), (45.0, 1.0), (80.0, 1.6)):
        members = [m for m in cr.family(swing, q, 25) if m.crank_rocker]
        assert len(members) > 10
        f = summarise_batch(params(fixed_link=1.0, crank=1.0, coupler=1.0, rocker=1.0),
                            {"fixed_link": [m.ground for m in members], "crank": [m.crank for m in members],
                             "coupler": [m.coupler for m in members], "rocker": [m.rocker for m in members]})
        assert f["rocker_swing_deg"].to_numpy() == pytest.approx(swing, abs=1e-7)
        assert f["time_ratio"].to_numpy() == pytest.approx(q, abs=1e-7)
    # a range short of a full turn has no time ratio
    f = summarise_batch(params(fixed_link=12.0, crank=5.0, coupler=15.0, rocker=9.0, stop_deg=350.0))
    assert math.isnan(f["time_ratio"].iloc[0])


def test_partial_ranges_and_long_ranges():
    base = params(fixed_link=12.0, crank=5.0, coupler=15.0, rocker=9.0, omega=5.0)
    f = summarise_batch(base, {"start_deg": [0, 30, -720, 100, 90], "stop_deg": [360, 200, 720, 100, 10]},
                        detail=True)
    for i, (lo, hi) in enumerate([(0, 360), (30, 200), (-720, 720), (100, 100), (10, 90)]):
        o = oracle(12.0, 5.0, 15.0, 9.0, lo, hi, omega=5.0) if hi > lo else None
        row = f.iloc[i]
        if o is None:   # one crank angle: every extreme at it
            one, _ = fourbar_kernel.fourbar_exact(np.radians([lo]), 12.0, 5.0, 15.0, 9.0, 5.0)
            assert row["rocker_omega_peak_rad_s"] == pytest.approx(one[0, 8], rel=1e-12)
            assert row["rocker_swing_deg"] == 0.0 and row["rocker_omega_peak_at_deg"] == lo
            continue
        assert lo <= row["rocker_omega_peak_at_deg"] <= hi and lo <= row["rocker_min_at_deg"] <= hi
        for name in ("mu_min_deg", "mu_max_deg", "rocker_swing_deg"):
            assert row[name] == pytest.approx(o[name], abs=1e-4), (lo, hi, name)
        for name in ("rocker_omega_peak_rad_s", "coupler_omega_peak_rad_s"):
            assert row[name] == pytest.approx(o[name], rel=1e-6), (lo, hi, name)


def test_not_assemblable_and_toggles():
    f = summarise_batch(params(fixed_link=1.0, crank=10.0, coupler=1.0, rocker=1.0), detail=True).iloc[0]
    assert not f["assemblable"] and f["assembled_fraction"] == 0.0
    assert all(math.isnan(f[k]) for k in ("mu_min_deg", "rocker_swing_deg", "rocker_omega_peak_rad_s"))
    # a triple-rocker: two toggles, peaks unbounded (missing), fraction between the limits
    f = summarise_batch(params(fixed_link=10.0, crank=6.0, coupler=7.0, rocker=8.0), detail=True).iloc[0]
    a = limit_angles(10.0, 6.0, 7.0, 8.0)
    assert f["toggle_in_range"] and f["toggles_in_range"] == len(a) == 2
    assert f["assembled_fraction"] == pytest.approx(1 - (a[1] - a[0]) / 360.0, abs=1e-12)
    assert math.isnan(f["coupler_omega_peak_rad_s"])
    # the rocker's travel runs to the toggle positions (the old sampled summary missed this)
    assert f["rocker_swing_deg"] == pytest.approx(oracle(10.0, 6.0, 7.0, 8.0)["rocker_swing_deg"], abs=1e-4)
    assert f["rocker_swing_deg"] > 100.0


lengths_st = st.floats(0.3, 10.0, allow_nan=False)


@settings(max_examples=60, deadline=None)
@given(links=st.lists(st.tuples(lengths_st, lengths_st, lengths_st, lengths_st), min_size=1, max_size=8),
       branch=st.sampled_from(["open", "crossed"]), lo=st.sampled_from([0.0, -90.0, 45.0]),
       span=st.sampled_from([360.0, 180.0, 37.5, 720.0]), omega=st.floats(-20, 20, allow_nan=False))
def test_single_case_equals_batch(links, branch, lo, span, omega):
    """What a run prints (summarise) is the batch row, column for column, to the last bit."""
    arr = np.array(links)
    cols = {"fixed_link": arr[:, 0], "crank": arr[:, 1], "coupler": arr[:, 2], "rocker": arr[:, 3]}
    base = params(fixed_link=1.0, crank=1.0, coupler=1.0, rocker=1.0, branch=branch, omega=omega,
                  start_deg=lo, stop_deg=lo + span)
    batch = summarise_batch(base, cols)
    for i, (p, q, r, s) in enumerate(links):
        one = summarise(params(fixed_link=p, crank=q, coupler=r, rocker=s, branch=branch, omega=omega,
                               start_deg=lo, stop_deg=lo + span))
        assert list(one) == list(batch.columns)
        for k, v in one.items():
            b = batch[k].iloc[i]
            assert (v is None and pd.isna(b)) or v == b, (k, v, b)
        assert one["grashof_class"] == grashof(p, q, r, s).name or \
            abs((min(p, q, r, s) + max(p, q, r, s)) - (sum((p, q, r, s)) - min(p, q, r, s) - max(p, q, r, s))) < 1e-9


def test_batch_input_errors():
    base = params(fixed_link=12.0, crank=5.0, coupler=15.0, rocker=9.0)
    with pytest.raises(DeckError, match="test.dat:1: key 'crank': design 1 has -2.0"):
        summarise_batch(base, {"crank": [1.0, -2.0]})
    with pytest.raises(DeckError, match="key 'rocker': design 0 has nan"):
        summarise_batch(base, {"fourbar.rocker": [np.nan]})
    with pytest.raises(DeckError, match="different lengths"):
        summarise_batch(base, {"crank": [1.0, 2.0], "coupler": [1.0, 2.0, 3.0]})
    with pytest.raises(DeckError, match="key 'colour': not a &fourbar key"):
        summarise_batch(base, {"colour": [1.0]})
    with pytest.raises(ValueError, match="branch: must be"):   # a plain mapping as the base
        summarise_batch(dict(base), {"branch": ["open", "sideways"]})
    f = summarise_batch(base, {"crank": np.linspace(1, 5, 5), "step_deg": 7.0, "branch": ["open"] * 5})
    assert len(f) == 5 and f["assemblable"].all()


def test_a_run_calls_the_summary_kernel_once_and_reports_its_row(monkeypatch):
    """The .out's headline figures (transmission, rocker, peaks) and the summary come from one call
    of the summary kernel: the same row, so they cannot disagree, and it is not computed twice."""
    import driver.fourbar
    calls = []
    real = fourbar_kernel.fourbar_summaries
    monkeypatch.setattr(fourbar_kernel, "fourbar_summaries", lambda *a, **k: (calls.append(1), real(*a, **k))[1])
    res = driver.fourbar.run(fixed_link=12.0, crank=5.0, coupler=15.0, rocker=9.0, omega=5.0, step_deg=20)
    assert len(calls) == 1
    s = res.summary
    assert f"min {s['mu_min_deg']:.2f} deg" in res.text and f"max {s['mu_max_deg']:.2f} deg" in res.text
    assert f"swing {s['rocker_swing_deg']:.3f} deg" in res.text
    assert f"peak rocker speed .... {s['rocker_omega_peak_rad_s']:.4f} rad/s" in res.text
