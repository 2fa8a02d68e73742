"""The one fixed-format table writer: Fortran F/I editing in Python.

Two number styles:

* ``modern``: what gfortran writes (``0.5``, ``-0.0`` avoided: a value that
  rounds to zero never carries a minus sign).
* ``legacy``: the style of the old compiler that printed the published tables:
  no optional leading zero (``.5``, ``-.8094``) and no sign on a value that
  rounds to zero (``.0``).

A value that does not fit its field is never written as ``****``: the writer
widens the whole column instead and records a note, and a NaN or infinity
raises :class:`TableValueError` (a kernel must mark such rows in words).
"""
from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from decimal import ROUND_HALF_UP, Context, Decimal, localcontext
from typing import TYPE_CHECKING, Any, Protocol, TypeAlias

from driver._errors import DriverError

if TYPE_CHECKING:   # numpy is imported by the block functions only (a --help imports this module's users)
    import numpy as np


class _Number(Protocol):
    """A Python or numpy number: what a numeric table cell holds."""

    def __float__(self) -> float: ...

    def __int__(self) -> int: ...


#: a table cell: a number, preformatted text, or None for a blank cell
Cell: TypeAlias = "_Number | str | None"

__all__ = ["TableValueError", "Column", "fortran_f", "fortran_i", "significant", "render_table", "fixed_cells",
           "render_block", "render_text"]


class TableValueError(DriverError, ValueError):
    """A NaN or infinite number was about to reach a table."""


