"""Visual regression: every figure kind the tool draws, rendered and compared with a stored
baseline image (tests/baseline_figures/*.png) within a tolerance (matplotlib.testing.compare,
RMS of the pixel difference on a 0-255 scale), so a later change cannot silently break a figure.

The baselines were drawn by this code and checked by eye at print size (issue 28); they are
rendered at 50 dpi to stay small (a few tens of kB each) with matplotlib's bundled DejaVu fonts
and no hinting, so the same matplotlib gives the same pixels on any machine.  When a figure is
changed on purpose, look at the new drawing and regenerate the baselines:

    DRIVER_REGEN_BASELINES=1 .venv/bin/python -m pytest -q tests/test_figure_baselines.py

A failing comparison leaves the drawn image and a difference image beside the test's tmp_path.
"""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

pytest.importorskip("matplotlib")
import matplotlib
from matplotlib.testing.compare import compare_images

import driver
from conftest import INPUTS, ROOT

BASELINES = Path(__file__).parent / "baseline_figures"
#: RMS tolerance on a 0-255 scale.  The same matplotlib draws the same pixels (RMS 0.0); a changed
#: axis label gives about 3.4, a curve in another colour 3.0, a missing curve 5.2 (fourbar_curves)
TOL = 1.0
DPI = 50
REGEN = bool(os.environ.get("DRIVER_REGEN_BASELINES"))
#: rendering settings that make pixels depend on matplotlib only (not on system fonts or hinting)
TEST_RC = {"font.family": "DejaVu Sans", "text.hinting": "none",
           "savefig.dpi": DPI, "figure.dpi": DPI, "svg.hashsalt": "baselines"}


def _fourbar(deck: str, name: str):
    return driver.run(str(INPUTS / deck)).figure(name)


def _design_map(keys: int):
    from driver import plotting
    from driver._output import column_label
    grid = {"crank": np.linspace(2.0, 5.0, 7), "coupler": np.linspace(10.0, 16.0, 7),
            "rocker": np.linspace(7.0, 11.0, 4)}
    grid = dict(list(grid.items())[:keys])
    s = driver.run_sweep({"fourbar": dict(fixed_link=12.0, crank=3.0, coupler=15.0, rocker=9.0, step_deg=10)},
                         grid=grid, keep="meets_transmission_band", case_outputs="none", jobs=1)
    frame = s.summary
    names = [f"fourbar.{k}" for k in grid]
    labels = {c: column_label(driver.fourbar.STUDY, c) for c in frame.columns}
    if keys == 1:
        best = plotting.best_index(frame, "mu_min_deg", "max")
        return plotting.design_space_map(frame, names, "mu_min_deg", labels, best=best, best_text="best",
                                         title="one swept key")
    return plotting.sweep_maps(frame, names, ["mu_min_deg"], labels, driver.fourbar.SWEEP_BEST,
                               title=f"{keys} swept keys", searched={f"fourbar.{k}": v for k, v in grid.items()})[0]


def _convergence():
    from driver import plotting
    history = pd.read_csv(ROOT / "outputs" / "optimize_manipulator_torque_history.csv")
    evals = pd.read_parquet(ROOT / "outputs" / "optimize_manipulator_torque_evals.parquet")
    from driver._output import expression_label  # the label the optimiser gives it (mathtext symbols)
    best = float(history["objective"].min())
    return plotting.convergence_plot(history, evals, expression_label(driver.manipulator.STUDY, "design_torque_demand_Nm"),
                                     "minimize", title="convergence", tolerance=1e-3 * best,
                                     tolerance_words=f"tol x max(1, |best|) = 0.001 x {best:.6g}")


def _manipulator_search():
    """The shipped manipulator design search's map (its labels carry mathtext symbols)."""
    from driver import plotting
    from driver._output import column_label
    frame = pd.read_parquet(ROOT / "outputs" / "manipulator_design_search_summary.parquet")
    labels = {c: column_label(driver.manipulator.STUDY, c) for c in frame.columns}
    return plotting.sweep_maps(frame, ["manipulator.designs_l1", "manipulator.designs_l2"],
                               ["design_torque_demand_Nm"], labels, driver.manipulator.SWEEP_BEST,
                               "manipulator design search", True)[0]


def _sweep_strips():
    from driver import plotting
    frame = pd.DataFrame({"case": [1, 2, 3, 4], "fourbar.crank": [2.0, 3.0, 4.0, 5.0],
                          "kept": [True, True, False, False],
                          "mu_min_deg": [40.27, 33.56, 26.32, 17.85], "rocker_swing_deg": [32.26, 49.30, 67.81, 89.47]})
    return plotting.sweep_summary(frame, ["fourbar.crank"], title="strips",
                                  labels={"fourbar.crank": "crank length [length units]",
                                          "mu_min_deg": "minimum transmission angle [deg]",
                                          "rocker_swing_deg": "rocker swing [deg]"})


def _result_figure(deck: str, name: str, **keys):
    return driver.run(str(INPUTS / deck)).figure(name)


def _slidercrank(name: str):
    deck = ("&slidercrank\n material = 'aluminium'\n crank_radius = 0.125, rod_length = 0.505\n"
            " slider_mass = 0.9, bearing_mass_crank = 0.05, bearing_mass_slider = 0.05\n"
            " speeds = 11.52, 29.32\n n_elements = 8, steps_per_rev = 360, revolutions = 2\n/\n")
    return driver.run(deck, name="slidercrank_small").figure(name)


def _function_error():
    from driver import plotting
    x = np.linspace(1.0, 2.0, 101)
    return plotting.line_panels(x, [("y", {"desired": np.log10(x), "generated": np.log10(x) + 1e-3 * np.sin(9 * x)}),
                                    ("error", {"error": 1e-3 * np.sin(9 * x)})], "x", title="line panels")


