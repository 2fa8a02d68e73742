"""Figures as a reader sees them: labels with units, the artists a title promises, no
wrapped-angle jumps, no clipped legends or overlapping titles, reproducible files.

The checks look inside the matplotlib Figure objects the studies build (what is drawn),
and at the bytes of the files written (PNG, SVG, PDF).
"""
from __future__ import annotations

import math
import subprocess
import sys
from functools import cache

import numpy as np
import pandas as pd
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure as MplFigure

from conftest import INPUTS
from driver import plotting
from driver._deck import read_deck
from driver._output import column_label
from driver._result import plot_format
from driver._runner import compute, study_of
from driver._study import load_study
from driver.ujoint import _figures as ujoint_figures


@cache
def figures_of(deck: str) -> dict[str, MplFigure]:
    """Every figure a shipped deck draws with --plot, by name (drawn once per test session)."""
    module, params = study_of(read_deck(INPUTS / deck))
    result = compute(module, params)
    return {f.name: f.draw() for f in result.figures}


def _renderer(fig: MplFigure):
    """Lay the figure out on an Agg canvas (as save_figure does) and return its renderer."""
    canvas = fig.canvas if isinstance(fig.canvas, FigureCanvasAgg) else FigureCanvasAgg(fig)
    canvas.draw()
    return canvas.get_renderer()


def _inside_figure(fig: MplFigure, artist) -> bool:
    box = artist.get_window_extent(_renderer(fig))
    fb = fig.bbox
    return box.x0 >= fb.x0 - 1 and box.y0 >= fb.y0 - 1 and box.x1 <= fb.x1 + 1 and box.y1 <= fb.y1 + 1


def _texts(fig: MplFigure) -> list:
    """Every visible, non-empty title and axis label of ``fig``."""
    out = [fig._suptitle] if fig._suptitle is not None else []
    for ax in fig.axes:
        out += [t for t in (ax.title, ax._left_title, ax._right_title, ax.xaxis.label, ax.yaxis.label)
                if t.get_visible() and t.get_text()]
    return out


def assert_no_overlapping_text(fig: MplFigure) -> None:
    r = _renderer(fig)
    boxes = [(t.get_text(), t.get_window_extent(r)) for t in _texts(fig)]
    for i, (a, ba) in enumerate(boxes):
        for b, bb in boxes[i + 1:]:
            assert not ba.overlaps(bb), f"{a!r} overlaps {b!r}"


# ----------------------------------------------------------------------------- labels


def test_column_labels_have_words_and_units():
    sc, fb = load_study("slidercrank"), load_study("fourbar")
    assert column_label(sc, "slidercrank.speeds") == "crank speed [rad/s]"
    assert column_label(sc, "peak_tensile_2_deg") == "crank angle of peak tension, speed 2 [deg]"
    assert column_label(sc, "peak_compressive_microstrain") == "peak compressive strain (negative) [microstrain]"
    assert column_label(sc, "rod_mass_kg") == "rod mass [kg]"          # an optimisation objective
    assert column_label(fb, "fourbar.omega") == "crank speed [rad/s]"          # units from the key's SPEC
    assert column_label(fb, "mu_min_deg") == "minimum transmission angle [deg]"
    assert column_label(None, "something_rad_s") == "something [rad/s]"       # units read off the suffix
    assert column_label(fb, "mu_max_deg - mu_min_deg") == "mu_max_deg - mu_min_deg"   # an expression


def _slider_sweep_frame() -> pd.DataFrame:
    rows = []
    for k, mat in enumerate(("aluminium", "steel")):
        for w in (10.0, 20.0, 30.0):
            rows.append({"case": len(rows) + 1, "slidercrank.material": mat, "slidercrank.speeds": w,
                         "status": "ok", "kept": True, "omega_1_rad_s": w, "euler_ratio_1": 1e-3 * w * w * (k + 1),
                         "peak_tensile_1_microstrain": 0.1 * w * w / (k + 1), "peak_tensile_1_deg": 0.0,
                         "peak_tensile_microstrain": 0.1 * w * w / (k + 1), "peak_tensile_deg": 0.0,
                         "euler_ratio_max": 1e-3 * w * w * (k + 1), "n_buckled": 0})
    return pd.DataFrame(rows)


