"""The one plotting module (matplotlib object API; no screen, no pyplot state).

The house style and the shared figure builders (sweeps, design-space maps, optimiser
convergence); each study draws its own figures in ``driver/<study>/figures.py`` with these
helpers (:func:`style`/:func:`styled`, :func:`new_figure`, :func:`plain_text`, :func:`save_figure`).
Every builder returns a :class:`matplotlib.figure.Figure` drawn inside
:func:`style` (an ``rc_context``), and :func:`save_figure` writes it atomically
as PNG, SVG or PDF, byte for byte the same for the same inputs.  Nothing here selects a
backend or changes the global ``rcParams``: importing this module or drawing a figure leaves a user's own matplotlib
settings (e.g. Jupyter's inline backend) exactly as they were.  Studies wrap
builders in :class:`driver._output.Figure` so nothing is drawn unless asked.
"""
from __future__ import annotations

import contextlib
import functools
import math
import re
import warnings
from collections.abc import Callable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any, TypeVar

import numpy as np

from driver._atomic import atomic_open
from driver._extras import require
from driver._formats import ANIMATION_FORMATS, PLOT_FORMATS, plot_format
from driver._output import best_index  # one rule for the maps' star and the sweep's best case

require("plot")   # a clear message naming the [plot] extra when matplotlib is missing; then import it:
import matplotlib  # noqa: E402 (after require above)
import matplotlib.colors  # noqa: E402 (after require above)
import matplotlib.font_manager  # noqa: E402 (after require above)
import matplotlib.ticker  # noqa: E402 (after require above)
from matplotlib.figure import Figure  # noqa: E402 (after require above)

__all__ = ["STYLE", "style", "styled", "new_figure", "save_figure", "line_panels", "plain_text", "break_wraps",
           "unwrap_angle"]

#: the house style, applied only inside :func:`style` (never written to the global rcParams)
STYLE: dict[str, Any] = {"figure.dpi": 150, "savefig.dpi": 150, "axes.grid": True, "grid.alpha": 0.3,
                         "axes.spines.top": False, "axes.spines.right": False, "font.size": 9,
                         "legend.fontsize": 8.5, "axes.formatter.useoffset": False}

_F = TypeVar("_F", bound=Callable[..., Any])

#: a scatter of more points than this is drawn as an image inside a vector figure (SVG, PDF):
#: each point as a vector marker would make a report page of megabytes that scrolls slowly
RASTER_POINTS = 150


def plain_text(text: Any) -> str:
    """Text from a deck (a title, a design name, the deck's file name, a value, an expression)
    as matplotlib draws it literally: never mathtext (every ``$`` escaped, so ``'$\\frac$'`` or
    nested braces cannot raise a parse error), control characters dropped.  Every figure
    builder passes deck text through this one function.  Each line is bounded to
    :data:`driver._names.NAME_CHARS` characters (a longer one cut in the middle, saying how many
    characters were left out: :func:`driver._names.shown`)."""
    from driver._names import NAME_CHARS, shown
    text = "".join(ch for ch in str(text) if ch.isprintable() or ch == "\n")
    return "\n".join(shown(line, NAME_CHARS) for line in text.split("\n")).replace("$", r"\$")


def wrap(text: str, width: int) -> str:
    """``text`` filled to lines of about ``width`` characters like :func:`textwrap.fill`, but a
    mathtext span (``$|\\tau_1| + |\\tau_2|$``) is never broken across lines: matplotlib
    parses each line on its own, and half a span would be drawn as its raw source.  A word
    longer than ``width`` (a name without blanks) is cut into lines of ``width``."""
    tokens = re.findall(r"(?:[^\s$\\]|\\.|(?<!\\)\$(?:[^$\\]|\\.)*\$)+", text)
    if re.sub(r"\s+", "", "".join(tokens)) != re.sub(r"\s+", "", text):   # an unpaired $: no span to keep whole
        import textwrap
        return textwrap.fill(text, width)
    # a word longer than a line (a long name without blanks) is cut into lines of ``width``; one
    # with a mathtext span or an escape stays whole (a cut could split a '\\$')
    tokens = [part for tok in tokens
              for part in ([tok[i:i + width] for i in range(0, len(tok), width)]
                           if len(tok) > width and not re.search(r"[$\\]", tok) else [tok])]
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


def suptitle(fig: Figure, text: str, **kw: Any) -> Any:
    """Give ``fig`` its title, each line wrapped to the figure's width (a deck's long title
    never runs off the canvas); mathtext spans are kept whole (:func:`wrap`)."""
    title = fig.suptitle(str(text), **kw)   # its font size as the style in force gives it
    chars = max(20, int(fig.get_figwidth() * 72.0 / (0.53 * title.get_fontproperties().get_size_in_points())))
    title.set_text("\n".join(wrap(line, chars) for line in str(text).split("\n")))
    return title


@contextlib.contextmanager
def style(**overrides: Any) -> Iterator[None]:
    """Draw inside this context to get the house style; rcParams are restored on exit.

    matplotlib's warnings (a glyph missing from the font, identical axis limits) are dropped
    here: they name package paths and say nothing a user of the tool can act on."""
    # matplotlib checks the keys when they are set; its stub's Literal key type cannot describe **overrides
    rc: dict[Any, Any] = {**STYLE, **overrides}
    with matplotlib.rc_context(rc), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        yield


