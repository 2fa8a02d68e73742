"""Figure text: deck text is drawn literally (never as mathtext), the tool's own labels use
mathtext symbols, and the figures the issue found missing exist with the right content."""
from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("matplotlib")

import driver
from conftest import INPUTS


def _is_math(text_artist) -> bool:
    return bool(text_artist._preprocess_math(text_artist.get_text())[1])


def test_deck_titles_are_never_mathtext(tmp_path):
    """A title with dollar signs ('cost $x$ per $y$') is drawn as written: every figure renders,
    and no title of a deck's text is parsed as mathtext."""
    title = "cost $x$ per $y$ \\alpha"
    r = driver.fourbar.run(fixed_link=12.0, crank=5.0, coupler=15.0, rocker=9.0, step_deg=20, title=title)
    for name in r.figure_names:
        fig = r.figure(name)
        fig.canvas.draw()   # a mathtext parse error would raise here
        titles = [t for t in ([fig._suptitle] if fig._suptitle else []) + [a.title for a in fig.axes]
                  if "cost" in t.get_text()]
        assert titles, name
        for t in titles:
            assert not _is_math(t)
            assert t._preprocess_math(t.get_text())[0].startswith("cost $x$ per $y$")


def _with_title(deck: str, title: str) -> str:
    """The shipped deck's text with its study group's title set to ``title``."""
    import re
    text = (INPUTS / f"{deck}.dat").read_text()
    if re.search(r"\btitle\s*=", text):
        return re.sub(r"\btitle\s*=\s*('[^']*'|\"[^\"]*\")", lambda m: f"title = '{title}'", text)
    return re.sub(r"(&\w+)", lambda m: f"{m.group(1)} title = '{title}',", text, count=1)


def test_a_deck_title_is_never_mathtext_in_the_force_figures():
    """The force analysis's figures (torque, pin forces, shaking) took the deck's title raw: a
    title 'cost $x$ per $y$' was typeset as mathtext there."""
    r = driver.run(_with_title("fourbar_forces_balanced", "cost $x$ per $y$"))
    for name in ("torque", "pin_forces", "shaking"):
        fig = r.figure(name)
        fig.canvas.draw()
        assert fig._suptitle is not None and "cost" in fig._suptitle.get_text(), name
        assert not _is_math(fig._suptitle)
        assert fig._suptitle._preprocess_math(fig._suptitle.get_text())[0].startswith("cost $x$ per $y$")


@pytest.mark.parametrize("deck", ["crank5", "fourbar_forces_balanced", "manipulator_case1_report", "robust_example"])
def test_a_75_kB_title_stays_on_the_canvas_bounded(deck):
    """A deck's 75 000-character title without a blank: every figure shows it cut in the middle
    to NAME_CHARS characters and wrapped to the figure's width, all its text on the canvas (it
    ran 158 000 pixels off the canvas and collapsed the force figures' layout)."""
    import re

    from driver._names import NAME_CHARS
    from figure_checks import text_outside
    r = driver.run(_with_title(deck, "t" * 75_000))
    assert r.figure_names
    for name in r.figure_names:
        fig = r.figure(name)
        assert text_outside(fig) == [], name
        from matplotlib.text import Text
        shown = "".join(t.get_text() for t in fig.findobj(Text))
        assert "characters)" in shown, name
        assert sum(len(m) for m in re.findall(r"t{50,}", shown)) <= NAME_CHARS, name


def test_tool_labels_use_mathtext_symbols():
    r = driver.fourbar.run(fixed_link=12.0, crank=5.0, coupler=15.0, rocker=9.0, step_deg=20)
    fig = r.figure("curves")
    assert fig.axes[-1].get_xlabel() == r"crank angle $\theta_2$ [deg]"
    legend = [t.get_text() for t in fig.axes[2].get_legend().get_texts()]
    assert any(r"$\omega_4$" in t and t.startswith("rocker") for t in legend)
    assert any(r"$\omega_3$" in t and t.startswith("coupler") for t in legend)


def test_an_expression_label_is_drawn_literally():
    import pandas as pd

    from driver import plotting
    from driver._output import column_label, expression_label
    expr = 'mu_min_deg + 0*("$" == "$")'
    frame = pd.DataFrame({"case": [1, 2, 3], "fourbar.crank": [2.0, 3.0, 4.0], "kept": [True] * 3,
                          expr: [40.0, 33.0, 26.0]})
    fig = plotting.sweep_summary(frame, ["fourbar.crank"], ys=[expr],
                                 labels={c: column_label(driver.fourbar.STUDY, c) for c in frame.columns})
    fig.canvas.draw() if fig.canvas is not None else None
    ylabel = fig.axes[0].yaxis.label
    assert not _is_math(ylabel) and "$" in ylabel._preprocess_math(ylabel.get_text())[0]
    lab = expression_label(driver.fourbar.STUDY, "min(mu_min_deg, 180 - mu_max_deg)")
    assert lab == "min(minimum transmission angle, 180 - maximum transmission angle) [deg]"


