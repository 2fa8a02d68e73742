"""Issue 35, item 2: a chain that cannot close is its own class, never a "full turn".

The truth is the assembly condition itself, written here apart from the kernel and from
``grashof``: with d = |A O4| = sqrt(p^2 + q^2 - 2 p q cos(theta)) ranging over [|p - q|, p + q],
the loop closes at theta exactly when |r - s| <= d <= r + s, so

* some position exists  <=>  [|p - q|, p + q] and [|r - s|, r + s] overlap
                         <=>  the longest link is no longer than the other three together;
* the crank turns fully  <=>  p + q <= r + s and |p - q| >= |r - s|;
* the assembled fraction of a crank range is the measure of the thetas where it closes.

Integer lengths make change points (S + L = P + Q) and flat chains (L = S + P + Q) frequent and
exact.  A run of a chain with no position (or no position in its crank range) fails: exit 1, the
reason in the .out and on stderr, ``--json`` ok = false.
"""
from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import driver
from conftest import ROOT
from driver.fourbar import grashof, summarise_batch


def closes_somewhere(p: float, q: float, r: float, s: float) -> bool:
    return abs(p - q) <= r + s and abs(r - s) <= p + q


def crank_turns(p: float, q: float, r: float, s: float) -> bool:
    return p + q <= r + s and abs(p - q) >= abs(r - s)


def fraction(p: float, q: float, r: float, s: float, lo: float, hi: float, n: int = 400_001) -> float:
    """Fraction of [lo, hi] deg where the loop closes (midpoint rule on a dense grid)."""
    t = np.radians(lo + (hi - lo) * (np.arange(n) + 0.5) / n)
    d = np.sqrt(p * p + q * q - 2 * p * q * np.cos(t))
    return float(np.mean((d >= abs(r - s)) & (d <= r + s)))


lengths = st.tuples(*[st.integers(1, 12)] * 4)


@settings(max_examples=400, deadline=None)
@given(lengths)
def test_the_class_says_whether_a_position_exists_and_whether_the_crank_turns(links):
    p, q, r, s = links
    g = grashof(p, q, r, s)
    longest, rest = max(links), sum(links) - max(links)
    assert (g.name == "impossible chain") == (longest > rest)
    assert (g.name == "flat chain") == (longest == rest)
    assert g.movable == (longest < rest)
    assert closes_somewhere(p, q, r, s) == (longest <= rest)      # the oracle's own consistency
    assert g.full_crank_rotation == (g.movable and crank_turns(p, q, r, s)), (links, g.name)
    assert "full turn" not in g.name


def test_the_batch_summary_classes_every_design_like_a_single_run():
    # every integer linkage up to 9: the kernel's class and full-rotation flag against the oracle
    grid = np.array(np.meshgrid(*[np.arange(1, 10, dtype=float)] * 4, indexing="ij")).reshape(4, -1).T
    base = driver.fourbar.SPEC  # noqa: F841 - the deck keys the batch takes
    frame = summarise_batch({"fixed_link": 1.0, "crank": 1.0, "coupler": 1.0, "rocker": 1.0, "omega": 1.0,
                             "start_deg": 0.0, "stop_deg": 360.0, "branch": "open"},
                            {"fixed_link": grid[:, 0], "crank": grid[:, 1], "coupler": grid[:, 2], "rocker": grid[:, 3]})
    longest, rest = grid.max(axis=1), grid.sum(axis=1) - grid.max(axis=1)
    names = frame["grashof_class"].to_numpy()
    assert np.array_equal(names == "impossible chain", longest > rest)
    assert np.array_equal(names == "flat chain", longest == rest)
    want = (longest < rest) & (grid[:, 0] + grid[:, 1] <= grid[:, 2] + grid[:, 3]) & \
        (np.abs(grid[:, 0] - grid[:, 1]) >= np.abs(grid[:, 2] - grid[:, 3]))
    assert np.array_equal(frame["full_crank_rotation"].to_numpy(dtype=bool), want)
    assert not frame.loc[longest >= rest, "assemblable"].any()
    assert (frame.loc[longest > rest, "assembled_fraction"] == 0.0).all()
    cp = (grid.min(axis=1) + longest == np.sort(grid, axis=1)[:, 1:3].sum(axis=1)) & (longest < rest)
    assert cp.sum() > 100 and all(n.startswith("change-point") for n in names[cp])


