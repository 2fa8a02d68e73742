"""The slider-crank figures: strain and deflection against crank angle, element convergence, the
time history of a benchmark run against its reference, and the nonlinear rod against the linear
one (strain, deflected shapes, lateral deflection per revolution).

Drawn in the house style (:mod:`driver.plotting`); this module imports matplotlib (the optional
[plot] extra), so the study imports it only when a figure is drawn.
"""
from __future__ import annotations

from typing import Sequence

import numpy as np
from matplotlib.figure import Figure

from driver.plotting import new_figure, plain_text, styled
from driver.deck import Params
from driver.slidercrank.analysis import Case, history
from driver.slidercrank.spec import Model


@styled
def slidercrank_strain_figure(series: Sequence[tuple[str, np.ndarray, np.ndarray]], title: str,
                              ylabel: str = "axial strain [microstrain]", above: dict[str, float] | None = None,
                              missing: Sequence[str] = (), ax=None) -> Figure:
    """A quantity against crank angle [deg], one line per case (label, angle, value): Figure 10.

    ``above`` maps the labels of cases whose rod compression exceeds the Euler load to that
    ratio N/P_E: their curves are dashed and flagged in the legend (a linear model draws
    them although the rod would buckle).  ``missing`` are one-line texts of cases not drawn (e.g. a speed that
    buckled): they are listed in the legend, so no speed silently disappears.  ``ax``: an axes
    to draw into (its figure is returned).
    """
    from matplotlib.lines import Line2D
    above = above or {}
    if ax is None:
        fig, (ax,) = new_figure(1, 1, figsize=(7.4, 4.4))
    else:
        fig = ax.figure
    for label, x, y in series:
        flagged = label in above
        ax.plot(x, y, label=f"{label}: N = {above[label]:.2f} $P_E$, above the Euler load" if flagged else label,
                lw=1.2, ls="--" if flagged else "-")
    for text in missing:
        ax.add_line(Line2D([], [], ls="none", marker="x", color="C3", label=text))
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xlim(0, 360)
    ax.set_xticks(np.arange(0, 361, 45))
    ax.set_xlabel(r"crank angle $\theta_2$ [deg]")
    ax.set_ylabel(ylabel)
    fig.legend(*ax.get_legend_handles_labels(), loc="outside lower center",
               ncol=3 if len(series) + len(missing) > 4 else 2, frameon=False, title="crank speed")
    ax.set_title(plain_text(title))
    return fig


@styled
def slidercrank_convergence_figure(series: dict[str, tuple[list[int], list[float]]], title: str) -> Figure:
    """Peak strain against element count and its percentage change (the paper's Figures 8-9)."""
    fig, axes = new_figure(2, 1, sharex=True, figsize=(7.0, 5.0))
    for label, (n, peak) in series.items():
        n, peak = np.asarray(n, dtype=float), np.asarray(peak, dtype=float)
        axes[0].plot(n, peak, "o-", ms=3, label=label)
        if n.size > 1:
            axes[1].plot(n[1:], 100 * np.diff(peak) / peak[:-1], "o-", ms=3, label=label)
    axes[0].set_xscale("log")
    axes[0].set_ylabel("peak tensile strain [microstrain]")
    axes[1].set_ylabel("change from previous count [%]")
    axes[1].set_xlabel("number of elements")
    axes[0].legend()
    fig.suptitle(plain_text(title))
    return fig


@styled
def slidercrank_history_figure(time: np.ndarray, series: dict[str, np.ndarray], labels: dict[str, str],
                               reference: dict[str, tuple[float, float]], title: str, reference_label: str = "",
                               axes=None) -> Figure:
    """Quantities against time [s], one panel each (``series`` keyed like ``labels``, the axis
    words with units), with a reference value (time, value) marked where given: a benchmark's
    published end state beside the computed history."""
    if axes is None:
        fig, axes = new_figure(len(series), 1, sharex=True, figsize=(7.4, 2.4 * len(series) + 0.8))
    else:
        fig = axes[0].figure
    for ax, (key, y) in zip(axes, series.items()):
        ax.plot(time, y, color="C0", lw=1.2, label="this model (linear KED, Newmark)")
        if key in reference:
            t, v = reference[key]
            ax.plot([t], [v], "D", ms=7, mfc="white", mec="C3", mew=1.5, label=reference_label or "reference")
            ax.annotate(f"{v:.4g}", (t, v), xytext=(-6, 8), textcoords="offset points", ha="right", fontsize=8,
                        color="C3")
        ax.set_ylabel(labels.get(key, key))
        ax.legend(loc="best")
    axes[-1].set_xlabel("time $t$ [s]")
    if title:
        fig.suptitle(plain_text(title))
    return fig


