"""Figures: house style without global state, names and units on the axes, the issue's
requirements per study, and byte-for-byte reproducible PNG/SVG/PDF."""
from __future__ import annotations

import subprocess
import sys

import matplotlib
import numpy as np
import pandas as pd
import pytest

from conftest import INPUTS

from driver import plotting
from driver.deck import read_deck
from driver.runner import run_study


def _figures(deck_name: str) -> dict:
    outcome = run_study(read_deck(INPUTS / f"{deck_name}.dat"), None, [], False)
    return {f.name: f for f in outcome.result.figures}


def _draw(fig_spec):
    with matplotlib.rc_context(plotting.STYLE):
        return fig_spec.draw()


def test_plotting_changes_no_global_state():
    before = dict(matplotlib.rcParams)
    backend = matplotlib.get_backend()
    fig = plotting.line_panels(np.arange(3.0), [("y [m]", {"a": np.arange(3.0)})], "x [s]")
    plotting.save_figure(fig, "/dev/null.png") if False else None
    assert dict(matplotlib.rcParams) == before and matplotlib.get_backend() == backend
    assert fig.axes[0].yaxis.label.get_fontsize() == plotting.STYLE["axes.labelsize"]


@pytest.mark.parametrize("fmt, magic", [("png", b"\x89PNG"), ("svg", b"<?xml"), ("pdf", b"%PDF")])
def test_figures_are_byte_for_byte_reproducible(tmp_path, fmt, magic):
    figs = _figures("crank5")
    a = plotting.save_figure(figs["linkage"].draw, tmp_path / f"a.{fmt}").read_bytes()
    b = plotting.save_figure(figs["linkage"].draw, tmp_path / f"b.{fmt}").read_bytes()
    assert a.startswith(magic) and a == b


def test_quantity_labels_carry_units():
    assert plotting.quantity_label("omega3_peak_rad_s") == "omega3 peak [rad/s]"
    assert plotting.quantity_label("peak_tensile_1_microstrain") == "peak tensile 1 [µε]"
    assert plotting.quantity_label("rocker_swing_deg") == "rocker swing [deg]"
    assert plotting.quantity_label("slidercrank.speeds", {"slidercrank.speeds": "rad/s"}) == "speeds [rad/s]"
    assert plotting.quantity_label("euler_ratio_max") == "euler ratio max"


def test_fourbar_angles_drawn_without_the_wrap_jump_and_axes_labelled():
    figs = _figures("nongrashof")
    curves = figs["curves"].draw()
    for line in curves.axes[0].get_lines():
        y = np.asarray(line.get_ydata(), float)
        d = np.abs(np.diff(y))
        assert not (d[np.isfinite(d)] > 180).any()
    linkage = figs["linkage"].draw()
    ax = linkage.axes[0]
    assert "x [" in ax.get_xlabel() and "y [" in ax.get_ylabel()
    legend = ax.get_legend()
    assert legend is not None and legend.get_bbox_to_anchor().x0 > ax.get_window_extent().x1 - 1  # beside the axes


def test_ujoint_overlays_designs_draws_the_paper_band_and_keeps_small_fluctuations_visible():
    figs = _figures("ujoint_option3")
    speed = figs["speed"].draw()
    assert len(speed.axes) == 1
    labels = [t.get_text() for t in speed.axes[0].get_legend().get_texts()]
    assert any("trial" in s for s in labels) and any("optimum" in s for s in labels)
    assert any("paper's trial band" in s for s in labels)
    polar = figs["polar"].draw()
    ax = polar.axes[0]
    assert ax.get_rmin() > 0 and "rpm" in " ".join(t.get_text() for t in ax.texts + [ax.title])
    w = plotting.ujoint_speed_figure(np.arange(361.0), 25.0, {"optimum": 25.0 + 0.4 * np.sin(np.radians(2 * np.arange(361.0)))},
                                     polar=True)
    lo, hi = w.axes[0].get_rmin(), w.axes[0].get_rmax()
    assert lo > 20 and hi - lo < 5   # a +-0.4 rpm fluctuation fills the plot


def test_manipulator_left_panel_draws_iso_ri2_ellipses_and_torques_mark_reach():
    figs = _figures("manipulator_case2_report")
    design = figs["design_space"].draw()
    left = design.axes[0]
    assert "iso-RI2" in left.get_title()
    assert any(len(getattr(c, "get_paths", lambda: [])()) for c in left.collections[1:])   # contour lines drawn
    torque = figs["torque_crob"].draw()
    labels = [t.get_text() for t in torque.axes[0].get_legend().get_texts()]
    assert any("reach conditions" in s for s in labels)


def test_ri2_closed_form_matches_the_kernel():
    from driver import kernels
    x, y = np.array([1.0, 2, 3, 4]), np.array([5.0, 7, 7, 6])
    l1, l2 = np.array([4.86, 5.61, 5.0]), np.array([4.86, 3.97, 4.5])
    ri = kernels.manipulator_design_indices(x, y, l1, l2)[0][:, 1]
    assert np.allclose(plotting.ri2_closed_form(l1, l2, float((x * x + y * y).sum()), 4), ri, rtol=1e-12)


def test_slidercrank_names_buckled_speeds_and_flags_cases_above_euler():
    fig = plotting.slidercrank_strain_figure([("10 rad/s", np.arange(361.0), np.zeros(361)),
                                              ("30 rad/s", np.arange(361.0), np.ones(361))], "t",
                                             buckled=["40 rad/s"], over_euler={"30 rad/s": 1.43})
    ax = fig.axes[0]
    assert any("40 rad/s" in t.get_text() for t in ax.texts)
    assert any("1.43" in t.get_text() for t in ax.get_legend().get_texts())


def test_sweep_summary_labels_units_and_drops_trivial_panels():
    frame = pd.DataFrame({"case": [1, 2, 3], "slidercrank.speeds": [10.0, 20.0, 30.0], "kept": [True] * 3,
                          "omega_1_rad_s": [10.0, 20.0, 30.0], "n_buckled": [0, 0, 0],
                          "peak_tensile_microstrain": [1.0, 4.0, 9.0], "peak_tensile_1_microstrain": [1.0, 4.0, 9.0]})
    fig = plotting.sweep_summary(frame, ["slidercrank.speeds"], units={"slidercrank.speeds": "rad/s"})
    assert [ax.get_ylabel() for ax in fig.axes] == ["peak tensile [µε]"]
    assert fig.axes[-1].get_xlabel() == "speeds [rad/s]"


def test_plot_format_svg_from_the_command_line(tmp_path):
    res = subprocess.run([sys.executable, "-m", "driver", str(INPUTS / "crank5_exact.dat"), "--plot-format", "svg",
                          "-o", "o", "-q"], cwd=tmp_path, capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    names = sorted(p.name for p in (tmp_path / "o").iterdir())
    assert names == ["crank5_exact.out", "crank5_exact_curves.svg", "crank5_exact_linkage.svg"]
    assert (tmp_path / "o" / "crank5_exact_curves.svg").read_bytes().startswith(b"<?xml")