def _round_half_up(value: float, decimals: int) -> str:
    """Decimal text of ``value`` rounded half away from zero (Fortran's RN-compatible).

    Python's ``f`` format rounds the exact binary value correctly, half to even; the two
    differ only when that exact value lies exactly halfway between two ``decimals``-digit
    numbers, which the integer ratio of the double tells exactly -- then Decimal rounds."""
    if 0 <= decimals <= 300 and math.isfinite(value):
        num, den = value.as_integer_ratio()
        twice = 2 * num * 10 ** decimals
        if twice % den or not (twice // den) % 2:   # not a tie: the fast text is the answer
            return f"{value:.{decimals}f}"
    q = Decimal(1).scaleb(-decimals)
    with localcontext(Context(prec=330 + decimals)):   # room for every finite double (<= 1.8e308)
        return format(Decimal(value).quantize(q, rounding=ROUND_HALF_UP), "f")


def fortran_f(value: float, w: int | None, d: int, style: str = "modern") -> str:
    """Fortran ``Fw.d`` editing of ``value``; ``w=None`` gives the minimal width.

    Raises TableValueError for NaN/inf.  The result may be longer than ``w``
    when the value does not fit (callers widen the column; never ``****``).
    """
    x = float(value)
    if not math.isfinite(x):   # in words: no 'nan' or 'FNone.3' in a message
        what = "a value that is not a number" if math.isnan(x) else ("+infinity" if x > 0 else "-infinity")
        column = f"an F{w}.{d} column" if w is not None else f"a column of {d} decimals"
        raise TableValueError(f"{what} cannot be written in {column}")
    text = _round_half_up(x, d)
    if text.startswith("-") and float(text) == 0.0:
        text = text[1:]  # no sign on a value that rounds to zero
    if style == "legacy":
        if text.startswith("0."):
            text = text[1:]
        elif text.startswith("-0."):
            text = "-" + text[2:]
    elif style != "modern":
        raise ValueError(f"unknown number style {style!r}")
    if d == 0:
        text = text + "."
    return text if w is None else text.rjust(w)


def significant(value: float, digits: int, style: str = "modern") -> str:
    """``value`` to ``digits`` significant digits: fixed notation (F editing, rounded half away
    from zero: 3.71000, 5.61249 for 6 digits) for magnitudes from 1e-4 up to 10^digits, ES
    notation (``3.53553E-07``) outside.  Zero is ``0.00000``.  Raises TableValueError for NaN/inf."""
    x = float(value)
    if not math.isfinite(x):
        raise TableValueError(f"non-finite value {x!r} cannot be written to {digits} significant digits")
    if x == 0.0:
        return fortran_f(0.0, None, max(1, digits - 1), style)
    e = math.floor(math.log10(abs(x)))
    if float(_round_half_up(abs(x), max(0, digits - 1 - e))) >= 10.0 ** (e + 1):
        e += 1                        # rounding carried into the next decade (9.999996 -> 10.0000)
    if -4 <= e < digits:
        return fortran_f(x, None, max(1, digits - 1 - e), style)
    return f"{x:.{digits - 1}E}"


def fortran_i(value: int, w: int | None) -> str:
    """Fortran ``Iw`` editing; may exceed ``w`` (callers widen, never ``***``)."""
    text = str(int(value))
    return text if w is None else text.rjust(w)


@dataclass
class Column:
    """One table column: header text, edit (``f``/``i``/``s``, or ``g``: ``decimals``
    significant digits, see :func:`significant`), field width, decimals.

    ``sep`` is the number of blanks written before the field (the ``nx`` of a format).
    """

    header: str
    kind: str = "f"
    width: int = 10
    decimals: int = 4
    sep: int = 2
    style: str = "modern"
    widened: bool = field(default=False, init=False)

    def cell(self, value: Cell) -> str:
        """Format one value without padding to the width."""
        if value is None:
            return ""
        if isinstance(value, str):
            return value
        if self.kind == "f":
            return fortran_f(float(value), None, self.decimals, self.style)
        if self.kind == "i":
            return fortran_i(int(value), None)
        if self.kind == "g":
            return significant(float(value), self.decimals, self.style)
        return str(value)


def render_table(columns: Sequence[Column], rows: Iterable[Sequence[Cell]],
                 trailers: Sequence[str] | None = None, header: bool = True) -> list[str]:
    """Render rows into fixed-format lines.

    Each row holds one value per column (a number, a preformatted string, or
    ``None`` for a blank cell).  ``trailers[k]`` (optional) is free text appended
    to row k, e.g. a status in words.  Columns whose values do not fit are
    widened for every row (the column stays aligned) and flagged ``widened``.
    """
    rows = [list(r) for r in rows]
    cells = [[col.cell(v) for col, v in zip(columns, row)] for row in rows]
    widths = []
    for j, col in enumerate(columns):
        need = max([len(r[j]) for r in cells] + [len(col.header) if header else 0, 0])
        if need > col.width:
            col.widened = True
        widths.append(max(col.width, need))
    lines = []
    if header:
        lines.append("".join(" " * c.sep + c.header.rjust(w) for c, w in zip(columns, widths)).rstrip())
    for k, r in enumerate(cells):
        line = "".join(" " * c.sep + v.rjust(w) for c, v, w in zip(columns, r, widths))
        if trailers is not None and trailers[k]:
            line += "   " + trailers[k]
        lines.append(line.rstrip())
    return lines


def fixed_cells(values: Any, decimals: int, style: str = "modern") -> np.ndarray:
    """Fortran ``F`` editing at minimal width of a whole array in one call: element for element
    the text :func:`fortran_f` ``(v, None, decimals, style)`` gives (what a table of many rows
    needs; ``fortran_f`` one value at a time cost most of a large sweep's ``.out``).

    Each value is scaled by 10**decimals and rounded half away from zero as an integer; where the
    scaled double lies within one unit in the last place of a half (a tie, or a product that
    rounding may have moved across one), or beyond 2**50, the value goes through
    :func:`fortran_f` itself, so the text is the exactly rounded one everywhere.

    Parameters
    ----------
    values : array_like of float
        Finite numbers (any shape; flattened).
    decimals : int
        Digits after the decimal point (``d`` of ``Fw.d``).
    style : {'modern', 'legacy'}
        As for :func:`fortran_f`.

    Returns
    -------
    numpy.ndarray of str
        One text per value, without padding.

    Raises
    ------
    TableValueError
        For a NaN or an infinity.
    """
    import numpy as np
    x = np.asarray(values, dtype=np.float64).ravel()
    bad = ~np.isfinite(x)
    if bad.any():
        fortran_f(float(x[bad][0]), None, decimals, style)   # raises, in words
    if style not in ("modern", "legacy"):
        raise ValueError(f"unknown number style {style!r}")
    if not 0 <= decimals <= 15:   # 10**decimals and the scaled integers exact in int64
        return np.array([fortran_f(v, None, decimals, style) for v in x.tolist()], dtype=str)
    with np.errstate(over="ignore", invalid="ignore"):   # beyond 2**50: the slow path's
        a = np.abs(x) * 10.0 ** decimals
        whole = np.floor(a)
        frac = a - whole                             # exact below 2**52
        slow = ~(a < 2.0 ** 50) | (np.abs(frac - 0.5) <= np.spacing(a))
    n = np.where(slow, 0.0, whole + (frac > 0.5)).astype(np.int64)
    text = _point_digits(n, decimals, style == "legacy")
    neg = (x < 0) & (n > 0)   # no sign on a value that rounds to zero
    if neg.any():
        text = np.where(neg, np.strings.add(b"-", text), text)
    text = _ascii_text(text)
    if slow.any():
        text = text.astype(object)
        for i in np.flatnonzero(slow).tolist():
            text[i] = fortran_f(float(x[i]), None, decimals, style)
        text = text.astype(str)
    return text


def _ascii_text(b: np.ndarray) -> np.ndarray:
    """``b.astype(str)`` for an array of ASCII bytes (digits, point, sign), widening each byte
    to its code point in one cast (numpy's decoding goes string by string)."""
    import numpy as np
    k = b.dtype.itemsize
    if not k or not b.size:
        return b.astype(str)
    return np.ascontiguousarray(b).view(np.uint8).astype(np.uint32).view(f"<U{k}").reshape(b.shape)


def _point_digits(n: np.ndarray, decimals: int, legacy: bool) -> np.ndarray:
    """Decimal texts (bytes) of the integers ``n`` >= 0 with a point ``decimals`` digits from the
    right: digit columns of a byte matrix (one integer division per column), no per-value call."""
    import numpy as np
    width = max(decimals + 1, len(str(int(n.max()))) if n.size else 1)
    powers = 10 ** np.arange(width - 1, -1, -1, dtype=np.int64)
    m = np.empty((n.size, width + 1), dtype=np.uint8)
    point = width - decimals              # the point's column in m
    digits = (n[:, None] // powers) % 10 + ord("0")
    m[:, :point] = digits[:, :point]
    m[:, point] = ord(".")
    m[:, point + 1:] = digits[:, point:]
    # blanks before the first digit (the one before the point always stays: 0.5, 0.; legacy .5)
    lead = n[:, None] < powers[:point - 1]
    m[:, :point - 1][lead] = ord(" ")
    if legacy and decimals:
        m[n < powers[point - 1], point - 1] = ord(" ")
    return np.strings.lstrip(m.view(f"S{width + 1}").ravel())


def render_block(columns: Sequence[Column], cells: Sequence[Any], widths: Sequence[int]) -> list[str]:
    """The table lines of a block of rows given column by column: ``cells[j]`` holds column j's
    texts (an array or list of str, one per row), each right-justified to ``widths[j]`` after
    its column's ``sep`` blanks, trailing blanks removed -- the lines :func:`render_table` writes
    for the same cells and widths, built as one character matrix (each column copied in at once).

    Parameters
    ----------
    columns : sequence of Column
        The table's columns (their ``sep``).
    cells : sequence of array_like of str
        Per column, the block's cell texts (equal lengths).
    widths : sequence of int
        Per column, the field width (at least each of its cells' lengths: a longer cell would be cut).

    Returns
    -------
    list of str
        One line per row.
    """
    import numpy as np
    if not cells or not len(cells[0]):   # (numpy's rjust fails on an empty array)
        return []
    total = sum(c.sep + w for c, w in zip(columns, widths))
    block = np.full((len(cells[0]), total), ord(" "), dtype=np.uint32)   # UCS-4 code points, one row a line
    at = 0
    for c, v, w in zip(columns, cells, widths):
        at += c.sep
        if w:
            field_ = np.strings.rjust(np.asarray(v, dtype=str), w).astype(f"<U{w}")
            block[:, at:at + w] = field_.view(np.uint32).reshape(-1, w)
        at += w
    return np.strings.rstrip(block.view(f"<U{total}").ravel()).tolist() if total else [""] * len(block)


#: the ASCII codes str.rstrip (and numpy's) strips: blank, tab, line feeds, form feeds, the separators
_ASCII_SPACE = tuple(c for c in range(128) if chr(c).isspace())


def render_text(columns: Sequence[Column], cells: Sequence[Any], widths: Sequence[int]) -> str:
    """The lines :func:`render_block` gives, each followed by a newline, as one text: where every
    cell is ASCII and no line ends in a blank (a table's usual block), laid out as one byte
    matrix with the newlines in its last column and decoded once (no string per line); else
    :func:`render_block`'s lines joined.

    Parameters
    ----------
    columns : sequence of Column
        The table's columns (their ``sep``).
    cells : sequence of array_like of str
        Per column, the block's cell texts (equal lengths).
    widths : sequence of int
        Per column, the field width (at least each of its cells' lengths).

    Returns
    -------
    str
        ``"".join(line + "\\n" for line in render_block(columns, cells, widths))``.
    """
    import numpy as np
    if not cells or not len(cells[0]):
        return ""
    total = sum(c.sep + w for c, w in zip(columns, widths))
    block = np.empty((len(cells[0]), total + 1), dtype=np.uint8)
    at, ascii_ = 0, total > 0
    for c, v, w in zip(columns, cells, widths):
        block[:, at:at + c.sep] = ord(" ")
        at += c.sep
        if w:   # (a longer cell would be cut, as in render_block)
            codes = np.strings.rjust(np.asarray(v, dtype=str), w).astype(f"<U{w}", copy=False).view(np.uint32)
            if codes.max() > 127:
                ascii_ = False
                break
            block[:, at:at + w] = codes.reshape(-1, w)
        at += w
    if not ascii_ or np.isin(block[:, total - 1], _ASCII_SPACE).any():   # lines to strip, or not ASCII
        return "".join(line + "\n" for line in render_block(columns, cells, widths))
    block[:, total] = ord("\n")
    return block.tobytes().decode("ascii")