def _nonlinear_strain():
    deck = ("&slidercrank\n material = 'aluminium'\n speeds = 11.52, 29.32\n n_elements = 8\n"
            " steps_per_rev = 720, revolutions = 4\n damping_ratio = 0.02\n model = 'nonlinear'\n/\n")
    return driver.run(deck, name="nonlinear_small").figure("strain_linear_nonlinear")


def _phasing_map():
    """The shipped phasing sweep's map: the ratio over the searched (rho, phi) plane."""
    from driver.sweep._report import summary_figures
    s = driver.run_sweep(str(INPUTS / "ujoint_phasing_sweep.dat"), jobs=1)
    return summary_figures(s.summary, s.sweep, ["ujoint.rho", "ujoint.phi"], driver.ujoint.STUDY,
                           "ujoint_phasing_sweep")[0]


#: figure kind -> how to draw it (real runs of shipped decks where they are quick)
KINDS = {
    "fourbar_curves": lambda: _fourbar("crank5.dat", "curves"),
    "fourbar_linkage": lambda: _fourbar("crank5.dat", "linkage"),
    "fourbar_linkage_coupler_point": lambda: _fourbar("crank5_coupler_point.dat", "linkage"),
    "fourbar_linkage_nongrashof": lambda: _fourbar("nongrashof.dat", "linkage"),
    "fourbar_linkage_doublerocker": lambda: _fourbar("doublerocker.dat", "linkage"),
    "fourbar_curves_double_crank": lambda: _fourbar("doublecrank.dat", "curves"),
    "design_space_1_key": lambda: _design_map(1),
    "design_space_2_keys": lambda: _design_map(2),
    "design_space_3_keys": lambda: _design_map(3),
    "convergence": _convergence,
    "manipulator_design_search": _manipulator_search,
    "sweep_strips": _sweep_strips,
    "ujoint_speed": lambda: _result_figure("ujoint_option1.dat", "speed"),
    "ujoint_polar": lambda: _result_figure("ujoint_option1.dat", "polar"),
    "manipulator_design_space": lambda: _result_figure("manipulator_case1_report.dat", "design_space"),
    "manipulator_torque_crob": lambda: _result_figure("manipulator_case1_report.dat", "torque_crob"),
    "robust_example_fits": lambda: _result_figure("robust_example.dat", "fits"),
    "slidercrank_strain": lambda: _slidercrank("strain"),
    "slidercrank_deflection": lambda: _slidercrank("deflection"),
    "slidercrank_convergence": lambda: driver.run(
        "&slidercrank\n material = 'aluminium'\n speeds = 29.32\n element_counts = 1, 2, 4, 8, 16, 32\n"
        " steps_per_rev = 360, revolutions = 2\n/\n", name="convergence_small").figure("convergence"),
    "slidercrank_simeon_history": lambda: _result_figure("slidercrank_simeon1996.dat", "history"),
    "line_panels": _function_error,
    "fourbar_linkage_balanced": lambda: _fourbar("fourbar_forces_balanced.dat", "linkage"),
    "fourbar_torque": lambda: _fourbar("fourbar_forces_balanced.dat", "torque"),
    "fourbar_pin_forces": lambda: _fourbar("fourbar_forces_balanced.dat", "pin_forces"),
    "fourbar_shaking": lambda: _fourbar("fourbar_forces_balanced.dat", "shaking"),
    "slidercrank_nonlinear_strain": _nonlinear_strain,
    "ujoint_phasing_map": _phasing_map,
}


@pytest.mark.parametrize("kind", sorted(KINDS))
def test_figure_matches_its_baseline(kind, tmp_path):
    with matplotlib.rc_context(TEST_RC):
        fig = KINDS[kind]()
        baseline = BASELINES / f"{kind}.png"
        if REGEN:
            BASELINES.mkdir(exist_ok=True)
            fig.savefig(baseline, dpi=DPI, metadata={"Software": None})
            pytest.skip(f"baseline {baseline.name} written")
        drawn = tmp_path / f"{kind}.png"
        fig.savefig(drawn, dpi=DPI, metadata={"Software": None})
    assert baseline.is_file(), f"no baseline for {kind}: run with DRIVER_REGEN_BASELINES=1 and look at it"
    diff = compare_images(str(baseline), str(drawn), tol=TOL)
    assert diff is None, diff


def test_baselines_are_small_and_complete():
    """Every stored baseline belongs to a figure kind, and none is large."""
    stored = {p.stem for p in BASELINES.glob("*.png")}
    assert stored == set(KINDS)
    assert sum(p.stat().st_size for p in BASELINES.glob("*.png")) < 1_500_000


@pytest.mark.parametrize("damage", ["remove a curve", "relabel an axis", "recolour a curve"])
def test_a_broken_figure_fails_the_comparison(tmp_path, damage):
    """The comparison can fail: a curve missing, an axis relabelled or a curve recoloured is
    more than the tolerance away from the baseline."""
    with matplotlib.rc_context(TEST_RC):
        fig = KINDS["fourbar_curves"]()
        ax = fig.axes[2]
        if damage == "remove a curve":
            ax.lines[0].remove()
        elif damage == "relabel an axis":
            fig.axes[0].set_ylabel("link angle [rad]")
        else:
            ax.lines[0].set_color("C5")
        drawn = tmp_path / "broken.png"
        fig.savefig(drawn, dpi=DPI, metadata={"Software": None})
    assert compare_images(str(BASELINES / "fourbar_curves.png"), str(drawn), tol=TOL) is not None
