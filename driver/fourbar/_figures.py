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

import numpy as np
from matplotlib.figure import Figure

from driver._mechanism import LINK_COLOURS, MARK_COLOUR, MASS_COLOUR
from driver.fourbar._kernel import Force, Point
from driver.fourbar._kernel import State as S
from driver.plotting import (
    break_wraps,
    drawing_figure,
    drawing_legend,
    keep_texts_inside,
    length_label,
    new_figure,
    plain_text,
    styled,
    suptitle,
)

if TYPE_CHECKING:
    from driver.fourbar._analysis_forces import ForceAnalysis


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
        suptitle(fig, (f"{plain_text(title)}: four-bar kinematics" if title else "four-bar kinematics")
                 + f"\n{plain_text(chain)}", fontsize="small")
    elif title:
        suptitle(fig, f"{plain_text(title)}: four-bar kinematics")
    return fig


@styled
def fourbar_chain(lengths: Mapping[str, float], name: str, reason: str, title: str, units: str = "",
                  ax=None) -> Figure:
    """A chain that cannot move (an impossible or a flat chain, :func:`driver.fourbar.grashof`):
    its longest link drawn as one bar and the other three laid end to end beside it, so the gap
    (or the exact match) is seen; the class and its reason in the title.

    ``lengths``: {'fixed link', 'crank', 'coupler', 'rocker': length} in ``units`` (the deck's
    length unit, '' when it is free).  ``ax``: the axes to draw into.
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
    ax.set_xlabel(length_label("length", units))
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


#: the drawing's colours: the page's animation draws the crank, coupler and output link in the same
CRANK_COLOUR, COUPLER_COLOUR, OUTPUT_COLOUR = LINK_COLOURS[:3]
#: the positions other than the one drawn solid: light ghosts
GHOST: dict[str, Any] = dict(color="0.8", lw=0.9, zorder=1)


def _pose(ax, ground: float, row: np.ndarray, p: np.ndarray | None, output: str, label: bool = True) -> None:
    """One position of the linkage drawn solid: crank, coupler (the plate A-B-P with a coupler
    point), output link in the page's colours, pins as open circles."""
    a, b = (row[S.XA], row[S.YA]), (row[S.XB], row[S.YB])
    ax.plot([0.0, a[0]], [0.0, a[1]], color=CRANK_COLOUR, lw=2.4, solid_capstyle="round", zorder=4,
            label="crank $O_2A$" if label else None)
    if p is not None:
        tri = np.array([a, b, p, a])
        ax.fill(tri[:, 0], tri[:, 1], color=COUPLER_COLOUR, alpha=0.18, lw=0, zorder=3)
        ax.plot(tri[:, 0], tri[:, 1], color=COUPLER_COLOUR, lw=2.0, solid_joinstyle="round", zorder=4,
                label="coupler plate $ABP$" if label else None)
        ax.plot(*p, "o", color=COUPLER_COLOUR, ms=5, zorder=6)
    else:
        ax.plot([a[0], b[0]], [a[1], b[1]], color=COUPLER_COLOUR, lw=2.4, solid_capstyle="round", zorder=4,
                label="coupler $AB$" if label else None)
    ax.plot([ground, b[0]], [0.0, b[1]], color=OUTPUT_COLOUR, lw=2.4, solid_capstyle="round", zorder=4,
            label=f"{output} $O_4B$" if label else None)
    ax.plot([a[0], b[0]], [a[1], b[1]], "o", ms=5.5, mfc="white", mec="k", mew=1.0, zorder=7)


def _ghost(ax, ground: float, row: np.ndarray, p: np.ndarray | None, ls: str = "-") -> None:
    """A position drawn as a light ghost behind the solid one (no fill, no pins)."""
    xs = [0.0, row[S.XA], row[S.XB], ground]
    ys = [0.0, row[S.YA], row[S.YB], 0.0]
    ax.plot(xs, ys, ls=ls, **GHOST)
    if p is not None:
        ax.plot([row[S.XA], p[0], row[S.XB]], [row[S.YA], p[1], row[S.YB]], ls=ls, **GHOST)


