"""The linkage figures: the mechanism drawn at its first input with every tracer's path over
one cycle; the motion curves (link angles, angular velocities, slides) against the input; the
driving torque and shaking force; the turning-moment diagram with the flywheel's energy band.

Drawn in the house style (:mod:`driver.plotting`); imported only when a figure is drawn
(matplotlib is the optional [plot] extra).  Each builder takes ``ax=`` (or ``axes=``) to draw
into an existing figure."""
from __future__ import annotations

import math
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from driver._deck import Params
from driver.linkage._analysis import input_label
from driver.linkage._analysis_frames import frames
from driver.linkage._kernel import DriverCol, LinkageStatus, LinkCol, ShakeCol, SlideCol
from driver.plotting import new_figure, plain_text, styled

__all__ = ["linkage_drawing", "motion_curves", "force_curves", "turning_moment"]

_COLOURS = ("#1f4e79", "#c0392b", "#27ae60", "#8e44ad", "#d35400", "#16a085", "#7f8c8d", "#2c3e50")


@styled
def linkage_drawing(p: Params, title: str = "", ax: Any = None, n: int = 361) -> Figure:
    """The mechanism at its first input, with the paths of its joints and points over one cycle."""
    if ax is None:
        fig, axes = new_figure(1, 1, figsize=(7.0, 5.6))
        ax = axes[0]
    else:
        fig = ax.figure
    m, f = frames(p, n)
    ok = f["ok"]
    pts = f["points"]
    for i, name in enumerate(f["paths"]):
        xy = np.where(ok[:, None], pts[name], np.nan)
        ax.plot(xy[:, 0], xy[:, 1], lw=0.8, ls="--", color=_COLOURS[(i + 3) % len(_COLOURS)], label=f"path of {name}")
    k = int(np.argmax(ok)) if ok.any() else 0
    span = np.ptp(np.vstack([v[ok] for v in pts.values()]), axis=0).max() if ok.any() else 1.0
    for gname, (gp, gu) in f["guides"].items():
        a, u = gp[k], gu[k]
        ax.plot([a[0] - 0.6 * span * u[0], a[0] + 0.6 * span * u[0]], [a[1] - 0.6 * span * u[1],
                a[1] + 0.6 * span * u[1]], color="0.55", lw=1.0, ls="-.")
        ax.annotate(gname, (a[0] + 0.55 * span * u[0], a[1] + 0.55 * span * u[1]), fontsize=8, color="0.4")
    if ok.any():
        for i, (lname, joints) in enumerate(f["links"]):
            xy = np.array([pts[j][k] for j in joints])
            if len(xy) == 1:   # a slotted link: draw its slot through the pivot
                continue
            if len(xy) > 2:
                xy = np.vstack([xy, xy[:1]])
            ax.plot(xy[:, 0], xy[:, 1], "-o", lw=2.4, ms=4, color=_COLOURS[i % len(_COLOURS)], label=lname)
        for lname, pin, gname in f["blocks"]:
            c = pts[pin][k]
            u = f["guides"][gname][1][k]
            w = 0.04 * span
            corners = np.array([[-1.5, -1], [1.5, -1], [1.5, 1], [-1.5, 1], [-1.5, -1]]) * w
            rot = np.array([[u[0], -u[1]], [u[1], u[0]]])
            box = corners @ rot.T + c
            ax.plot(box[:, 0], box[:, 1], color="#444444", lw=1.4)
            ax.annotate(lname, c, textcoords="offset points", xytext=(6, -12), fontsize=8)
        for name in pts:
            ax.annotate(name, pts[name][k], textcoords="offset points", xytext=(4, 4), fontsize=9)
    for g in f["ground"]:
        x, y = pts[g][0]
        ax.plot([x], [y], marker="^", ms=11, color="0.3", ls="none")
    xname, xunit = input_label(m.mech)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x [length]")
    ax.set_ylabel("y [length]")
    ax.set_title(plain_text(f"{title}: at {xname.split('_')[0]} = {f['input'][k]:g} {xunit}"), fontsize=10)
    ax.legend(loc="best", fontsize=7)
    return fig


def _cycle(p: Params, n: int = 721) -> Any:
    """The analysis over one cycle at ``n`` inputs."""
    m, _ = frames(p, n)
    return m