def test_sweep_summary_labels_and_no_trivial_panels():
    frame = _slider_sweep_frame()
    module = load_study("slidercrank")
    labels = {c: column_label(module, c) for c in frame.columns}
    fig = plotting.sweep_summary(frame, ["slidercrank.material", "slidercrank.speeds"], title="t", labels=labels,
                                 preferred=module.sweep_plot)
    ylabels = [ax.get_ylabel().replace("\n", " ") for ax in fig.axes]
    # omega_1 repeats x, the angles and n_buckled are constants, the _1 columns repeat the totals
    assert ylabels == ["peak tensile strain [microstrain]", "peak compression / Euler load [-]"]
    assert fig.axes[-1].get_xlabel() == "crank speed [rad/s]"
    assert all("_" not in y for y in ylabels)
    legend = fig.legends[0]   # the figure's legend, under the panels
    assert [t.get_text() for t in legend.get_texts()] == ["material = aluminium", "material = steel"]
    assert _inside_figure(fig, legend)
    assert_no_overlapping_text(fig)


def test_sweep_summary_keeps_panels_the_deck_asks_for():
    frame = _slider_sweep_frame()
    fig = plotting.sweep_summary(frame, ["slidercrank.material", "slidercrank.speeds"],
                                 ys=["omega_1_rad_s", "peak_tensile_deg"])
    assert len(fig.axes) == 2


# ----------------------------------------------------------------------------- ujoint


def test_ujoint_trial_and_optimum_on_one_panel_with_the_paper_band():
    figs = figures_of("ujoint_option1.dat")
    for name in ("speed", "polar"):
        fig = figs[name]
        (ax,) = fig.axes
        labels = [ln.get_label() for ln in ax.get_lines()]
        assert any(s.startswith("trial: output") for s in labels), labels
        assert any(s.startswith("optimum: output") for s in labels), labels
        assert any(s.startswith("input shaft") for s in labels), labels
        band = [c for c in ax.collections + ax.patches if "trial band 24-26 rpm" in c.get_label()]
        assert len(band) == 1, name
        legend = fig.legends[0]
        assert _inside_figure(fig, legend), f"{name}: legend clipped"
        assert_no_overlapping_text(fig)
    polar = figs["polar"].axes[0]
    lo, hi = polar.get_ylim()
    assert 20.0 < lo < 23.0 and 27.17 < hi < 28.0          # not from 0: the fluctuation fills the radius
    assert polar.get_rorigin() < lo                         # an empty centre says so
    ticks = [t.get_text() for t in polar.texts if t.get_text()]   # radial labels on white patches
    assert ticks and all(t.endswith(" rpm") for t in ticks)
    assert all(t.get_bbox_patch() is not None and t.get_zorder() > 5 for t in polar.texts)
    # the input speed on top of every curve (an optimum close to it must not hide it)
    inp = [ln for ln in polar.lines if ln.get_label().startswith("input shaft")][0]
    assert inp.get_zorder() > max(ln.get_zorder() for ln in polar.lines if ln is not inp)


def test_ujoint_small_fluctuation_fills_the_polar_radius():
    theta = np.arange(0.0, 361.0)
    w = 25.0 + 0.4 * np.sin(np.radians(2 * theta))
    fig = ujoint_figures.ujoint_speed_figure(theta, 25.0, {"optimum": w}, polar=True)
    lo, hi = fig.axes[0].get_ylim()
    assert lo > 24.0 and hi < 26.0 and (0.8 / (hi - lo)) > 0.5


# ----------------------------------------------------------------------------- files


def _figure() -> MplFigure:
    theta = np.arange(0.0, 361.0)
    return ujoint_figures.ujoint_speed_figure(theta, 25.0, {"trial": 25 + np.sin(np.radians(2 * theta))},
                                        band=(24.0, 26.0), title="t")


@pytest.mark.parametrize("fmt, magic", [("png", b"\x89PNG"), ("svg", b"<?xml"), ("pdf", b"%PDF")])
def test_figures_are_byte_identical_for_the_same_inputs(tmp_path, fmt, magic):
    a = plotting.save_figure(_figure(), tmp_path / "a.png", fmt)
    b = plotting.save_figure(_figure(), tmp_path / "b.png", fmt)
    assert a.suffix == f".{fmt}" and b.suffix == f".{fmt}"
    assert a.read_bytes()[:len(magic)] == magic
    assert a.read_bytes() == b.read_bytes()
    if fmt != "png":   # no date written into the file
        assert b"CreationDate" not in a.read_bytes() and b"<dc:date>" not in a.read_bytes()