def _ground(ax, ground: float) -> None:
    ax.plot([0.0, ground], [0.0, 0.0], color="k", lw=2.5, zorder=2)
    ax.plot([0.0, ground], [0.0, 0.0], "^", color="k", ms=9, zorder=8, label="ground pivots $O_2$, $O_4$")


def _counterweights(ax, ground: float, row: np.ndarray, cw: Mapping[str, Any], units: str) -> None:
    """The Berkof-Lowen counterweights at the solid position: on the crank at its radius and
    angle off the crank line, on the output link likewise, each a disc on an arm from its pivot."""
    crank_dir = math.atan2(row[S.YA], row[S.XA])
    out_dir = math.atan2(row[S.YB], row[S.XB] - ground)
    for k, (pivot, direction) in enumerate((((0.0, 0.0), crank_dir), ((ground, 0.0), out_dir))):
        r, ang, m = cw["radius"][k], math.radians(cw["angle_deg"][k]), cw["mass"][k]
        if not (m > 0 and r > 0):
            continue
        c = (pivot[0] + r * math.cos(direction + ang), pivot[1] + r * math.sin(direction + ang))
        ax.plot([pivot[0], c[0]], [pivot[1], c[1]], color=MASS_COLOUR, lw=1.6, zorder=4)
        ax.plot(*c, "o", ms=11 if k else 9, color=MASS_COLOUR, mec="k", zorder=6,
                label=f"{('crank', 'output link')[k]} counterweight {m:.3g} kg at {r:g} {units or 'length units'}")


def _drawing_size(ground: float, out: np.ndarray, point: np.ndarray | None, targets: np.ndarray | None,
                  motions: Sequence[dict] | None) -> tuple[float, float]:
    """A figure size [in] that fits the drawing at equal scales beside its legend: the axes about
    5.6 in wide, as tall as the drawing's aspect asks (3.4 to 6.4 in of it)."""
    parts = [np.array([[0.0, 0.0], [ground, 0.0]])]
    rows = [np.asarray(m["out"]) for m in motions] if motions else [out]
    for o in rows:
        parts += [o[:, [S.XA, S.YA]], o[:, [S.XB, S.YB]]]
    for pt in ([np.asarray(m["point"]) for m in motions if m.get("point") is not None] if motions
               else ([] if point is None else [np.asarray(point)])):
        parts.append(pt[:, :2])
    if targets is not None and len(targets):
        parts.append(np.asarray(targets, dtype=float)[:, :2])
    xy = np.vstack(parts)
    xy = xy[np.isfinite(xy).all(axis=1)]
    w, h = np.ptp(xy[:, 0]), np.ptp(xy[:, 1])
    aspect = min(max(h / w if w > 0 else 1.0, 0.55), 1.15)
    return (9.6, 5.8 * aspect + 1.5)


def _finish(fig, ax, units: str, texts: Sequence[Any] = ()) -> None:
    """Equal scales, axes in the deck's length unit, the legend beside the drawing, labels beside
    points kept inside."""
    ax.set_aspect("equal")
    ax.set_xlabel(length_label("x", units))
    ax.set_ylabel(length_label("y", units))
    drawing_legend(ax, order=("crank $", "coupler", "$O_4B$", "counterweight", "path of", "target", "listing", "limit",
                              "other positions", "ground"))
    if texts:
        ax.margins(0.06)
        keep_texts_inside(ax, texts)


