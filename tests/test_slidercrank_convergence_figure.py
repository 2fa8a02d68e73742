"""The slider-crank element-convergence figure as an engineer reads a convergence study (issue
28): the peak strain against the number of elements on a log axis, and the size of its
difference from the finest mesh on log-log axes, in words with units.

Truth: the values drawn are those the run prints in its Table 3 (read back from the .out text,
not from the figure code), the differences are recomputed here from them, and the drawn slopes
are the orders the model's notes claim: the crank-end element strain (an element average of a
strain that varies along the rod) converges as 1/N, the pin strain recovered by linear
extrapolation from the first two elements as 1/N^2.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("matplotlib")

import driver

DECK = ("&slidercrank\n material = 'aluminium'\n speeds = 29.32\n"
        " element_counts = 2, 4, 8, 16, 32, 64, 128\n steps_per_rev = 360, revolutions = 2\n/\n")


def _table3(text: str) -> np.ndarray:
    """(elements, element tensile peak, pin tensile peak) rows of the .out's Table 3."""
    rows = []
    for line in text[text.index("Table 3"):].splitlines():
        parts = line.split()
        if len(parts) == 10 and parts[0].isdigit():
            rows.append([float(parts[0]), float(parts[2]), float(parts[6])])
        elif rows and not line.strip():
            break
    return np.array(rows)


@pytest.fixture(scope="module")
def run():
    return driver.run(DECK, name="conv")


def test_the_figure_draws_the_printed_study_on_log_axes(run):
    table = _table3(run.text)
    fig = run.figure("convergence")
    fig.canvas.draw()
    ax_q, ax_e = fig.axes[:2]
    assert ax_q.get_xscale() == "log" and ax_e.get_xscale() == "log" and ax_e.get_yscale() == "log"
    assert ax_q.get_xlabel() == ax_e.get_xlabel() == "number of rod elements $N$"
    assert ax_q.get_ylabel() == "peak tensile strain [microstrain]"
    assert ax_e.get_ylabel() == "|difference from the finest mesh| [%]"
    assert ax_q.xaxis.get_major_formatter()(10.0, 0) == "10"   # plain numbers, not 10^1
    element, pin = ax_q.lines[0], ax_q.lines[2]   # (the finest-mesh line sits between them)
    assert np.allclose(element.get_xdata(), table[:, 0]) and np.allclose(element.get_ydata(), table[:, 1], atol=6e-4)
    assert np.allclose(pin.get_ydata(), table[:, 2], atol=6e-4)
    finest = table[-1]
    for line, col in ((ax_e.lines[0], 1), (ax_e.lines[1], 2)):
        want = 100 * np.abs(table[:-1, col] - finest[col]) / finest[col]
        x, y = np.asarray(line.get_xdata()), np.asarray(line.get_ydata())
        assert set(table[:-1, 0][want > 5e-3]) <= set(x) <= set(table[:-1, 0])   # every coarser mesh drawn
        at = np.searchsorted(table[:, 0], x)
        assert np.allclose(y, want[at], atol=2e-3)   # the table prints 3 decimals of microstrain
    texts = [t.get_text() for t in fig.legends[0].get_texts()]
    assert any(t.startswith("crank-end element") for t in texts) and any("crank pin" in t for t in texts)
    assert "aluminium rod at 29.32 rad/s" in fig._suptitle.get_text()


def test_the_drawn_convergence_orders_are_the_models(run):
    """Observed order between N = 4 and N = 32 (well inside the study, away from the finest mesh
    the differences are taken against): about 1 for the element average, about 2 at the pin."""
    ax_e = run.figure("convergence").axes[1]
    for line, order in ((ax_e.lines[0], 1.0), (ax_e.lines[1], 2.0)):
        x, y = np.asarray(line.get_xdata()), np.asarray(line.get_ydata())
        a, b = np.flatnonzero(x == 4)[0], np.flatnonzero(x == 32)[0]
        observed = -math.log(y[b] / y[a]) / math.log(x[b] / x[a])
        assert observed == pytest.approx(order, abs=0.25), (order, observed)


def test_the_settled_mesh_is_named(run):
    """The legend names the coarsest mesh from which every finer one is within 0.1 % of the
    finest (recomputed from the printed table)."""
    table = _table3(run.text)
    texts = [t.get_text() for t in run.figure("convergence").legends[0].get_texts()]
    for col, key in ((1, "crank-end element"), (2, "crank pin")):
        err = 100 * np.abs(table[:, col] - table[-1, col]) / table[-1, col]
        bad = np.flatnonzero(err > 0.1)
        n_ok = table[bad[-1] + 1, 0] if bad.size else table[0, 0]
        label = [t for t in texts if key in t][0]
        assert label.endswith(f"within 0.1 % from N = {n_ok:g}") or n_ok == table[-1, 0]
