"""The one plotting module (matplotlib, Agg backend, no screen needed).

Shared helpers first; then one section per study with its figure builders.
Every builder returns a matplotlib Figure; :func:`save_figure` writes it
atomically as PNG.  Studies wrap builders in :class:`driver.study.Figure`
so nothing is drawn unless ``--plot`` is given.
"""
from __future__ import annotations

from pathlib import Path
from typing import Sequence

from driver.extras import require

require("plot")   # a clear message naming the [plot] extra when matplotlib is missing
import matplotlib  # noqa: E402

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


# ----------------------------------------------------------------------------- fourbar

def fourbar_curves(exact, listing, title: str) -> Figure:
    """Angles, angular velocities and transmission angle against crank angle.

    ``exact`` and ``listing`` are tidy frames from driver.fourbar; listing rows are
    drawn as markers over the exact curves so the listing's defect is visible.
    """
    panels = [("coupler, rocker [deg]", ["coupler_deg", "rocker_deg"]),
              ("transmission [deg]", ["transmission_deg"]),
              ("angular velocity [rad/s]", ["omega2_rad_s", "omega3_rad_s"])]
    fig, axes = new_figure(3, 1, sharex=True, figsize=(7.0, 7.4))
    colors = {"coupler_deg": "C0", "rocker_deg": "C1", "transmission_deg": "C2",
              "omega2_rad_s": "C0", "omega3_rad_s": "C1"}
    for ax, (label, keys) in zip(axes, panels):
        for k in keys:
            ax.plot(exact["theta_deg"], exact[k], color=colors[k], label=f"{k.split('_')[0]} (exact)")
            if listing is not None:
                ax.plot(listing["theta_deg"], listing[k], "o", ms=4, mfc="none", color=colors[k],
                        label=f"{k.split('_')[0]} (listing)")
        ax.set_ylabel(label)
        ax.legend(fontsize=7, ncol=2)
    axes[1].axhspan(40, 120, color="C2", alpha=0.08, label="40-120 deg")
    axes[-1].set_xlabel("crank angle [deg]")
    fig.suptitle(f"{title}: four-bar kinematics")
    return fig


def fourbar_linkage(ground: float, theta: np.ndarray, out: np.ndarray, ok: np.ndarray,
                    listing, title: str, n_poses: int = 6, point: np.ndarray | None = None) -> Figure:
    """The linkage drawn at a few crank angles with the paths of A and B (exact), and the
    path of a coupler point (``point``: (n, 2) positions) when the deck defines one."""
    fig, (ax,) = new_figure(1, 1, figsize=(7.0, 5.0))
    ax.plot(out[:, 3], out[:, 4], color="0.6", lw=0.8, label="path of A")
    bx = np.where(ok, out[:, 5], np.nan)
    by = np.where(ok, out[:, 6], np.nan)
    ax.plot(bx, by, color="C3", lw=1.2, label="path of B (exact)")
    if point is not None:
        ax.plot(np.where(ok, point[:, 0], np.nan), np.where(ok, point[:, 1], np.nan), color="C4", lw=1.2,
                ls="--", label="coupler point P")
    if listing is not None:
        ax.plot(listing["xb"], listing["yb"], "x", color="k", ms=5, label="B (listing)")
    idx = np.flatnonzero(ok)
    for j, k in enumerate(idx[np.linspace(0, len(idx) - 1, n_poses, endpoint=False).astype(int)] if len(idx) else []):
        xs = [0.0, out[k, 3], out[k, 5], ground]
        ys = [0.0, out[k, 4], out[k, 6], 0.0]
        ax.plot(xs, ys, "-o", color=plt.cm.viridis(j / max(1, n_poses - 1)), ms=3, lw=1.4,
                label=f"theta = {theta[k]:.0f} deg")
    ax.plot([0.0, ground], [0.0, 0.0], color="k", lw=2.5)
    ax.plot([0.0, ground], [0.0, 0.0], "^", color="k", ms=9)
    ax.set_aspect("equal")
    ax.legend(fontsize=7, loc="best")
    ax.set_title(f"{title}: linkage positions")
    return fig


# ----------------------------------------------------------------------------- manipulator