@styled
def fourbar_linkage(ground: float, theta: np.ndarray, out: np.ndarray, ok: np.ndarray,
                    listing, title: str, n_poses: int = 6, point: np.ndarray | None = None,
                    units: str = "", output: str = "rocker",
                    limits: Sequence[tuple[float, np.ndarray]] = (), ax=None,
                    motions: Sequence[dict] | None = None, targets: np.ndarray | None = None,
                    counterweights: Mapping[str, Any] | None = None) -> Figure:
    """The linkage drawn as a lecturer draws it: one position solid (crank, coupler, output link
    in the report page's colours; the one of ``n_poses`` whose transmission angle is nearest 90
    deg), the others as light ghosts, and on top the paths of A and B and of the coupler point
    (``point``: (n, 2) positions, the coupler then drawn as the plate A-B-P), the ``targets``
    ((k, 2) points a path synthesis aims at) and the listing's B.

    ``theta`` [deg] is the drawn crank range (a function generator's design range, or a whole
    turn); the crank pin's path is drawn only where the linkage assembles, so a crank that
    cannot turn shows the arc it swings through, not a circle.  Separate assembly intervals
    are drawn and named as separate motions.  ``limits``: (crank angle [deg], kernel row)
    of the limit (toggle) positions, drawn dashed and labelled.  ``motions``: for a crank that
    cannot turn (driver.fourbar.rocking_motions), per motion a dict of ``lo``, ``hi`` [deg],
    ``theta``, ``out`` (kernel rows), ``stroke`` (0 forward, 1 back), ``branch`` (+1 open, -1
    crossed) and ``point`` (coupler point positions or None): then the linkage is drawn rocking
    between its limit positions, out on one assembly branch and back on the other, each
    motion (a separate assembly interval) on its own.  ``counterweights``: the force balance's
    ``radius``, ``angle_deg`` (off the link line) and ``mass`` [kg] per (crank, output link),
    drawn on the solid position.  ``output`` names the output link.  Coordinates in the deck's
    length ``units`` ('' when the deck's unit is free), crank pivot at the origin, ground along
    +x, equal scales; the legend sits beside the drawing.
    """
    if ax is None:
        fig, ax = drawing_figure(_drawing_size(ground, out, point, targets, motions))
    else:
        fig = ax.figure
    if motions:
        _rocking_drawing(fig, ax, ground, motions, title, units, output, counterweights)
        return fig
    runs = _runs(ok)
    full = bool(ok.all()) and np.ptp(theta) >= 359.0
    idx = np.flatnonzero(ok)
    picks = idx[np.linspace(0, len(idx) - 1, n_poses, endpoint=not full).astype(int)] if len(idx) else np.array([], int)
    solid = None
    if len(picks):   # a clear position: transmission angle near 90 deg, crank off the ground line
        score = np.abs(np.sin(out[picks, S.TRANSMISSION_ANGLE])) * (0.3 + np.abs(np.sin(np.radians(theta[picks]))))
        solid = int(picks[int(np.argmax(np.round(score, 9)))])
    pt = (lambda k: None) if point is None else (lambda k: np.asarray(point[k, :2], dtype=float))
    ghosts = [int(k) for k in picks if k != solid]
    for k in ghosts:
        _ghost(ax, ground, out[k], pt(k))
    if ghosts:
        ax.plot([], [], **GHOST, label="other positions: $\\theta_2$ = " + ", ".join(f"{theta[k]:.0f}" for k in ghosts) + "°")
    for j, (_, row) in enumerate(limits):
        ax.plot([0.0, row[S.XA], row[S.XB], ground], [0.0, row[S.YA], row[S.YB], 0.0], "--", color="k", lw=1.1,
                zorder=2, label="limit (toggle) positions" if j == 0 else None)
    _ground(ax, ground)
    if solid is not None:
        _pose(ax, ground, out[solid], pt(solid), output)
        if counterweights:
            _counterweights(ax, ground, out[solid], counterweights, units)
    for j, r in enumerate(runs if not full else [np.arange(len(ok))]):   # the paths, on top of the positions
        ax.plot(out[r, S.XA], out[r, S.YA], color="0.55", lw=0.9, zorder=5,
                label="path of A (crank pin)" if j == 0 else None)
        ax.plot(out[r, S.XB], out[r, S.YB], color="C3", lw=1.3, zorder=5,
                label=f"path of B ({output} pin)" if j == 0 else None)
        if point is not None:
            ax.plot(point[r, Point.X], point[r, Point.Y], color="C4", lw=1.4, ls="--", zorder=5,
                    label="path of coupler point P" if j == 0 else None)
    if listing is not None:
        ax.plot(listing["xb"], listing["yb"], "x", color="k", ms=5, zorder=9, label="B (listing)")
    if targets is not None and len(targets):
        ax.plot(np.asarray(targets)[:, 0], np.asarray(targets)[:, 1], "s", mfc="none", mec=MARK_COLOUR, mew=1.4,
                ms=8, zorder=10, label="target points")
    texts = [_limit_label(ax, row, rf"$\theta_2$ = {angle:.1f}°") for angle, row in limits]
    lo, hi = float(np.min(theta)), float(np.max(theta))
    what = "linkage" + ("" if full or (hi - lo) >= 359.0 else f" over the crank range {lo:g}-{hi:g}°")
    if solid is not None:
        what += f" at \u03b8\u2082 = {theta[solid]:.0f}°" + (", other positions light" if ghosts else "")
    if len(runs) > 1:
        spans = ", ".join(f"{theta[r[0]]:.0f}-{theta[r[-1]]:.0f}°" for r in runs)
        what += f"\nassembles over {len(runs)} separate crank intervals ({spans}): separate motions"
    suptitle(fig, f"{plain_text(title)}: {what}" if title else what)
    _finish(fig, ax, units, texts)
    return fig