ISSUE = "&fourbar fixed_link = 12, crank = 5, coupler = 150, rocker = 9, step_deg = 30 /\n"


def run_cli(tmp_path, text: str, *flags: str) -> tuple[subprocess.CompletedProcess, str]:
    deck = tmp_path / "deck.dat"
    deck.write_text(text)
    r = subprocess.run([sys.executable, "-m", "driver", "-q", "-o", str(tmp_path / "o"), str(deck), *flags],
                       cwd=ROOT, capture_output=True, text=True, timeout=300)
    out = tmp_path / "o" / "deck.out"
    return r, out.read_text() if out.exists() else ""


def test_the_issues_chain_fails_with_its_class_everywhere(tmp_path):
    r, text = run_cli(tmp_path, ISSUE, "--json", "--csv")
    assert r.returncode == 1, r.stderr
    assert "impossible chain" in r.stderr and "coupler (150)" in r.stderr and "12 + 5 + 9 = 26" in r.stderr
    assert "full turn" not in text and "triple-rocker" not in text
    assert "Grashof class ........ impossible chain" in text and "FAILED: impossible chain" in text
    rec = json.loads((tmp_path / "o" / "deck.json").read_text())
    assert rec["ok"] is False and rec["exit_code"] == 1
    assert rec["summary"]["grashof_class"] == "impossible chain"
    assert rec["summary"]["full_crank_rotation"] is False and rec["summary"]["assemblable"] is False
    import pandas as pd
    tidy = pd.read_csv(tmp_path / "o" / "deck.csv")
    assert len(tidy) == 13 and (tidy["status"] == "impossible_chain").all()
    # the crank pin is placed (it always can be); nothing else is
    assert tidy["xa"].notna().all() and tidy["xb"].isna().all() and tidy["rocker_omega_rad_s"].isna().all()


def test_the_api_result_of_an_impossible_chain_is_not_ok():
    r = driver.run(ISSUE)
    assert not r.ok and r.failure.startswith("impossible chain")
    assert r.summary["grashof_class"] == "impossible chain"


def test_a_flat_chain_fails_and_says_it_lies_flat(tmp_path):
    r, text = run_cli(tmp_path, "&fourbar fixed_link = 12, crank = 5, coupler = 4, rocker = 3, step_deg = 10 /\n")
    assert r.returncode == 1 and "flat chain" in r.stderr and "5 + 4 + 3 = 12" in r.stderr
    assert "crank rotation ....... none" in text


def test_the_force_analysis_of_an_impossible_chain_fails_too(tmp_path):
    r, text = run_cli(tmp_path, "&fourbar fixed_link = 0.12, crank = 0.05, coupler = 1.5, rocker = 0.09,\n"
                                " step_deg = 30, mass = 1, 1, 1 /\n")
    assert r.returncode == 1 and "impossible chain" in r.stderr
    force_rows = [l for l in text.splitlines() if l.strip().startswith(("0 ", "30 ")) and "no position" in l]
    assert force_rows and "not placed" not in text


@pytest.mark.parametrize("links, full", [((12, 5, 15, 8), True),      # change-point crank-rocker
                                         ((12, 8, 15, 5), False),     # change-point rocker-crank
                                         ((4, 2, 4, 2), True),        # parallelogram
                                         ((10, 10, 6, 6), False),
                                         ((12, 5, 15, 9), True), ((10, 6, 7, 8), False)])
def test_the_out_and_the_summary_agree_on_the_cranks_rotation(links, full):
    p, q, r, s = links
    assert crank_turns(p, q, r, s) == full               # the oracle
    res = driver.fourbar.run(fixed_link=p, crank=q, coupler=r, rocker=s, step_deg=15)
    line = next(l for l in res.out.splitlines() if "crank rotation" in l)
    assert line.split("....... ")[1].startswith("full turn") == full, line
    assert res.summary["full_crank_rotation"] is full and res.ok