@styled
def motion_curves(p: Params, title: str = "", axes: Any = None) -> Figure:
    """Link angles, angular velocities and accelerations, and the slides, against the input."""
    m = _cycle(p)
    mech, a = m.mech, m.a
    npanel = 3 + (1 if mech.slides else 0)
    if axes is None:
        fig, axes = new_figure(npanel, 1, sharex=True, figsize=(7.0, 2.1 * npanel + 0.6))
    else:
        fig = axes[0].figure
    placed = np.all((a.status == LinkageStatus.ok) | (a.status == LinkageStatus.toggle), axis=1)
    ok = np.all(a.status == LinkageStatus.ok, axis=1)
    for i, name in enumerate(mech.links[1:], start=1):
        col = _COLOURS[(i - 1) % len(_COLOURS)]
        ang = np.degrees(np.unwrap(a.links[:, LinkCol.ANGLE, i]))
        axes[0].plot(m.x, np.where(placed, ang, np.nan), color=col, label=name)
        axes[1].plot(m.x, np.where(ok, a.links[:, LinkCol.OMEGA, i], np.nan), color=col, label=name)
        axes[2].plot(m.x, np.where(ok, a.links[:, LinkCol.ALPHA, i], np.nan), color=col, label=name)
    axes[0].set_ylabel("angle [deg]")
    axes[1].set_ylabel("omega [rad/s]")
    axes[2].set_ylabel("alpha [rad/s²]")
    if mech.slides:
        for j, (name, _, _) in enumerate(mech.slides):
            col = _COLOURS[(j + 4) % len(_COLOURS)]
            axes[3].plot(m.x, np.where(placed, a.slides[:, SlideCol.S, j], np.nan), color=col, label=f"{name} s")
            axes[3].plot(m.x, np.where(ok, a.slides[:, SlideCol.V, j] / max(abs(mech.omega), 1e-300), np.nan),
                         color=col, ls="--", label=f"{name} ds/d(input)")
        axes[3].set_ylabel("slide [length]")
    for ax in axes:
        ax.legend(loc="best", fontsize=7)
    xname, xunit = input_label(mech)
    axes[-1].set_xlabel(f"input {xname.split('_')[0]} [{xunit}]")
    if title:
        fig.suptitle(plain_text(title))
    return fig


@styled
def force_curves(p: Params, title: str = "", axes: Any = None) -> Figure:
    """The driving torque (or force), the shaking force's components and size, and the shaking
    moment against the input."""
    m = _cycle(p)
    a = m.a
    if axes is None:
        fig, axes = new_figure(3, 1, sharex=True, figsize=(7.0, 7.0))
    else:
        fig = axes[0].figure
    ok = np.all(a.status == LinkageStatus.ok, axis=1)
    crank = m.mech.driver == "crank"
    axes[0].plot(m.x, np.where(ok, a.driver[:, DriverCol.DRIVE], np.nan), color=_COLOURS[0])
    axes[0].set_ylabel("driving torque [N m]" if crank else "driving force [N]")
    axes[1].plot(m.x, np.where(ok, a.shaking[:, ShakeCol.FX], np.nan), label="x", color=_COLOURS[1])
    axes[1].plot(m.x, np.where(ok, a.shaking[:, ShakeCol.FY], np.nan), label="y", color=_COLOURS[2])
    axes[1].plot(m.x, np.where(ok, np.hypot(a.shaking[:, 0], a.shaking[:, 1]), np.nan), label="size", color="0.3")
    axes[1].set_ylabel("shaking force [N]")
    axes[1].legend(loc="best", fontsize=7)
    axes[2].plot(m.x, np.where(ok, a.shaking[:, ShakeCol.M], np.nan), color=_COLOURS[3])
    axes[2].set_ylabel("shaking moment [N m]")
    xname, xunit = input_label(m.mech)
    axes[-1].set_xlabel(f"input {xname.split('_')[0]} [{xunit}]")
    if title:
        fig.suptitle(plain_text(title))
    return fig


@styled
def turning_moment(p: Params, title: str = "", ax: Any = None) -> Figure:
    """The turning-moment diagram over one cycle (the analysis's driving torque and/or the
    deck's table), its mean, and the energy above the mean with its band (max - min: the
    energy fluctuation the flywheel absorbs)."""
    if ax is None:
        fig, axs = new_figure(2, 1, sharex=True, figsize=(7.0, 5.4))
        axes = list(axs)
    else:
        fig, axes = ax.figure, [ax, ax.twinx()]
    curves: list[tuple[str, np.ndarray, np.ndarray]] = []
    if p.turning_moment is not None:
        curves.append(("table", np.asarray(p.turning_moment_deg, float), np.asarray(p.turning_moment, float)))
    mech_forces = p.bodies is not None
    if mech_forces:
        from driver.linkage._analysis import solve
        xs = p.start + np.linspace(0.0, p.cycle_deg, 721)
        m = solve(p, xs)
        if np.all(m.a.status == LinkageStatus.ok):
            curves.append(("analysis (driving torque)", xs, m.a.driver[:, DriverCol.DRIVE]))
    for i, (label, x, t) in enumerate(curves):
        col = _COLOURS[i]
        work = np.trapezoid(t, np.radians(x))
        mean = work / math.radians(x[-1] - x[0])
        e = np.concatenate([[0.0], np.cumsum(0.5 * (t[1:] + t[:-1] - 2 * mean) * np.radians(np.diff(x)))])
        axes[0].plot(x, t, color=col, label=label)
        axes[0].axhline(mean, color=col, ls=":", lw=0.9)
        axes[1].plot(x, e, color=col, label=label)
        axes[1].axhspan(e.min(), e.max(), color=col, alpha=0.12)
    axes[0].set_ylabel("torque [N m]")
    axes[0].legend(loc="best", fontsize=7)
    axes[1].set_ylabel("energy above the mean [J]")
    axes[1].set_xlabel("crank angle [deg]")
    if title:
        fig.suptitle(plain_text(title + " (band: energy fluctuation)"))
    return fig
