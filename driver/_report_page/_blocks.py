"""The parts of a report page as data: sections of blocks (a paragraph, a table, a figure, an
animation ...), each drawn by one macro of ``templates/blocks.html.j2``.

Nothing here writes markup: a block holds text and numbers, and the templates (Jinja2, with
autoescaping) turn them into HTML.  The helpers turn a run's data into blocks: a summary into a
key-value table, a DataFrame into a table, the comparison with the published cells into counts
and the cells that differ.
"""
from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

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
    """A table with a header row, scrolled on screen, and a note under it (rows left out)."""

    kind: ClassVar[str] = "table"
    columns: list[str]
    rows: list[list[str]]
    note: str = ""


@dataclass
class FigureBlock(Block):
    """A figure as inline SVG markup (made by matplotlib, edited as XML) and its caption."""

    kind: ClassVar[str] = "figure"
    svg: Markup
    caption: str


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


def key_values(rows: Mapping[str, Any] | Iterable[tuple[str, Any]], labels: Mapping[str, str] | None = None) -> KeyValues:
    """A key-value table of ``rows``; ``labels`` gives a name in words for a key (the key is
    then its tooltip)."""
    items = rows.items() if isinstance(rows, Mapping) else rows
    labels = labels or {}
    return KeyValues([(labels.get(k, k), fmt(v), k if k in labels else "") for k, v in items])


def frame_table(frame: pd.DataFrame, limit: int = MAX_TIDY_ROWS) -> Table:
    """The first ``limit`` rows of ``frame`` as a table (a note says when rows are left out)."""
    shown = frame.head(limit)
    rows = [[fmt(v) for v in r] for r in shown.itertuples(index=False, name=None)]
    note = (f"first {limit} of {len(frame)} rows; the whole table is in the CSV/Parquet files "
            "(--csv, --format parquet)") if len(frame) > limit else ""
    return Table([str(c) for c in shown.columns], rows, note)


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
