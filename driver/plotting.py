"""The one plotting module (matplotlib object API; no screen, no pyplot state).

Shared helpers first; then one section per study with its figure builders.
Every builder returns a :class:`matplotlib.figure.Figure` drawn inside
:func:`style` (an ``rc_context``), and :func:`save_figure` writes it atomically
as PNG, SVG or PDF, byte for byte the same for the same inputs.  Nothing here selects a backend or changes the global ``rcParams``:
importing this module or drawing a figure leaves a user's own matplotlib
settings (e.g. Jupyter's inline backend) exactly as they were.  Studies wrap
builders in :class:`driver.study.Figure` so nothing is drawn unless asked.
"""
from __future__ import annotations

import contextlib
import functools
import math
import re
import warnings
from pathlib import Path
from typing import Any, Callable, Iterator, Sequence, TypeVar

from driver.extras import require

require("plot")   # a clear message naming the [plot] extra when matplotlib is missing
import matplotlib  # noqa: E402
import matplotlib.ticker
import matplotlib.colors
import numpy as np
from matplotlib.figure import Figure

from driver.atomic import atomic_open
from driver.study import PLOT_FORMATS, plot_format

__all__ = ["STYLE", "style", "styled", "new_figure", "save_figure", "line_panels", "plain_text"]

#: the house style, applied only inside :func:`style` (never written to the global rcParams)
STYLE: dict[str, Any] = {"figure.dpi": 150, "savefig.dpi": 150, "axes.grid": True, "grid.alpha": 0.3,
                         "axes.spines.top": False, "axes.spines.right": False, "font.size": 9,
                         "legend.fontsize": 8.5, "axes.formatter.useoffset": False}

_F = TypeVar("_F", bound=Callable[..., Any])


def plain_text(text: Any) -> str:
    """Text from a deck (a title, a design name, the deck's file name, a value, an expression)
    as matplotlib draws it literally: never mathtext (every ``$`` escaped, so ``'$\\frac$'`` or
    nested braces cannot raise a parse error), control characters dropped.  Every figure
    builder passes deck text through this one function."""
    text = "".join(ch for ch in str(text) if ch.isprintable() or ch == "\n")
    return text.replace("$", r"\$")


def wrap(text: str, width: int) -> str:
    """``text`` filled to lines of about ``width`` characters like :func:`textwrap.fill`, but a
    mathtext span (``$|\\tau_1| + |\\tau_2|$``) is never broken across lines: matplotlib
    parses each line on its own, and half a span would be drawn as its raw source."""
    tokens = re.findall(r"(?:[^\s$\\]|\\.|(?<!\\)\$(?:[^$\\]|\\.)*\$)+", text)
    if re.sub(r"\s+", "", "".join(tokens)) != re.sub(r"\s+", "", text):   # an unpaired $: no span to keep whole
        import textwrap
        return textwrap.fill(text, width)
    lines: list[str] = []
    line = ""
    for tok in tokens:
        shown = len(re.sub(r"\\[A-Za-z]+|[{}_^$]", "", tok)) or 1
        if line and len(re.sub(r"\\[A-Za-z]+|[{}_^$]", "", line)) + 1 + shown > width:
            lines.append(line)
            line = tok
        else:
            line = f"{line} {tok}" if line else tok
    if line:
        lines.append(line)
    return "\n".join(lines)


@contextlib.contextmanager
def style(**overrides: Any) -> Iterator[None]:
    """Draw inside this context to get the house style; rcParams are restored on exit.

    matplotlib's warnings (a glyph missing from the font, identical axis limits) are dropped
    here: they name package paths and say nothing a user of the tool can act on."""
    with matplotlib.rc_context({**STYLE, **overrides}), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        yield


def styled(builder: _F) -> _F:
    """Decorator: run a figure builder inside :func:`style`."""
    @functools.wraps(builder)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        with style():
            return builder(*args, **kwargs)
    return wrapper  # type: ignore[return-value]


def new_figure(nrows: int = 1, ncols: int = 1, **kw) -> tuple[Figure, np.ndarray]:
    """A figure and a flat array of axes (no pyplot state is kept)."""
    fig = Figure(figsize=kw.pop("figsize", (6.4 * ncols, 3.2 * nrows)), layout="constrained")
    axes = fig.subplots(nrows, ncols, squeeze=False, **kw)
    return fig, axes.ravel()


#: metadata written into every figure file: no dates, no software versions, so the same
#: inputs give byte-identical files (PNG, SVG and PDF alike)
_METADATA = {"png": {"Software": None},
             "svg": {"Date": None, "Creator": None},
             "pdf": {"Creator": None, "Producer": None, "CreationDate": None}}
#: fixed seed for the ids matplotlib writes into SVG files (otherwise random per run)
_SVG_SALT = "driver-figures"


def save_figure(fig: Figure, path: str | Path, fmt: bool | str | None = None) -> Path:
    """Write ``fig`` to ``path`` atomically and reproducibly (no dates or versions inside), in the
    house style's resolution.

    ``fmt`` is a format of :data:`driver.study.PLOT_FORMATS` (``True`` or None: PNG, or the
    format of ``path``'s suffix when that is one); ``path``'s suffix is replaced by it.
    Returns the path written.
    """
    path = Path(path)
    if fmt is None or fmt is True:
        fmt = path.suffix.lstrip(".").lower() if path.suffix.lstrip(".").lower() in PLOT_FORMATS else "png"
    fmt = plot_format(fmt)
    path = path.with_suffix(f".{fmt}")
    with style(**{"svg.hashsalt": _SVG_SALT}), atomic_open(path, "wb") as fh:
        fig.savefig(fh, format=fmt, metadata=_METADATA[fmt])
    return path


@styled
def line_panels(x: np.ndarray, panels: Sequence[tuple[str, dict[str, np.ndarray]]], xlabel: str,
                title: str = "", styles: dict[str, dict] | None = None, axes=None) -> Figure:
    """Stacked panels sharing x: each panel is (ylabel, {label: y}); NaN gaps break lines.
    ``axes``: one axes per panel to draw into (their figure is returned)."""
    if axes is None:
        fig, axes = new_figure(len(panels), 1, sharex=True, figsize=(7.0, 2.2 * len(panels) + 0.6))
    else:
        fig = axes[0].figure
    for ax, (ylabel, series) in zip(axes, panels):
        for label, y in series.items():
            ax.plot(x, y, label=label, **(styles or {}).get(label, {}))
        ax.set_ylabel(ylabel)
        if len(series) > 1:
            ax.legend(loc="best")
    axes[-1].set_xlabel(xlabel)
    if title:
        fig.suptitle(plain_text(title))
    return fig


# ----------------------------------------------------------------------------- fourbar

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