def styled(builder: _F) -> _F:
    """Decorator: run a figure builder inside :func:`style`."""
    @functools.wraps(builder)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        with style():
            return builder(*args, **kwargs)
    return wrapper  # type: ignore[return-value]  # functools.wraps keeps the call signature; its stub says _Wrapped


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
SVG_SALT = "driver-figures"


def save_figure(fig: Figure, path: str | Path, fmt: bool | str | None = None) -> Path:
    """Write ``fig`` to ``path`` atomically and reproducibly (no dates or versions inside), in the
    house style's resolution.

    ``fmt`` is a format of :data:`driver._output.PLOT_FORMATS` (``True`` or None: PNG, or the
    format of ``path``'s suffix when that is one); ``path``'s suffix is replaced by it.
    Returns the path written.
    """
    path = Path(path)
    if fmt is None or fmt is True:
        fmt = path.suffix.lstrip(".").lower() if path.suffix.lstrip(".").lower() in PLOT_FORMATS else "png"
    chosen = plot_format(fmt)
    if chosen is None:   # fmt False or ''
        raise ValueError(f"no figure format in {fmt!r}")
    path = path.with_suffix(f".{chosen}")
    with style(**{"svg.hashsalt": SVG_SALT}), atomic_open(path, "wb") as fh:
        fig.savefig(fh, format=chosen, metadata=_METADATA[chosen])
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
        suptitle(fig, plain_text(title))
    return fig


# ----------------------------------------------------------------------------- drawings of mechanisms

