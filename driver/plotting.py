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


# ---- ujoint

def ujoint_speed_figure(theta_deg: np.ndarray, rpm: float, curves: dict[str, np.ndarray],
                        polar: bool = False) -> Figure:
    """Input and output shaft speed [rpm] against the input angle [deg], one panel per design
    (the paper's Figures 6-11: trial and optimum), cartesian or polar."""
    n = len(curves)
    if polar:
        fig = Figure(figsize=(3.6 * n, 3.8), layout="constrained")
        axes = [fig.add_subplot(1, n, k + 1, projection="polar") for k in range(n)]
    else:
        fig, axes = new_figure(n, 1, sharex=True, figsize=(7.0, 2.3 * n + 0.6))
    top = max(float(np.max(w)) for w in curves.values())
    low = min(float(np.min(w)) for w in curves.values())
    for ax, (label, w) in zip(axes, curves.items()):
        x = np.radians(theta_deg) if polar else theta_deg
        ax.plot(x, np.full_like(theta_deg, rpm), "k--", lw=1.0, label="input shaft")
        ax.plot(x, w, lw=1.5, label="output shaft")
        ax.set_title(f"{label}: output {w.min():.2f}-{w.max():.2f} rpm", fontsize=9, pad=14 if polar else 4)
        if polar:
            ax.set_ylim(0.0, 1.05 * top)
        else:
            pad = 0.05 * max(top - low, 1e-3 * rpm)
            ax.set_ylim(low - pad, top + pad)
            ax.set_ylabel("speed [rpm]")
            ax.legend(fontsize=7, loc="upper right")
    if not polar:
        axes[-1].set_xlabel("input angle [deg]")
        axes[-1].set_xlim(0.0, 360.0)
    else:
        axes[0].legend(fontsize=7, loc="lower left", bbox_to_anchor=(-0.1, -0.15))
    fig.suptitle("Hooke-joint chain: input and output shaft speed")
    return fig