def _deg(value: float, digits: int = 1) -> str:
    """An angle [deg] as printed in a figure: ``digits`` decimals, no '-0'."""
    text = f"{value:.{digits}f}"
    return text[1:] if text.lstrip("-").strip("0.") == "" and text.startswith("-") else text


def _limit_label(ax, row: np.ndarray, text: str):
    """A limit position's label beside its crank pin A, pushed outward (away from the crank
    pivot) on a white ground so it does not sit on the pose lines; returns the text (the
    drawing's limits then grow to hold it: :func:`driver.plotting.keep_texts_inside`)."""
    x, y = float(row[S.XA]), float(row[S.YA])
    r = math.hypot(x, y) or 1.0
    ux, uy = x / r, y / r
    return ax.annotate(text, (x, y), xytext=(14 * ux, 14 * uy), textcoords="offset points", fontsize=8,
                       ha="left" if ux > 0.3 else "right" if ux < -0.3 else "center",
                       va="bottom" if uy > 0.3 else "top" if uy < -0.3 else "center",
                       bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="none", alpha=0.85), zorder=11)


def _rocking_drawing(fig, ax, ground: float, motions: Sequence[dict], title: str, units: str, output: str,
                     counterweights: Mapping[str, Any] | None = None) -> None:
    """The linkage of a crank that cannot turn, rocking between its limit positions (see
    :func:`fourbar_linkage`): per motion the crank pin's arc, B's path out (solid, the first
    branch) and back (dashed, the other branch), the coupler point's likewise, the middle of the
    first forward stroke drawn solid, a few other positions of each stroke as light ghosts
    (dotted on the way back), and the two limit positions dashed black and labelled."""
    word = {1: "open", -1: "crossed"}
    n_m = len(motions)
    texts = []
    ghost_words: list[str] = []
    solid: tuple[np.ndarray, np.ndarray | None] | None = None
    solid_words = ""
    for i, m in enumerate(motions):
        out, stroke, theta = np.asarray(m["out"]), np.asarray(m["stroke"]), np.asarray(m["theta"])
        branch = np.asarray(m["branch"])
        fwd, back = np.flatnonzero(stroke == 0), np.flatnonzero(stroke == 1)
        pt = None if m.get("point") is None else np.asarray(m["point"])
        at = [1 / 3, 2 / 3] if n_m > 1 else [0.2, 0.5, 0.8]   # fractions of a stroke's samples
        picks = [fwd[int(f * (len(fwd) - 1))] for f in at] + [back[int(f * (len(back) - 1))] for f in at]
        # drawn solid: the clearest position of the first stroke (transmission angle near 90 deg,
        # crank off the ground line)
        stroke1 = picks[:len(at)]
        score = np.abs(np.sin(out[stroke1, S.TRANSMISSION_ANGLE])) * (0.3 + np.abs(np.sin(np.radians(theta[stroke1]))))
        best = int(np.argmax(np.round(score, 9)))
        for j, k in enumerate(picks):
            p = None if pt is None else pt[k, :2]
            if i == 0 and j == best:
                solid = (out[k], p)
                solid_words = f"\u03b8\u2082 = {_deg(theta[k], 0)}° \u2192 {word[int(branch[k])]}"
                continue
            _ghost(ax, ground, out[k], p, ls=":" if stroke[k] == 1 else "-")
            ghost_words.append(f"{_deg(theta[k], 0)}°")
        for end, angle in ((fwd[0], m["lo"]), (fwd[-1], m["hi"])):
            row = out[end]
            ax.plot([0.0, row[S.XA], row[S.XB], ground], [0.0, row[S.YA], row[S.YB], 0.0], "--", color="k", lw=1.1,
                    zorder=2, label="limit positions (the crank reverses)" if i == 0 and end == fwd[0] else None)
            ax.plot([row[S.XA]], [row[S.YA]], "o", color="k", ms=4, zorder=6)
            texts.append(_limit_label(ax, row, rf"limit $\theta_2$ = {_deg(angle)}°"))
    if ghost_words:
        ax.plot([], [], **GHOST, label="other positions (dotted: on the way back)")
    _ground(ax, ground)
    if solid is not None:
        _pose(ax, ground, solid[0], solid[1], output)
        if counterweights:
            _counterweights(ax, ground, solid[0], counterweights, units)
    for i, m in enumerate(motions):   # the paths, on top of the positions
        out, stroke = np.asarray(m["out"]), np.asarray(m["stroke"])
        first = int(np.asarray(m["branch"])[0])
        fwd, back = np.flatnonzero(stroke == 0), np.flatnonzero(stroke == 1)
        ax.plot(out[fwd, S.XA], out[fwd, S.YA], color="0.55", lw=0.9, zorder=5,
                label="path of A (crank pin): an arc" if i == 0 else None)
        ax.plot(out[fwd, S.XB], out[fwd, S.YB], color="C3", lw=1.3, zorder=5,
                label=f"path of B, out on the {word[first]} assembly" if i == 0 else None)
        ax.plot(out[back, S.XB], out[back, S.YB], color="C3", lw=1.3, ls="--", zorder=5,
                label=f"path of B, back on the {word[-first]} assembly" if i == 0 else None)
        pt = m.get("point")
        if pt is not None:
            pt = np.asarray(pt)
            ax.plot(pt[fwd, Point.X], pt[fwd, Point.Y], color="C4", lw=1.2, zorder=5,
                    label="path of coupler point P" if i == 0 else None)
            ax.plot(pt[back, Point.X], pt[back, Point.Y], color="C4", lw=1.2, ls="--", zorder=5)
    out_word = word[int(np.asarray(motions[0]["branch"])[0])]
    back_word = word[-int(np.asarray(motions[0]["branch"])[0])]
    what = "the crank rocks between its limit positions"
    if n_m == 1:
        m = motions[0]
        what += (f"\n\u03b8\u2082 = {_deg(m['lo'])}° to {_deg(m['hi'])}°: out on the {out_word} assembly, "
                 f"back on the {back_word}")
    else:
        spans = " and ".join(f"{_deg(m['lo'])}-{_deg(m['hi'])}°" for m in motions)
        what += (f"\n{n_m} separate motions (mirror assemblies, \u03b8\u2082 = {spans}),"
                 f"\neach out on the {out_word} assembly, back on the {back_word}")
    if solid_words:
        what += f"\ndrawn at {solid_words}"
    suptitle(fig, f"{plain_text(title)}: {what}" if title else what)
    _finish(fig, ax, units, texts)