def test_a_linkage_assembling_on_part_of_the_range_reports_that_part():
    p, q, r, s = 10.0, 8.0, 3.0, 6.0          # a Grashof double-rocker: two mirror intervals
    res = driver.fourbar.run(fixed_link=p, crank=q, coupler=r, rocker=s, step_deg=1)
    assert res.ok and res.warnings
    assert res.summary["assembled_fraction"] == pytest.approx(fraction(p, q, r, s, 0, 360), abs=1e-5)
    assert res.summary["full_crank_rotation"] is False
    # a range inside the gap between the intervals: no position at all -> a failure naming where it assembles
    res = driver.fourbar.run(fixed_link=p, crank=q, coupler=r, rocker=s, start_deg=90, stop_deg=270, step_deg=10)
    assert fraction(p, q, r, s, 90, 270) == 0.0
    assert not res.ok and "90 to 270" in res.failure and "14.36" in res.failure
    a = math.degrees(math.acos((p * p + q * q - (r - s) ** 2) / (2 * p * q)))
    assert f"{a:.3f}" in res.failure


@pytest.mark.parametrize("outputs", ["all", "none"])
def test_a_sweep_summary_names_the_impossible_chains_on_both_paths(tmp_path, outputs):
    """A sweep is a design search: an impossible design is an answer its row classifies, not a
    failed case, whether each case runs in full (its files written) or the batch summarises."""
    deck = tmp_path / "sw.dat"
    deck.write_text("&fourbar fixed_link = 12, crank = 5, coupler = 15, rocker = 9, step_deg = 30 /\n"
                    f"&sweep key1 = 'fourbar.coupler', values1 = 15, 30, 150, case_outputs = '{outputs}' /\n")
    s = driver.run_sweep(deck, jobs=1)
    assert s.batch == (outputs == "none")
    assert list(s.summary["grashof_class"]) == ["crank-rocker", "impossible chain", "impossible chain"]
    assert not s.summary["full_crank_rotation"].iloc[1:].any() and not s.summary["assemblable"].iloc[1:].any()
    assert s.status == 0 and s.n_failed == 0 and (s.summary["status"] == "ok").all()


def test_both_figures_of_an_impossible_chain_name_its_class():
    import matplotlib
    matplotlib.use("Agg")
    res = driver.run(ISSUE)
    words = []
    for fig in (f.draw() for f in res.figures):
        words += [fig.get_suptitle()] + [t.get_text() for ax in fig.axes for t in ax.texts]
        words += [ax.get_title() for ax in fig.axes]
    text = " ".join(words)
    assert {f.name for f in res.figures} >= {"curves", "linkage"}
    assert "impossible chain" in text and "full turn" not in text and "triple-rocker" not in text
    # the linkage figure shows how far the longest link is from closing: 150 - (12 + 5 + 9)
    assert "short by 124" in text


def _function_deck(links: tuple[float, float, float, float], theta: np.ndarray, crank_range: float) -> str:
    """A function-generation deck through three positions of a known linkage (its rocker angles
    by the kernel's own loop solve are data here: the test is what the check says of the result)."""
    from driver.fourbar import _kernel as fourbar_kernel
    d, a, b, c = links
    out, st = fourbar_kernel.fourbar_exact(np.radians(theta), d, a, b, c, 1.0, 0.0, 1)
    assert (st == 0).all()
    psi = np.degrees(out[:, 1])
    t0 = float(theta[0])
    return ("&synthesis task = 'function', x_values = " + ", ".join(repr(float(t)) for t in theta)
            + ", y_values = " + ", ".join(repr(float(v)) for v in psi)
            + f", x_start = {t0!r}, x_stop = {t0 + crank_range!r}, crank_start_deg = {t0!r},"
            f" crank_range_deg = {crank_range!r}, rocker_start_deg = {float(psi[0])!r},"
            f" rocker_range_deg = {float(psi[-1] - psi[0])!r}, fixed_link = {d!r} /\n")


@pytest.mark.parametrize("links, crank_range", [((1.0, 0.8, 0.6, 0.7), 100.0),    # triple-rocker, assembles to 91.79 deg
                                                ((1.0, 0.45, 1.1, 0.9), 100.0)])  # crank-rocker