#: legend words of the four-bar curves: words first, textbook link numbers (2 crank, 3 coupler,
#: 4 output link) as symbols; the tidy columns keep the paper's names (omega2 = coupler)
def _fourbar_names(output: str = "rocker") -> dict[str, str]:
    return {"coupler_deg": r"coupler angle $\theta_3$", "rocker_deg": rf"{output} angle $\theta_4$",
            "transmission_deg": r"transmission angle $\mu$",
            "omega2_rad_s": r"coupler angular velocity $\omega_3$",
            "omega3_rad_s": rf"{output} angular velocity $\omega_4$"}


@styled
def fourbar_curves(exact, listing, title: str, band: Sequence[float] = (40.0, 120.0), output: str = "rocker",
                   axes=None) -> Figure:
    """Angles, angular velocities and transmission angle against crank angle.

    ``exact`` and ``listing`` are tidy frames from driver.fourbar; listing rows are
    drawn as markers over the exact curves so the listing's defect is visible.  Angles
    wrapped into 0-360 deg break at the wrap (no vertical line); crank angles where the
    linkage cannot be assembled are shaded and said so; the transmission-angle ``band``
    [deg] is shaded.  ``output`` names the output link ('rocker', 'output crank').
    ``axes``: three axes to draw into.
    """
    names = _fourbar_names(output)
    panels = [("link angle [deg]", ["coupler_deg", "rocker_deg"]),
              ("transmission angle [deg]", ["transmission_deg"]),
              ("angular velocity [rad/s]", ["omega2_rad_s", "omega3_rad_s"])]
    if axes is None:
        fig, axes = new_figure(3, 1, sharex=True, figsize=(7.4, 7.6))
    else:
        fig = axes[0].figure
    colors = {"coupler_deg": "C0", "rocker_deg": "C1", "transmission_deg": "C2",
              "omega2_rad_s": "C0", "omega3_rad_s": "C1"}
    theta = exact["theta_deg"].to_numpy(dtype=float)
    spans = _unassembled_spans(theta, np.isfinite(exact["transmission_deg"].to_numpy(dtype=float)))
    for ax, (label, keys) in zip(axes, panels):
        for j, (lo, hi) in enumerate(spans):
            ax.axvspan(lo, hi, color="0.85", alpha=0.6, lw=0, label="cannot be assembled" if j == 0 else None)
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
    if title:
        fig.suptitle(f"{plain_text(title)}: four-bar kinematics")
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
    motion (a separate assembly interval) on its own.  ``output`` names the output link.  Coordinates in the deck's length ``units``, crank pivot at the origin, ground along
    +x; the legend sits beside the drawing.
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
        ax.plot(out[r, 3], out[r, 4], color="0.55", lw=0.9, label="path of A (crank pin)" if j == 0 else None)
        ax.plot(out[r, 5], out[r, 6], color="C3", lw=1.3, label=f"path of B ({output} pin)" if j == 0 else None)
        if point is not None:
            ax.plot(point[r, 0], point[r, 1], color="C4", lw=1.3, ls="--",
                    label="path of coupler point P" if j == 0 else None)
    if listing is not None:
        ax.plot(listing["xb"], listing["yb"], "x", color="k", ms=5, label="B (listing)")
    cmap = matplotlib.colormaps["viridis"]
    # poses spread over the assembled samples (every run gets some)
    idx = np.flatnonzero(ok)
    picks = idx[np.linspace(0, len(idx) - 1, n_poses, endpoint=not full).astype(int)] if len(idx) else []
    for j, k in enumerate(picks):
        c = cmap(j / max(1, n_poses - 1))
        xs = [0.0, out[k, 3], out[k, 5], ground]
        ys = [0.0, out[k, 4], out[k, 6], 0.0]
        ax.plot(xs, ys, "-o", color=c, ms=3, lw=1.5, label=rf"$\theta_2$ = {theta[k]:.0f}°")
        if point is not None:
            tri = np.array([[out[k, 3], out[k, 4]], [out[k, 5], out[k, 6]], point[k], [out[k, 3], out[k, 4]]])
            ax.fill(tri[:, 0], tri[:, 1], color=c, alpha=0.15, lw=0)
            ax.plot(tri[:, 0], tri[:, 1], color=c, lw=1.0)
            ax.plot(*point[k], "o", color=c, ms=3.5)
    for j, (angle, row) in enumerate(limits):
        xs = [0.0, row[3], row[5], ground]
        ys = [0.0, row[4], row[6], 0.0]
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
    x, y = float(row[3]), float(row[4])
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
        ax.plot(out[fwd, 3], out[fwd, 4], color="0.55", lw=0.9, label="path of A (crank pin): an arc" if i == 0 else None)
        ax.plot(out[fwd, 5], out[fwd, 6], color="C3", lw=1.3,
                label=f"path of B, out on the {word[first]} assembly" if i == 0 else None)
        ax.plot(out[back, 5], out[back, 6], color="C3", lw=1.3, ls="--",
                label=f"path of B, back on the {word[-first]} assembly" if i == 0 else None)
        pt = m.get("point")
        if pt is not None:
            pt = np.asarray(pt)
            ax.plot(pt[fwd, 0], pt[fwd, 1], color="C4", lw=1.2, label="path of coupler point P" if i == 0 else None)
            ax.plot(pt[back, 0], pt[back, 1], color="C4", lw=1.2, ls="--")
        # poses: three inside each stroke (the limits are drawn on their own)
        at = [1 / 3, 2 / 3] if n_m > 1 else [0.2, 0.5, 0.8]   # fractions of a stroke's samples
        picks = [fwd[int(f * (len(fwd) - 1))] for f in at] + [back[int(f * (len(back) - 1))] for f in at]
        for j, k in enumerate(picks):
            c = cmap((j + 0.5) / len(picks))
            back_pose = stroke[k] == 1
            xs = [0.0, out[k, 3], out[k, 5], ground]
            ys = [0.0, out[k, 4], out[k, 6], 0.0]
            arrow = "\u2192" if not back_pose else "\u2190"
            ax.plot(xs, ys, "-o", color=c, ms=3, lw=1.4, ls=":" if back_pose else "-", alpha=0.95,
                    label=(rf"$\theta_2$ = {_deg(theta[k], 0)}° {arrow} {word[int(np.asarray(m['branch'])[k])]}"
                           + tag))
            if pt is not None:
                tri = np.array([[out[k, 3], out[k, 4]], [out[k, 5], out[k, 6]], pt[k], [out[k, 3], out[k, 4]]])
                ax.fill(tri[:, 0], tri[:, 1], color=c, alpha=0.12, lw=0)
                ax.plot(tri[:, 0], tri[:, 1], color=c, lw=0.9, ls=":" if back_pose else "-")
        for end, angle in ((fwd[0], m["lo"]), (fwd[-1], m["hi"])):
            row = out[end]
            ax.plot([0.0, row[3], row[5], ground], [0.0, row[4], row[6], 0.0], "--", color="k", lw=1.1,
                    label="limit positions (the crank reverses)" if i == 0 and end == fwd[0] else None)
            ax.plot([row[3]], [row[4]], "o", color="k", ms=4)
            _limit_label(ax, row, rf"limit $\theta_2$ = {_deg(angle)}°")
    ax.plot([0.0, ground], [0.0, 0.0], color="k", lw=2.5)
    ax.plot([0.0, ground], [0.0, 0.0], "^", color="k", ms=9, label="ground pivots $O_2$, $O_4$")
    ax.set_aspect("equal")
    ax.margins(0.1)   # room for the limit labels
    ax.set_xlabel(f"x [{units}]")
    ax.set_ylabel(f"y [{units}]")
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), frameon=False)
    first = word[int(np.asarray(motions[0]["branch"])[0])]
    other = word[-int(np.asarray(motions[0]["branch"])[0])]
    what = "the crank rocks between its limit positions"
    if n_m == 1:
        m = motions[0]
        what += (f"\n$\\theta_2$ = {_deg(m['lo'])}° to {_deg(m['hi'])}°: out on the {first} assembly, "
                 f"back on the {other}")
    else:
        spans = " and ".join(f"{_deg(m['lo'])}-{_deg(m['hi'])}°" for m in motions)
        what += (f"\n{n_m} separate motions (mirror assemblies, $\\theta_2$ = {spans}),"
                 f"\neach out on the {first} assembly, back on the {other}")
    ax.set_title(f"{plain_text(title)}: {what}" if title else what)