# ----------------------------------------------------------------------------- figures of a run


# ----------------------------------------------------------------------------- the force analysis

#: one style per meaning in every force figure: the linkage analysed (with its counterweights
#: when the deck balances) solid blue, the same linkage without counterweights dashed red
AS_ANALYSED: dict[str, Any] = dict(color="C0", lw=1.5, ls="-")
WITHOUT_COUNTERWEIGHTS: dict[str, Any] = dict(color="C3", lw=1.2, ls="--")
#: crank angles marked on the pin-force loci [deg]
MARKED_ANGLES = (0.0, 90.0, 180.0, 270.0)


def _analysed_label(fa: ForceAnalysis) -> str:
    return "with counterweights (Berkof-Lowen)" if fa.unbalanced is not None else "as given"


def plot_torque(theta: np.ndarray, fa: ForceAnalysis, p: Mapping[str, Any], ax: Any, legend: bool = True) -> Any:
    """Plot the input torque against crank angle, its mean, and the energy fluctuation dE.

    dE is shaded between the torque curve and the mean; with balancing the torque of the
    linkage without counterweights is dashed (the same style as in the pin-force and shaking
    figures).

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
    legend : bool, default True
        Give ``ax`` its legend (beside it); False leaves it to the caller (a figure legend).

    Returns
    -------
    matplotlib.axes.Axes
        ``ax``.
    """
    t = np.where(fa.ok, fa.forces[:, Force.INPUT_TORQUE], np.nan)
    ax.plot(theta, t, **AS_ANALYSED, label=f"input torque, {_analysed_label(fa)}")
    if fa.ok.all() and len(theta) > 1:
        mean = np.trapezoid(t, theta) / (theta[-1] - theta[0])
        e = np.concatenate([[0.0], np.cumsum(0.5 * (t[1:] + t[:-1] - 2 * mean) * np.diff(np.radians(theta)))])
        shown = 0.0 if abs(mean) < 5e-4 else mean   # the .out's 3 decimals; no '-0.000'
        ax.axhline(mean, color="0.35", lw=0.9, ls=":", label=f"mean {shown:.3f} N m")
        ax.fill_between(theta, t, mean, color="C0", alpha=0.15,
                        label=f"energy fluctuation dE = {e.max() - e.min():.4g} J (largest minus smallest area)")
    if fa.unbalanced is not None:
        ax.plot(theta, np.where(fa.ok, fa.unbalanced[:, Force.INPUT_TORQUE], np.nan), **WITHOUT_COUNTERWEIGHTS,
                label="input torque, without counterweights")
    ax.set_xlim(float(np.min(theta)), float(np.max(theta)))
    ax.set_xlabel("crank angle \u03b8\u2082 [deg]")
    ax.set_ylabel("input torque [N m]")
    if legend:
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    return ax