def test_a_synthesised_linkage_is_classed_and_its_assembly_limit_found(links, crank_range):
    from driver.synthesis import synthesise
    p, q, r, s = links
    theta = np.array([10.0, 25.0, 40.0])
    syn = synthesise(_function_deck(links, theta, crank_range))
    assert (syn.design.crank, syn.design.coupler, syn.design.rocker) == pytest.approx((q, r, s), abs=1e-10)
    srt = sorted(links)
    word = "triple-rocker" if srt[0] + srt[3] > srt[1] + srt[2] else "crank-rocker"
    turns = crank_turns(p, q, r, s)
    line = next(l for l in syn.text.splitlines() if "class of the linkage" in l)
    assert word in line and ("turns fully" if turns else "does not turn fully") in line, line
    # the crank range leaves the assembled interval where |A O4| = r + s: cos(theta) = (p^2 + q^2 - (r + s)^2) / (2 p q)
    lim = math.degrees(math.acos((p * p + q * q - (r + s) ** 2) / (2 * p * q))) if not turns else math.inf
    assert fraction(p, q, r, s, 10.0, 10.0 + crank_range) == pytest.approx(
        min(1.0, (lim - 10.0) / crank_range), abs=1e-5)
    if turns:
        assert syn.failure is None
    else:
        x = np.linspace(10.0, 10.0 + crank_range, 201)   # the check's default error_points
        first = x[x > lim][0]
        assert syn.failure is not None and "cannot be assembled" in syn.failure and f"x = {first:g})" in syn.failure


def _closes(p: float, q: float, r: float, s: float, theta_deg: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(the loop closes, it closes only flat: |A O4| = |r - s| or r + s) at each crank angle."""
    d = np.sqrt(p * p + q * q - 2 * p * q * np.cos(np.radians(theta_deg)))
    flat = np.isclose(d, abs(r - s), rtol=0, atol=1e-9) | np.isclose(d, r + s, rtol=0, atol=1e-9)
    return (d >= abs(r - s) - 1e-9) & (d <= r + s + 1e-9), flat


@pytest.mark.parametrize("links", [(0.12, 0.05, 0.15, 0.08),    # change-point crank-rocker: flat at 0 deg
                                   (0.10, 0.08, 0.03, 0.06)])   # Grashof double-rocker: part of the turn
def test_the_force_analysis_at_a_change_point_and_on_part_of_the_turn(links):
    p, q, r, s = links
    res = driver.fourbar.run(fixed_link=p, crank=q, coupler=r, rocker=s, step_deg=5, mass=[1.0, 1.0, 1.0])
    t = res.tidy
    theta = t["theta_deg"].to_numpy()
    closes, flat = _closes(p, q, r, s, theta)
    assert res.ok and res.summary["full_crank_rotation"] == crank_turns(p, q, r, s)
    # forces exactly where the loop closes and does not lie flat (there the pin forces are indeterminate)
    has_force = t["input_torque_Nm"].notna().to_numpy()
    assert np.array_equal(has_force, closes & ~flat)
    assert np.array_equal((t["status"] == "cannot_assemble").to_numpy(), ~closes)
    if flat.any():
        assert set(t.loc[flat, "status"]) == {"toggle"}
        assert "through the change point" in res.out
    else:
        assert res.warnings and f"at {int((~closes).sum())} of {len(t)} crank angles" in res.warnings[0]


def test_the_batch_assembled_fraction_of_a_partial_linkage_is_the_measure_where_it_closes():
    grid = np.array([[10.0, 8.0, 3.0, 6.0], [9.0, 7.0, 2.0, 5.0], [7.0, 6.0, 8.0, 4.0], [5.0, 9.0, 3.0, 4.0]])
    frame = summarise_batch({"fixed_link": 1.0, "crank": 1.0, "coupler": 1.0, "rocker": 1.0, "omega": 1.0,
                             "start_deg": 0.0, "stop_deg": 360.0, "branch": "open"},
                            {"fixed_link": grid[:, 0], "crank": grid[:, 1], "coupler": grid[:, 2], "rocker": grid[:, 3]})
    for (p, q, r, s), got in zip(grid, frame["assembled_fraction"]):
        want = fraction(p, q, r, s, 0.0, 360.0)
        assert 0.0 < want < 1.0 and got == pytest.approx(want, abs=1e-5), (p, q, r, s)