# ----------------------------------------------------------------------------- manipulator

def _ellipse_levels(levels: Sequence[float], n: int) -> list[float]:
    """The RI2 values whose ellipses the design-space figure draws: the deck's (its Table 4.1
    rows) and, as RI2 = sqrt(n) is the C_rob circle itself, three more so the family shows."""
    lo, hi = math.sqrt(n), math.sqrt(2 * n)
    extra = [lo + f * (hi - lo) for f in (0.05, 0.2, 0.5)]
    return sorted({round(float(v), 12) for v in [*levels, *extra] if 0.0 < v < hi})


def ri2_ellipses(ri2: float, n: int, c: float, samples: int = 721) -> list[tuple[np.ndarray, np.ndarray]]:
    """The two iso-RI2 ellipses (the report's eqs 4.14-4.17) as (l1, l2) [m] point arrays, cut to
    l1, l2 >= 0: in the 45-deg frame L1 = (l1 + l2)/sqrt2, L2 = (l1 - l2)/sqrt2 they are
    RI2^2 L1^2 + (2n - RI2^2) L2^2 = c and the same with the coefficients swapped (c = sum d^2 [m^2])."""
    phi = np.linspace(0.0, 2.0 * np.pi, samples)
    out = []
    for ca, cb in ((ri2 * ri2, 2 * n - ri2 * ri2), (2 * n - ri2 * ri2, ri2 * ri2)):
        P, Q = math.sqrt(c / ca) * np.cos(phi), math.sqrt(c / cb) * np.sin(phi)
        x, y = (P + Q) / math.sqrt(2.0), (P - Q) / math.sqrt(2.0)
        keep = (x >= -1e-9) & (y >= -1e-9)
        out.append((np.where(keep, x, np.nan), np.where(keep, y, np.nan)))
    return out


@styled
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
            for j, v in enumerate(_ellipse_levels(levels, n)):
                for k2, (x, y) in enumerate(ri2_ellipses(v, n, sum_d2)):
                    ax.plot(x, y, ":", lw=1.0, color=matplotlib.colormaps["viridis"](j / 4), gid=f"iso-RI2 ellipse {v!r}",
                            label=f"iso-RI2 ellipse, RI2 = {v:.3g}" if k2 == 0 else None)
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
            ax.annotate(plain_text(name), (a, b), textcoords="offset points", xytext=(4, 4), fontsize=7)
        ax.set_xlim(0, top)
        ax.set_ylim(0, top)
        ax.set_aspect("equal")
        ax.set_xlabel("l1 [m]")
        ax.set_ylabel("l2 [m]")
    axes[0].set_title("reach region, C_rob, iso-RI2 ellipses")
    axes[1].set_title("RI2 over the design plane")
    fig.legend(*axes[0].get_legend_handles_labels(), loc="outside lower center", ncol=4, frameon=False)
    if title:
        fig.suptitle(plain_text(title))
    return fig


@styled
def manipulator_torque_crob(l1: np.ndarray, tau1: np.ndarray, tau2: np.ndarray, c: float,
                            violates: np.ndarray | None = None, title: str = "") -> Figure:
    """Motor torques tau1, tau2 and their sum [N m] against l1 [m] along C_rob (Table 4.8).

    Rows where the target is out of reach are gaps; ``violates`` marks the rows (a boolean
    per row) whose design does not reach the whole workspace (the reach conditions
    |l1 - l2| <= r, l1 + l2 >= R fail): their points are crossed and named in the legend."""
    fig, (ax,) = new_figure(1, 1, figsize=(7.4, 3.8))
    total = tau1 + tau2
    for label, y in (("tau1", tau1), ("tau2", tau2), ("tau1 + tau2", total)):
        ax.plot(l1, y, "-o", ms=2.5, lw=1.2, label=label)
    if violates is not None and np.any(violates):
        bad = np.asarray(violates, dtype=bool)
        for k, y in enumerate((tau1, tau2, total)):
            ax.plot(l1[bad], y[bad], "x", color="C3", ms=7, mew=1.5,
                    label="violates the workspace reach conditions" if k == 0 else None)
    ax.set_ylabel("motor torque [N m]")
    ax.set_xlabel("l1 [m]  (l2 = sqrt(%g - l1^2) [m])" % c)
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    fig.suptitle(f"{plain_text(title)}: motor torques along C_rob" if title else "Motor torques along C_rob")
    return fig


# ----------------------------------------------------------------------------- sweep

def _trivial(y, x, chosen, unit: str = "") -> bool:
    """A panel that shows nothing: a constant column, round-off (angles all below 1e-5 deg), the
    x column or a swept key again, or a column already shown."""
    import pandas as pd
    v = pd.to_numeric(y, errors="coerce").to_numpy(dtype=float)
    fin = v[np.isfinite(v)]
    if fin.size == 0 or np.ptp(fin) <= 1e-12 * max(1.0, float(np.max(np.abs(fin)))):
        return True
    if unit == "deg" and float(np.max(np.abs(fin))) < 1e-5:
        return True
    for other in [x, *chosen]:
        w = pd.to_numeric(other, errors="coerce").to_numpy(dtype=float)
        if w.shape == v.shape and np.array_equal(np.isfinite(w), np.isfinite(v)) and \
                np.allclose(w[np.isfinite(w)], fin, rtol=1e-12, atol=0.0):
            return True
    return False