def _empty_sector(curves: list[tuple[np.ndarray, np.ndarray]]) -> float:
    """The direction [deg] of the 45-deg sector where the drawn loci reach least far: the radial
    tick labels go there, off the curves."""
    best, where = np.inf, 22.5
    for centre in np.arange(22.5, 360.0, 45.0):
        reach = 0.0
        for ang, rad in curves:
            d = np.abs((np.degrees(ang) - centre + 180.0) % 360.0 - 180.0)
            near = (d < 22.5) & np.isfinite(rad)
            if near.any():
                reach = max(reach, float(np.max(rad[near])))
        if reach < best - 1e-12:
            best, where = reach, float(centre)
    return where


def plot_pin_polars(fa: ForceAnalysis, axes: Any, theta: np.ndarray | None = None) -> Any:
    """Plot the force at each pin over the cycle on polar axes.

    Angle = direction of the force, radius = its magnitude in N; with balancing, the linkage
    without counterweights dashed (the same style as in the torque and shaking figures).  The
    crank angles of :data:`MARKED_ANGLES` are marked on each locus (with ``theta``), the radial
    labels sit in the emptiest sector, off the curves.

    Parameters
    ----------
    fa : ForceAnalysis
        The forces (``driver.fourbar.forces.analyse``).
    axes : sequence of matplotlib.axes.Axes
        Four polar axes: O2, A, B, O4.
    theta : numpy.ndarray, optional
        The crank angles of the forces, deg (to mark the loci).

    Returns
    -------
    sequence of matplotlib.axes.Axes
        ``axes``.
    """
    names = ("$O_2$: ground on crank", "A: crank on coupler", "B: coupler on rocker", "$O_4$: ground on rocker")
    pins = ((Force.F_O2_X, Force.F_O2_Y), (Force.F_A_X, Force.F_A_Y), (Force.F_B_X, Force.F_B_Y),
            (Force.F_O4_X, Force.F_O4_Y))
    for j, ax in enumerate(np.ravel(axes)[:4]):
        fx = np.where(fa.ok, fa.forces[:, pins[j][0]], np.nan)
        fy = np.where(fa.ok, fa.forces[:, pins[j][1]], np.nan)
        ang, rad = np.arctan2(fy, fx), np.hypot(fx, fy)
        ax.plot(ang, rad, **AS_ANALYSED, label=_analysed_label(fa))
        curves = [(ang, rad)]
        if fa.unbalanced is not None:
            bx = np.where(fa.ok, fa.unbalanced[:, pins[j][0]], np.nan)
            by = np.where(fa.ok, fa.unbalanced[:, pins[j][1]], np.nan)
            ax.plot(np.arctan2(by, bx), np.hypot(bx, by), **WITHOUT_COUNTERWEIGHTS, label="without counterweights")
            curves.append((np.arctan2(by, bx), np.hypot(bx, by)))
        if theta is not None:   # where the crank is at 0, 90, 180, 270 deg, on the analysed locus
            for a in MARKED_ANGLES:
                k = int(np.argmin(np.abs((np.asarray(theta) - a + 180.0) % 360.0 - 180.0)))
                if fa.ok[k] and abs((theta[k] - a + 180.0) % 360.0 - 180.0) < 1.0:
                    ax.plot([ang[k]], [rad[k]], "o", ms=4, color="k", zorder=5,
                            label="crank angle \u03b8\u2082 = 0, 90, 180, 270°" if a == 0.0 else None)
                    ax.annotate(f"{a:.0f}", (ang[k], rad[k]), xytext=(3, 3), textcoords="offset points", fontsize=7,
                                zorder=6, bbox=dict(boxstyle="round,pad=0.1", fc="white", ec="none", alpha=0.8))
        ax.set_rlabel_position(_empty_sector(curves))
        ax.tick_params(axis="y", labelsize=7)
        ax.tick_params(axis="x", labelsize=7, pad=1)
        ax.set_title(f"force on pin {names[j]} [N]", fontsize=8.5)
    return axes


