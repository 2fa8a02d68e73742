"""Readers of the published record: the transcribed tables in the top-level ``published/`` folder
(installed inside the package as ``driver/published_record/``).

Every file there holds printed values exactly as the papers print them (text, so the number of
printed decimals is kept) and one ``match:`` line naming the study group and the deck values the
table belongs to, e.g. ``match: fourbar fixed_link=12 crank=5 coupler=15 rocker=9 omega=5``.
:func:`records` finds the files of a study; the study's reader turns a file into a
:class:`Published` table of printed cells.  The test suite reads its expected values through
this module too, so the published record has one source of truth.

Nothing here computes anything.  Each study's ``published.py`` (its ``Study.published``) puts
the printed cells of its tables beside a run with the cell primitives at the end of this module
(:func:`cell`, :func:`numeric_cell`, :func:`agrees_printed`); :mod:`driver._compare` runs the
comparison and reports it.
"""
from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from decimal import Decimal, InvalidOperation
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
import pandas as pd

from driver._errors import DriverError

__all__ = ["PUBLISHED_DIR", "Published", "PrintedCell", "printed_cells", "PublishedError", "match_line", "records",
           "read_listing", "read_blocks", "matches", "listing_rows", "LISTING_COLUMNS", "agrees_printed", "cell", "numeric_cell",
           "one_digit_apart", "decimals"]

def _published_dir() -> Path:
    """The installed copy (``driver/published_record/``, a wheel or ``pip install .``) when there is
    one, else the source checkout's ``published/`` (an editable install reads the checkout)."""
    package = Path(__file__).resolve().parent
    installed = package / "published_record"
    return installed if installed.is_dir() else package.parent / "published"


#: the folder of published tables: ``published/`` of the source tree, shipped inside the package
#: as ``driver/published_record/``
PUBLISHED_DIR = _published_dir()

_MATCH = re.compile(r"^\W*match:\s*(\w+)((?:\s+\w+=\S+)*)\s*$")


class PublishedError(DriverError, ValueError):
    """A published file is missing or not in its documented layout."""


@dataclass
class Published:
    """One published table: where it comes from and its printed cells.

    name     how the comparison names it, e.g. ``Lampiran 3 (crank 5)``
    path     the file in ``published/``
    group    the study group it belongs to
    match    deck values it was printed for (key -> text)
    cells    one row per printed cell: ``table``, ``row``, ``column``, ``printed`` (text as
             printed) and, where the transcription records one, ``note``
    """

    name: str
    path: Path
    group: str
    match: dict[str, str]
    cells: pd.DataFrame = field(repr=False)


class PrintedCell(NamedTuple):
    """One printed cell of a :class:`Published` table; every field is text, as printed."""

    table: str
    row: str
    column: str
    printed: str
    note: str = ""


def printed_cells(cells: pd.DataFrame) -> list[PrintedCell]:
    """The rows of :attr:`Published.cells` (or of a selection of them) as :class:`PrintedCell`,
    in order; ``note`` is empty where the table records none."""
    notes = cells["note"] if "note" in cells.columns else [""] * len(cells)
    return [PrintedCell(str(t), str(r), str(c), str(p), str(n))
            for t, r, c, p, n in zip(cells["table"], cells["row"], cells["column"], cells["printed"], notes)]


def match_line(path: Path) -> tuple[str, dict[str, str]]:
    """The study group and deck values of a published file's ``match:`` line."""
    for line in Path(path).read_text().splitlines():
        m = _MATCH.match(line)
        if m:
            pairs = dict(kv.split("=", 1) for kv in m.group(2).split())
            return m.group(1), pairs
    raise PublishedError(f"{path}: no 'match:' line")


def records(group: str, folder: Path | None = None) -> list[Path]:
    """The published files of study ``group`` (sorted by name)."""
    folder = PUBLISHED_DIR if folder is None else Path(folder)
    if not folder.is_dir():
        return []
    found = []
    for path in sorted(folder.iterdir()):
        if path.suffix in (".out", ".txt", ".csv") and path.is_file():
            try:
                g, _ = match_line(path)
            except PublishedError:
                continue
            if g == group:
                found.append(path)
    return found


def matches(match: dict[str, str], values: Mapping[str, object], rel: float = 1e-12) -> bool:
    """Whether deck ``values`` equal a file's ``match`` values (numbers compared as numbers,
    comma-separated lists element by element)."""
    for key, text in match.items():
        if key not in values:
            return False
        want = text.split(",")
        value = values[key]
        got: Sequence[object] = value if isinstance(value, (list, tuple)) else [value]
        if len(want) != len(got):
            return False
        for t, v in zip(want, got):
            try:
                a, b = float(t), float(v)  # type: ignore[arg-type]  # any deck value: a non-number raises, handled below
            except (TypeError, ValueError):
                if str(v).strip().lower() != t.strip().lower():
                    return False
                continue
            if abs(a - b) > rel * max(1.0, abs(a)):
                return False
    return True


# ----------------------------------------------------------------------------- four-bar listing

#: columns of the listing's table (FORMAT 25), in order
LISTING_COLUMNS = ("i", "epsl", "phi", "beta", "xa", "ya", "xb", "yb", "omr", "oms")


def listing_rows(text: str) -> list[list[str]]:
    """The rows of a four-bar listing table (as printed, split into fields).

    The table runs from the blank line after the column line ``i epsl phi ...`` to the next
    blank line; works on the published files and on the tool's own ``.out`` alike.
    """
    lines = text.splitlines()
    try:
        start = next(k for k, l in enumerate(lines) if l.split()[:3] == ["i", "epsl", "phi"])
    except StopIteration:
        raise PublishedError("no listing table (column line 'i epsl phi ...') found") from None
    rows = []
    for line in lines[start + 2:]:
        if not line.strip():
            break
        rows.append(line.split())
    return rows