def keep_texts_inside(ax, texts: Sequence[Any], pad: float = 3.0, rounds: int = 5) -> None:
    """Grow the data limits of ``ax`` until each of ``texts`` (labels placed beside points of the
    drawing, offset in points) lies inside the axes box, ``pad`` pixels in: a label pushed out
    of a drawing must not sit on the tick labels or leave the canvas.  Lays the figure out
    (``draw_without_rendering``) a few times; equal aspect is kept."""
    fig = ax.figure
    for _ in range(rounds):
        fig.draw_without_rendering()
        r = fig._get_renderer()
        box = ax.get_window_extent(r)
        left = bottom = right = top = 0.0
        for t in texts:
            bb = t.get_window_extent(r)
            left, bottom = max(left, box.x0 + pad - bb.x0), max(bottom, box.y0 + pad - bb.y0)
            right, top = max(right, bb.x1 - (box.x1 - pad)), max(top, bb.y1 - (box.y1 - pad))
        if max(left, bottom, right, top) <= 0.5:
            return
        (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
        sx, sy = (x1 - x0) / max(box.width, 1.0), (y1 - y0) / max(box.height, 1.0)
        grow = 1.3   # the limits grow, the scale shrinks: overshoot a little to converge
        ax.set_xlim(x0 - grow * left * sx, x1 + grow * right * sx)
        ax.set_ylim(y0 - grow * bottom * sy, y1 + grow * top * sy)


def drawing_figure(figsize: tuple[float, float] = (9.6, 5.4), legend_width: float = 3.2) -> tuple[Figure, Any]:
    """A figure for a drawing of a mechanism at equal scales: the drawing's axes and, beside it,
    a panel of ``legend_width`` inches that holds its legend (:func:`drawing_legend`).  The
    legend has a place of its own in the layout, so equal scales never push it (or the axis
    labels) off the canvas.  Returns (figure, drawing axes)."""
    fig = Figure(figsize=figsize, layout="constrained")
    ax, side = fig.subplots(1, 2, width_ratios=[max(figsize[0] - legend_width, 1.0), legend_width])
    side.set_axis_off()
    side.set_label("legend")
    ax._drawing_legend_panel = side   # where drawing_legend puts the legend
    return fig, ax


def drawing_legend(ax, **kw: Any) -> Any:
    """The legend of a drawing: in its panel beside it (a figure of :func:`drawing_figure`), or
    beside the axes outside the drawing (axes of the caller's own figure).  ``order=`` (words)
    sorts the entries by the first of the words each label contains (the rest keep their order)."""
    side = getattr(ax, "_drawing_legend_panel", None)
    handles, labels = ax.get_legend_handles_labels()
    order = kw.pop("order", ())
    if order:   # entries in the order of the first word of ``order`` each label contains
        rank = [next((i for i, w in enumerate(order) if w in lab), len(order)) for lab in labels]
        pairs = sorted(zip(rank, range(len(labels)), handles, labels))
        handles, labels = [h for _, _, h, _ in pairs], [lab for _, _, _, lab in pairs]
    opts = dict(frameon=False, borderaxespad=0.0, **kw)
    if side is not None:
        return side.legend(handles, labels, loc="upper left", **opts)
    return ax.legend(handles, labels, loc="upper left", bbox_to_anchor=(1.02, 1.0), **opts)


def length_label(axis: str, units: str) -> str:
    """A drawing's axis label: ``'x [m]'``, or ``'x [length units]'`` when the deck's length unit is free."""
    return f"{axis} [{units or 'length units'}]"


# ----------------------------------------------------------------------------- angles

def break_wraps(x: np.ndarray, y: np.ndarray, period: float = 360.0) -> tuple[np.ndarray, np.ndarray]:
    """``x``, ``y`` with a NaN inserted wherever ``y`` (an angle wrapped into one ``period``) jumps
    by more than half a period between neighbours, so the drawn line breaks at the wrap instead
    of running vertically across the panel.  For angles drawn on a fixed 0-period axis."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    jumps = np.flatnonzero(np.abs(np.diff(y)) > 0.5 * period) + 1
    return np.insert(x, jumps, np.nan), np.insert(y, jumps, np.nan)


def unwrap_angle(y: Any, period: float = 360.0) -> np.ndarray:
    """An angle defined modulo ``period`` (deg) made continuous along its order (``numpy.unwrap``
    with that period; NaN gaps kept, each finite run unwrapped from where it starts, the first
    value kept): ``phi = 90, 120, 150, 0`` (mod 180) becomes ``90, 120, 150, 180``."""
    v = np.asarray(y, dtype=float).copy()
    ok = np.isfinite(v)
    if ok.sum() > 1:
        v[ok] = np.unwrap(v[ok], period=period)
    return v


def angle_period(values: Any, unit: str = "deg") -> float | None:
    """The period of a swept angle inferred from its searched values: equally spaced values
    ``a, a + h, ..., a + (n - 1) h`` with ``n h`` = 180 or 360 deg cover one period (a phase
    swept over a half or a whole turn); None otherwise (or when ``unit`` is not 'deg')."""
    if unit != "deg":
        return None
    v = np.unique(np.asarray(values, dtype=float)[np.isfinite(np.asarray(values, dtype=float))])
    if len(v) < 3:
        return None
    h = np.diff(v)
    if not np.allclose(h, h[0], rtol=1e-6, atol=1e-9):
        return None
    span = len(v) * h[0]
    for period in (180.0, 360.0):
        if math.isclose(span, period, rel_tol=1e-6):
            return period
    return None


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
                  labels: dict[str, str] | None = None, preferred: Sequence[str] = (),
                  searched: Mapping[str, Any] | None = None, n_cases: int | None = None) -> Figure:
    """Summary of a sweep: chosen (or the study's headline) figures against a swept key.

    ``labels`` maps column names to axis labels with units (driver._output.column_label);
    ``preferred`` are the study's headline columns, plotted when ``ys`` is empty.  Panels
    chosen automatically never repeat x, a constant or another panel.  With one numeric x
    the figures are drawn as lines over the cases, one line per value of the other keys;
    when some cases are not kept, kept cases are circled.  When every headline figure is
    constant over the rows (a table of the kept designs only), the kept designs' keys are drawn
    against each other as points over the searched grid (``searched``: the values each key was
    searched over; ``n_cases`` how many cases that made): a swept angle whose searched values
    cover one period (a phase over a half turn) is drawn continuous along the kept points, not
    wrapped back to 0 (:func:`unwrap_angle`).
    """
    import pandas as pd
    labels = labels or {}
    only_points = False

    def label(c: str) -> str:   # a label that is the column's own name may be deck text (an expression): drawn literally
        return wrap(labels.get(c, c) if labels.get(c, c) != c else plain_text(c), 28)

    x = x or next((k for k in keys if pd.api.types.is_numeric_dtype(frame[k])), "case")
    if ys:
        ys = list(ys)
    else:
        numeric = [c for c in frame.columns if c not in (x, "case") and pd.api.types.is_numeric_dtype(frame[c])
                   and not pd.api.types.is_bool_dtype(frame[c]) and c not in keys]
        ordered = [c for c in preferred if c in numeric] + [c for c in numeric if c not in preferred]
        ys = []
        unit = lambda c: labels.get(c, "").rpartition("[")[2].rstrip("]")
        for c in ordered:
            if len(ys) < 6 and not _trivial(frame[c], frame[x], [frame[k] for k in [*ys, *keys]], unit(c)):
                ys.append(c)
        if not ys:   # every figure constant or round-off: show how the kept designs' other keys vary with x
            ys = [k for k in keys if k != x and pd.api.types.is_numeric_dtype(frame[k])] or ordered[:1]
            keys = [k for k in keys if k not in ys]
            only_points = True   # a key against a key: points, no line (angles may wrap between them)
    searched = {k: _numeric_axis(v) for k, v in (searched or {}).items()}
    if only_points:
        return _kept_keys(frame, x, list(ys), title, label, searched, n_cases)
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
            style = "-" if len(frame) <= 2000 else "none"
            ax.plot(g[x], g[y], ls=style, marker="o" if len(frame) <= 200 else ".", ms=3, lw=1,
                    label=", ".join(f"{labels.get(k, k).split(' [')[0]} = {plain_text(v)}"
                                    for k, v in zip(others, key if isinstance(key, tuple) else (key,))) or None)
        if not kept.all():
            ax.plot(frame.loc[kept, x], frame.loc[kept, y], "o", ms=4, mfc="none", color="k", label="kept")
        ax.set_ylabel(label(y))
    if others or not kept.all():
        handles, names = axes[0].get_legend_handles_labels()
        # as many columns as fit the figure's width (about 7 pt a character at 8.5 pt)
        fits = max(1, int(fig.get_figwidth() * 72.0 / (0.6 * 8.5 * (max(map(len, names), default=10) + 6))))
        fig.legend(handles, names, ncol=min(3, fits, max(1, len(names))), loc="outside lower center", frameon=False)
    axes[-1].set_xlabel(label(x))
    suptitle(fig, f"{plain_text(title)}: sweep summary" if title else "sweep summary")
    return fig


def _kept_keys(frame, x: str, ys: list[str], title: str, label: Callable[[str], str],
               searched: Mapping[str, np.ndarray], n_cases: int | None) -> Figure:
    """The kept designs' swept keys against ``x`` as points, over the searched grid (grey dots),
    on axes spanning the searched values; an angle key that covers one period unwrapped along x
    (its label says modulo what)."""
    import pandas as pd
    fig, axes = new_figure(len(ys), 1, sharex=True, figsize=(7.0, 2.6 * len(ys) + 1.0))
    kept = frame[frame["kept"].astype(bool)] if "kept" in frame else frame
    order = kept.sort_values(x)
    xv = pd.to_numeric(order[x], errors="coerce").to_numpy(dtype=float)
    for ax, y in zip(axes, ys):
        yv = pd.to_numeric(order[y], errors="coerce").to_numpy(dtype=float)
        unit = label(y).rpartition("[")[2].rstrip("]")
        period = angle_period(searched[y], unit) if y in searched else None
        words = label(y)
        if period is not None:
            yv = unwrap_angle(yv, period)
            words = f"{words}\n(mod {period:g}\u00b0, drawn continuous)"
        if x in searched and y in searched:   # the searched grid behind the kept designs
            gx, gy = np.meshgrid(searched[x], searched[y])
            ax.plot(gx.ravel(), gy.ravel(), ".", ms=1.5, color="0.75", zorder=1, rasterized=gx.size > RASTER_POINTS,
                    label=f"searched ({gx.size} designs)")
            if period is not None and len(yv) and np.nanmax(yv) > searched[y][-1]:   # the next period, as far as drawn
                top = gy.ravel() + period <= np.nanmax(yv) + 1e-9
                ax.plot(gx.ravel()[top], gy.ravel()[top] + period, ".", ms=1.5, color="0.88", zorder=1,
                        rasterized=gx.size > RASTER_POINTS)
        ax.plot(xv, yv, "o", ms=6, color="C3", mec="k", zorder=3, label=f"kept ({len(order)})")
        ax.set_ylabel(words)
        plain_numbers(ax)
    axes[0].legend(loc="lower left", bbox_to_anchor=(0.0, 1.02), ncol=2, frameon=False)
    axes[-1].set_xlabel(label(x))
    counted = f"{len(order)} kept of {n_cases} cases" if n_cases else f"{len(order)} kept designs"
    suptitle(fig, f"{plain_text(title)}: the kept designs ({counted})" if title else f"the kept designs ({counted})")
    return fig


# ----------------------------------------------------------------------------- design spaces and convergence

def _numeric_axis(values) -> np.ndarray:
    """Sorted distinct finite values of a swept key."""
    import pandas as pd
    v = pd.to_numeric(pd.Series(values), errors="coerce").to_numpy(dtype=float)
    return np.unique(v[np.isfinite(v)])


def _grid_of(frame, kx: str, ky: str, col: str, xs: np.ndarray | None = None,
             ys: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Values of ``col`` on the (kx, ky) grid of the rows of ``frame`` (NaN where no row); the
    grid's values ``xs``, ``ys`` (the searched ones), default the rows' own."""
    import pandas as pd
    xs = _numeric_axis(frame[kx]) if xs is None else np.asarray(xs, dtype=float)
    ys = _numeric_axis(frame[ky]) if ys is None else np.asarray(ys, dtype=float)
    z = np.full((len(ys), len(xs)), np.nan)
    if not (len(xs) and len(ys)):
        return xs, ys, z
    fx = pd.to_numeric(frame[kx], errors="coerce").to_numpy(dtype=float)
    fy = pd.to_numeric(frame[ky], errors="coerce").to_numpy(dtype=float)
    ix = np.clip(np.searchsorted(xs, fx), 0, len(xs) - 1)
    iy = np.clip(np.searchsorted(ys, fy), 0, len(ys) - 1)
    vals = pd.to_numeric(frame[col], errors="coerce").to_numpy(dtype=float)
    ok = np.isclose(xs[ix], fx, rtol=1e-9, atol=1e-12) & np.isclose(ys[iy], fy, rtol=1e-9, atol=1e-12)
    z[iy[ok], ix[ok]] = vals[ok]
    return xs, ys, z


def _edges(v: np.ndarray) -> np.ndarray:
    """Cell edges around grid values (midpoints; half a step beyond the ends)."""
    if len(v) == 1:
        return np.array([v[0] - 0.5, v[0] + 0.5])
    mid = 0.5 * (v[1:] + v[:-1])
    return np.concatenate([[2 * v[0] - mid[0]], mid, [2 * v[-1] - mid[-1]]])


def outline_cells(ax, xe: np.ndarray, ye: np.ndarray, mask: np.ndarray, **kw: Any) -> None:
    """Outline the cells of a map where ``mask`` ((ny, nx) bool) holds, along the cell edges
    ``xe`` (nx + 1), ``ye`` (ny + 1): a line on every edge between a marked cell and an unmarked
    one (or the map's border), so a single kept cell is a square, not a contour's sliver."""
    from matplotlib.collections import LineCollection
    m = np.pad(np.asarray(mask, dtype=bool), 1)
    segs = []
    vert = m[1:-1, 1:] != m[1:-1, :-1]       # (ny, nx + 1): edge left of column j
    for i, j in zip(*np.nonzero(vert)):
        segs.append([(xe[j], ye[i]), (xe[j], ye[i + 1])])
    horiz = m[1:, 1:-1] != m[:-1, 1:-1]      # (ny + 1, nx): edge below row i
    for i, j in zip(*np.nonzero(horiz)):
        segs.append([(xe[j], ye[i]), (xe[j + 1], ye[i])])
    if segs:
        ax.add_collection(LineCollection(segs, colors=kw.get("color", "k"), linewidths=kw.get("lw", 1.2),
                                         zorder=kw.get("zorder", 4)), autolim=False)


def plain_numbers(ax) -> None:
    """No offset or scientific notation on either axis (a reader sees the numbers themselves)."""
    for axis in (ax.xaxis, ax.yaxis):
        fmt = axis.get_major_formatter()
        if isinstance(fmt, matplotlib.ticker.ScalarFormatter):
            fmt.set_useOffset(False)
            fmt.set_scientific(False)


@styled
def design_space_map(frame, keys: Sequence[str], metric: str, labels: dict[str, str] | None = None,
                     best: int | None = None, best_text: str = "", title: str = "", panels: int = 6,
                     cmap: str = "viridis", only_kept: bool = False, ax=None,
                     searched: Mapping[str, Any] | None = None, slices: Sequence[float] | None = None,
                     slice_note: str = "") -> Figure:
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
    ``searched``: the values each key was searched over (the sweep's grid): the axes span them
    and the cells sit on them, so a map of the kept designs shows where they lie in the searched
    space.  ``slices``: the values of the third key to draw (the same in every map of one sweep,
    :func:`sweep_maps`), ``slice_note`` the words that say how they were chosen.
    """
    import pandas as pd
    labels = labels or {}

    def lab(c: str) -> str:   # a label that is the column's own name may be deck text (an expression): drawn literally
        return labels.get(c, c) if labels.get(c, c) != c else plain_text(c)

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
        plain_numbers(ax)
        ax.legend(loc="best")
        if title:
            ax.set_title(title)   # composed by the caller: deck parts through plain_text
        return fig

    kx, ky = keys[0], keys[1]
    searched = {k: _numeric_axis(v) for k, v in (searched or {}).items() if k in keys and len(_numeric_axis(v))}
    parts: list[tuple[float | None, Any]]
    if len(keys) == 3:
        kz = keys[2]
        if slices is None:
            slices = pick_slices(frame, kz, panels, brow[kz] if brow is not None else None)
        zcol = pd.to_numeric(frame[kz], errors="coerce")
        parts = [(float(z), frame[np.isclose(zcol, z)]) for z in slices]
    else:
        kz, parts = "", [(None, frame)]
    n = len(parts)
    if ax is not None and n == 1:
        fig, axes = ax.figure, [ax]
    else:
        ncols = min(3, n)
        nrows = int(math.ceil(n / ncols))
        fig, grid = new_figure(nrows, ncols, sharex=True, sharey=True,
                               figsize=(6.4, 5.0) if n == 1 else (3.3 * ncols + 1.2, 2.9 * nrows + 1.0))
        axes = list(grid)
        for extra in axes[n:]:
            extra.set_visible(False)
    xs_all = searched.get(kx, _numeric_axis(frame[kx]))
    ys_all = searched.get(ky, _numeric_axis(frame[ky]))
    image = None
    for a, (zval, part) in zip(axes, parts):
        xs, ys, z = _grid_of(part, kx, ky, metric, xs_all if kx in searched else None,
                             ys_all if ky in searched else None)
        _, _, keep = _grid_of(part.assign(_kept=kept[part.index].astype(float)), kx, ky, "_kept",
                              xs_all if kx in searched else None, ys_all if ky in searched else None)
        a.grid(False)
        a.set_facecolor("0.93")
        image = a.pcolormesh(_edges(xs), _edges(ys), np.ma.masked_invalid(z), cmap=cmap, norm=norm,
                             shading="flat", rasterized=True)
        if np.nansum(keep) and not np.all(keep[np.isfinite(keep)] == 1):
            outline_cells(a, _edges(xs), _edges(ys), np.nan_to_num(keep, nan=0.0) > 0.5)
        if brow is not None and (zval is None or np.isclose(float(brow[kz]), zval)):
            a.plot([brow[kx]], [brow[ky]], "*", ms=15, color="C3", mec="k", mew=0.8, zorder=5)
        a.set_xlim(_edges(xs_all)[[0, -1]])
        a.set_ylim(_edges(ys_all)[[0, -1]])
        if zval is not None:
            a.set_title(f"{lab(kz).split(' [')[0]} = {zval:.4g}", fontsize=9)
        plain_numbers(a)
    for a in axes[:n]:
        if a.get_subplotspec() is None or a.get_subplotspec().is_last_row() or n == 1:
            a.set_xlabel(lab(kx))
        if a.get_subplotspec() is None or a.get_subplotspec().is_first_col() or n == 1:
            a.set_ylabel(lab(ky))
    if (brow is not None and best_text) or slice_note:   # the best design's values and the slices, under the panels
        hidden = brow is not None and kz and not any(z is not None and np.isclose(float(brow[kz]), z) for z, _ in parts)
        words = ("\u2605 " + wrap(best_text + ("; its slice is not among those drawn" if hidden else ""), 110)
                 if brow is not None and best_text else "")
        if slice_note:
            words = f"{words}\n{wrap(slice_note, 110)}" if words else wrap(slice_note, 110)
        fig.supxlabel(words, fontsize=8.5, color="0.15")
    if image is None:   # no panel (an empty frame)
        raise ValueError("design_space_map: no design to draw")
    cb = fig.colorbar(image, ax=list(axes[:n]), shrink=0.9, pad=0.02)
    cb.set_label(lab(metric))
    plain_numbers(cb.ax)
    note = ("kept designs outlined in black" if not kept.all() else
            "only kept designs tabulated (blank: not kept)" if only_kept else "every design kept")
    if title:
        suptitle(fig, f"{title}\n{note}" if (n > 1 or not kept.all() or only_kept) else title)
    elif not kept.all() or only_kept:
        axes[0].set_title(note, fontsize=8)
    return fig


@styled
def convergence_plot(history, evals, objective: str, sense: str = "minimize", title: str = "",
                     axes=None, tolerance: float | None = None, tolerance_words: str = "") -> Figure:
    """How an optimisation converged, as an engineer reads it: three panels against the number
    of designs evaluated, judged against the tolerance the deck states.

    Left: the best feasible objective so far (a step line) over every feasible design (grey
    dots), the band within ``tolerance`` of the final best shaded; the window shows the descent
    and at least that band, plain numbers (no offset).  Middle: the gap between the best so far
    and the final best in units of ``tolerance`` on a log axis, drawn until it first falls within
    the tolerance (the line at 1) and no further: what changes below the stated tolerance is not
    convergence (a lattice's last bits).  Right: the constraint violation of every design on a
    log axis (feasible designs, violation 0, are not drawn) and its running minimum.

    ``history`` has columns evals, feasible, objective; ``evals`` eval, feasible, objective,
    violation.  ``objective`` is the axis label (words and unit); ``sense`` 'minimize' or
    'maximize'; ``tolerance`` the stated tolerance in the objective's unit (None: the gap is drawn
    in the objective's unit, down to its last change) and ``tolerance_words`` how it was stated
    (``'tol x |best| + atol'``).  ``axes``: three axes to draw into.
    """
    import pandas as pd
    if axes is None:
        fig, axes = new_figure(1, 3, sharex=True, figsize=(11.5, 4.4))
    else:
        fig = axes[0].figure
    a1, a2, a3 = axes
    objective = wrap(objective, 40)
    unit = re.search(r"\[([^\[\]]+)\]\s*$", objective)   # the objective's unit, when its label has one
    unit_text = f" {unit.group(1)}" if unit and unit.group(1) not in ("-", "1") else ""
    ev = evals.sort_values("eval")
    feas = ev[ev["feasible"].astype(bool)]
    sign = -1.0 if sense.startswith("max") else 1.0
    obj = pd.to_numeric(feas["objective"], errors="coerce").to_numpy(dtype=float)
    tol = tolerance if tolerance is not None and tolerance > 0 else None
    a1.plot(feas["eval"], obj, ".", ms=2.5, color="0.65", label="feasible designs", rasterized=len(obj) > RASTER_POINTS)
    if len(obj):
        best = sign * np.minimum.accumulate(sign * obj)
        at = feas["eval"].to_numpy(dtype=float)
        x = np.concatenate([at, [float(ev["eval"].max())]])
        y = np.concatenate([best, best[-1:]])
        a1.step(x, y, where="post", color="C3", lw=1.8, label="best feasible so far")
        final = best[-1]
        if tol is not None:
            a1.axhspan(final - tol, final + tol, color="C2", alpha=0.15, lw=0,
                       label=f"within the stated tolerance of the final best (\u00b1{tol:.3g}{unit_text})")
        gap = np.abs(best - final)
        scale = tol if tol is not None else 1.0
        rel = gap / scale
        if tol is not None:
            inside = np.flatnonzero(rel <= 1.0)
            first_in = int(inside[0])   # the final best is within its own tolerance: always found
            if first_in == 0:
                a2.text(0.5, 0.72, f"the first feasible design (design {at[0]:.0f})\nwas within the stated "
                                   f"tolerance\nof the final best", transform=a2.transAxes, ha="center", va="center",
                        bbox=dict(boxstyle="round,pad=0.3", fc="white", ec="0.8"))
            else:
                a2.step(at[:first_in + 1], np.maximum(rel[:first_in + 1], 1e-3), where="post", color="C3", lw=1.6,
                        label="gap of the best so far")
                a2.plot([at[first_in]], [max(rel[first_in], 1e-3)], "o", color="C2", ms=6, zorder=5,
                        label=f"within the tolerance from design {at[first_in]:.0f}")
                a2.set_yscale("log")
            a2.axhline(1.0, color="C2", lw=1.2, ls="--", label="the stated tolerance")
            a2.set_ylim(bottom=min(0.3, float(np.min(np.maximum(rel[:first_in + 1], 1e-3)))) * 0.8)
            a2.set_ylabel("|best so far - final best| / tolerance")
            a2.set_title("gap to the final best, in tolerances")
            if a2.get_yscale() == "linear":
                a2.set_ylim(0.0, 2.0)
        else:
            pos = gap > 0
            if pos.any():
                a2.step(at[pos], gap[pos], where="post", color="C3", lw=1.6, label="gap of the best so far")
                a2.set_yscale("log")
            else:
                a2.text(0.5, 0.5, "the first feasible design\nwas already the best", transform=a2.transAxes,
                        ha="center", va="center")
            a2.set_ylabel("|best so far - final best|" + (f" [{unit.group(1)}]" if unit else ""))
            a2.set_title("gap to the final best")
        lo, hi = float(np.min(best)), float(np.max(best))
        span = max(hi - lo, 4.0 * tol if tol is not None else 1e-4 * max(abs(final), 1e-12))
        mid = 0.5 * (lo + hi)
        a1.set_ylim(mid - 0.6 * span, mid + 0.6 * span)
    else:
        a1.text(0.5, 0.5, "no feasible design", transform=a1.transAxes, ha="center", va="center")
        a2.text(0.5, 0.5, "no feasible design", transform=a2.transAxes, ha="center", va="center")
        a2.set_title("gap to the final best")
    a1.set_ylabel(objective)
    a1.set_title(f"best feasible objective ({'largest' if sign < 0 else 'smallest'} so far)")
    viol = pd.to_numeric(ev["violation"], errors="coerce").to_numpy(dtype=float) if "violation" in ev else np.array([])
    if viol.size and np.nanmax(viol) > 0:
        pos = viol > 0
        a3.plot(ev["eval"].to_numpy()[pos], viol[pos], ".", ms=2.5, color="C0", alpha=0.6,
                label="constraint violation of each design", rasterized=pos.sum() > RASTER_POINTS)
        run = np.minimum.accumulate(np.where(np.isfinite(viol), viol, np.inf))
        shown = run > 0
        a3.step(ev["eval"].to_numpy()[shown], run[shown], where="post", color="k", lw=1.4,
                label="smallest violation so far (0 once feasible)")
        a3.set_yscale("log")
    else:
        a3.text(0.5, 0.5, "every design feasible", transform=a3.transAxes, ha="center", va="center")
    a3.set_ylabel("constraint violation [constraint units]")
    a3.set_title("constraint violation")
    for a in axes:
        a.set_xlabel("designs evaluated")
    plain_numbers(a1)
    plain_numbers(a3) if a3.get_yscale() == "linear" else None
    handles, labels = [], []
    for a in axes:
        h, lab = a.get_legend_handles_labels()
        handles += h
        labels += lab
    if handles:
        fig.legend(handles, labels, loc="outside lower center", ncol=3, frameon=False,
                   title=f"tolerance: {tolerance_words}" if tolerance_words else None, title_fontsize=8.5)
    if title:
        suptitle(fig, title)   # composed by the caller: deck parts through plain_text
    return fig


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


def pick_slices(frame, kz: str, panels: int = 6, must: Any = None) -> list[float]:
    """Up to ``panels`` values of the third swept key ``kz`` for a map's small multiples: evenly
    over the values whose rows hold a kept design (all values when none is kept), with ``must``
    (the best design's value) among them."""
    import pandas as pd
    col = pd.to_numeric(frame[kz], errors="coerce")
    kept = frame["kept"].astype(bool) if "kept" in frame else pd.Series(True, index=frame.index)
    zs = _numeric_axis(col[kept]) if kept.any() else _numeric_axis(col)
    if not len(zs):
        zs = _numeric_axis(col)
    pick = np.unique(np.linspace(0, len(zs) - 1, min(panels, len(zs))).round().astype(int))
    if must is not None and np.isfinite(float(must)):
        bz = int(np.argmin(np.abs(zs - float(must))))
        if bz not in pick:
            pick[np.argmin(np.abs(pick - bz))] = bz
        pick = np.unique(pick)
    return [float(zs[i]) for i in pick]


def sweep_maps(frame, keys: Sequence[str], ys: Sequence[str], labels: dict[str, str], senses: Mapping[str, str],
               title: str = "", only_kept: bool = False, searched: Mapping[str, Any] | None = None) -> list[Figure]:
    """Design-space maps of a 2-3-key grid sweep, one per plotted column ``ys``: the best kept
    design (by ``senses[y]``, 'min' or 'max', when the study knows which is better) starred and
    labelled with its key values.  ``searched``: the values each key was searched over (the axes
    span them).  Over three keys every map shows the same values of the third (chosen once, by
    the first column's best design, and stated under the panels)."""
    figs = []
    slices, note = None, ""
    keys = list(keys)
    if len(keys) == 3 and ys:
        kz = keys[2]
        first = best_index(frame, ys[0], senses.get(ys[0]))
        slices = pick_slices(frame, kz, 6, frame.loc[first, kz] if first is not None else None)
        every = _numeric_axis((searched or {}).get(kz, frame[kz]))
        word = labels.get(kz, kz).split(" [")[0]
        shown = ", ".join(f"{z:.4g}" for z in slices)
        note = (f"{word} = {shown}: {len(slices)} of the {len(every)} searched values"
                + (f" ({every[0]:.4g} to {every[-1]:.4g})" if len(every) > 1 else "")
                + ", evenly over those with kept designs; the same in every map of this sweep")
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
                                     only_kept=only_kept, searched=searched, slices=slices, slice_note=note))
    return figs




# ----------------------------------------------------------------------------- the mechanism's animation

def mechanism_animation(frames: Any, title: str = "", figsize: tuple[float, float] = (6.4, 4.8),
                        max_frames: int = 120) -> Any:
    """The motion of a mechanism (a :class:`driver._mechanism.MechanismFrames`, what the report
    page animates) as a matplotlib ``FuncAnimation``: the same parts in the same colours (links,
    rigid bodies, pins, coupler points, counterweights, ground marks, guides, traced paths and
    target points), equal scales, the frame's label as the title.  Points that do not exist at
    a frame hide the parts through them; at most ``max_frames`` frames (every k-th).  Drawn in
    the house style; no pyplot state."""
    from matplotlib.animation import FuncAnimation
    from matplotlib.patches import Polygon

    from driver._mechanism import LINK_COLOURS, MARK_COLOUR, MASS_COLOUR, PATH_COLOURS
    step = max(1, -(-frames.n_frames // max_frames))
    with style():
        fig, (ax,) = new_figure(1, 1, figsize=figsize)
        ax.set_aspect("equal")
        ax.grid(False)
        x0, y0, w, h = frames.extent()
        pad = 0.08 * max(w, h, 1e-9)
        ax.set_xlim(x0 - pad, x0 + w + pad)
        ax.set_ylim(y0 - pad, y0 + h + pad)
        ax.set_axis_off()   # a drawing for slides: no ticks (and a frame draws in a fraction of the time)
        pts = frames.points
        for g in frames.guides:
            xy = np.vstack([g.xy, g.xy[:1]]) if g.closed else g.xy
            ax.plot(xy[:, 0], xy[:, 1], color="0.35", lw=0.8, ls="--" if g.dashed else "-", zorder=1)
        for j, i in enumerate(frames.paths):
            for a, b in frames.runs():
                seg = pts[a:b, i]
                if frames.closed_paths():
                    seg = np.vstack([seg, seg[:1]])
                ax.plot(seg[:, 0], seg[:, 1], color=PATH_COLOURS[j % len(PATH_COLOURS)], lw=0.9, ls="--", zorder=2)
        artists: list[tuple[Any, tuple[int, ...], str]] = []
        for k, link in enumerate(frames.links):
            colour = LINK_COLOURS[(k if link.colour is None else link.colour) % len(LINK_COLOURS)]
            if link.body:
                patch = Polygon(np.zeros((len(link.points), 2)), closed=True, fc=matplotlib.colors.to_rgba(colour, 0.25),
                                ec=colour, lw=2.6, joinstyle="round", zorder=3)
                ax.add_patch(patch)
                artists.append((patch, link.points, "body"))
            else:
                (line,) = ax.plot([], [], color=colour, lw=3.0, solid_capstyle="round", solid_joinstyle="round",
                                  zorder=3)
                artists.append((line, link.points, "line"))
        dots = []
        for idx, kw in ((frames.joints, dict(marker="o", ms=7, mfc="white", mec="k", mew=1.0, zorder=6)),
                        (frames.markers, dict(marker="o", ms=6, color="#8e44ad", zorder=6)),
                        (frames.masses, dict(marker="o", ms=12, color=MASS_COLOUR, mec="k", zorder=5))):
            for i in idx:
                (dot,) = ax.plot([], [], ls="none", **kw)
                dots.append((dot, i))
        for i in frames.ground:
            ax.plot(*pts[0, i], "^", color="0.3", ms=11, zorder=4)
        for m in frames.marks:
            ax.plot(m.xy[:, 0], m.xy[:, 1], "s", mfc="none", mec=MARK_COLOUR, mew=1.4, ms=8, zorder=7)
        label = ax.set_title("")

        def show(k: int) -> list[Any]:
            for artist, idx, kind in artists:
                xy = pts[k, list(idx)]
                ok = bool(np.isfinite(xy).all())
                artist.set_visible(ok)
                if ok and kind == "body":
                    artist.set_xy(xy)
                elif ok:
                    artist.set_data(xy[:, 0], xy[:, 1])
            for dot, i in dots:
                ok = bool(np.isfinite(pts[k, i]).all())
                dot.set_visible(ok)
                if ok:
                    dot.set_data([pts[k, i, 0]], [pts[k, i, 1]])
            words = f"{frames.frame_name} {frames.labels[k]}"
            if frames.units:
                words += f"   (lengths in {frames.units})"
            if not frames.valid[k]:
                words += f"  ({frames.invalid_note})"
            label.set_text(f"{plain_text(title)}\n{words}" if title else words)
            return [a for a, _, _ in artists] + [d for d, _ in dots] + [label]

        show(0)
        # lay the figure out once (room for a two-line title), then keep it: every frame moves the
        # parts only, and a layout per frame would cost more than the drawing
        label.set_text(f"{plain_text(title)}\nX" if title else "X")
        fig.draw_without_rendering()
        fig.set_layout_engine("none")
        show(0)
    return FuncAnimation(fig, show, frames=range(0, frames.n_frames, step), interval=1000 // 25, blit=False)


def save_animation(frames: Any, path: str | Path, fmt: str = "gif", title: str = "", fps: int = 25,
                   dpi: int = 90) -> Path:
    """Write the motion of a mechanism (:func:`mechanism_animation`) as ``path`` with the suffix
    of ``fmt``: 'gif' through matplotlib's Pillow writer, 'mp4' (H.264) through its ffmpeg writer
    (ffmpeg must be on PATH).  Encoded in a scratch folder, then written atomically (as every
    output: an interrupted export never leaves half a file).  Returns the path written."""
    import tempfile

    from matplotlib.animation import FFMpegWriter, PillowWriter, writers
    fmt = str(fmt).lower().lstrip(".")
    if fmt not in ANIMATION_FORMATS:
        raise ValueError(f"animation format {fmt!r} is not one of {', '.join(ANIMATION_FORMATS)}")
    if fmt == "mp4" and not writers.is_available("ffmpeg"):
        raise RuntimeError("an MP4 animation needs ffmpeg on PATH (apt-get install ffmpeg); GIF needs nothing more")
    path = Path(path).with_suffix(f".{fmt}")
    anim = mechanism_animation(frames, title)
    writer = PillowWriter(fps=fps) if fmt == "gif" else FFMpegWriter(fps=fps, codec="h264",
                                                                       extra_args=["-pix_fmt", "yuv420p"])
    with tempfile.TemporaryDirectory(prefix="driver_animation_") as scratch:
        tmp = Path(scratch) / f"animation.{fmt}"
        with style():
            anim.save(str(tmp), writer=writer, dpi=dpi)
        with atomic_open(path, "wb") as fh:
            fh.write(tmp.read_bytes())
    return path