def manipulator_design_space(r: float, R: float, radius: float, L1: np.ndarray, L2: np.ndarray,
                             ri2: np.ndarray, sum_d2: float, n: int, levels: Sequence[float],
                             optima: dict, names: Sequence[str], l1: np.ndarray, l2: np.ndarray,
                             title: str = "") -> Figure:
    """Design space (l1, l2) [m] of a 2R arm, like the report's Figures 4.2-4.11.

    Left: reach region |l1 - l2| <= r, l1 + l2 >= R (shaded), C_rob circle, iso-RI2 ellipses
    (eqs 4.14-4.17, c = sum d^2), dexterity line l2 = l1 sqrt(2)/2, manipulability line l1 = l2,
    optima and chosen designs.  Right: RI2 contours over the design plane with the same lines.
    """
    fig, axes = new_figure(1, 2, figsize=(11.0, 5.0))
    top = float(L1.max())
    g = np.linspace(0, top, 400)
    G1, G2 = np.meshgrid(g, g)
    ok = (np.abs(G1 - G2) <= r) & (G1 + G2 >= R)
    t = np.linspace(0, np.pi / 2, 200)
    for k, ax in enumerate(axes):
        if k == 0:
            ax.contourf(G1, G2, ok.astype(float), levels=[0.5, 1.5], colors=["#cfe3f7"])
            ax.plot(g, g - r, "b-", lw=0.8, label="|l1 - l2| = r")
            ax.plot(g, g + r, "b-", lw=0.8)
            ax.plot(g, R - g, "g-", lw=0.8, label="l1 + l2 = R")
            for v in levels:  # ellipses in the 45-deg frame; both branches
                for ca, cb in ((v * v, 2 * n - v * v), (2 * n - v * v, v * v)):
                    phi = np.linspace(0, 2 * np.pi, 400)
                    A, B = np.sqrt(sum_d2 / ca), np.sqrt(sum_d2 / cb)
                    P, Q = A * np.cos(phi), B * np.sin(phi)
                    keep = np.abs(P) >= np.abs(Q)
                    x, y = (P + Q) / np.sqrt(2), (P - Q) / np.sqrt(2)
                    ax.plot(np.where(keep, x, np.nan), np.where(keep, y, np.nan), ":", lw=0.8, color="gray")
        else:
            cs = ax.contour(L1, L2, ri2, levels=np.sqrt(n) + np.array([0.001, 0.01, 0.05, 0.1, 0.2, 0.4, 0.8]),
                            linewidths=0.7, cmap="viridis")
            ax.clabel(cs, fontsize=6, fmt="%.3f")
        ax.plot(radius * np.cos(t), radius * np.sin(t), "r-", lw=1.2, label=f"C_rob (radius {radius:.3f})")
        ax.plot(g, g * np.sqrt(2) / 2, "m--", lw=0.8, label="dexterity l2 = l1 sqrt2/2")
        ax.plot(g, g, "k--", lw=0.8, label="manipulability l1 = l2")
        for key, mk in (("dexterity", "ms"), ("manipulability", "ko")):
            ax.plot(*optima[key], mk, ms=5, mfc="none")
        ax.plot(l1, l2, "r*", ms=9, label="chosen designs")
        for name, a, b in zip(names, l1, l2):
            ax.annotate(name, (a, b), textcoords="offset points", xytext=(4, 4), fontsize=7)
        ax.set_xlim(0, top)
        ax.set_ylim(0, top)
        ax.set_aspect("equal")
        ax.set_xlabel("l1 [m]")
        ax.set_ylabel("l2 [m]")
    axes[0].set_title("reach region, C_rob, iso-RI2 ellipses")
    axes[1].set_title("RI2 over the design plane")
    axes[0].legend(fontsize=7, loc="upper right")
    if title:
        fig.suptitle(title)
    return fig


def manipulator_torque_crob(l1: np.ndarray, tau1: np.ndarray, tau2: np.ndarray, c: float) -> Figure:
    """Motor torques tau1, tau2 and their sum [N m] against l1 [m] along C_rob (Table 4.8)."""
    return line_panels(l1, [("torque [N m]", {"tau1": tau1, "tau2": tau2, "tau1 + tau2": tau1 + tau2})],
                       xlabel="l1 [m] (l2 = sqrt(%g - l1^2))" % c, title="Motor torques along C_rob")


# ----------------------------------------------------------------------------- sweep

def sweep_summary(frame, keys: Sequence[str], x: str = "", ys: Sequence[str] = (), title: str = "") -> Figure:
    """Summary of a sweep: chosen (or all numeric) headline figures against a swept key.

    With one numeric x the figures are drawn as lines over the cases; a boolean
    ``kept`` column, when some cases are not kept, is shown as filled vs hollow markers.
    """
    import pandas as pd
    x = x or next((k for k in keys if pd.api.types.is_numeric_dtype(frame[k])), "case")
    numeric = [c for c in frame.columns if c not in (x, "case") and pd.api.types.is_numeric_dtype(frame[c])
               and not pd.api.types.is_bool_dtype(frame[c]) and c not in keys]
    ys = list(ys) or numeric[:6]
    fig, axes = new_figure(len(ys), 1, sharex=True, figsize=(7.0, 1.9 * len(ys) + 0.8))
    kept = frame["kept"].astype(bool) if "kept" in frame else pd.Series(True, index=frame.index)
    others = [k for k in keys if k != x]
    many = len(frame) > 2000 or (others and frame.groupby(others).ngroups > 12)
    groups = [("", frame)] if (many or not others) else frame.groupby(others, sort=False)
    if many:
        others = []
    for ax, y in zip(axes, ys):
        if many:   # a design-space search: every case as a dot, kept cases circled
            ax.plot(frame[x], frame[y], ".", ms=1, color="0.6", alpha=0.3, rasterized=True)
            if not kept.all():
                ax.plot(frame.loc[kept, x], frame.loc[kept, y], "o", ms=3, mfc="none", color="C3", label="kept")
            ax.set_ylabel(y, fontsize=7)
            continue
        for label, g in groups:
            g = g.sort_values(x)
            style = "-" if len(frame) <= 2000 else ""
            ax.plot(g[x], g[y], style, marker="o" if len(frame) <= 200 else ".", ms=3, lw=1,
                    label=", ".join(f"{k}={v}" for k, v in zip(others, label if isinstance(label, tuple) else (label,))) or None)
        if not kept.all():
            ax.plot(frame.loc[kept, x], frame.loc[kept, y], "o", ms=4, mfc="none", color="k", label="kept")
        ax.set_ylabel(y, fontsize=7)
    if others or not kept.all():
        axes[0].legend(fontsize=6, ncol=2)
    axes[-1].set_xlabel(x)
    fig.suptitle(f"{title}: sweep summary" if title else "sweep summary")
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