def _own_axes(ax, figsize: tuple[float, float]):
    """(figure, axes): the given axes and its figure, or a new house-style figure."""
    if ax is not None:
        return ax.figure, ax
    fig, axes = new_figure(1, 1, figsize=figsize)
    return fig, axes[0]


@styled
def slidercrank_nl_strain_figure(series: Sequence[tuple[str, np.ndarray, np.ndarray, np.ndarray]], title: str,
                                 ax=None) -> Figure:
    """Crank-end axial strain [microstrain] against crank angle [deg]: per speed (label, angle,
    linear, nonlinear), the linear model dashed and the nonlinear rod solid in one colour."""
    fig, ax = _own_axes(ax, (7.4, 4.4))
    for k, (label, x, lin, nl) in enumerate(series):
        ax.plot(x, nl, color=f"C{k % 10}", lw=1.2, label=label)
        ax.plot(x, lin, color=f"C{k % 10}", lw=0.9, ls="--")
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xlim(0, 360)
    ax.set_xticks(np.arange(0, 361, 45))
    ax.set_xlabel("crank angle theta2 [deg]")
    ax.set_ylabel("axial strain [microstrain]")
    ax.legend(fontsize=7, title="crank speed", title_fontsize=7)
    ax.set_title(title)
    return fig


@styled
def slidercrank_nl_shapes_figure(series: Sequence[tuple[str, tuple[float, float], np.ndarray]], length: float,
                                 title: str, ax=None) -> Figure:
    """Lateral deflection [mm] along the rod [m] at the step of largest deflection (solid) and of
    largest crank-end compression (dotted), one colour per speed; true scale in mm (the axis
    is stretched, not the shape)."""
    fig, ax = _own_axes(ax, (7.4, 4.4))
    for k, (label, (a1, a2), shapes) in enumerate(series):
        s = np.linspace(0.0, length, shapes.shape[0])
        ax.plot(s, shapes[:, 0] * 1e3, color=f"C{k % 10}", lw=1.2, label=f"{label}, theta2 = {a1:.0f} deg")
        ax.plot(s, shapes[:, 1] * 1e3, color=f"C{k % 10}", lw=0.8, ls=":")
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xlabel("position along the rod from the crank pin [m]")
    ax.set_ylabel("lateral deflection from the chord [mm]")
    ax.legend(fontsize=7)
    ax.set_title(title)
    return fig


@styled
def slidercrank_nl_revolutions_figure(series: Sequence[tuple[str, np.ndarray]], title: str, ax=None) -> Figure:
    """Peak lateral deflection [mm] in each revolution, one line per speed (log scale)."""
    fig, ax = _own_axes(ax, (7.0, 4.0))
    for label, d in series:
        ax.plot(np.arange(1, len(d) + 1), d, "o-", ms=3, label=label)
    ax.set_yscale("log")
    ax.set_xlabel("revolution")
    ax.set_ylabel("peak lateral deflection [mm]")
    ax.legend(fontsize=7)
    ax.set_title(title)
    return fig


# ----------------------------------------------------------------------------- figures of a run
def history_figure(model: Model, params: Params, case: Case, alpha: float, beta: float, ref: dict | None):
    """Midpoint deflection and rod elongation against time of a benchmark run, with the
    reference end state (Simeon 1996) marked."""
    h = history(model, params, case.omega, case.n_elements, alpha, beta)
    refs = {}
    if ref is not None:
        refs = {"mid": (ref["t"], ref["q1"]), "elong": (ref["t"], ref["q4"])}
    return slidercrank_history_figure(
        h["time"], {"mid": h["mid"] * 1e3, "elong": h["elong"] * 1e6},
        {"mid": "midpoint deflection $q_1$ [mm]", "elong": "rod elongation $q_4$ [$\\mu$m]"},
        {k: (t, v * (1e3 if k == "mid" else 1e6)) for k, (t, v) in refs.items()},
        f"{'Simeon (1996) crank benchmark' if ref is not None else params.material}: {case.n_elements} elements "
        f"at {case.omega:g} rad/s, t = 0 to {params.end_time:g} s",
        "Simeon (1996), MEBDFI tol 1e-14")