def plot_shaking(theta: np.ndarray, fa: ForceAnalysis, ax: Any, polar_ax: Any | None = None) -> Any:
    """Plot the shaking force magnitude against crank angle, and its locus.

    With and without counterweights, in the same styles as the torque and pin-force figures.

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
    shaking = [Force.SHAKING_X, Force.SHAKING_Y]
    s = np.where(fa.ok[:, None], fa.forces[:, shaking], np.nan)
    ax.plot(theta, np.hypot(*s.T), **AS_ANALYSED, label=_analysed_label(fa))
    if polar_ax is not None:
        polar_ax.plot(s[:, 0], s[:, 1], **AS_ANALYSED, label=_analysed_label(fa))
        if fa.unbalanced is not None and np.nanmax(np.hypot(*s.T)) < 1e-9 * max(1.0, float(np.nanmax(np.abs(fa.forces)))):
            polar_ax.plot([0.0], [0.0], "o", ms=5, color=AS_ANALYSED["color"], zorder=5)   # a locus that is a point
    if fa.unbalanced is not None:
        b = np.where(fa.ok[:, None], fa.unbalanced[:, shaking], np.nan)
        ax.plot(theta, np.hypot(*b.T), **WITHOUT_COUNTERWEIGHTS, label="without counterweights")
        if polar_ax is not None:
            polar_ax.plot(b[:, 0], b[:, 1], **WITHOUT_COUNTERWEIGHTS, label="without counterweights")
    ax.set_xlim(float(np.min(theta)), float(np.max(theta)))
    ax.set_xlabel("crank angle \u03b8\u2082 [deg]")
    ax.set_ylabel("|shaking force| [N]")
    if polar_ax is not None:
        polar_ax.set_xlabel("shaking force x [N]")
        polar_ax.set_ylabel("shaking force y [N]")
        polar_ax.set_aspect("equal", adjustable="datalim")
        polar_ax.set_title("locus of the shaking force", fontsize=9)
    return ax