def test_robust_example_draws_its_fits():
    """robust_example draws the mean and spread of Y against the target with the four t_min
    estimates, at the values the .out reports (true t_min = -b1 / (2 b2) = 15 for (2.1))."""
    r = driver.run(str(INPUTS / "robust_example.dat"))
    assert r.figure_names == ["fits"]
    fig = r.figure("fits")
    top, bot = fig.axes[:2]
    assert bot.get_yscale() == "log"
    vlines = {ln.get_label(): ln.get_xdata()[0] for ln in bot.lines if ln.get_label().startswith("$t_{min}$")}
    b = [-6.0, 1.2, -0.04]
    assert vlines["$t_{min}$ true (2.2) = 15.000"] == pytest.approx(-b[1] / (2 * b[2]))
    for key, label in (("tmin_dual_response", "dual response (2.9)"), ("tmin_taguchi", "Taguchi (2.13)"),
                       ("tmin_tolerance_analysis", "tolerance analysis (2.15)")):
        name = f"$t_{{min}}$ {label} = {r.summary[key]:.3f}"
        assert vlines[name] == pytest.approx(r.summary[key])
    # the known relation's spread (2.2) at t = 15 is sqrt(2 b2^2 sigma_x^4) = sqrt(2) |b2| sigma_x^2 (the slope term vanishes)
    exact = [ln for ln in bot.lines if ln.get_label().startswith("tolerance analysis of (2.1)")][0]
    t, s = exact.get_xdata(), exact.get_ydata()
    assert np.interp(15.0, t, s) == pytest.approx(math.sqrt(2) * 0.04 * 0.5 ** 2, rel=1e-3)


def test_simeon_benchmark_draws_its_history():
    """The Simeon (1996) benchmark deck draws q1 and q4 against time; the drawn history ends at
    the end state the .out tabulates, the reference marker sits at Simeon's published values,
    and the two agree within the .out's 0.2 % (a linear KED model against the full model)."""
    from driver.slidercrank import SIMEON1996
    r = driver.run(str(INPUTS / "slidercrank_simeon1996.dat"))
    assert "history" in r.figure_names
    fig = r.figure("history")
    mid_ax, elong_ax = fig.axes[:2]
    model = mid_ax.lines[0]
    ref = [ln for ln in mid_ax.lines if ln.get_label().startswith("Simeon")][0]
    t, q1 = model.get_xdata(), model.get_ydata()
    assert t[0] == 0.0 and t[-1] == pytest.approx(0.1)
    table = {line.split()[-5]: float(line.split()[-3]) for line in r.text.splitlines()
             if "(q1)" in line or "(q4)" in line}   # quantity ... (q1)  m  this-model  Simeon  diff%
    assert q1[-1] == pytest.approx(table["(q1)"] * 1e3, rel=1e-9)   # [mm]
    assert elong_ax.lines[0].get_ydata()[-1] == pytest.approx(table["(q4)"] * 1e6, rel=1e-9)   # [um]
    assert ref.get_xdata()[0] == SIMEON1996["t"] and ref.get_ydata()[0] == pytest.approx(SIMEON1996["q1"] * 1e3)
    assert q1[-1] == pytest.approx(ref.get_ydata()[0], rel=5e-3)
    # the end values written beside the marker, with units, in the figure's own font and size
    note = mid_ax.texts[0]
    assert note.get_text() == f"reference {SIMEON1996['q1'] * 1e3:.4g} mm\nthis model {q1[-1]:.4g} mm"
    assert elong_ax.texts[0].get_text().endswith(r"$\mu$m") and "this model" in elong_ax.texts[0].get_text()
    assert note.get_fontname() == mid_ax.yaxis.label.get_fontname() and note.get_fontsize() >= 8.5
    assert ref.get_xdata()[0] < mid_ax.get_xlim()[1] - 0.1 * (mid_ax.get_xlim()[1] - mid_ax.get_xlim()[0])   # room for it


def test_report_page_text_of_a_label():
    """The report page writes figure labels as text: mathtext symbols as Unicode, a deck's
    escaped dollar as a dollar."""
    from driver._report_page import plain
    assert plain(r"phase angle $\varphi_{12}$ [deg]") == "phase angle φ₁₂ [deg]"
    assert plain(r"crank angle $\theta_2$ [deg]") == "crank angle θ₂ [deg]"
    assert plain(r"cost \$x\$ per part") == "cost $x$ per part"