@styled
def sweep_summary(frame, keys: Sequence[str], x: str = "", ys: Sequence[str] = (), title: str = "",
                  labels: dict[str, str] | None = None, preferred: Sequence[str] = ()) -> Figure:
    """Summary of a sweep: chosen (or the study's headline) figures against a swept key.

    ``labels`` maps column names to axis labels with units (driver.study.column_label);
    ``preferred`` are the study's headline columns, plotted when ``ys`` is empty.  Panels
    chosen automatically never repeat x, a constant or another panel.  With one numeric x
    the figures are drawn as lines over the cases, one line per value of the other keys;
    when some cases are not kept, kept cases are circled.
    """
    import pandas as pd
    labels = labels or {}
    only_points = False
    # a label that is the column's own name may be deck text (an expression): drawn literally
    label = lambda c: wrap(labels.get(c, c) if labels.get(c, c) != c else plain_text(c), 28)  # noqa: E731
    x = x or next((k for k in keys if pd.api.types.is_numeric_dtype(frame[k])), "case")
    if ys:
        ys = list(ys)
    else:
        numeric = [c for c in frame.columns if c not in (x, "case") and pd.api.types.is_numeric_dtype(frame[c])
                   and not pd.api.types.is_bool_dtype(frame[c]) and c not in keys]
        ordered = [c for c in preferred if c in numeric] + [c for c in numeric if c not in preferred]
        ys = []
        unit = lambda c: labels.get(c, "").rpartition("[")[2].rstrip("]")  # noqa: E731
        for c in ordered:
            if len(ys) < 6 and not _trivial(frame[c], frame[x], [frame[k] for k in [*ys, *keys]], unit(c)):
                ys.append(c)
        if not ys:   # every figure constant or round-off: show how the kept designs' other keys vary with x
            ys = [k for k in keys if k != x and pd.api.types.is_numeric_dtype(frame[k])] or ordered[:1]
            keys = [k for k in keys if k not in ys]
            only_points = True   # a key against a key: points, no line (angles may wrap between them)
    fig, axes = new_figure(len(ys), 1, sharex=True, figsize=(7.0, 1.9 * len(ys) + 0.9))
    kept = frame["kept"].astype(bool) if "kept" in frame else pd.Series(True, index=frame.index)
    others = [k for k in keys if k != x]
    many = len(frame) > 2000 or bool(others and frame.groupby(others).ngroups > 12)
    groups = [("", frame)] if (many or not others) else frame.groupby(others, sort=False)
    if many:
        others = []
    for ax, y in zip(axes, ys):
        if many:   # a design-space search: every case as a dot, kept cases circled
            ax.plot(frame[x], frame[y], ".", ms=1, color="0.6", alpha=0.3, rasterized=True, label="all cases")
            if not kept.all():
                ax.plot(frame.loc[kept, x], frame.loc[kept, y], "o", ms=3, mfc="none", color="C3", label="kept")
            ax.set_ylabel(label(y))
            continue
        for key, g in groups:
            g = g.sort_values(x)
            style = "-" if len(frame) <= 2000 and not only_points else ""
            ax.plot(g[x], g[y], style, marker="o" if len(frame) <= 200 else ".", ms=3, lw=1,
                    label=", ".join(f"{labels.get(k, k).split(' [')[0]} = {plain_text(v)}"
                                    for k, v in zip(others, key if isinstance(key, tuple) else (key,))) or None)
        if not kept.all():
            ax.plot(frame.loc[kept, x], frame.loc[kept, y], "o", ms=4, mfc="none", color="k", label="kept")
        ax.set_ylabel(label(y))
    if others or not kept.all():
        axes[0].legend(ncol=min(3, max(1, len(frame.groupby(others)) if others else 1)),
                       loc="lower left", bbox_to_anchor=(0.0, 1.02), frameon=False)
    axes[-1].set_xlabel(label(x))
    fig.suptitle(f"{plain_text(title)}: sweep summary" if title else "sweep summary")
    return fig


# ---- ujoint

#: line styles of the Hooke-joint designs, by the label driver.ujoint gives them
_UJOINT_STYLES = {"trial": dict(color="C1", lw=1.4), "design": dict(color="C1", lw=1.4),
                  "optimum": dict(color="C0", lw=2.0), "last iterate": dict(color="C3", lw=1.6, ls="-."),
                  "paper printed": dict(color="C2", lw=1.2, ls=":")}


@styled
def ujoint_speed_figure(theta_deg: np.ndarray, rpm: float, curves: dict[str, np.ndarray],
                        polar: bool = False, band: Sequence[float] | None = None, title: str = "",
                        ax=None) -> Figure:
    """Input and output shaft speed [rpm] against the input angle [deg], every design (trial,
    optimum, the paper's printed optimum) overlaid on one panel as in the paper's Figures 6-11,
    with the paper's trial band ``band`` = (min, max) [rpm] shaded when given.

    Cartesian or polar (angle = input angle, radius = speed); the polar radius starts near
    the slowest speed, not at 0, so a fluctuation of a fraction of an rpm stays visible (the
    empty centre says the radius does not start at 0)."""
    if ax is not None:   # the caller's axes (a polar one for polar = True)
        fig = ax.figure
    elif polar:
        fig = Figure(figsize=(7.4, 5.2), layout="constrained")
        ax = fig.add_subplot(1, 1, 1, projection="polar")
    else:
        fig, (ax,) = new_figure(1, 1, figsize=(7.4, 4.0))
    x = np.radians(theta_deg) if polar else theta_deg
    values = [rpm, *(float(v) for w in curves.values() for v in (np.min(w), np.max(w)))] + list(band or [])
    low, top = min(values), max(values)
    pad = 0.08 * max(top - low, 1e-3 * rpm)
    if band is not None:
        lo, hi = band
        text = f"paper's trial band {lo:g}-{hi:g} rpm (read off its plot)"
        if polar:
            ax.fill_between(x, lo, hi, color="0.5", alpha=0.15, lw=0, label=text)
        else:
            ax.axhspan(lo, hi, color="0.5", alpha=0.15, lw=0, label=text)
    for k, (label, w) in enumerate(curves.items()):
        style = _UJOINT_STYLES.get(label, dict(color=f"C{k + 4}", lw=1.4))
        ax.plot(x, w, label=f"{label}: output {np.min(w):.2f}-{np.max(w):.2f} rpm", **style)
    # the input speed last and on top: an optimum close to it must not hide it
    ax.plot(x, np.full_like(theta_deg, rpm, dtype=float), "k--", lw=1.1, zorder=5, label=f"input shaft {rpm:g} rpm")
    if polar:
        ax.set_rlim(low - pad, top + pad)
        ax.set_rorigin(low - pad - 0.6 * (top - low + 2 * pad))
        ticks = [t for t in matplotlib.ticker.MaxNLocator(4).tick_values(low - pad, top + pad)
                 if low - pad <= t <= top + pad]
        ax.set_yticks(ticks)
        ax.set_yticklabels([])
        for t in ticks:   # radial labels cross the curves: drawn on a white patch, above them
            ax.text(np.radians(112.5), t, f"{t:g} rpm", fontsize=7.5, ha="center", va="center", zorder=6,
                    bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="none", alpha=0.85))
        ax.set_xlabel("input angle [deg]; radius: shaft speed [rpm], not starting at 0", fontsize=8)
        fig.legend(*ax.get_legend_handles_labels(), loc="outside lower center", ncol=2, frameon=False)
    else:
        ax.set_ylim(low - pad, top + pad)
        ax.set_ylabel("shaft speed [rpm]")
        ax.set_xlabel("input angle [deg]")
        ax.set_xlim(0.0, 360.0)
        ax.set_xticks(np.arange(0, 361, 45))
        fig.legend(*ax.get_legend_handles_labels(), loc="outside lower center", ncol=2, frameon=False)
    fig.suptitle(f"{plain_text(title)}: Hooke-joint chain, input and output shaft speed" if title
                 else "Hooke-joint chain: input and output shaft speed")
    return fig


