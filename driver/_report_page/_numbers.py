"""Numbers on the page as the run's own tables print them.

A headline figure or a tidy column is printed with the decimals its fixed-format table (the
``.out`` text) prints it with: the value is looked up among the numbers of that text, and the
printed number it rounds to with the most decimals gives the decimals (``mu_min_deg`` 17.8477...
is printed ``17.85`` in the .out, so the page says 17.85).  A value the text does not print is
given six significant digits of its column (a tidy column) or of the largest value of its unit
(the summary's N m values together), so round-off reads as zero: a balanced linkage's mean input
torque of -4.4e-16 N m is 0.0000, not -4.40635e-16.  Zero is never printed with a minus sign.
"""
from __future__ import annotations

import bisect
import math
import re
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

import numpy as np

__all__ = ["Printed", "column_decimals", "format_number", "summary_texts"]

_NUMBER = re.compile(r"(?<![\w.])[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?(?![\w.])")
#: significant digits of a value the text does not print
SIGNIFICANT = 6


class Printed:
    """The numbers a fixed-format text prints, with their decimals, for looking values up."""

    def __init__(self, text: str) -> None:
        pairs = []
        for m in _NUMBER.finditer(text or ""):
            token = m.group(0)
            if "e" in token.lower():
                continue   # an exponent says its precision in significant digits, not decimals
            _, _, frac = token.partition(".")
            try:
                pairs.append((float(token), len(frac), len(token.strip("+-").replace(".", "").lstrip("0"))))
            except ValueError:   # pragma: no cover - the pattern only takes numbers
                continue
        pairs.sort()
        self._values = [p[0] for p in pairs]
        self._info = [(p[1], p[2]) for p in pairs]

    def decimals(self, value: float) -> int | None:
        """The decimals of the printed number ``value`` rounds to (most decimals when several
        do); None when the text prints no such number.  A printed number with decimals must
        carry at least three significant digits, or print ``value`` as zero with at least two
        decimals, to count; an integer counts only for an integral value (a lone '7' in a text
        says nothing about a value of 7.19)."""
        if not math.isfinite(value):
            return None
        lo = bisect.bisect_left(self._values, value - 0.5)
        hi = bisect.bisect_right(self._values, value + 0.5)
        best = None
        for k in range(lo, hi):
            printed, (dec, sig) = self._values[k], self._info[k]
            if dec == 0 and not float(value).is_integer():
                continue   # an integer in the text (a count, a step) says nothing of a fraction
            if abs(printed - value) >= 0.5 * 10.0 ** -dec * (1 - 1e-9) and printed != value:
                continue   # a tie (359.5 printed 360) is no evidence either
            if not (dec == 0 or sig >= 3 or (printed == 0.0 and dec >= 2)):
                continue
            if best is None or dec > best:
                best = dec
        return best


def _plain(value: float, decimals: int) -> str:
    """``value`` with ``decimals`` decimals, never '-0' (a negative zero prints as zero)."""
    text = f"{value:.{decimals}f}"
    return text[1:] if text.startswith("-") and float(text) == 0.0 else text


def _significant(value: float, scale: float) -> str:
    """``value`` to :data:`SIGNIFICANT` significant digits of ``scale`` (its column's or unit's
    largest magnitude): round-off below that is zero."""
    if not math.isfinite(value):
        return "\u2014"
    if value == 0.0 or scale <= 0.0 or not math.isfinite(scale):
        return "0" if value == 0.0 else f"{value:.{SIGNIFICANT}g}"
    decimals = max(0, SIGNIFICANT - 1 - math.floor(math.log10(scale)))
    if decimals > 12:   # a column of tiny numbers: significant digits of each
        return f"{value:.{SIGNIFICANT}g}"
    return _plain(value, decimals)


def format_number(value: Any, decimals: int | None = None, scale: float | None = None) -> str:
    """A value as the page prints it: '—' for a missing or non-finite number, text as it is,
    an integer as an integer, a float with ``decimals`` decimals (the .out's) or to six
    significant digits of ``scale``."""
    if value is None:
        return "\u2014"
    if isinstance(value, (bool, np.bool_)):
        return "yes" if value else "no"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        v = float(value)
        if not math.isfinite(v):
            return "\u2014"
        if decimals is not None:
            return _plain(v, decimals)
        return _significant(v, abs(v) if scale is None else scale)
    return str(value)


def summary_texts(summary: Mapping[str, Any], printed: Printed, unit_of: Mapping[str, str]) -> dict[str, str]:
    """Each headline figure of ``summary`` as the page prints it: the .out's decimals where the
    .out prints it, else six significant digits of the largest value of its unit (``unit_of``:
    name -> unit; the values of one unit share a scale, so round-off among them reads zero)."""
    scales: dict[str, float] = {}
    for name, v in summary.items():
        if isinstance(v, (float, np.floating)) and math.isfinite(float(v)):
            u = unit_of.get(name, "")
            scales[u] = max(scales.get(u, 0.0), abs(float(v)))
    out = {}
    for name, v in summary.items():
        if isinstance(v, (float, np.floating)) and math.isfinite(float(v)):
            out[name] = format_number(v, printed.decimals(float(v)), scales.get(unit_of.get(name, ""), 0.0))
        else:
            out[name] = format_number(v)
    return out


def column_decimals(values: Sequence[Any] | Iterable[Any], printed: Printed, sample: int = 40) -> int | None:
    """The decimals a numeric column is printed with in the text: the most decimals any of its
    first ``sample`` non-zero values is printed with; None when the text prints none of them."""
    found: list[int] = []
    for v in values:
        if len(found) >= sample:
            break
        try:
            f = float(v)
        except (TypeError, ValueError):
            continue
        if not math.isfinite(f) or f == 0.0:
            continue
        d = printed.decimals(f)
        if d is not None:
            found.append(d)
    return max(found) if found else None