def test_plot_format_names():
    assert plot_format(True) == "png" and plot_format(False) is None and plot_format("SVG") == "svg"
    with pytest.raises(ValueError):
        plot_format("jpeg")


def test_cli_plot_format_svg_and_repeatable(tmp_path):
    def run(out):
        return subprocess.run([sys.executable, "-m", "driver", str(INPUTS / "ujoint_analyse.dat"), "-q",
                               "-o", str(tmp_path / out), "--plot-format", "svg"], capture_output=True, text=True)
    for out in ("a", "b"):
        res = run(out)
        assert res.returncode == 0, res.stderr
    names = sorted(p.name for p in (tmp_path / "a").glob("*.svg"))
    assert names == ["ujoint_analyse_polar.svg", "ujoint_analyse_speed.svg"]
    assert not list((tmp_path / "a").glob("*.png"))
    for n in names:
        assert (tmp_path / "a" / n).read_bytes() == (tmp_path / "b" / n).read_bytes()
    bad = subprocess.run([sys.executable, "-m", "driver", str(INPUTS / "ujoint_analyse.dat"), "--plot-format", "gif"],
                         capture_output=True, text=True, cwd=tmp_path)
    assert bad.returncode == 2 and "gif" in bad.stderr


# ----------------------------------------------------------------------------- fourbar


def test_break_wraps_breaks_only_at_the_wrap():
    x = np.arange(6.0)
    y = np.array([350.0, 355.0, 2.0, 8.0, 10.0, 12.0])
    bx, by = plotting.break_wraps(x, y)
    assert np.isnan(by[2]) and np.count_nonzero(np.isnan(by)) == 1
    assert np.allclose(by[~np.isnan(by)], y)


def test_fourbar_wrapped_angle_curves_have_no_vertical_jump():
    fig = figures_of("nongrashof.dat")["curves"]
    angles = fig.axes[0]
    lines = [ln for ln in angles.get_lines() if "(exact)" in ln.get_label()]
    assert len(lines) == 2
    for ln in lines:
        y = np.asarray(ln.get_ydata(), dtype=float)
        pairs = np.isfinite(y[1:]) & np.isfinite(y[:-1])
        assert np.abs(np.diff(y))[pairs].max() < 180.0, ln.get_label()
    coupler = np.asarray(lines[0].get_ydata(), dtype=float)
    assert lines[0].get_label().startswith("coupler") and np.nanmax(coupler) > 350.0 and np.nanmin(coupler) < 5.0
    # the crank angles where it cannot be assembled are shaded and named
    assert any(p.get_label() == "cannot be assembled" for p in angles.patches)
    for ax in fig.axes:
        assert "[" in ax.get_ylabel()
    assert "[deg]" in fig.axes[-1].get_xlabel()


def test_fourbar_linkage_labelled_with_the_legend_off_the_mechanism():
    fig = figures_of("crank5.dat")["linkage"]
    ax, panel = fig.axes   # the drawing, and the legend's own panel beside it
    assert ax.get_xlabel() == "x [length units]" and ax.get_ylabel() == "y [length units]"
    assert ax.get_aspect() == 1.0
    r = _renderer(fig)
    legend = panel.get_legend()
    assert not legend.get_window_extent(r).overlaps(ax.get_window_extent(r))
    assert _inside_figure(fig, legend)
    assert_no_overlapping_text(fig)


# ----------------------------------------------------------------------------- slidercrank

_SLIDER = """&slidercrank
  material = 'aluminium'
  geometric_stiffness = {g}
  speeds = 11.52, 29.32        ! rad/s; N/P_E = 1.43 at 29.32 (the Euler load is exceeded)
  n_elements = 20
  steps_per_rev = 720, revolutions = 2
/
"""


def _slider_figures(write_deck, geometric: bool) -> dict[str, MplFigure]:
    deck = write_deck(_SLIDER.format(g=".true." if geometric else ".false."), f"sc_{geometric}.dat")
    module, params = study_of(read_deck(deck))
    return {f.name: f.draw() for f in compute(module, params).figures}


