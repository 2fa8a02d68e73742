"""The one plotting module (matplotlib, Agg backend, no screen needed).

Shared helpers first; then one section per study with its figure builders.
Every builder returns a matplotlib Figure; :func:`save_figure` writes it
atomically as PNG.  Studies wrap builders in :class:`driver.study.Figure`
so nothing is drawn unless ``--plot`` is given.
"""
from __future__ import annotations

from pathlib import Path
from typing import Sequence

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from driver.atomic import atomic_open  # noqa: E402

__all__ = ["new_figure", "save_figure", "line_panels"]

plt.rcParams.update({"figure.dpi": 110, "axes.grid": True, "grid.alpha": 0.3,
                     "axes.spines.top": False, "axes.spines.right": False, "font.size": 9})


def new_figure(nrows: int = 1, ncols: int = 1, **kw) -> tuple[Figure, np.ndarray]:
    """A figure and a flat array of axes (no pyplot state is kept)."""
    fig = Figure(figsize=kw.pop("figsize", (6.4 * ncols, 3.2 * nrows)), layout="constrained")
    axes = fig.subplots(nrows, ncols, squeeze=False, **kw)
    return fig, axes.ravel()


def save_figure(fig: Figure, path: str | Path) -> Path:
    """Write ``fig`` as PNG to ``path`` atomically."""
    path = Path(path)
    with atomic_open(path, "wb") as fh:
        fig.savefig(fh, format="png")
    return path


def line_panels(x: np.ndarray, panels: Sequence[tuple[str, dict[str, np.ndarray]]], xlabel: str,
                title: str = "", styles: dict[str, dict] | None = None) -> Figure:
    """Stacked panels sharing x: each panel is (ylabel, {label: y}); NaN gaps break lines."""
    fig, axes = new_figure(len(panels), 1, sharex=True, figsize=(7.0, 2.2 * len(panels) + 0.6))
    for ax, (ylabel, series) in zip(axes, panels):
        for label, y in series.items():
            ax.plot(x, y, label=label, **(styles or {}).get(label, {}))
        ax.set_ylabel(ylabel)
        if len(series) > 1:
            ax.legend(fontsize=7, loc="best")
    axes[-1].set_xlabel(xlabel)
    if title:
        fig.suptitle(title)
    return fig


# ----------------------------------------------------------------------------- slidercrank


def slidercrank_strain_figure(series: Sequence[tuple[str, np.ndarray, np.ndarray]], title: str,
                              ylabel: str = "axial strain [microstrain]") -> Figure:
    """A quantity against crank angle [deg], one line per case (label, angle, value): Figure 10."""
    fig, axes = new_figure(1, 1, figsize=(7.0, 3.6))
    ax = axes[0]
    for label, x, y in series:
        ax.plot(x, y, label=label, lw=1.2)
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xlim(0, 360)
    ax.set_xticks(np.arange(0, 361, 45))
    ax.set_xlabel("crank angle theta2 [deg]")
    ax.set_ylabel(ylabel)
    ax.legend(fontsize=7, loc="best")
    ax.set_title(title)
    return fig


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
    axes[0].legend(fontsize=7)
    fig.suptitle(title)
    return fig