# ----------------------------------------------------------------------------- slidercrank


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
def slidercrank_convergence_figure(series: dict[str, Any], title: str, axes=None) -> Figure:
    """An element-convergence study as an engineer reads it (the paper's Figures 8-9 redrawn).

    ``series``: per crank speed (its label) either ``(n, element)`` or ``(n, element, pin)``:
    the element counts and the peak tensile strain [microstrain] of the crank-end element (the
    paper's quantity, an element average) and, optionally, at the crank pin recovered from the
    first two elements.  Left: the strain against the number of elements (log axis), the
    finest mesh's value dotted.  Right: the size of the difference from the finest mesh [%] on
    log-log axes, with a slope -1 guide (an element average converges as 1/N) and the 0.1 %
    line.  ``axes``: two axes of the caller's figure to draw into."""
    if axes is None:
        fig, axes = new_figure(1, 2, figsize=(10.0, 4.8))
    else:
        fig = axes[0].figure
    ax_q, ax_e = axes[0], axes[1]
    one = len(series) == 1
    n_all: list[float] = []
    for k, (label, data) in enumerate(series.items()):
        n = np.asarray(data[0], dtype=float)
        kinds = [("crank-end element (the paper's quantity)", np.asarray(data[1], dtype=float), "-", "o")]
        if len(data) > 2 and data[2] is not None:
            kinds.append(("at the crank pin (recovered from two elements)", np.asarray(data[2], dtype=float), "--", "s"))
        colour = f"C{k % 10}"
        for j, (what, v, ls, mk) in enumerate(kinds):
            name = what if one else f"{label}: {what}"
            if n.size > 1:   # where it settles: every finer mesh within 0.1 % of the finest
                err_ = 100 * np.abs(v - v[np.argmax(n)]) / abs(v[np.argmax(n)])
                order = np.argsort(n)
                bad = np.nonzero(err_[order] > 0.1)[0]
                n_ok = n[order][bad[-1] + 1] if bad.size else n[order][0]
                name += f", within 0.1 % from N = {n_ok:g}" if n_ok < n.max() else ""
            ax_q.plot(n, v, ls=ls, marker=mk, ms=4, color=colour if one is False else f"C{j}", label=name,
                      mfc="white" if j else None)
            if n.size > 1:
                finest = v[np.argmax(n)]
                err = 100 * np.abs(v - finest) / abs(finest)
                use = (n < n.max()) & (err > 0)
                ax_e.plot(n[use], err[use], ls=ls, marker=mk, ms=4, color=colour if one is False else f"C{j}",
                          mfc="white" if j else None, label=name)
                if j == 0:
                    ax_q.axhline(finest, color="0.45", lw=0.8, ls=":", zorder=0,
                                 label=f"{'' if one else label + ': '}finest mesh, N = {n.max():g}: "
                                       f"{finest:.4g} microstrain")
        n_all += list(n)
    from matplotlib.ticker import FuncFormatter
    for ax in (ax_q, ax_e):
        ax.set_xscale("log")
        ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.set_xlabel("number of rod elements $N$")
    ax_q.set_ylabel("peak tensile strain [microstrain]")
    ax_q.set_title("peak strain against mesh size")
    ax_e.set_yscale("log")
    ax_e.set_ylabel("|difference from the finest mesh| [%]")
    ax_e.set_title("difference from the finest mesh")
    lines = [ln for ln in ax_e.lines if len(ln.get_xdata())]
    if lines:
        x0 = min(float(np.min(ln.get_xdata())) for ln in lines)
        y0 = max(float(ln.get_ydata()[0]) for ln in lines)
        xs = np.array([x0, max(n_all) / 2])
        ax_e.plot(xs, y0 * x0 / xs, color="0.5", lw=0.9, ls="-.", label="slope $-1$ (error $\\propto 1/N$)")
        pins = [ln for ln in lines if ln.get_linestyle() == "--" and len(ln.get_xdata()) > 1]
        if pins:   # the recovered pin strain is second order: a slope -2 guide through its second point
            x1, y1 = float(pins[0].get_xdata()[1]), float(pins[0].get_ydata()[1])
            xs2 = np.array([x1, max(n_all) / 2])
            ax_e.plot(xs2, 0.6 * y1 * (x1 / xs2) ** 2, color="0.5", lw=0.9, ls=(0, (1, 1.5)),
                      label="slope $-2$ (error $\\propto 1/N^2$)")
        ax_e.axhline(0.1, color="0.6", lw=0.8, ls=":")
        ax_e.annotate("0.1 %", (0.0, 0.1), xycoords=("axes fraction", "data"), xytext=(4, 3),
                      textcoords="offset points", fontsize=8, color="0.35")
    handles, names = ax_q.get_legend_handles_labels()
    more = [(h, t) for h, t in zip(*ax_e.get_legend_handles_labels()) if t.startswith("slope")]
    handles, names = handles + [h for h, _ in more], names + [t for _, t in more]
    fig.legend(handles, names, loc="outside lower center", ncol=1 if max(map(len, names)) > 60 else 2,
               frameon=False)
    if title:
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
    import re as _re
    model_label = "this model (linear KED, Newmark)"
    for ax, (key, y) in zip(axes, series.items()):
        ax.plot(time, y, color="C0", lw=1.2, label=model_label)
        if key in reference:
            t, v = reference[key]
            ax.plot([t], [v], "D", ms=7, mfc="white", mec="C3", mew=1.5, label=reference_label or "reference")
            m = _re.search(r"\[([^\]]+)\]\s*$", labels.get(key, ""))
            unit = f" {m.group(1)}" if m else ""
            mine = float(np.interp(t, time, y))
            # the two end values side by side, in the figure's own font, on a white ground beside the marker
            span = float(np.nanmax(time) - np.nanmin(time)) or 1.0
            ax.set_xlim(right=max(float(np.nanmax(time)), t) + 0.24 * span)   # room right of the curves
            ax.annotate(f"reference {v:.4g}{unit}\nthis model {mine:.4g}{unit}", (t, v), xytext=(12, 0),
                        textcoords="offset points", ha="left", va="center", fontsize=8.5, color="0.15",
                        bbox=dict(boxstyle="round,pad=0.3", fc="white", ec="C3", lw=0.8, alpha=0.9),
                        arrowprops=dict(arrowstyle="-", color="C3", lw=0.8), zorder=6)
        ax.set_ylabel(labels.get(key, key))
    axes[-1].set_xlabel("time $t$ [s]")
    handles, names = axes[0].get_legend_handles_labels()
    fig.legend(handles, names, loc="outside lower center", ncol=2, frameon=False)
    if title:
        fig.suptitle(plain_text(title))
    return fig