def _legend_texts(fig: MplFigure) -> list[str]:
    legends = list(fig.legends) + [ax.get_legend() for ax in fig.axes if ax.get_legend() is not None]
    return [t.get_text() for lg in legends for t in lg.get_texts()]


def test_slidercrank_buckled_speed_is_named_not_missing(write_deck):
    figs = _slider_figures(write_deck, True)
    for name in ("strain", "deflection"):
        fig = figs[name]
        texts = _legend_texts(fig)
        drawn = [ln for ln in fig.axes[0].get_lines() if len(ln.get_xdata()) > 2]
        assert [ln.get_label() for ln in drawn] == ["11.52 rad/s"]          # 29.32 has no numbers to draw
        starts = ("29.32 rad/s: static instability at theta2 = ", "29.32 rad/s: limit l/20 at theta2 = ")
        assert any(t.startswith(starts) and t.endswith("not drawn") for t in texts), texts
        assert _inside_figure(fig, fig.legends[0])
        assert_no_overlapping_text(fig)


def test_slidercrank_linear_model_flags_cases_above_the_euler_load(write_deck):
    fig = _slider_figures(write_deck, False)["strain"]
    lines = {ln.get_label(): ln for ln in fig.axes[0].get_lines() if len(ln.get_xdata()) > 2}
    assert set(lines) == {"11.52 rad/s", "29.32 rad/s: N = 1.43 $P_E$, above the Euler load"}
    assert lines["29.32 rad/s: N = 1.43 $P_E$, above the Euler load"].get_linestyle() == "--"
    assert lines["11.52 rad/s"].get_linestyle() == "-"
    assert "linear model" in fig.axes[0].get_title()


# ----------------------------------------------------------------------------- manipulator


def test_manipulator_design_space_draws_the_iso_ri2_ellipses():
    fig = figures_of("manipulator_case1_report.dat")["design_space"]
    left = fig.axes[0]
    assert "iso-$RI_2$ ellipses" in left.get_title()
    ellipses = [ln for ln in left.get_lines() if (ln.get_gid() or "").startswith("iso-RI2 ellipse")]
    levels = sorted({float(ln.get_gid().split()[-1]) for ln in ellipses})
    assert len(ellipses) == 2 * len(levels) and len(levels) >= 3 and 2.0 in levels   # the deck's Table 4.1 level
    n, c = 4, 189.0      # four workspace points; c = sum of d^2 = 26 + 53 + 58 + 52 m^2
    for ln in ellipses:
        v = float(ln.get_gid().split()[-1])
        l1, l2 = (np.asarray(a, dtype=float) for a in ln.get_data())
        ok = np.isfinite(l1) & np.isfinite(l2)
        assert ok.sum() > 100 and (l1[ok] >= -1e-6).all() and (l2[ok] >= -1e-6).all()
        big, small = (l1[ok] + l2[ok]) ** 2 / 2, (l1[ok] - l2[ok]) ** 2 / 2      # L1^2, L2^2 (45-deg frame)
        lhs = np.minimum(np.abs(v * v * big + (2 * n - v * v) * small - c),
                         np.abs((2 * n - v * v) * big + v * v * small - c))
        assert lhs.max() < 1e-9 * c
        if v == 2.0:   # RI2 = sqrt(n): the C_rob circle of the report, radius 6.874 m
            assert np.allclose(np.hypot(l1[ok], l2[ok]), 6.874, atol=5e-4)
    assert_no_overlapping_text(fig)


def test_manipulator_torque_curves_mark_rows_violating_the_reach_conditions():
    module, params = study_of(read_deck(INPUTS / "manipulator_case2_exact.dat"))
    result = compute(module, params)
    fig = next(f.draw() for f in result.figures if f.name == "torque_crob")
    (ax,) = fig.axes
    curves = {ln.get_label(): ln for ln in ax.get_lines() if ln.get_label().startswith("$\\tau")}
    shoulder = curves["$\\tau_1$ (shoulder)"]
    l1 = np.asarray(shoulder.get_xdata(), dtype=float)
    drawn = np.isfinite(np.asarray(shoulder.get_ydata(), dtype=float))
    c = 51.5                                        # C_rob: l1^2 + l2^2 [m^2] of this deck
    l2 = np.sqrt(c - l1 ** 2)
    r, R = result.summary["r_m"], result.summary["R_m"]
    violating = drawn & ((np.abs(l1 - l2) > r + 1e-9) | (l1 + l2 < R - 1e-9))
    assert violating.sum() == 4
    marks = [ln for ln in ax.get_lines() if ln.get_marker() == "x"]
    assert len(marks) == 3 and marks[0].get_label() == "violates the workspace reach conditions"
    for ln in marks:
        assert np.allclose(np.sort(ln.get_xdata()), np.sort(l1[violating]))
    assert "[N m]" in ax.get_ylabel() and "[m]" in ax.get_xlabel()
    assert _inside_figure(fig, ax.get_legend())


