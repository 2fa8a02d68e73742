"""The four-bar figures: angle, speed and transmission-angle curves against the crank angle, the
linkage drawn over its turn at its limit positions, and the force analysis's input torque, pin
forces and shaking force (each drawn into axes the caller gives).

Drawn in the house style (:mod:`driver.plotting`); this module imports matplotlib (the optional
[plot] extra), so the study imports it only when a figure is drawn.
"""
from __future__ import annotations

import math
import textwrap
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import matplotlib
import matplotlib.colors
import matplotlib.ticker
import numpy as np
from matplotlib.figure import Figure

from driver.fourbar._kernel import Force, Point
from driver.fourbar._kernel import State as S
from driver.plotting import new_figure, plain_text, styled

if TYPE_CHECKING:
    from driver.fourbar._analysis_forces import ForceAnalysis


def break_wraps(x: np.ndarray, y: np.ndarray, period: float = 360.0) -> tuple[np.ndarray, np.ndarray]:
    """``x``, ``y`` with a NaN inserted wherever ``y`` (an angle wrapped into one period) jumps
    by more than half a period between neighbours, so the drawn line breaks at the wrap
    instead of running vertically across the panel."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    jumps = np.flatnonzero(np.abs(np.diff(y)) > 0.5 * period) + 1
    return np.insert(x, jumps, np.nan), np.insert(y, jumps, np.nan)


def _unassembled_spans(theta: np.ndarray, ok: np.ndarray) -> list[tuple[float, float]]:
    """Crank-angle intervals [deg] where ``ok`` is False (the linkage cannot be assembled)."""
    spans, start = [], None
    for t, good in zip(theta, ok):
        if not good and start is None:
            start = t
        elif good and start is not None:
            spans.append((start, t))
            start = None
    if start is not None:
        spans.append((start, theta[-1]))
    return spans


#: legend words of the four-bar curves: the link's name first (as in every column name:
#: coupler_omega_rad_s), then its symbol in the one documented numbering (docs/fourbar.md, "Names":
#: 1 ground, 2 crank, 3 coupler, 4 output link; the pivots O2, O4)
def _fourbar_names(output: str = "rocker") -> dict[str, str]:
    return {"coupler_deg": r"coupler angle $\theta_3$", "rocker_deg": rf"{output} angle $\theta_4$",
            "transmission_deg": r"transmission angle $\mu$",
            "coupler_omega_rad_s": r"coupler angular velocity $\omega_3$",
            "rocker_omega_rad_s": rf"{output} angular velocity $\omega_4$"}


@styled
def fourbar_curves(exact, listing, title: str, band: Sequence[float] = (40.0, 120.0), output: str = "rocker",
                   axes=None, chain: str | None = None) -> Figure:
    """Angles, angular velocities and transmission angle against crank angle.

    ``exact`` and ``listing`` are tidy frames from driver.fourbar; listing rows are
    drawn as markers over the exact curves so the listing's defect is visible.  Angles
    wrapped into 0-360 deg break at the wrap (no vertical line); crank angles where the
    linkage cannot be assembled are shaded and said so; the transmission-angle ``band``
    [deg] is shaded.  ``output`` names the output link ('rocker', 'output crank').
    ``axes``: three axes to draw into.  ``chain``: the class and reason of a chain that cannot
    move, written on the panels (which then hold no curve) and in the title.
    """
    names = _fourbar_names(output)
    panels = [("link angle [deg]", ["coupler_deg", "rocker_deg"]),
              ("transmission angle [deg]", ["transmission_deg"]),
              ("angular velocity [rad/s]", ["coupler_omega_rad_s", "rocker_omega_rad_s"])]
    if axes is None:
        fig, axes = new_figure(3, 1, sharex=True, figsize=(7.4, 7.6))
    else:
        fig = axes[0].figure
    colors = {"coupler_deg": "C0", "rocker_deg": "C1", "transmission_deg": "C2",
              "coupler_omega_rad_s": "C0", "rocker_omega_rad_s": "C1"}
    theta = exact["theta_deg"].to_numpy(dtype=float)
    spans = _unassembled_spans(theta, np.isfinite(exact["transmission_deg"].to_numpy(dtype=float)))
    for ax, (label, keys) in zip(axes, panels):
        for j, (lo, hi) in enumerate(spans):
            ax.axvspan(lo, hi, color="0.85", alpha=0.6, lw=0,
                       label=("cannot be assembled" if not chain else chain.split(":")[0]) if j == 0 else None)
        for k in keys:
            wrap = k.endswith("_deg")
            ax.plot(*(break_wraps(theta, exact[k]) if wrap else (theta, exact[k])), color=colors[k],
                    label=f"{names[k]} (exact)")
            if listing is not None:
                ax.plot(listing["theta_deg"], listing[k], "o", ms=4, mfc="none", color=colors[k],
                        label=f"{names[k]} (listing)")
        ax.set_ylabel(label)
    angles = exact[["coupler_deg", "rocker_deg"]].to_numpy(dtype=float)
    if np.isfinite(angles).any() and np.ptp(angles[np.isfinite(angles)]) > 180.0:   # wrapped: the whole turn
        axes[0].set_ylim(-5, 365)
        axes[0].set_yticks(np.arange(0, 361, 90))
    axes[1].axhspan(band[0], band[1], color="C2", alpha=0.08, label=f"{band[0]:g}-{band[1]:g} deg band")
    for ax in axes:
        ax.legend(loc="center left", bbox_to_anchor=(1.01, 0.5), frameon=False)
    axes[-1].set_xlabel(r"crank angle $\theta_2$ [deg]")
    if chain:
        for ax in axes:
            ax.text(0.5, 0.5, "no position: " + chain.split(":")[0], transform=ax.transAxes, ha="center",
                    va="center", color="C3")
    if chain:
        fig.suptitle((f"{plain_text(title)}: four-bar kinematics" if title else "four-bar kinematics")
                     + f"\n{textwrap.fill(plain_text(chain), 80)}", fontsize="small")
    elif title:
        fig.suptitle(f"{plain_text(title)}: four-bar kinematics")
    return fig


@styled
def fourbar_chain(lengths: Mapping[str, float], name: str, reason: str, title: str, units: str = "length units",
                  ax=None) -> Figure:
    """A chain that cannot move (an impossible or a flat chain, :func:`driver.fourbar.grashof`):
    its longest link drawn as one bar and the other three laid end to end beside it, so the gap
    (or the exact match) is seen; the class and its reason in the title.

    ``lengths``: {'fixed link', 'crank', 'coupler', 'rocker': length} in ``units``.  ``ax``: the
    axes to draw into.
    """
    if ax is None:
        fig, (ax,) = new_figure(1, 1, figsize=(8.6, 3.2))
    else:
        fig = ax.figure
    longest = max(lengths, key=lambda k: lengths[k])
    others = [k for k in lengths if k != longest]
    ax.plot([0.0, lengths[longest]], [1.0, 1.0], "-o", color="k", lw=3, ms=5,
            label=f"longest link: {longest} {lengths[longest]:g}")
    x = 0.0
    for j, k in enumerate(others):
        ax.plot([x, x + lengths[k]], [0.0, 0.0], "-o", color=f"C{j}", lw=3, ms=5, label=f"{k} {lengths[k]:g}")
        x += lengths[k]
    gap = lengths[longest] - x
    if gap > 0:
        ax.annotate("", xy=(lengths[longest], 0.0), xytext=(x, 0.0),
                    arrowprops={"arrowstyle": "<->", "color": "C3", "lw": 1.2})
        ax.text(0.5 * (x + lengths[longest]), 0.12, f"short by {gap:g}", color="C3", ha="center", va="bottom")
    ax.set_ylim(-0.8, 1.8)
    ax.set_yticks([])
    ax.set_xlabel(f"length [{units}]")
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), frameon=False)
    what = f"{name}: no position exists" if gap > 0 else f"{name}: it closes only lying flat"
    ax.set_title((f"{plain_text(title)}: " if title else "") + what + "\n" + textwrap.fill(plain_text(reason), 90),
                 fontsize="small")
    return fig


def _runs(ok: np.ndarray) -> list[np.ndarray]:
    """Index runs where ``ok`` holds (a run wrapping past the end of a full turn is joined)."""
    idx = np.arange(len(ok))
    runs = [r for r in np.split(idx, np.flatnonzero(np.diff(ok.astype(int))) + 1) if len(r) and ok[r[0]]]
    return runs


@styled
def fourbar_linkage(ground: float, theta: np.ndarray, out: np.ndarray, ok: np.ndarray,
                    listing, title: str, n_poses: int = 6, point: np.ndarray | None = None,
                    units: str = "length units", output: str = "rocker",
                    limits: Sequence[tuple[float, np.ndarray]] = (), ax=None,
                    motions: Sequence[dict] | None = None) -> Figure:
    """The linkage drawn at a few crank angles with the paths of A and B (exact), and the
    path of a coupler point (``point``: (n, 2) positions) when the deck defines one, the
    coupler then drawn as the plate A-B-P in every pose.

    ``theta`` [deg] is the drawn crank range (a function generator's design range, or a whole
    turn); the crank pin's path is drawn only where the linkage assembles, so a crank that
    cannot turn shows the arc it swings through, not a circle.  Separate assembly intervals
    are drawn and named as separate motions.  ``limits``: (crank angle [deg], kernel row)
    of the limit (toggle) positions, drawn dashed and labelled.  ``motions``: for a crank that
    cannot turn (driver.fourbar.rocking_motions), per motion a dict of ``lo``, ``hi`` [deg],
    ``theta``, ``out`` (kernel rows), ``stroke`` (0 forward, 1 back), ``branch`` (+1 open, -1
    crossed) and ``point`` (coupler point positions or None): then the linkage is drawn rocking
    between its limit positions, out on one assembly branch and back on the other, each
    motion (a separate assembly interval) on its own.  ``output`` names the output link.
    Coordinates in the deck's length ``units``, crank pivot at the origin, ground along +x;
    the legend sits beside the drawing.
    """
    if ax is None:
        fig, (ax,) = new_figure(1, 1, figsize=(8.6, 5.2))
    else:
        fig = ax.figure
    if motions:
        _rocking_drawing(ax, ground, motions, title, units, output)
        return fig
    runs = _runs(ok)
    full = bool(ok.all()) and np.ptp(theta) >= 359.0
    for j, r in enumerate(runs if not full else [np.arange(len(ok))]):
        ax.plot(out[r, S.XA], out[r, S.YA], color="0.55", lw=0.9, label="path of A (crank pin)" if j == 0 else None)
        ax.plot(out[r, S.XB], out[r, S.YB], color="C3", lw=1.3, label=f"path of B ({output} pin)" if j == 0 else None)
        if point is not None:
            ax.plot(point[r, Point.X], point[r, Point.Y], color="C4", lw=1.3, ls="--",
                    label="path of coupler point P" if j == 0 else None)
    if listing is not None:
        ax.plot(listing["xb"], listing["yb"], "x", color="k", ms=5, label="B (listing)")
    cmap = matplotlib.colormaps["viridis"]
    # poses spread over the assembled samples (every run gets some)
    idx = np.flatnonzero(ok)
    picks = idx[np.linspace(0, len(idx) - 1, n_poses, endpoint=not full).astype(int)] if len(idx) else []
    for j, k in enumerate(picks):
        c = cmap(j / max(1, n_poses - 1))
        xs = [0.0, out[k, S.XA], out[k, S.XB], ground]
        ys = [0.0, out[k, S.YA], out[k, S.YB], 0.0]
        ax.plot(xs, ys, "-o", color=c, ms=3, lw=1.5, label=rf"$\theta_2$ = {theta[k]:.0f}°")
        if point is not None:
            tri = np.array([[out[k, S.XA], out[k, S.YA]], [out[k, S.XB], out[k, S.YB]], point[k], [out[k, S.XA], out[k, S.YA]]])
            ax.fill(tri[:, 0], tri[:, 1], color=c, alpha=0.15, lw=0)
            ax.plot(tri[:, 0], tri[:, 1], color=c, lw=1.0)
            ax.plot(*point[k], "o", color=c, ms=3.5)
    for j, (angle, row) in enumerate(limits):
        xs = [0.0, row[S.XA], row[S.XB], ground]
        ys = [0.0, row[S.YA], row[S.YB], 0.0]
        ax.plot(xs, ys, "--", color="k", lw=1.1, label="limit (toggle) positions" if j == 0 else None)
        _limit_label(ax, row, rf"$\theta_2$ = {angle:.1f}°")
    ax.plot([0.0, ground], [0.0, 0.0], color="k", lw=2.5)
    ax.plot([0.0, ground], [0.0, 0.0], "^", color="k", ms=9, label="ground pivots $O_2$, $O_4$")
    ax.set_aspect("equal")
    ax.set_xlabel(f"x [{units}]")
    ax.set_ylabel(f"y [{units}]")
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), frameon=False)
    lo, hi = float(np.min(theta)), float(np.max(theta))
    what = "linkage positions" + ("" if full or (hi - lo) >= 359.0 else f" over the crank range {lo:g}-{hi:g}°")
    if len(runs) > 1:
        spans = ", ".join(f"{theta[r[0]]:.0f}-{theta[r[-1]]:.0f}°" for r in runs)
        what += f"\nassembles over {len(runs)} separate crank intervals ({spans}): separate motions"
    ax.set_title(f"{plain_text(title)}: {what}" if title else what)
    return fig


def _deg(value: float, digits: int = 1) -> str:
    """An angle [deg] as printed in a figure: ``digits`` decimals, no '-0'."""
    text = f"{value:.{digits}f}"
    return text[1:] if text.lstrip("-").strip("0.") == "" and text.startswith("-") else text


def _limit_label(ax, row: np.ndarray, text: str) -> None:
    """A limit position's label beside its crank pin A, pushed outward (away from the crank
    pivot) on a white ground so it does not sit on the pose lines."""
    x, y = float(row[S.XA]), float(row[S.YA])
    r = math.hypot(x, y) or 1.0
    ux, uy = x / r, y / r
    ax.annotate(text, (x, y), xytext=(14 * ux, 14 * uy), textcoords="offset points", fontsize=8,
                ha="left" if ux > 0.3 else "right" if ux < -0.3 else "center",
                va="bottom" if uy > 0.3 else "top" if uy < -0.3 else "center",
                bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="none", alpha=0.85), zorder=6)


def _rocking_drawing(ax, ground: float, motions: Sequence[dict], title: str, units: str, output: str) -> None:
    """The linkage of a crank that cannot turn, rocking between its limit positions (see
    :func:`fourbar_linkage`): per motion the crank pin's arc, B's path out (solid, the first
    branch) and back (dashed, the other branch), the coupler point's likewise, a few poses of
    each stroke and the two limit positions dashed black and labelled."""
    cmap = matplotlib.colormaps["viridis"]
    word = {1: "open", -1: "crossed"}
    n_m = len(motions)
    for i, m in enumerate(motions):
        out, stroke, theta = np.asarray(m["out"]), np.asarray(m["stroke"]), np.asarray(m["theta"])
        first = int(np.asarray(m["branch"])[0])
        tag = "" if n_m == 1 else f" (motion {i + 1})"
        fwd, back = np.flatnonzero(stroke == 0), np.flatnonzero(stroke == 1)
        ax.plot(out[fwd, S.XA], out[fwd, S.YA], color="0.55", lw=0.9, label="path of A (crank pin): an arc" if i == 0 else None)
        ax.plot(out[fwd, S.XB], out[fwd, S.YB], color="C3", lw=1.3,
                label=f"path of B, out on the {word[first]} assembly" if i == 0 else None)
        ax.plot(out[back, S.XB], out[back, S.YB], color="C3", lw=1.3, ls="--",
                label=f"path of B, back on the {word[-first]} assembly" if i == 0 else None)
        pt = m.get("point")
        if pt is not None:
            pt = np.asarray(pt)
            ax.plot(pt[fwd, Point.X], pt[fwd, Point.Y], color="C4", lw=1.2, label="path of coupler point P" if i == 0 else None)
            ax.plot(pt[back, Point.X], pt[back, Point.Y], color="C4", lw=1.2, ls="--")
        # poses: three inside each stroke (the limits are drawn on their own)
        at = [1 / 3, 2 / 3] if n_m > 1 else [0.2, 0.5, 0.8]   # fractions of a stroke's samples
        picks = [fwd[int(f * (len(fwd) - 1))] for f in at] + [back[int(f * (len(back) - 1))] for f in at]
        for j, k in enumerate(picks):
            c = cmap((j + 0.5) / len(picks))
            back_pose = stroke[k] == 1
            xs = [0.0, out[k, S.XA], out[k, S.XB], ground]
            ys = [0.0, out[k, S.YA], out[k, S.YB], 0.0]
            arrow = "\u2192" if not back_pose else "\u2190"
            ax.plot(xs, ys, "-o", color=c, ms=3, lw=1.4, ls=":" if back_pose else "-", alpha=0.95,
                    label=(rf"$\theta_2$ = {_deg(theta[k], 0)}° {arrow} {word[int(np.asarray(m['branch'])[k])]}"
                           + tag))
            if pt is not None:
                tri = np.array([[out[k, S.XA], out[k, S.YA]], [out[k, S.XB], out[k, S.YB]], pt[k], [out[k, S.XA], out[k, S.YA]]])
                ax.fill(tri[:, 0], tri[:, 1], color=c, alpha=0.12, lw=0)
                ax.plot(tri[:, 0], tri[:, 1], color=c, lw=0.9, ls=":" if back_pose else "-")
        for end, angle in ((fwd[0], m["lo"]), (fwd[-1], m["hi"])):
            row = out[end]
            ax.plot([0.0, row[S.XA], row[S.XB], ground], [0.0, row[S.YA], row[S.YB], 0.0], "--", color="k", lw=1.1,
                    label="limit positions (the crank reverses)" if i == 0 and end == fwd[0] else None)
            ax.plot([row[S.XA]], [row[S.YA]], "o", color="k", ms=4)
            _limit_label(ax, row, rf"limit $\theta_2$ = {_deg(angle)}°")
    ax.plot([0.0, ground], [0.0, 0.0], color="k", lw=2.5)
    ax.plot([0.0, ground], [0.0, 0.0], "^", color="k", ms=9, label="ground pivots $O_2$, $O_4$")
    ax.set_aspect("equal")
    ax.margins(0.1)   # room for the limit labels
    ax.set_xlabel(f"x [{units}]")
    ax.set_ylabel(f"y [{units}]")
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), frameon=False)
    out_word = word[int(np.asarray(motions[0]["branch"])[0])]
    back_word = word[-int(np.asarray(motions[0]["branch"])[0])]
    what = "the crank rocks between its limit positions"
    if n_m == 1:
        m = motions[0]
        what += (f"\n$\\theta_2$ = {_deg(m['lo'])}° to {_deg(m['hi'])}°: out on the {out_word} assembly, "
                 f"back on the {back_word}")
    else:
        spans = " and ".join(f"{_deg(m['lo'])}-{_deg(m['hi'])}°" for m in motions)
        what += (f"\n{n_m} separate motions (mirror assemblies, $\\theta_2$ = {spans}),"
                 f"\neach out on the {out_word} assembly, back on the {back_word}")
    ax.set_title(f"{plain_text(title)}: {what}" if title else what)


# ----------------------------------------------------------------------------- figures of a run


# ----------------------------------------------------------------------------- the force analysis

def plot_torque(theta: np.ndarray, fa: ForceAnalysis, p: Mapping[str, Any], ax: Any) -> Any:
    """Plot the input torque against crank angle, its mean, and the energy fluctuation dE.

    dE is shaded between the torque curve and the mean; with balancing the torque of the
    linkage without counterweights is dashed.

    Parameters
    ----------
    theta : numpy.ndarray
        Crank angles, deg.
    fa : ForceAnalysis
        The forces (``driver.fourbar.forces.analyse``).
    p : mapping
        The ``&fourbar`` keys.
    ax : matplotlib.axes.Axes
        The axes to draw into (crank angle in deg, torque in N m, dE in J in the legend).

    Returns
    -------
    matplotlib.axes.Axes
        ``ax``.
    """
    t = np.where(fa.ok, fa.forces[:, Force.INPUT_TORQUE], np.nan)
    ax.plot(theta, t, color="C0", label="input torque")
    if fa.ok.all() and len(theta) > 1:
        mean = np.trapezoid(t, theta) / (theta[-1] - theta[0])
        e = np.concatenate([[0.0], np.cumsum(0.5 * (t[1:] + t[:-1] - 2 * mean) * np.diff(np.radians(theta)))])
        ax.axhline(mean, color="C1", lw=1, label=f"mean {mean:.3f} N m")
        ax.fill_between(theta, t, mean, color="C0", alpha=0.15,
                        label=f"dE = {e.max() - e.min():.4g} J (max - min of the area)")
    if fa.unbalanced is not None:
        ax.plot(theta, np.where(fa.ok, fa.unbalanced[:, Force.INPUT_TORQUE], np.nan), "--", color="C3",
                label="without counterweights")
    ax.set_xlabel("crank angle [deg]")
    ax.set_ylabel("input torque [N m]")
    ax.legend(fontsize=7, loc="best")
    return ax


def plot_pin_polars(fa: ForceAnalysis, axes: Any) -> Any:
    """Plot the force at each pin over the cycle on polar axes.

    Angle = direction of the force, radius = its magnitude in N; with balancing, the
    unbalanced linkage's dashed.

    Parameters
    ----------
    fa : ForceAnalysis
        The forces (``driver.fourbar.forces.analyse``).
    axes : sequence of matplotlib.axes.Axes
        Four polar axes: O2, A, B, O4.

    Returns
    -------
    sequence of matplotlib.axes.Axes
        ``axes``.
    """
    names = ("O2 (ground on crank)", "A (crank on coupler)", "B (coupler on rocker)", "O4 (ground on rocker)")
    pins = ((Force.F_O2_X, Force.F_O2_Y), (Force.F_A_X, Force.F_A_Y), (Force.F_B_X, Force.F_B_Y),
            (Force.F_O4_X, Force.F_O4_Y))
    for j, ax in enumerate(np.ravel(axes)[:4]):
        fx = np.where(fa.ok, fa.forces[:, pins[j][0]], np.nan)
        fy = np.where(fa.ok, fa.forces[:, pins[j][1]], np.nan)
        ax.plot(np.arctan2(fy, fx), np.hypot(fx, fy), color="C0", lw=1,
                label="balanced" if fa.unbalanced is not None else "as given")
        if fa.unbalanced is not None:
            bx = np.where(fa.ok, fa.unbalanced[:, pins[j][0]], np.nan)
            by = np.where(fa.ok, fa.unbalanced[:, pins[j][1]], np.nan)
            ax.plot(np.arctan2(by, bx), np.hypot(bx, by), color="C3", lw=1, ls="--", label="unbalanced")
        ax.set_title(f"F at {names[j]} [N]", fontsize=8)
    np.ravel(axes)[0].legend(fontsize=6, loc="lower left")
    return axes


def plot_shaking(theta: np.ndarray, fa: ForceAnalysis, ax: Any, polar_ax: Any | None = None) -> Any:
    """Plot the shaking force magnitude against crank angle, and its locus, before and after balancing.

    Parameters
    ----------
    theta : numpy.ndarray
        Crank angles, deg.
    fa : ForceAnalysis
        The forces (``driver.fourbar.forces.analyse``).
    ax : matplotlib.axes.Axes
        Axes for |shaking force| (N) against crank angle (deg).
    polar_ax : matplotlib.axes.Axes, optional
        Axes for the locus F_y against F_x (N, equal scales).

    Returns
    -------
    matplotlib.axes.Axes
        ``ax``.
    """
    before = fa.unbalanced if fa.unbalanced is not None else fa.forces
    shaking = [Force.SHAKING_X, Force.SHAKING_Y]
    s = np.where(fa.ok[:, None], before[:, shaking], np.nan)
    ax.plot(theta, np.hypot(*s.T), color="C0", label="unbalanced")
    if polar_ax is not None:
        polar_ax.plot(s[:, 0], s[:, 1], color="C0", label="unbalanced")
    if fa.unbalanced is not None:
        b = np.where(fa.ok[:, None], fa.forces[:, shaking], np.nan)
        ax.plot(theta, np.hypot(*b.T), "--", color="C3", label="balanced (Berkof-Lowen)")
        if polar_ax is not None:
            polar_ax.plot(b[:, 0], b[:, 1], "o", ms=3, color="C3", label="balanced (Berkof-Lowen)")
    ax.set_xlabel("crank angle [deg]")
    ax.set_ylabel("|shaking force| [N]")
    ax.legend(fontsize=7)
    if polar_ax is not None:
        polar_ax.set_xlabel("shaking force x [N]")
        polar_ax.set_ylabel("shaking force y [N]")
        polar_ax.set_aspect("equal", adjustable="datalim")
    return ax
