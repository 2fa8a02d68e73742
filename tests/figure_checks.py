"""Checks of a drawn matplotlib figure as a reader sees it (used by the figure tests).

* :func:`text_outside` lists every visible piece of text (titles, axis and tick labels, legend
  entries, annotations, colour-bar labels, contour labels) whose box, laid out by matplotlib's own
  renderer as ``savefig`` lays it out, reaches past the canvas.
* :func:`raw_names` lists the titles, axis labels, legend entries and colour-bar labels that show
  a column name instead of words: a known column or key name of the run, or any
  ``snake_case_with_a_unit`` (``mu_min_deg``, ``torque_peak_Nm``, ``fourbar.crank``).
  Mathtext spans (``$\\theta_2$``) are symbols, not names, and are left out.
"""
from __future__ import annotations

import re
from collections.abc import Iterable

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.text import Text

from driver._export import SUFFIX_UNITS

#: a name with a unit suffix (``omega3_rad_s``) or a dotted deck key (``fourbar.crank``)
_UNIT = "|".join(re.escape(s) for s, _ in sorted(SUFFIX_UNITS, key=lambda su: -len(su[0])))
RAW = re.compile(rf"\b[A-Za-z][A-Za-z0-9]*(?:_[A-Za-z0-9]+)*(?:{_UNIT})\b|\b[a-z][a-z0-9_]+\.[a-z][a-z0-9_]+\b")
_MATH = re.compile(r"(?<!\\)\$.*?(?<!\\)\$")


def renderer(fig: Figure):
    """Lay ``fig`` out on an Agg canvas as ``savefig`` does (constrained layout included)."""
    canvas = fig.canvas if isinstance(fig.canvas, FigureCanvasAgg) else FigureCanvasAgg(fig)
    canvas.draw()
    return canvas.get_renderer()


def _tick_labels(fig: Figure) -> tuple[set[int], set[int]]:
    """(ids of every tick label Text of ``fig``, ids of those drawn): matplotlib keeps labels of
    ticks outside the view limits, and does not draw them."""
    every, drawn = set(), set()
    for ax in fig.axes:
        for axis in ax._axis_map.values():
            for tick in [*axis.majorTicks, *axis.minorTicks]:
                every |= {id(tick.label1), id(tick.label2)}
            if not (ax.axison and axis.get_visible()):
                continue   # an axis that is not drawn draws no tick label
            for tick in axis._update_ticks():
                drawn |= {id(t) for t in (tick.label1, tick.label2) if tick.get_visible() and t.get_visible()}
    return every, drawn


def texts(fig: Figure) -> list[Text]:
    """Every visible, non-empty Text artist ``fig`` draws (ticks, legends, annotations included)."""
    out = []
    every, drawn = _tick_labels(fig)
    for t in fig.findobj(Text):
        if not t.get_visible() or not t.get_text().strip():
            continue
        if id(t) in every and id(t) not in drawn:
            continue
        owner = t.axes
        if owner is not None and not owner.get_visible():
            continue
        out.append(t)
    return out


def text_outside(fig: Figure, tolerance: float = 1.0) -> list[str]:
    """The texts of ``fig`` whose drawn box is not inside the canvas (``tolerance`` pixels)."""
    r = renderer(fig)
    fb = fig.bbox
    bad = []
    for t in texts(fig):
        box = t.get_window_extent(r)
        if box.width == 0 and box.height == 0:
            continue
        if box.x0 < fb.x0 - tolerance or box.y0 < fb.y0 - tolerance or box.x1 > fb.x1 + tolerance \
                or box.y1 > fb.y1 + tolerance:
            bad.append(f"{t.get_text()!r} at ({box.x0:.0f}, {box.y0:.0f})-({box.x1:.0f}, {box.y1:.0f}) "
                       f"outside {fb.width:.0f} x {fb.height:.0f}")
    return bad


def labels(fig: Figure) -> list[str]:
    """The words of ``fig`` a reader reads as names: titles, axis labels, legend entries and
    titles, colour-bar labels (tick labels and annotations of values are not)."""
    out = []
    if fig._suptitle is not None:
        out.append(fig._suptitle.get_text())
    for attr in ("_supxlabel", "_supylabel"):
        t = getattr(fig, attr, None)
        if t is not None:
            out.append(t.get_text())
    legends = list(fig.legends)
    for ax in fig.axes:
        out += [ax.title.get_text(), ax._left_title.get_text(), ax._right_title.get_text(),
                ax.xaxis.label.get_text(), ax.yaxis.label.get_text()]
        if ax.get_legend() is not None:
            legends.append(ax.get_legend())
    for lg in legends:
        out += [t.get_text() for t in lg.get_texts()] + [lg.get_title().get_text()]
    return [t for t in out if t and t.strip()]


def raw_names(fig: Figure, names: Iterable[str] = ()) -> list[str]:
    """The labels of ``fig`` (:func:`labels`) that show a raw column name: one of ``names`` (the
    run's columns and keys) as a word, or any name with a unit suffix or a dotted deck key."""
    known = {n for n in names if "_" in n or "." in n}
    bad = []
    for text in labels(fig):
        words = _MATH.sub(" ", text)
        hits = set(RAW.findall(words))
        hits |= {n for n in known if re.search(rf"(?<![\w.]){re.escape(n)}(?![\w.])", words)}
        if hits:
            bad.append(f"{text!r} shows {sorted(hits)}")
    return bad


def figure_problems(fig: Figure, names: Iterable[str] = ()) -> list[str]:
    """Every text outside the canvas and every raw name of ``fig``."""
    return text_outside(fig) + raw_names(fig, names)