# ----------------------------------------------------------------------------- optimisation


def test_optimisation_convergence_figure_names_its_objective_with_units(tmp_path):
    from driver.optimize import optimize
    deck = tmp_path / "opt.dat"
    deck.write_text("&fourbar fixed_link = 12, crank = 3, coupler = 15, rocker = 9, omega = 5, step_deg = 10 /\n"
                    "&optimize\nvar1 = 'fourbar.coupler', lower1 = 10, upper1 = 20\n"
                    "maximize = 'rocker_swing_deg'\nmethod = 'slsqp', starts = 1\n/\n")
    oc = optimize(deck, tmp_path / "out", plot="svg", jobs=1)
    svg = [p for p in oc.written if p.suffix == ".svg"]
    assert [p.name for p in svg] == ["opt.optimum_curves.svg", "opt.optimum_linkage.svg", "opt_convergence.svg",
                                     "opt_designs.svg"]
    from driver.optimize import _report as report
    fig = report.convergence_figure(oc.problem, report.history_frame(oc.problem, oc.history),
                                    oc.evaluator.frame(), "opt")
    assert fig.axes[0].get_ylabel() == "rocker swing [deg]"
    # the designs evaluated: the one variable against the objective, the optimum starred where x is
    designs = oc.figures[1].draw().axes[0]
    assert designs.get_xlabel().startswith("coupler") and designs.get_ylabel() == "rocker swing [deg]"
    star = next(line for line in designs.get_lines() if line.get_label() == "optimum")
    assert star.get_xdata()[0] == pytest.approx(oc.x["fourbar.coupler"]) and star.get_ydata()[0] == pytest.approx(oc.fun)
    # the gap in units of the stated tolerance (tol x max(1, |best|) for a local method), drawn
    # until it is within it; the title names the objective in words
    assert fig.axes[1].get_ylabel() == "|best so far - final best| / tolerance"
    assert fig.get_suptitle() == "opt: maximize rocker swing [deg]"
    tol, how = report.stated_tolerance(oc.problem, oc.fun)
    assert tol == pytest.approx(1e-3 * abs(oc.fun)) and how.startswith("tol x max(1, |best|)")
    gap = [ln for ln in fig.axes[1].get_lines() if ln.get_label() == "gap of the best so far"]
    if gap:   # it stops at the first design within the tolerance
        y = np.asarray(gap[0].get_ydata(), dtype=float)
        assert y[-1] <= 1.0 and (y[:-1] > 1.0).all()


# ----------------------------------------------------------------------------- issue 39: drawings, angles, maps


def test_linkage_drawing_one_solid_position_ghosts_counterweights_units():
    """fourbar_forces_balanced: one position drawn in the link colours (crank, coupler, rocker),
    the others as light ghosts, the Berkof-Lowen counterweights on the solid position at their
    deck radii, axes in metres (a deck with masses), equal scales, every text on the canvas."""
    from driver._mechanism import LINK_COLOURS
    from figure_checks import text_outside
    fig = figures_of("fourbar_forces_balanced.dat")["linkage"]
    ax = fig.axes[0]
    assert ax.get_xlabel() == "x [m]" and ax.get_ylabel() == "y [m]" and ax.get_aspect() == 1.0
    solid = [ln for ln in ax.get_lines() if ln.get_color() in LINK_COLOURS[:3] and len(ln.get_xdata()) == 2]
    assert len(solid) == 3   # one crank, one coupler, one rocker
    ghosts = [ln for ln in ax.get_lines() if ln.get_color() == "0.8" and len(ln.get_xdata()) == 4]
    assert len(ghosts) == 5
    crank = next(ln for ln in solid if ln.get_color() == LINK_COLOURS[0])
    discs = [ln for ln in ax.get_lines() if "counterweight" in ln.get_label()]
    assert [ln.get_label().split(" counterweight")[0] for ln in discs] == ["crank", "output link"]
    x, y = discs[0].get_xdata()[0], discs[0].get_ydata()[0]
    assert math.hypot(x, y) == pytest.approx(0.06) and "at 0.06 m" in discs[0].get_label()
    assert math.hypot(discs[1].get_xdata()[0] - 0.30, discs[1].get_ydata()[0]) == pytest.approx(0.10)
    assert crank.get_zorder() < min(ln.get_zorder() for ln in ax.get_lines() if ln.get_label().startswith("path of"))
    assert text_outside(fig) == []


