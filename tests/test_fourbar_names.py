"""Issue 35, item 1: one naming of the four-bar's links everywhere a user reads or types a name.

Every column says its link in words (``coupler_omega_rad_s``, ``rocker_omega_peak_rad_s``); the
exact .out headers are the same names; figures label the curve of each column with that link's
name; the paper's listing keeps ``omr``/``oms``.  The truth each name is checked against is an
independent position solution written here (two-circle intersection, not the kernel) and its
central differences: a column called the coupler's must hold the coupler's angular velocity.  An
old name (the paper's numbering: omega2 = coupler, omega3 = rocker) in a sweep filter, a sweep's
summary_columns or an &optimize expression is refused with the new name given.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import driver
from driver._deck import DeckError

P, Q, R, S, W = 12.0, 5.0, 15.0, 9.0, 5.0   # the paper's crank-5 linkage, crank speed rad/s


def angles(theta2: np.ndarray, branch: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """Coupler and rocker angles [rad] of the open (+1) assembly, by intersecting the circle of
    radius R about A with the circle of radius S about O4 = (P, 0) (an oracle apart from the kernel)."""
    ax, ay = Q * np.cos(theta2), Q * np.sin(theta2)
    dx, dy = P - ax, -ay                        # A -> O4
    d = np.hypot(dx, dy)
    a = (R * R - S * S + d * d) / (2 * d)       # along A -> O4 to the chord's foot
    h = np.sqrt(R * R - a * a)
    ux, uy = dx / d, dy / d
    bx, by = ax + a * ux - branch * h * uy, ay + a * uy + branch * h * ux   # B left of A -> O4 (open)
    return np.arctan2(by - ay, bx - ax), np.arctan2(by, bx - P)


def rates(theta2: np.ndarray, h: float = 1e-6) -> tuple[np.ndarray, np.ndarray]:
    """Coupler and rocker angular velocities [rad/s] by central differences at crank speed W."""
    c1, r1 = angles(theta2 + h)
    c0, r0 = angles(theta2 - h)
    wrap = lambda x: (x + math.pi) % (2 * math.pi) - math.pi
    return wrap(c1 - c0) / (2 * h) * W, wrap(r1 - r0) / (2 * h) * W


@pytest.fixture(scope="module")
def run():
    return driver.fourbar.run(fixed_link=P, crank=Q, coupler=R, rocker=S, omega=W, step_deg=5)


def test_the_columns_that_name_a_link_hold_that_links_speed(run):
    t = run.tidy
    th = np.radians(t["theta_deg"].to_numpy())
    wc, wr = rates(th)
    assert np.allclose(t["coupler_omega_rad_s"], wc, atol=1e-6)
    assert np.allclose(t["rocker_omega_rad_s"], wr, atol=1e-6)
    # the coupler's and the rocker's speeds differ: a swapped pair would fail above
    assert np.max(np.abs(wc - wr)) > 1.0
    for old in ("omega2_rad_s", "omega3_rad_s", "alpha2_rad_s2", "alpha3_rad_s2"):
        assert old not in t.columns


def test_the_summary_peaks_name_their_link(run):
    # the peak (largest in size, signed) of each link's speed over a fine grid, refined by the
    # oracle's own golden-section search on |omega|
    th = np.radians(np.arange(0.0, 360.0, 0.05))
    wc, wr = rates(th)
    s = run.summary
    for col, w, which in (("coupler_omega_peak_rad_s", wc, 0), ("rocker_omega_peak_rad_s", wr, 1)):
        k = int(np.argmax(np.abs(w)))
        lo, hi = th[k] - 1e-3, th[k] + 1e-3
        def f(x: float, which: int = which) -> float:
            return -abs(rates(np.array([x]))[which][0])
        g = (math.sqrt(5) - 1) / 2
        for _ in range(60):
            a, b = hi - g * (hi - lo), lo + g * (hi - lo)
            lo, hi = (lo, b) if f(a) < f(b) else (a, hi)
        peak = rates(np.array([0.5 * (lo + hi)]))[which][0]
        assert s[col] == pytest.approx(peak, rel=1e-7), col
    assert s["rocker_omega_peak_rad_s"] == pytest.approx(-6.3573, abs=5e-5)   # docs/fourbar.md
    assert not {"omega2_peak_rad_s", "omega3_peak_rad_s"} & set(s)


def test_the_exact_out_headers_are_the_tidy_names(run):
    lines = run.out.splitlines()
    k = next(i for i, l in enumerate(lines) if l.split()[:2] == ["theta", "coupler"])
    heads = lines[k].split()
    units = {"[deg]": "_deg", "[rad/s]": "_rad_s", "[rad/s2]": "_rad_s2"}
    # the unit line stands under its header (right-aligned columns): match them by their right edge
    ends = {lines[k].index(h) + len(h): h for h in heads}
    unit_of = {}
    pos = 0
    for u in lines[k + 1].split():
        pos = lines[k + 1].index(u, pos) + len(u)
        unit_of[ends[pos]] = u
    for h in heads:
        name = h + units.get(unit_of.get(h, ""), "")
        assert name in run.tidy.columns, (h, name)
    assert {"coupler_omega", "rocker_omega", "coupler_alpha", "rocker_alpha"} <= set(heads)


def test_the_figure_labels_each_curve_with_the_link_whose_column_it_draws(run):
    pytest.importorskip("matplotlib")
    fig = run.figure("curves")
    theta = np.linspace(0.0, 360.0, 721)
    wc, wr = rates(np.radians(theta))
    seen = 0
    for ax in fig.axes:
        for line in ax.get_lines():
            label = line.get_label()
            if "angular velocity" not in label or "(exact)" not in label:
                continue
            y = np.asarray(line.get_ydata(), dtype=float)
            want = wc if label.startswith("coupler") else wr
            assert label.startswith(("coupler", "rocker")), label
            assert np.allclose(y, want, atol=1e-5), label
            seen += 1
    assert seen == 2


def test_the_listing_keeps_the_papers_headers_and_its_tidy_rows_the_new_names():
    r = driver.run("inputs/crank5.dat")
    assert any(l.split()[-2:] == ["omr", "oms"] for l in r.out.splitlines())
    lst = r.tidy[r.tidy["method"] == "listing"]
    # the listing is right from 0 to 180 deg (docs/fourbar.md): its rocker column is the rocker's speed
    first = lst[lst["theta_deg"] <= 160]
    _, wr = rates(np.radians(first["theta_deg"].to_numpy()))
    assert np.allclose(first["rocker_omega_rad_s"], wr, atol=1e-3)


SWEEP = """&fourbar
  fixed_link = 12.0, crank = 2.0, coupler = 15.0, rocker = 9.0, omega = 5.0, step_deg = 20