def test_figure_functions_draw_into_a_users_axes():
    """The matplotlib convention: a figure function given ``ax=``/``axes=`` draws there and returns
    that figure (a user's own layout, e.g. two studies side by side)."""
    from matplotlib.figure import Figure

    from driver import plotting
    from driver.fourbar import _figures as fourbar_figures
    from driver.slidercrank import _figures as slidercrank_figures
    from driver.ujoint import _figures as ujoint_figures
    fig = Figure(layout="constrained")
    a, b = fig.subplots(1, 2)
    theta = np.linspace(0.0, 360.0, 73)
    assert ujoint_figures.ujoint_speed_figure(theta, 25.0, {"optimum": 25 + np.sin(np.radians(2 * theta))}, ax=a) is fig
    assert slidercrank_figures.slidercrank_strain_figure([("10 rad/s", theta, np.cos(np.radians(theta)))], "t", ax=b) is fig
    assert a.lines and b.lines
    fig2 = Figure()
    axes = fig2.subplots(2, 1)
    assert plotting.line_panels(theta, [("y", {"a": theta}), ("z", {"b": -theta})], "x", axes=axes) is fig2
    assert axes[0].lines and axes[1].lines
    fig3 = Figure()
    axes3 = fig3.subplots(3, 1)
    r = driver.fourbar.run(fixed_link=12.0, crank=5.0, coupler=15.0, rocker=9.0, step_deg=20)
    from driver.fourbar._analysis import exact_columns, exact_grid, tidy_frame
    out, st = exact_grid(r.params, theta)
    assert fourbar_figures.fourbar_curves(tidy_frame("exact", theta, exact_columns(out, st), st), None, "",
                                   axes=axes3) is fig3


def test_manipulator_labels_set_their_symbols_in_mathtext():
    """The manipulator's summary labels name l1, l2, tau1, tau2, RI2, C_rob as mathtext symbols
    (the renamed torque columns included), render, and the design-search map shows them."""
    import matplotlib.pyplot as plt
    import pandas as pd

    from conftest import ROOT
    from driver import plotting
    from driver._output import column_label
    m = driver.manipulator.STUDY
    want = {"design_tau_sum_signed_Nm": r"$\tau_1 + \tau_2$", "design_torque_demand_Nm": r"$|\tau_1| + |\tau_2|$",
            "design_peak_torque_Nm": r"$\max(|\tau_1|, |\tau_2|)$", "sweep_min_tau_sum_signed_Nm": r"$\tau_1 + \tau_2$",
            "design_l1_m": "$l_1$", "design_l2_m": "$l_2$", "design_ri2": "$RI_2$", "crob_radius_m": "$C_{rob}$",
            "designs_l1": "$l_1$", "designs_l2": "$l_2$", "design_ri2_excess": r"$RI_2 - \sqrt{n}$"}
    fig = plt.figure()
    for name, symbol in want.items():
        label = column_label(m, name)
        assert symbol in label, (name, label)
        t = fig.text(0, 0, label)
        assert _is_math(t)
    fig.canvas.draw()   # every label parses as mathtext
    import re
    for name, (words, units) in m.labels.items():   # no ASCII symbol left outside the mathtext
        outside = re.sub(r"\$[^$]*\$", "", f"{words} [{units}]")
        for ascii_ in ("tau", " l1", " l2", "RI", "C_rob", "sqrt", "^"):
            assert ascii_ not in outside, (name, words, units)
    plt.close(fig)
    frame = pd.read_parquet(ROOT / "outputs" / "manipulator_design_search_summary.parquet")
    keys = ["manipulator.designs_l1", "manipulator.designs_l2"]
    labels = {c: column_label(m, c) for c in frame.columns}
    fig = plotting.sweep_maps(frame, keys, ["design_torque_demand_Nm"], labels, m.sweep_best, "search", True)[0]
    fig.canvas.draw()
    texts = [a.get_xlabel() for a in fig.axes] + [a.get_ylabel() for a in fig.axes]
    assert "design link length $l_1$ [m]" in texts and "design link length $l_2$ [m]" in texts
    assert any(r"$|\tau_1| + |\tau_2|$" in t for t in texts)   # the colour bar


def test_report_page_writes_manipulator_symbols_as_unicode():
    from driver._output import column_label
    from driver._report_page import plain
    m = driver.manipulator.STUDY
    assert plain(column_label(m, "design_torque_demand_Nm")) == \
        "design torque demand |\u03c4\u2081| + |\u03c4\u2082| at the target [N m]"
    assert plain(column_label(m, "design_ri2_excess")) == "design RI\u2082 - \u221an [-]"
    assert plain(column_label(m, "crob_c_m2")) == "C_rob: l\u2081\u00b2 + l\u2082\u00b2 [m\u00b2]"
    assert plain(r"cost \$x\$ of $\omega_2$") == "cost $x$ of \u03c9\u2082"


def test_a_wrapped_label_keeps_each_mathtext_span_on_one_line():
    """Long labels are wrapped onto lines; each line is parsed on its own, so a span
    ($|\\tau_1| + |\\tau_2|$) cut in two would be drawn as raw source."""
    from driver import plotting
    label = driver._output.column_label(driver.manipulator.STUDY, "design_torque_demand_Nm")
    for width in (10, 20, 30, 40):
        lines = plotting.wrap(label, width).split("\n")
        assert len(lines) > 1
        for line in lines:
            assert line.replace(r"\$", "").count("$") % 2 == 0, line
        assert " ".join(lines) == label
    assert plotting.wrap("cost $ more than a long line", 10).replace("\n", " ") == "cost $ more than a long line"