@pytest.mark.parametrize("links, extra, unit", [
    (dict(fixed_link=12, crank=5, coupler=150, rocker=9), {}, "length units"),
    (dict(fixed_link=12, crank=5, coupler=26, rocker=9), {}, "length units"),
    (dict(fixed_link=0.3, crank=0.05, coupler=3.0, rocker=0.1),
     dict(mass=[1, 1, 1], inertia=[0.01, 0.01, 0.01], omega=10), "m"),
])
def test_the_chain_that_cannot_move_is_drawn_in_the_decks_unit_inside_the_canvas(links, extra, unit):
    """An impossible (or flat) chain's drawing: its longest link beside the other three laid end to
    end, short by exactly the longest minus their sum, the axis in the deck's length unit (metres
    for a deck with masses), every text on the canvas and in words."""
    import driver
    from figure_checks import figure_problems
    r = driver.fourbar.run(step_deg=30, **links, **extra)
    assert r.failure
    fig = r.figure("linkage")
    ax = fig.axes[0]
    assert ax.get_xlabel() == f"length [{unit}]"
    longest = max(links.values())
    bars = [ln for ln in ax.get_lines() if len(ln.get_xdata()) == 2]
    assert max(ln.get_xdata()[1] for ln in bars) == pytest.approx(longest)
    laid = [ln for ln in bars if ln.get_ydata()[0] == 0.0]
    assert laid[-1].get_xdata()[1] == pytest.approx(sum(links.values()) - longest)
    assert figure_problems(fig, r.summary) == []
    assert figure_problems(r.figure("curves"), r.summary) == []


def test_synthesis_targets_drawn_on_top_of_the_linkage(tmp_path):
    from driver._deck import read_deck
    from driver.synthesis import synthesis_figures, synthesise
    syn = synthesise(read_deck(INPUTS / "synthesis_path.dat"))
    fig = synthesis_figures(syn, "synthesis_path")[0].draw()
    ax = fig.axes[0]
    targets = next(ln for ln in ax.get_lines() if ln.get_label() == "target points")
    assert len(targets.get_xdata()) == 5
    assert targets.get_zorder() > max(ln.get_zorder() for ln in ax.get_lines() if ln is not targets)


def test_unwrap_angle_and_the_period_of_a_swept_angle():
    assert np.allclose(plotting.unwrap_angle([90.0, 120.0, 150.0, 0.0], 180.0), [90, 120, 150, 180])
    assert np.allclose(plotting.unwrap_angle([350.0, 10.0, np.nan, 20.0], 360.0)[[0, 1, 3]], [350, 370, 380])
    assert plotting.angle_period(np.arange(0.0, 180.0, 1.0)) == 180.0       # a phase over a half turn
    assert plotting.angle_period(np.arange(0.0, 360.0, 30.0)) == 360.0
    assert plotting.angle_period([0.0, 30.0, 60.0, 90.0]) is None           # a part of a turn
    assert plotting.angle_period(np.arange(0.0, 180.0, 1.0), "m") is None   # not an angle