def read_listing(path: Path) -> Published:
    """A four-bar table of Lampiran 2-3 (``published/crankN.out``)."""
    path = Path(path)
    text = path.read_text()
    group, match = match_line(path)
    rows = listing_rows(text)
    m = re.search(r"(Lampiran \d)", text[text.index("Published record"):]) if "Published record" in text else None
    name = f"{m.group(1) if m else path.stem} (crank {match.get('crank', '?')})"
    recs = []
    for k, row in enumerate(rows):
        if len(row) != len(LISTING_COLUMNS):
            raise PublishedError(f"{path}: row {k + 1} has {len(row)} fields, expected {len(LISTING_COLUMNS)}")
        for col, value in zip(LISTING_COLUMNS, row):
            recs.append({"table": name, "row": row[0], "column": col, "printed": value})
    return Published(name, path, group, match, pd.DataFrame.from_records(recs))


# ----------------------------------------------------------------------------- titled blocks

def read_blocks(path: Path) -> Published:
    """A file of titled tables (the manipulator report, section 2.3, the Hooke-joint paper, ...).

    A block is a title line starting in column 1 (``Table 4.8  ...``, ``Text values``), a dashed
    underline, a column line, and rows up to the next blank line.  The first column is the row
    label; a row with fewer fields than columns has its last cells blank (printed blank); a last
    column named ``where`` takes the rest of the line (where in the paper the value is printed).
    The table name is the title up to two spaces (``Table 4.8``).
    """
    path = Path(path)
    group, match = match_line(path)
    lines = path.read_text().splitlines()
    recs = []
    k = 0
    while k < len(lines):
        line = lines[k]
        if (line[:1].isalpha() and k + 2 < len(lines) and lines[k + 1].startswith("---")
                and not line.startswith("match:")):
            table = line.split("  ")[0].strip()
            header = lines[k + 2].split()
            free = header[-1] == "where"
            k += 3
            while k < len(lines) and lines[k].strip():
                fields = lines[k].split(None, len(header) - 1) if free else lines[k].split()
                if len(fields) > len(header):
                    raise PublishedError(f"{path}: line {k + 1} has {len(fields)} fields for {len(header)} columns")
                fields += [""] * (len(header) - len(fields))
                note = fields[-1].strip() if free else ""
                for col, value in zip(header[1:len(header) - free], fields[1:len(fields) - free]):
                    recs.append({"table": table, "row": fields[0], "column": col, "printed": value, "note": note})
                k += 1
        k += 1
    if not recs:
        raise PublishedError(f"{path}: no table found")
    return Published(path.stem, path, group, match, pd.DataFrame.from_records(recs))


# ----------------------------------------------------------------------------- cells of a comparison

def agrees_printed(computed: float, printed: str) -> bool:
    """|computed - printed| <= half a unit of the printed last digit (+1e-9)."""
    try:
        exp = Decimal(printed.strip()).as_tuple().exponent
    except InvalidOperation:
        return False
    half = 0.5 * 10.0 ** int(exp)
    return math.isfinite(computed) and abs(float(computed) - float(printed)) <= half + 1e-9


def decimals(printed: str) -> int:
    """The number of decimals ``printed`` shows."""
    exp = Decimal(printed.strip()).as_tuple().exponent
    return max(0, -int(exp))


def cell(table: str, row: Any, column: str, printed: str, computed: str, status: str, reason: str = "") -> dict:
    """One row of a comparison (the columns of :data:`driver._compare.COLUMNS` but the deck)."""
    return {"table": table, "row": str(row), "column": column, "printed": printed, "computed": computed,
            "status": status, "reason": reason}


def numeric_cell(table: str, row: str, column: str, printed: str, value: float | None,
                 flagged: str | None, departs: str | None) -> dict:
    """One printed number against a computed one (None/NaN: the run leaves the cell blank).

    ``flagged``: why the printed value is known not to be reproducible; ``departs``: why the
    deck's correct answer differs (None when the deck reproduces the published conventions).
    """
    number = None if value is None or not np.isfinite(value) else value   # None: blank
    if printed == "":
        comp = "" if number is None else f"{number:g}"
        return cell(table, row, column, "", comp, "identical" if number is None else "differs",
                    "" if number is None else "the report leaves this cell blank (target out of reach)")
    if number is None:
        return cell(table, row, column, printed, "", "not reproducible" if flagged else
                    ("departs" if departs else "differs"), flagged or departs or "the run leaves this cell blank")
    comp = f"{number:.{decimals(printed)}f}"
    if comp.startswith("-") and float(comp) == 0.0:
        comp = comp[1:]
    if agrees_printed(number, printed):
        return cell(table, row, column, printed, comp, "identical" if comp == printed else "agrees")
    if flagged:
        return cell(table, row, column, printed, comp, "not reproducible", flagged)
    if departs:
        return cell(table, row, column, printed, comp, "departs", departs)
    return cell(table, row, column, printed, comp, "differs", "")


def one_digit_apart(a: str, b: str, column: str) -> bool:
    """Whether two printed values differ by at most one unit of the printed last digit
    (a whole degree for the truncated angle columns)."""
    try:
        # int() of the exponent: 'n'/'N'/'F' (a printed nan or inf) is a ValueError, not a number
        unit = 1.0 if column in ("epsl", "phi", "beta") else 10.0 ** int(Decimal(b).as_tuple().exponent)
        return abs(float(a) - float(b)) <= unit * (1 + 1e-9)
    except (ValueError, InvalidOperation):
        return False
