"""The parts of a report page as data: sections of blocks (a paragraph, a table, a figure, an
animation ...), each drawn by one macro of ``templates/blocks.html.j2``.

Nothing here writes markup: a block holds text and numbers, and the templates (Jinja2, with
autoescaping) turn them into HTML.  The helpers turn a run's data into blocks: a summary into a
key-value table, a DataFrame into a table, the comparison with the published cells into counts
and the cells that differ.
"""
from __future__ import annotations

import math
import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from driver._report_page._numbers import Printed, column_decimals, format_number

if TYPE_CHECKING:
    import pandas as pd
    from markupsafe import Markup

    from driver._report_page._animation import AnimationView

__all__ = ["Block", "Text", "Pre", "KeyValues", "Table", "FigureBlock", "Details", "Warnings", "Animation",
           "Section", "Page", "MAX_TIDY_ROWS", "fmt", "key_values", "frame_table", "comparison_blocks"]

#: at most this many rows of a table are shown on the page (the whole table is in the CSV/Parquet)
MAX_TIDY_ROWS = 200


class Block:
    """A part of a section; ``kind`` names the macro that draws it."""

    kind: ClassVar[str] = ""


@dataclass
class Text(Block):
    """A paragraph; ``cls`` 'note' (muted), 'ok' (a good outcome) or '' (plain)."""

    kind: ClassVar[str] = "text"
    text: str
    cls: str = ""


@dataclass
class Pre(Block):
    """Preformatted text: a fixed-format table, a deck."""

    kind: ClassVar[str] = "pre"
    text: str


@dataclass
class KeyValues(Block):
    """A two-column table: (name, value, tooltip) rows."""

    kind: ClassVar[str] = "kv"
    rows: list[tuple[str, str, str]]


@dataclass
class Table(Block):
    """A table with a header row (names in words, each column's own name as its tooltip), scrolled
    on screen, and a note under it (rows left out)."""

    kind: ClassVar[str] = "table"
    columns: list[str]
    rows: list[list[str]]
    note: str = ""
    tips: list[str] = field(default_factory=list)


@dataclass
class FigureBlock(Block):
    """A figure as inline SVG markup (made by matplotlib, edited as XML) and its caption;
    ``anchor`` its id on the page (the figure enlarges to the whole window at ``#anchor``)."""

    kind: ClassVar[str] = "figure"
    svg: Markup
    caption: str
    anchor: str = ""

    def __post_init__(self) -> None:
        if not self.anchor:
            self.anchor = anchor_of(self.caption.split(":")[0])


def anchor_of(name: str) -> str:
    """A page id from a figure's name (letters, digits and hyphens)."""
    return "fig-" + (re.sub(r"[^A-Za-z0-9]+", "-", name).strip("-") or "x")


@dataclass
class Details(Block):
    """Blocks folded under a summary line (an optimum deck, an extra file)."""

    kind: ClassVar[str] = "details"
    summary: str
    body: list[Block]


@dataclass
class Warnings(Block):
    """The run's warnings, or a line saying there are none."""

    kind: ClassVar[str] = "warnings"
    items: list[str]


@dataclass
class Animation(Block):
    """A mechanism's animation (:mod:`driver._report_page._animation`)."""

    kind: ClassVar[str] = "animation"
    view: AnimationView


@dataclass
class Section:
    """One part of the page: an anchor id, a heading and its blocks."""

    id: str
    title: str
    blocks: list[Block] = field(default_factory=list)


@dataclass
class Page:
    """The whole page: title, subtitle, sections and the run's metadata (tool, build, date)."""

    title: str
    subtitle: str
    sections: list[Section]
    meta: dict[str, str]


def fmt(v: Any) -> str:
    """A value as a table shows it: six significant digits, '—' for a missing or non-finite number."""
    if v is None:
        return "\u2014"
    if isinstance(v, (float, np.floating)):
        return "\u2014" if not math.isfinite(float(v)) else f"{float(v):.6g}"
    return str(v)


def key_values(rows: Mapping[str, Any] | Iterable[tuple[str, Any]], labels: Mapping[str, str] | None = None,
               texts: Mapping[str, str] | None = None) -> KeyValues:
    """A key-value table of ``rows``; ``labels`` gives a name in words for a key (the key is
    then its tooltip), ``texts`` a value as printed (:func:`driver._report_page._numbers.summary_texts`)."""
    items = rows.items() if isinstance(rows, Mapping) else rows
    labels, texts = labels or {}, texts or {}
    return KeyValues([(labels.get(k, k), texts.get(k, fmt(v)), k if k in labels else "") for k, v in items])


def frame_table(frame: pd.DataFrame, limit: int = MAX_TIDY_ROWS, labels: Mapping[str, str] | None = None,
                printed: Printed | None = None) -> Table:
    """The first ``limit`` rows of ``frame`` as a table (a note says when rows are left out).

    ``labels`` names a column in words (its own name becomes the header's tooltip); a float
    column is printed with the decimals ``printed`` (the run's fixed-format text) prints it
    with, else to six significant digits of its largest magnitude (round-off reads zero)."""
    shown = frame.head(limit)
    labels = labels or {}
    cells = []
    for name in shown.columns:
        col = shown[name]
        if col.dtype.kind == "f":
            vals = col.to_numpy(dtype=float)
            fin = vals[np.isfinite(vals)]
            scale = float(np.max(np.abs(fin))) if fin.size else 0.0
            dec = column_decimals(vals, printed) if printed is not None else None
            cells.append([format_number(v, dec, scale) for v in vals])
        else:
            cells.append([format_number(v) if not isinstance(v, float) else fmt(v) for v in col.tolist()])
    rows = [list(r) for r in zip(*cells)] if cells else []
    note = (f"first {limit} of {len(frame)} rows; the whole table is in the CSV/Parquet files "
            "(--csv, --format parquet)") if len(frame) > limit else ""
    names = [str(c) for c in shown.columns]
    return Table([labels.get(c, c) for c in names], rows, note, [c if labels.get(c, c) != c else "" for c in names])


def comparison_blocks(frame: pd.DataFrame | None, note: str = "") -> list[Block]:
    """The comparison with the published cells: how many, per table and status, and every cell
    that is not identical or within its printed precision; ``note`` when there is none."""
    if frame is None or not len(frame):
        return [Text(note or "No published table belongs to this deck.", "note")]
    counts = frame.groupby(["table", "status"]).size().unstack(fill_value=0).reset_index()
    off = frame[~frame["status"].isin(["identical", "agrees"])]
    detail: Block = (frame_table(off[["table", "row", "column", "printed", "computed", "status", "reason"]], 300)
                     if len(off) else Text("Every published cell is reproduced (identical or within half a unit of "
                                           "its last printed digit).", "ok"))
    return [Text(f"{len(frame)} published cells compared; cells per table and status:"), frame_table(counts, 100),
            Text("Cells that are not identical or within the printed precision:"), detail]


def warnings_section(items: Sequence[str]) -> Section:
    """The page's first section: the warnings."""
    return Section("warnings", "warnings", [Warnings(list(items))])