def test_kept_designs_of_a_phase_sweep_lie_on_a_straight_line():
    """A sweep that tabulated only its kept rows (phi = rho + 90 mod 180) draws them as points
    over the searched grid, phi unwrapped: a straight line, not a dive from 150 to 0 deg."""
    frame = pd.DataFrame({"case": [91, 301, 511, 541], "ujoint.rho": [0.0, 30.0, 60.0, 90.0],
                          "ujoint.phi": [90.0, 120.0, 150.0, 0.0], "status": "ok", "kept": True,
                          "pp_ratio": [0.0] * 4})
    study = load_study("ujoint")
    labels = {c: column_label(study, c) for c in frame.columns}
    searched = {"ujoint.rho": np.array([0.0, 30.0, 60.0, 90.0]), "ujoint.phi": np.arange(0.0, 180.0, 1.0)}
    fig = plotting.sweep_summary(frame, ["ujoint.rho", "ujoint.phi"], labels=labels, searched=searched, n_cases=720)
    ax = fig.axes[0]
    kept = next(ln for ln in ax.get_lines() if ln.get_label().startswith("kept"))
    assert kept.get_linestyle() == "None"
    x, y = np.asarray(kept.get_xdata(), float), np.asarray(kept.get_ydata(), float)
    assert np.allclose(y - x, 90.0)                       # phi = rho + 90, continuous
    assert "mod 180" in ax.get_ylabel() and "720" in fig.get_suptitle()


def test_maps_of_one_sweep_share_their_slices_and_span_the_searched_range():
    rng = np.random.default_rng(1)
    crank, coupler, rocker = np.linspace(1, 7, 7), np.linspace(6, 20, 8), np.linspace(4, 16, 9)
    rows = [(a, b, c) for a in crank for b in coupler for c in rocker]
    frame = pd.DataFrame(rows, columns=["fourbar.crank", "fourbar.coupler", "fourbar.rocker"])
    frame["kept"] = (frame["fourbar.crank"] < 4) & (frame["fourbar.rocker"] < 12)
    frame = frame[frame["kept"]].reset_index(drop=True)   # a kept-only table
    for col in ("mu_min_deg", "mu_max_deg", "rocker_swing_deg"):
        frame[col] = rng.uniform(20, 80, len(frame))
    study = load_study("fourbar")
    labels = {c: column_label(study, c) for c in frame.columns}
    searched = {"fourbar.crank": crank, "fourbar.coupler": coupler, "fourbar.rocker": rocker}
    figs = plotting.sweep_maps(frame, list(searched), ["rocker_swing_deg", "mu_min_deg", "mu_max_deg"], labels,
                               study.sweep_best, "t", True, searched=searched)
    titles = [[a.get_title() for a in f.axes if a.get_title().startswith("rocker length")] for f in figs]
    assert titles[0] and titles[0] == titles[1] == titles[2]   # one shared slice
    for f in figs:
        ax = next(a for a in f.axes if a.get_title().startswith("rocker length"))
        assert ax.get_xlim()[0] < 1.0 and ax.get_xlim()[1] > 7.0     # the searched crank range, not the kept
        assert ax.get_ylim()[0] < 6.0 and ax.get_ylim()[1] > 20.0
        assert "of the 9 searched values" in f._supxlabel.get_text()


def test_manipulator_design_space_has_one_ri2_scale_with_its_bar():
    fig = figures_of("manipulator_case1_report.dat")["design_space"]
    bars = [a for a in fig.axes if "robustness index" in a.get_ylabel()]
    assert len(bars) == 1
    legend = fig.legends[0]
    assert "$RI_2$" in legend.get_title().get_text() and "$C_{rob}$" in legend.get_title().get_text()
    assert len(legend.get_texts()) <= 9   # one entry for all the ellipses


def test_nonlinear_strain_per_speed_with_buckled_speeds_framed():
    from driver.slidercrank import _figures as sc
    x = np.linspace(0.0, 360.0, 73)
    calm = (x, 10 * np.cos(np.radians(x)), 10.5 * np.cos(np.radians(x)))
    spike = (x, 20 * np.cos(np.radians(x)), 4600 * np.exp(-((x - 350) / 3) ** 2))
    fig = sc.slidercrank_nl_strain_figure([("11.52 rad/s", *calm), ("29.32 rad/s", *spike)], "t",
                                          buckled={"29.32 rad/s": "lateral deflection 127 mm > 10.1 mm"})
    a, b = fig.axes[:2]
    assert a.get_ylim()[1] < 50 and b.get_ylim()[1] > 4000     # each speed on its own scale
    assert b.get_title().startswith("29.32 rad/s: buckled") and "buckled" not in a.get_title()
    assert b.title.get_color() == sc.BUCKLED
    keys = [t.get_text() for t in fig.legends[0].get_texts()]
    assert any(k.startswith("nonlinear rod") for k in keys) and any(k.startswith("linear model") for k in keys)