/
&sweep
  key1 = 'fourbar.crank', values1 = 2, 3
  {line}
/
"""


@pytest.mark.parametrize("line, key", [("keep = 'abs(omega3_peak_rad_s) <= 3'", "keep"),
                                        ("plot_y = 'omega2_peak_rad_s'", "plot_y"),
                                        ("summary_columns = 'omega3_peak_at_deg'", "summary_columns")])
def test_an_old_name_in_a_sweep_is_refused_with_the_new_one(write_deck, line, key):
    path = write_deck(SWEEP.format(line=line))
    with pytest.raises(DeckError) as e:
        driver.run_sweep(path, jobs=1)
    old = line.split("'")[1].replace("abs(", "").split(")")[0]
    assert e.value.key == key and f"is now {driver.fourbar.STUDY.renamed[old]}" in str(e.value)


def test_an_old_name_in_run_sweep_keep_is_refused():
    with pytest.raises(DeckError, match="rocker_omega_peak_rad_s"):
        driver.run_sweep({"fourbar": {"fixed_link": 12, "crank": 2, "coupler": 15, "rocker": 9, "step_deg": 20}},
                         grid={"crank": [2, 3]}, keep="omega3_peak_rad_s < 0", jobs=1)


OPT = """&fourbar
  fixed_link = 12.0, crank = 3.0, coupler = 15.0, rocker = 9.0, omega = 5.0, step_deg = 10
/
&optimize
  var1 = 'fourbar.crank', lower1 = 1.0, upper1 = 5.0
  maximize = 'rocker_swing_deg'
  constraint1 = 'abs(omega2_peak_rad_s) <= 2'
  maxiter = 2, popsize = 4
/
"""


def test_an_old_name_in_an_optimize_expression_is_refused_with_the_new_one(write_deck):
    from driver.optimize import optimize
    with pytest.raises(DeckError) as e:
        optimize(write_deck(OPT), None, jobs=1)
    assert e.value.key == "constraint1" and "coupler_omega_peak_rad_s" in str(e.value)
    with pytest.raises(DeckError, match="rocker_omega_peak_rad_s"):
        optimize(write_deck(OPT.replace("maximize = 'rocker_swing_deg'", "minimize = 'abs(omega3_peak_rad_s)'")
                            .replace("  constraint1 = 'abs(omega2_peak_rad_s) <= 2'\n", "")), None, jobs=1)


def test_the_command_line_refuses_an_old_name_with_exit_2(write_deck):
    import subprocess
    import sys

    from conftest import ROOT
    path = write_deck(SWEEP.format(line="keep = 'omega3_peak_rad_s < 0'"))
    r = subprocess.run([sys.executable, "-m", "driver", "-q", "-o", str(path.parent / "o"), str(path)],
                       cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert r.returncode == 2 and "rocker_omega_peak_rad_s" in r.stderr
    assert not (path.parent / "o").exists() or not any((path.parent / "o").iterdir())