# ----------------------------------------------------------------------------- design spaces and convergence

def _numeric_axis(values) -> np.ndarray:
    """Sorted distinct finite values of a swept key."""
    import pandas as pd
    v = pd.to_numeric(pd.Series(values), errors="coerce").to_numpy(dtype=float)
    return np.unique(v[np.isfinite(v)])


def _grid_of(frame, kx: str, ky: str, col: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Values of ``col`` on the (kx, ky) grid of the rows of ``frame`` (NaN where no row)."""
    import pandas as pd
    xs, ys = _numeric_axis(frame[kx]), _numeric_axis(frame[ky])
    z = np.full((len(ys), len(xs)), np.nan)
    ix = np.searchsorted(xs, pd.to_numeric(frame[kx], errors="coerce").to_numpy(dtype=float))
    iy = np.searchsorted(ys, pd.to_numeric(frame[ky], errors="coerce").to_numpy(dtype=float))
    vals = pd.to_numeric(frame[col], errors="coerce").to_numpy(dtype=float)
    ok = (ix < len(xs)) & (iy < len(ys))
    z[iy[ok], ix[ok]] = vals[ok]
    return xs, ys, z


def _edges(v: np.ndarray) -> np.ndarray:
    """Cell edges around grid values (midpoints; half a step beyond the ends)."""
    if len(v) == 1:
        return np.array([v[0] - 0.5, v[0] + 0.5])
    mid = 0.5 * (v[1:] + v[:-1])
    return np.concatenate([[2 * v[0] - mid[0]], mid, [2 * v[-1] - mid[-1]]])


def _plain_numbers(ax) -> None:
    """No offset or scientific notation on either axis (a reader sees the numbers themselves)."""
    for axis in (ax.xaxis, ax.yaxis):
        fmt = axis.get_major_formatter()
        if isinstance(fmt, matplotlib.ticker.ScalarFormatter):
            fmt.set_useOffset(False)
            fmt.set_scientific(False)


@styled
def design_space_map(frame, keys: Sequence[str], metric: str, labels: dict[str, str] | None = None,
                     best: int | None = None, best_text: str = "", title: str = "", panels: int = 6,
                     cmap: str = "viridis", only_kept: bool = False, ax=None) -> Figure:
    """A metric over the design space of a sweep, as a textbook prints it.

    ``frame`` has one row per case (the sweep summary: swept keys, ``kept``, the metric);
    ``keys`` are the 1-3 swept keys.  One key: the metric against it as a line, kept cases
    as filled markers.  Two keys: the metric as an image over the two keys (cells without a
    row left blank), the kept designs outlined in black.  Three keys: small multiples of
    that image over up to ``panels`` values of the third key (the best's value always among
    them), one shared colour scale.  ``only_kept``: the frame holds the kept designs only (blank
    cells are designs not kept, not missing ones).  ``best`` is the frame index of the design to mark (a
    star labelled ``best_text``); ``labels`` maps columns to axis words with units.  With
    ``ax`` (one key or two) the map is drawn into that axes and its figure returned.
    """
    import pandas as pd
    labels = labels or {}
    lab = lambda c: labels.get(c, c) if labels.get(c, c) != c else plain_text(c)  # noqa: E731  (deck text: literal)
    keys = [k for k in keys if k in frame.columns][:3]
    kept = frame["kept"].astype(bool) if "kept" in frame else pd.Series(True, index=frame.index)
    z_all = pd.to_numeric(frame[metric], errors="coerce").to_numpy(dtype=float)
    fin = z_all[np.isfinite(z_all)]
    vmin, vmax = (float(fin.min()), float(fin.max())) if fin.size else (0.0, 1.0)
    if vmax - vmin <= 1e-12 * max(1.0, abs(vmax)):
        vmin, vmax = vmin - 0.5, vmax + 0.5
    norm = matplotlib.colors.Normalize(vmin, vmax)
    brow = frame.loc[best] if best is not None and best in frame.index else None

    if len(keys) <= 1:
        if ax is None:
            fig, (ax,) = new_figure(1, 1, figsize=(6.4, 3.6))
        else:
            fig = ax.figure
        x = keys[0] if keys else "case"
        order = frame.sort_values(x)
        ax.plot(order[x], order[metric], "-", color="C0", lw=1.2, label="all cases")
        ax.plot(order.loc[kept, x], order.loc[kept, metric], "o", ms=4, color="C0", label="kept")
        if brow is not None:
            ax.plot([brow[x]], [brow[metric]], "*", ms=14, color="C3", mec="k", label=best_text or "best")
        ax.set_xlabel(lab(x))
        ax.set_ylabel(lab(metric))
        _plain_numbers(ax)
        ax.legend(loc="best")
        if title:
            ax.set_title(title)   # composed by the caller: deck parts through plain_text
        return fig

    kx, ky = keys[0], keys[1]
    if len(keys) == 3:
        kz = keys[2]
        zs = _numeric_axis(frame[kz])
        pick = np.unique(np.linspace(0, len(zs) - 1, min(panels, len(zs))).round().astype(int))
        if brow is not None:
            bz = int(np.argmin(np.abs(zs - float(brow[kz]))))
            if bz not in pick:
                pick[np.argmin(np.abs(pick - bz))] = bz
            pick = np.unique(pick)
        slices = [(zs[i], frame[np.isclose(pd.to_numeric(frame[kz], errors="coerce"), zs[i])]) for i in pick]
    else:
        kz, slices = "", [(None, frame)]
    n = len(slices)
    if ax is not None and n == 1:
        fig, axes = ax.figure, [ax]
    else:
        ncols = min(3, n)
        nrows = int(math.ceil(n / ncols))
        fig, axes = new_figure(nrows, ncols, sharex=True, sharey=True,
                               figsize=(6.4, 5.0) if n == 1 else (3.3 * ncols + 1.2, 2.9 * nrows + 1.0))
        for extra in axes[n:]:
            extra.set_visible(False)
    xs_all, ys_all = _numeric_axis(frame[kx]), _numeric_axis(frame[ky])
    image = None
    for a, (zval, part) in zip(axes, slices):
        xs, ys, z = _grid_of(part, kx, ky, metric)
        _, _, keep = _grid_of(part.assign(_kept=kept[part.index].astype(float)), kx, ky, "_kept")
        a.grid(False)
        a.set_facecolor("0.93")
        image = a.pcolormesh(_edges(xs), _edges(ys), np.ma.masked_invalid(z), cmap=cmap, norm=norm,
                             shading="flat", rasterized=True)
        if np.nansum(keep) and not np.all(keep[np.isfinite(keep)] == 1):
            k = np.nan_to_num(keep, nan=0.0)
            a.contour(xs, ys, k, levels=[0.5], colors="k", linewidths=1.2)
        if brow is not None and (zval is None or np.isclose(float(brow[kz]), zval)):
            a.plot([brow[kx]], [brow[ky]], "*", ms=15, color="C3", mec="k", mew=0.8, zorder=5)
            right = float(brow[kx]) > 0.5 * (xs_all[0] + xs_all[-1])
            a.annotate("best", (brow[kx], brow[ky]), xytext=(-9 if right else 9, 7), textcoords="offset points",
                       ha="right" if right else "left", fontsize=9, fontweight="bold", color="k",
                       bbox=dict(boxstyle="round,pad=0.15", fc="w", ec="none", alpha=0.8))
        a.set_xlim(_edges(xs_all)[[0, -1]])
        a.set_ylim(_edges(ys_all)[[0, -1]])
        if zval is not None:
            a.set_title(f"{lab(kz).split(' [')[0]} = {zval:.4g}", fontsize=9)
        _plain_numbers(a)
    for a in axes[:n]:
        if a.get_subplotspec() is None or a.get_subplotspec().is_last_row() or n == 1:
            a.set_xlabel(lab(kx))
        if a.get_subplotspec() is None or a.get_subplotspec().is_first_col() or n == 1:
            a.set_ylabel(lab(ky))
    if brow is not None and best_text:   # the best design's values, under the panels
        fig.supxlabel("\u2605 " + wrap(best_text, 110), fontsize=8.5, color="0.15")
    cb = fig.colorbar(image, ax=list(axes[:n]), shrink=0.9, pad=0.02)
    cb.set_label(lab(metric))
    _plain_numbers(cb.ax)
    note = ("kept designs outlined in black" if not kept.all() else
            "only kept designs tabulated (blank: not kept)" if only_kept else "every design kept")
    if title:
        fig.suptitle(f"{title}\n{note}" if (n > 1 or not kept.all() or only_kept) else title)
    elif not kept.all() or only_kept:
        axes[0].set_title(note, fontsize=8)
    return fig


@styled
def convergence_plot(history, evals, objective: str, sense: str = "minimize", title: str = "",
                     axes=None) -> Figure:
    """How an optimisation converged, as an engineer reads it: three panels against the number
    of designs evaluated.

    Left: the best feasible objective so far (a step line), every feasible design as a grey
    dot; the axis shows plain numbers (no offset).  Middle: the gap between the best so far
    and the final best on a log axis (zero gaps left out), so the last digits gained are
    visible without a 1e-7 change looking like a big step.  Right: the constraint violation
    of every design on a log axis (feasible designs, violation 0, are not drawn) and its
    running minimum.  ``history`` has columns evals, feasible, objective; ``evals`` eval,
    feasible, objective, violation.  ``objective`` is the axis label (words and unit);
    ``sense`` 'minimize' or 'maximize'.  ``axes``: three axes to draw into.
    """
    import pandas as pd
    if axes is None:
        fig, axes = new_figure(1, 3, sharex=True, figsize=(11.0, 3.8))
    else:
        fig = axes[0].figure
    a1, a2, a3 = axes
    objective = wrap(objective, 40)
    ev = evals.sort_values("eval")
    feas = ev[ev["feasible"].astype(bool)]
    sign = -1.0 if sense.startswith("max") else 1.0
    obj = pd.to_numeric(feas["objective"], errors="coerce").to_numpy(dtype=float)
    a1.plot(feas["eval"], obj, ".", ms=2.5, color="0.65", label="feasible designs", rasterized=len(obj) > 2000)
    if len(obj):
        best = sign * np.minimum.accumulate(sign * obj)
        x = np.concatenate([feas["eval"].to_numpy(dtype=float), [float(ev["eval"].max())]])
        y = np.concatenate([best, best[-1:]])
        a1.step(x, y, where="post", color="C3", lw=1.8, label="best so far")
        final = best[-1]
        gap = np.abs(best - final)
        pos = gap > 0
        if pos.any():
            a2.step(x[:-1][pos], gap[pos], where="post", color="C3", lw=1.6)
            a2.set_yscale("log")
        else:
            a2.text(0.5, 0.5, "the first feasible design\nwas already the best", transform=a2.transAxes,
                    ha="center", va="center")
        a2.axvline(float(feas["eval"].iloc[int(np.argmax(best == final))]), color="0.4", ls=":", lw=1,
                   label="final best found")
        a2.legend(loc="upper right")
        lo, hi = np.nanmin(obj), np.nanmax(obj)
        # at least 1e-4 of the objective's size: a change in the 7th digit reads as converged here
        # (a flat line), and the gap panel beside it shows how small it is
        span = max(hi - lo, 1e-4 * max(abs(final), 1e-12))
        mid = 0.5 * (lo + hi)
        a1.set_ylim(mid - 0.55 * span, mid + 0.55 * span)
    else:
        a1.text(0.5, 0.5, "no feasible design", transform=a1.transAxes, ha="center", va="center")
    a1.set_ylabel(objective)
    a1.set_title(f"best feasible ({'largest' if sign < 0 else 'smallest'})")
    a1.legend(loc="best")
    unit = re.search(r"\[([^\[\]]+)\]\s*$", objective)   # the objective's unit, when its label has one
    a2.set_ylabel("|best so far - final best|" + (f" [{unit.group(1)}]" if unit else ""))
    a2.set_title("gap to the final best")
    viol = pd.to_numeric(ev["violation"], errors="coerce").to_numpy(dtype=float) if "violation" in ev else np.array([])
    if viol.size and np.nanmax(viol) > 0:
        pos = viol > 0
        a3.plot(ev["eval"].to_numpy()[pos], viol[pos], ".", ms=2.5, color="C0", alpha=0.6,
                label="violation of each design", rasterized=pos.sum() > 2000)
        run = np.minimum.accumulate(np.where(np.isfinite(viol), viol, np.inf))
        shown = run > 0
        a3.step(ev["eval"].to_numpy()[shown], run[shown], where="post", color="k", lw=1.4,
                label="smallest so far (0 once feasible)")
        a3.set_yscale("log")
        a3.legend(loc="best")
    else:
        a3.text(0.5, 0.5, "every design feasible", transform=a3.transAxes, ha="center", va="center")
    a3.set_ylabel("constraint violation")
    a3.set_title("constraint violation")
    for a in axes:
        a.set_xlabel("designs evaluated")
    _plain_numbers(a1)
    _plain_numbers(a3) if a3.get_yscale() == "linear" else None
    if title:
        fig.suptitle(title)   # composed by the caller: deck parts through plain_text
    return fig


def best_index(frame, metric: str, sense: str | None):
    """The frame index of the kept, ok design with the best ``metric`` (``sense`` 'min' or 'max'),
    or None (no sense known, or no such design)."""
    import pandas as pd
    if sense not in ("min", "max") or metric not in frame:
        return None
    ok = frame
    if "status" in ok:
        ok = ok[ok["status"] == "ok"]
    if "kept" in ok:
        ok = ok[ok["kept"].astype(bool)]
    m = pd.to_numeric(ok[metric], errors="coerce")
    if not m.notna().any():
        return None
    return m.idxmax() if sense == "max" else m.idxmin()


def is_grid(frame, keys: Sequence[str]) -> bool:
    """Whether 2-3 numeric swept ``keys`` span a grid worth a map (several values on each of two)."""
    import pandas as pd
    numeric = [k for k in keys if k in frame and pd.api.types.is_numeric_dtype(frame[k])
               and not pd.api.types.is_bool_dtype(frame[k])]
    if not (2 <= len(numeric) <= 3 and len(numeric) == len(keys)):
        return False
    counts = [len(_numeric_axis(frame[k])) for k in numeric[:2]]
    # a map needs cells: at least 3 values on each axis and two designs per value on average
    return min(counts) >= 3 and len(frame) >= 2 * max(counts)


def _words_value(label: str, value: float, name: bool = True) -> str:
    """``'crank length [length units]', 4.0`` -> ``'crank length 4 length units'`` (``name``
    False: the value and unit only)."""
    words, _, unit = label.partition(" [")
    unit = unit.rstrip("]")
    text = f"{value:.4g}" + (f" {unit}" if unit and unit != "-" else "")
    return f"{words} {text}" if name else text


def sweep_maps(frame, keys: Sequence[str], ys: Sequence[str], labels: dict[str, str], senses: dict[str, str],
               title: str = "", only_kept: bool = False) -> list[Figure]:
    """Design-space maps of a 2-3-key grid sweep, one per plotted column ``ys``: the best kept
    design (by ``senses[y]``, 'min' or 'max', when the study knows which is better) starred and
    labelled with its key values."""
    figs = []
    for y in ys:
        best = best_index(frame, y, senses.get(y))
        text = ""
        if best is not None:
            word = "largest" if senses[y] == "max" else "smallest"
            text = f"best ({word} {labels.get(y, y).split(' [')[0]}): " + ", ".join(
                f"{_words_value(labels.get(k, k), frame.loc[best, k])}" for k in keys) + \
                f"; {labels.get(y, y).split(' [')[0]} {_words_value(labels.get(y, y), frame.loc[best, y], name=False)}"
        figs.append(design_space_map(frame, keys, y, labels, best=best, best_text=text,
                                     title=f"{plain_text(title)}: {labels.get(y, y)}" if title else labels.get(y, y),
                                     only_kept=only_kept))
    return figs


# ----------------------------------------------------------------------------- robust design (Taylor)

@styled
def robust_design_figure(t: np.ndarray, means: dict[str, np.ndarray], spreads: dict[str, np.ndarray],
                         points: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]],
                         tmins: dict[str, float | None], sigma_x: float, title: str = "", axes=None) -> Figure:
    """Taylor's robust-design example: the mean of Y (top) and its spread (bottom, log axis)
    against the target t, every fitted curve beside the known relation's, the measured means
    and standard deviations as markers, and the estimates of the target of least spread as
    vertical lines.  ``means``/``spreads``: {label: values on ``t``}; ``points``: {label: (t,
    mean, std)}; ``tmins``: {label: t_min or None}.  ``axes``: two axes to draw into."""
    if axes is None:
        fig, axes = new_figure(2, 1, sharex=True, figsize=(7.6, 6.4))
    else:
        fig = axes[0].figure
    top, bot = axes
    styles = ["-", "--", "-.", ":", (0, (5, 1, 1, 1))]
    for k, (label, y) in enumerate(means.items()):
        top.plot(t, y, ls=styles[k % len(styles)], color=f"C{k}", lw=1.5, label=label)
    for k, (label, y) in enumerate(spreads.items()):
        printed = "printed" in label
        bot.plot(t, y, ls=":" if printed else styles[k % len(styles)], color="0.5" if printed else f"C{k}",
                 lw=1.2 if printed else 1.6, label=label)
    for k, (label, (pt, m, sd)) in enumerate(points.items()):
        mk = "os"[k % 2]
        top.plot(pt, m, mk, ms=6, mfc="white", mec="k", label=label)
        bot.plot(pt, sd, mk, ms=6, mfc="white", mec="k", label=label)
    for k, (label, tm) in enumerate(tmins.items()):
        if tm is not None and np.isfinite(tm):
            bot.axvline(tm, color=f"C{k}", lw=0.9, ls=(0, (2, 2)), alpha=0.9,
                        label=rf"$t_{{min}}$ {label} = {tm:.3f}")
    top.set_ylabel(r"mean of $Y$, $\mu_Y$")
    bot.set_ylabel(r"spread of $Y$, $\sigma_Y$ (log)")
    bot.set_yscale("log")
    bot.set_xlabel(rf"target $t$ (X varies about $t$ with $\sigma_x$ = {sigma_x:g})")
    finite = np.concatenate([y[np.isfinite(y) & (y > 0)] for label, y in spreads.items() if "printed" not in label]
                            + [sd for _, _, sd in points.values()])
    if finite.size:
        bot.set_ylim(max(finite.min() * 0.5, 1e-6), finite.max() * 3.0)
    top.legend(loc="center left", bbox_to_anchor=(1.01, 0.5), frameon=False)
    bot.legend(loc="center left", bbox_to_anchor=(1.01, 0.5), frameon=False)
    if title:
        fig.suptitle(plain_text(title))
    return fig


# ----------------------------------------------------------------------------- slidercrank, nonlinear rod

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
