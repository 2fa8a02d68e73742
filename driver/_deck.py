"""The one deck reader: Fortran namelist decks with validation.

A deck is a text file of namelist groups with ``!`` comments::

    &fourbar            ! four-bar linkage
      fixed_link = 12, crank = 5, coupler = 15, rocker = 9
      omega = 5.0, step_deg = 20
    /

Each study declares its group as a :class:`GroupSpec` (keys with kinds,
defaults, choices and checks); :func:`validate` turns the raw group into
:class:`Params`.  Every problem is a :class:`DeckError` that names the file,
the line and the key.  The four-bar listing's own terminal input (three lines
``p q r s`` / ``omq`` / ``incr``) is accepted as a legacy deck.

Values are read as Fortran list-directed input reads them (the pre-scan's
:func:`_list_values`, compared with gfortran's own namelist reader by
tests/test_fortran_reader.py); f90nml reads the same text as a second reader, and a deck on
which the two disagree is refused.  Null values, and the separators Fortran readers disagree
on, are refused: a deck states every value.
"""
from __future__ import annotations

import contextlib
import io
import math
import os
import re
import stat
import unicodedata
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import f90nml

from driver._groupspec import DeckError, GroupSpec, Key, Params
from driver._names import name_problem, shown
from driver._study import group_spec

__all__ = ["DeckError", "Key", "GroupSpec", "Params", "RawGroup", "Deck", "read_deck", "validate"]


#: magnitudes no deck value of any study needs; larger ones only overflow the kernels
MAX_FLOAT, MAX_INT = 1e15, 10**9


@dataclass
class RawGroup:
    """A group as read: values from f90nml, first line of each key, line of the group."""

    name: str
    values: dict[str, Any]
    lines: dict[str, int]
    line: int


@dataclass
class Deck:
    """A parsed deck: its path and raw groups in file order."""

    path: Path
    groups: dict[str, RawGroup]
    legacy: bool = False


# --------------------------------------------------------------------------- reading the file

#: a deck larger than this is refused without reading it all (the largest shipped deck is < 4 KiB)
MAX_DECK_BYTES = 1 << 20
#: a repeat count ``n*value`` and the values of one key are capped before f90nml expands them
MAX_VALUES = 10_000


def _read_text(path: Path) -> str:
    """The deck's text: a regular UTF-8 file of at most MAX_DECK_BYTES, BOM dropped, newlines unified."""
    try:
        st = os.stat(path)
        if stat.S_ISDIR(st.st_mode):
            raise DeckError(path, None, None, "is a folder, not a deck file")
        if not stat.S_ISREG(st.st_mode):
            raise DeckError(path, None, None, "is not a regular file (a FIFO, socket or device); "
                            "decks are read from ordinary files only")
        if st.st_size > MAX_DECK_BYTES:
            raise DeckError(path, None, None, f"deck is {st.st_size} bytes; decks larger than "
                            f"{MAX_DECK_BYTES} bytes are refused (a deck is a few lines of text)")
        with open(path, "rb") as fh:
            data = fh.read(MAX_DECK_BYTES + 1)
    except OSError as exc:
        raise DeckError(path, None, None, f"cannot read deck: {exc.strerror or exc}") from None
    if len(data) > MAX_DECK_BYTES:   # grew while we looked
        raise DeckError(path, None, None, f"deck is larger than {MAX_DECK_BYTES} bytes")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data[:exc.start].count(b"\n") + 1
        col = exc.start - (data.rfind(b"\n", 0, exc.start) + 1) + 1
        raise DeckError(path, line, None, f"column {col}: byte 0x{data[exc.start]:02x} is not UTF-8 text "
                        "(is this a binary file?)") from None


def _normalise(text: str) -> str:
    """Drop a UTF-8 byte-order mark; CRLF and lone CR line ends become LF."""
    if text.startswith("\ufeff"):
        text = text[1:]
    return text.replace("\r\n", "\n").replace("\r", "\n")


# --------------------------------------------------------------------------- pre-scan

@dataclass
class _Item:
    """One ``key = value`` of a group as found by the pre-scan."""

    group: str
    key: str
    line: int
    text: str          # the value text (strings kept), possibly over several lines
    count: int = 0     # number of values after repeat-count expansion
    value: Any = None  # the value(s) read: one value, or a list of them
    #: the value text line by line: (line, text, whether a '!' comment follows it on its line)
    segments: list[tuple[int, str, bool]] = field(default_factory=list)

    def add(self, line: int, text: str, comment: bool) -> None:
        self.text += text + " "
        self.segments.append((line, text, comment))


def _code_mask(path: Path, n: int, line: str) -> tuple[str, str]:
    """(code, raw code): the line without its comment, and with strings blanked to '0's.

    Checks on the way that no string is left open and that the code outside strings and
    comments is printable ASCII (a Unicode minus pasted from a PDF is an error, not dropped).
    """
    quote, start = None, 0
    code = []
    for i, ch in enumerate(line):
        if quote:
            code.append("0" if ch != quote else ch)
            if ch == quote:
                quote = None
            continue
        if ch in "'\"":
            quote, start = ch, i
            code.append(ch)
            continue
        if ch == "!":
            line = line[:i]
            break
        if not (" " <= ch <= "~" or ch == "\t"):
            name = unicodedata.name(ch, "") if ch.isprintable() else "a control character"
            hint = " (write an ASCII '-')" if ch in _DASHES else ""
            raise DeckError(path, n, None, f"column {i + 1}: character {ch!r} (U+{ord(ch):04X} "
                            f"{name}) is not allowed outside comments and strings{hint}")
        code.append(ch)
    if quote:
        raise DeckError(path, n, None, f"column {start + 1}: string not closed on this line")
    return "".join(code), line


#: what Fortran list-directed input reads as one value (ASCII only): an integer, a real with an
#: optional E/D exponent, a logical; optionally after a repeat count ``r*`` (r >= 1)
_INTEGER = r"[+-]?[0-9]+"
_REAL = r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eEdD][+-]?[0-9]+)?"
_LOGICAL = r"\.(?:true|false|t|f)\.|true|false|t|f"
_NUMBER_RE = re.compile(rf"(?:{_REAL})", re.ASCII)
_VALUE_RE = re.compile(rf"(?:{_REAL}|{_LOGICAL})", re.ASCII | re.IGNORECASE)
_COUNT_RE = re.compile(r"([0-9]+)\*(.*)", re.ASCII | re.DOTALL)
#: digits a number may have: more is no measurement, and only overflows (a 400-digit integer)
MAX_DIGITS = 40


def is_number(text: str) -> bool:
    """True when ``text`` (surrounding blanks allowed) is a number as Fortran list-directed input
    reads one: ``5``, ``-5.``, ``.5``, ``5.0e-3``, ``5d0``; never ``5_0``, ``5.0_8``, ``4+1``,
    ``0x10``, ``inf``, ``nan`` or digits other than ASCII 0-9."""
    t = text.strip(" \t")
    return bool(_NUMBER_RE.fullmatch(t)) and sum(c.isdigit() for c in t) <= MAX_DIGITS


def _token_end(text: str, i: int) -> int:
    """Where the value token starting at ``text[i]`` ends: at a blank, a comma or the end; a
    quoted string (its doubled-quote escapes, a repeat count glued in front) kept whole."""
    j, n = i, len(text)
    while j < n and text[j] not in " \t\n,'\"":
        j += 1
    if j < n and text[j] in "'\"" and (j == i or text[j - 1] == "*"):
        q = text[j]
        j += 1
        while j < n:
            if text[j] == q:
                if j + 1 < n and text[j + 1] == q:
                    j += 2
                    continue
                break
            j += 1
        j += 1
    return j


@dataclass
class _Value:
    """One value of a key's list as Fortran list-directed input reads it."""

    text: str          # as written, with its repeat count
    line: int


#: how to write a list so that it means the same to every Fortran reader (in null-value messages)
_NULL_HELP = "a deck states every value (a null value would leave the key's default in a Fortran program)"


def _null(path: Path, it: _Item, line: int, what: str) -> DeckError:
    return DeckError(path, line, it.key, f"{what}: Fortran reads a null value (an empty entry) there; {_NULL_HELP}")


def _list_values(path: Path, it: _Item) -> list[_Value]:
    """The values of ``it``'s list, read as Fortran list-directed input reads them.

    Values are separated by a comma (blanks around it allowed), by blanks, or by a line end.
    A null value is refused: ``r*`` followed by a blank, a comma or a line end (``2* 5`` is two
    null values and then 5, not ``2*5``), a comma before the first value, two commas with only
    blanks between, an empty list.  So are the separators Fortran readers disagree on, where
    gfortran reads a null value and the Fortran standard reads none: a ``!`` comment right
    after a comma, or after the ``=``, with the list going on below, and a line that starts
    with a comma after a value.  A comma followed by a comment at the end of a list (before the
    next key or the ``/``) is no value to anyone and is fine.
    """
    out: list[_Value] = []
    last = "start"                        # what came last: 'start' (the '='), 'value' or 'comma'
    pending: tuple[int, str] | None = None   # a separator read differently, if a value follows it
    for index, (line, text, comment) in enumerate(it.segments):
        first = True                      # no token yet on this line
        i, n = 0, len(text)
        while i < n:
            ch = text[i]
            if ch in " \t":
                i += 1
                continue
            if ch == ",":
                if last == "start":
                    raise _null(path, it, line, "a comma before the first value")
                if last == "comma":
                    raise _null(path, it, line, "two commas with nothing between")
                if first and index > 0:
                    pending = (line, "a line that starts with a comma after a value, with the list going on: "
                                     "gfortran reads a null value before the comma and the Fortran standard "
                                     "reads none; end the line before with the comma instead")
                last, first = "comma", False
                i += 1
                continue
            if pending is not None:
                raise DeckError(path, pending[0], it.key, pending[1])
            j = _token_end(text, i)
            tok = text[i:j]
            m = _COUNT_RE.fullmatch(tok)
            if m and not m.group(2):
                nxt = text[j:].lstrip(" \t")
                follows = f" and then {nxt.split()[0].rstrip(',')!r}" if nxt and nxt[0] != "," else ""
                raise _null(path, it, line, f"{tok!r} followed by a {'comma' if nxt[:1] == ',' else 'blank or a line end'} "
                            f"is {m.group(1)} null value(s){follows}, not a repeated value (write {tok}VALUE without "
                            "a blank)")
            out.append(_Value(tok, line))
            last, first = "value", False
            i = j
        # the comma (or the '=') on this very line: a comment on a line of its own is no separator
        if comment and ((last == "comma" and not first) or (last == "start" and index == 0)):
            where = ("the '=', with the values on the lines below: gfortran reads a null value first and the "
                     "Fortran standard reads none; put the first value on the line of the key"
                     if last == "start" else
                     "a comma, with the list going on below: gfortran reads a null value there and the Fortran "
                     "standard reads none; drop the comma before the comment")
            pending = (line, f"a comment right after {where} (a comment after a value, without a comma, means "
                             "the same to every reader)")
    if not out:
        raise _null(path, it, it.line, "no value after the '=' (an empty list)")
    return out


def _check_values(path: Path, it: _Item) -> list[_Value]:
    """Every value of ``it`` is a number, a logical or a quoted string as Fortran list-directed
    input reads them, with at most one repeat count, and no value is null (:func:`_list_values`);
    anything else is a DeckError naming the token (f90nml would read ``5.0_8`` as 5.08, ``4+1``
    as 40, ``2*1*4.0`` as 1, 1, 4 and ``2* 5`` as 5, 5).  Returns the values."""
    values = _list_values(path, it)
    for v in values:
        tok = v.text
        value = tok
        m = _COUNT_RE.fullmatch(tok)
        if m:
            if int(m.group(1)[:7]) == 0:
                raise DeckError(path, v.line, it.key, f"repeat count 0 in {tok[:40]!r}: a count is at least 1")
            value = m.group(2)
        if value[:1] in "'\"":
            if len(value) < 2 or value[-1] != value[0]:
                raise DeckError(path, v.line, it.key, f"text after a quoted string in {tok[:40]!r}")
            continue
        if _VALUE_RE.fullmatch(value):
            digits = sum(c.isdigit() for c in value)
            if digits > MAX_DIGITS:
                raise DeckError(path, v.line, it.key, f"number with {digits} digits: not a value any study "
                                f"takes (at most {MAX_DIGITS} digits)")
            continue
        raise DeckError(path, v.line, it.key, _why_not(tok, value))
    return values


class QuotedText(str):
    """A value written in quotes in a deck: text, never a number (Fortran reads no number from
    ``'5'``), whatever it spells; :func:`validate` gives string keys a plain ``str``."""

    __slots__ = ()


def _value_of(tok: str) -> list[Any]:
    """The values a checked token stands for (:func:`_check_values`): its repeat count expanded;
    a quoted string as :class:`QuotedText` without its quotes, a logical as bool, an integer as
    int (``-0`` as the float -0.0: a real read from it keeps its sign), any other number as float."""
    count, value = 1, tok
    m = _COUNT_RE.fullmatch(tok)
    if m:
        count, value = int(m.group(1)), m.group(2)
    v: Any
    if value[:1] in "'\"":
        q = value[0]
        v = QuotedText(value[1:-1].replace(q + q, q))
    elif re.fullmatch(_LOGICAL, value, re.IGNORECASE | re.ASCII):
        v = value.lstrip(".")[:1].lower() == "t"
    elif re.fullmatch(_INTEGER, value, re.ASCII):
        v = int(value)
        if v == 0 and value.startswith("-"):
            v = -0.0
    else:
        v = float(value.replace("d", "e").replace("D", "e"))
    return [v] * count


def _why_not(tok: str, value: str) -> str:
    """Why ``value`` (token ``tok``) is no value of a deck."""
    shown = repr(tok[:40])
    if "*" in value and _COUNT_RE.fullmatch(value):
        return f"not a number: {shown}: a repeat count applied to a repeat count"
    if "_" in value:
        return f"not a number: {shown}: a kind suffix or '_' inside a number (write the number itself: 5.0, 15)"
    if ";" in value:
        return (f"not a number: {shown}: a semicolon separates values only in DECIMAL='COMMA' input; separate "
                "values with commas or blanks")
    if re.fullmatch(r"[+-]?[0-9.]+[eEdD]?[0-9]*[+-][0-9.]+", value):
        return (f"not a number: {shown}: arithmetic is not read in a deck (write the number itself; '4+1' "
                "would be read as 4e+1)")
    if re.fullmatch(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)[qQ][+-]?[0-9]+", value):
        return f"not a number: {shown}: a Q exponent is a gfortran extension; write E or D (1.0e3, 1.0d3)"
    if re.fullmatch(r"[+-]?(?:inf|infinity|nan(?:\(.*\))?)", value, re.IGNORECASE):
        return f"not a number: {shown}: infinity and NaN are not deck values (every value is a finite number)"
    if value[:1] == "(":
        return f"not a number: {shown}: complex numbers and parentheses are not read"
    if re.fullmatch(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)[eEdD][+-]?", value):
        return f"not a number: {shown}: an exponent without digits"
    if re.fullmatch(r"\.?[tTfF]\w*\.?", value):
        return (f"not a value: {shown}: Fortran would read a logical from its first letter alone (.t, .tomato, "
                "tx); write .true. or .false. (or quote text)")
    if re.fullmatch(r"[A-Za-z_]\w*", value):
        return (f"not a number: {shown}: not a number, a logical (.true./.false.) or a 'quoted string' (text is "
                "written in quotes in a deck)")
    return (f"not a number: {shown}: not a number as Fortran reads one (digits, '.', an E or D exponent), a "
            "logical or a 'quoted string'")


_DASHES = "\u2212\u2010\u2011\u2012\u2013\u2014\ufe63\uff0d"
_NAME_EQ = re.compile(r"(?<![\w.%])([A-Za-z_]\w*)\s*(\([^)]*\)|%\s*\w+)?\s*=")
_REPEAT = re.compile(r"(?<![\w.])(\d+)\s*\*")


def _count_values(text: str) -> int:
    """Number of values in a value text (strings already blanked), repeat counts expanded."""
    n = 0
    for tok in re.split(r"[\s,]+", text.strip()):
        if not tok:
            continue
        m = re.match(r"(\d+)\s*\*", tok)
        n += (int(m.group(1)) if len(m.group(1)) <= 6 else 10**6) if m else 1
    return max(n, 1)


#: keys one group may have (the largest group has under 60): more is refused in the pre-scan
MAX_KEYS_PER_GROUP = 200
_KNOWN: dict[str, frozenset[str] | None] = {}


def _known_keys(group: str) -> frozenset[str] | None:
    """The keys of group ``group`` (a study's or &sweep, &optimize, &synthesis), or None when the
    registry knows no such group (the runner then refuses the group itself)."""
    if group not in _KNOWN:
        spec = group_spec(group)
        _KNOWN[group] = frozenset(spec.keys) if spec is not None else None
    return _KNOWN[group]


def _prescan(path: Path, text: str) -> tuple[list[tuple[str, int]], list[_Item]]:
    """Check the deck's layout line by line before f90nml sees it.

    Returns the groups (name, line) in order and every key item.  Refused (DeckError with
    line and key): non-ASCII outside comments and strings, text outside a group, text after
    a group's closing '/', a group not closed, array subscripts and derived-type components
    on keys, a key given twice, repeat counts and lists beyond MAX_VALUES values.
    """
    groups: list[tuple[str, int]] = []
    items: list[_Item] = []
    current: str | None = None
    group_line = 0
    seen: dict[str, dict[str, int]] = {}
    item: _Item | None = None
    slash_key: str | None = None   # the key whose value a '/' cut (360/7)
    for n, raw_line in enumerate(text.split("\n"), start=1):
        try:
            code, raw = _code_mask(path, n, raw_line)
        except DeckError as exc:   # name the key whose value holds the character
            column = re.match(r"column (\d+)", exc.message)
            prefix = raw_line[:int(column.group(1)) - 1] if column else ""
            here = list(_NAME_EQ.finditer(prefix))
            key = here[-1].group(1).lower() if here else (item.key if item is not None and current else None)
            raise DeckError(path, n, key, exc.message) from None
        pos, after_slash = 0, None
        while pos < len(code):
            if current is None:
                m = re.compile(r"\s*").match(code, pos)
                assert m is not None   # r"\s*" matches everywhere
                pos = m.end()
                if pos >= len(code):
                    break
                g = re.compile(r"[&$]\s*([A-Za-z_]\w*)").match(code, pos)
                if g and g.group(1).lower() != "end":
                    current, group_line, item = g.group(1).lower(), n, None
                    groups.append((current, n))
                    seen.setdefault(current, {})
                    pos = g.end()
                    after_slash = None
                    continue
                rest = raw[pos:].strip()
                if after_slash is not None:
                    raise DeckError(path, n, slash_key, f"column {pos + 1}: text after the closing '/' of "
                                    f"&{after_slash}: {rest!r} (a '/' ends the group, also inside a value "
                                    "such as 360/7: write the number itself)")
                if code[pos] == "/" or (g and g.group(1).lower() == "end"):
                    raise DeckError(path, n, None, f"column {pos + 1}: '{rest[:4]}' closes no group")
                raise DeckError(path, n, None, f"column {pos + 1}: text outside a namelist group: {rest!r} "
                                "(a group starts with '&name' and ends with '/')")
            # inside a group: up to the closing '/' (or '&end'), or the end of the line
            end = re.compile(r"/|[&$]\s*end\b|[&$]", re.IGNORECASE).search(code, pos)
            stop = end.start() if end else len(code)
            segment = code[pos:stop]
            keys = list(_NAME_EQ.finditer(segment))
            cut = 0
            stray = re.compile(r"=").search(_NAME_EQ.sub(lambda m: " " * len(m.group()), segment))
            if stray:
                raise DeckError(path, n, item.key if item else None,
                                f"column {pos + stray.start() + 1}: '=' without a key name before it")
            for km in keys:
                if item is not None:
                    item.add(n, raw[pos + cut:pos + km.start()], False)
                elif segment[cut:km.start()].strip(" \t,"):
                    raise DeckError(path, n, None, f"column {pos + cut + 1}: value without a key: "
                                    f"{raw[pos + cut:pos + km.start()].strip()!r}")
                key = km.group(1).lower()
                if km.group(2):
                    what = "array subscripts" if km.group(2).startswith("(") else "derived-type components"
                    raise DeckError(path, n, key, f"{what} are not supported ('{km.group(0).rstrip('= ')}'): "
                                    "give the whole list, e.g. key = 1, 2, 4")
                known = _known_keys(current)
                if known is not None and key not in known:
                    raise DeckError(path, n, key, f"unknown key in &{current} (known keys: {', '.join(sorted(known))})")
                if len(seen[current]) >= MAX_KEYS_PER_GROUP:
                    raise DeckError(path, n, key, f"more than {MAX_KEYS_PER_GROUP} keys in &{current}; no group "
                                    "has that many (refused before the namelist reader, whose work grows with "
                                    "the square of a group's keys)")
                if key in seen[current]:
                    raise DeckError(path, n, key, f"given twice in &{current}: on line {seen[current][key]} "
                                    f"and on line {n} (keep one)")
                seen[current][key] = n
                item = _Item(current, key, n, "")
                items.append(item)
                cut = km.end()
            tail = raw[pos + cut:stop]
            if item is not None:
                item.add(n, tail, end is None and len(raw) < len(raw_line))
            elif segment[cut:].strip(" \t,"):
                raise DeckError(path, n, None, f"column {pos + cut + 1}: value without a key: "
                                f"{segment[cut:].strip()!r}")
            if end is None:
                pos = len(code)
                break
            if end.group(0) in "&$" and not end.group(0).lower().endswith("end"):
                nxt = re.compile(r"[&$]\s*(\w*)").match(code, stop)
                raise DeckError(path, n, None, f"group &{current} (line {group_line}) is not closed with '/' "
                                f"before '&{nxt.group(1) if nxt else ''}'")
            slash_key = item.key if item is not None else None
            after_slash, current, item = current, None, None
            pos = end.end()
    if current is not None:
        raise DeckError(path, group_line, None, f"group &{current} is not closed (end it with '/')")
    for it in items:
        tokens = _check_values(path, it)
        blank, _ = _code_mask(path, it.line, it.text)
        big = [m.group(1) for m in _REPEAT.finditer(blank) if len(m.group(1)) > 6 or int(m.group(1)) > MAX_VALUES]
        if big:
            raise DeckError(path, it.line, it.key, f"repeat count {big[0][:20]}* is beyond {MAX_VALUES} values "
                            "(checked before anything is expanded)")
        it.count = _count_values(blank)
        if it.count > MAX_VALUES:
            raise DeckError(path, it.line, it.key, f"{it.count} values; at most {MAX_VALUES} are read per key")
        values = [v for t in tokens for v in _value_of(t.text)]
        it.value = values[0] if len(values) == 1 else values
    return groups, items


# --------------------------------------------------------------------------- parsing

def _strip_comment(line: str) -> str:
    """Remove a trailing ``!`` comment, respecting quoted strings."""
    quote = None
    for i, ch in enumerate(line):
        if quote:
            if ch == quote:
                quote = None
        elif ch in "'\"":
            quote = ch
        elif ch == "!":
            return line[:i]
    return line


def _is_legacy_shape(text: str) -> bool:
    """True when the text has no namelist group marker or assignment outside comments (so it can
    only be a legacy deck, or no deck)."""
    return not any(c in _strip_comment(l) for l in text.splitlines() for c in "&$=")


def _is_legacy(text: str) -> bool:
    """True for the four-bar listing's terminal input: numbers only, no namelist group."""
    lines = [_strip_comment(l).strip() for l in text.splitlines()]
    lines = [l for l in lines if l]
    if not lines or any("&" in l or "$" in l or "=" in l for l in lines):
        return False
    return all(re.fullmatch(r"[-+0-9.eEdD,\s]+", l) for l in lines)


def _read_legacy(path: Path, text: str) -> Deck:
    """``p q r s`` / ``omq`` / ``incr`` (list-directed, one read per line) -> &fourbar."""
    names = [["fixed_link", "crank", "coupler", "rocker"], ["omega"], ["step_deg"]]
    content = [(n, _strip_comment(l).strip()) for n, l in enumerate(text.splitlines(), 1)]
    content = [(n, l) for n, l in content if l]
    if len(content) != 3:
        raise DeckError(path, content[-1][0] if content else None, None,
                        "legacy four-bar deck needs three lines: 'p q r s', 'omq', 'incr' "
                        f"(found {len(content)})")
    values: dict[str, Any] = {"method": "listing"}
    lines: dict[str, int] = {"method": content[0][0]}
    for (n, line), keys in zip(content, names):
        tokens = [t for t in re.split(r"[\s,]+", line) if t]
        if len(tokens) != len(keys):
            raise DeckError(path, n, keys[min(len(tokens), len(keys) - 1)],
                            f"expected {len(keys)} value(s) ({' '.join(keys)}), found {len(tokens)}")
        for key, tok in zip(keys, tokens):
            f = _as_float(tok)
            if f is None:
                raise DeckError(path, n, key, f"not a number: {shown_value(tok)}")
            values[key] = f
            lines[key] = n
    return Deck(path, {"fourbar": RawGroup("fourbar", values, lines, content[0][0])}, legacy=True)


def _plain(value: Any) -> Any:
    """f90nml values -> plain Python (lists with None for skipped entries kept)."""
    if isinstance(value, list):
        return [_plain(v) for v in value]
    return value


def _same(a: Any, b: Any) -> bool:
    """Whether two readings of a value agree: equal numbers (-0.0 and 0 alike), logicals and
    texts, item by item; a value and a list of that one value alike."""
    a = a if isinstance(a, list) else [a]
    b = b if isinstance(b, list) else [b]
    return len(a) == len(b) and all(type(x) is type(y) or (isinstance(x, str) and isinstance(y, str)) or
                                    (isinstance(x, (int, float)) and isinstance(y, (int, float)) and
                                     not isinstance(x, bool) and not isinstance(y, bool))
                                    for x, y in zip(a, b)) and a == b


def _f90nml_reads(text: str) -> tuple[Any, list[str]]:
    """f90nml's parse of ``text`` with its warnings captured (never printed)."""
    with warnings.catch_warnings(record=True) as caught, contextlib.redirect_stdout(io.StringIO()):
        warnings.simplefilter("always")   # and f90nml's debug prints (its state table) go nowhere
        nml = f90nml.reads(text)
    return nml, [str(w.message) for w in caught]


def _locate(path: Path, items: list[_Item], exc: Exception | None) -> DeckError:
    """The deck error for an f90nml failure or misread: the first item that fails alone."""
    for it in items:
        try:
            _, warned = _f90nml_reads(f"&{it.group}\n{it.key} = {it.text}\n/\n")
        except Exception:   # f90nml raises ValueError, AssertionError, IndexError, StopIteration...
            return DeckError(path, it.line, it.key, f"cannot read the value {it.text.strip()[:60]!r} "
                             "(numbers, 'strings' in quotes, .true./.false., lists separated by commas)")
        if warned:
            return DeckError(path, it.line, it.key, f"cannot read the value {it.text.strip()[:60]!r}: "
                             "part of it would be dropped")
    what = "values not assigned to any key" if exc is None else "namelist syntax error"
    return DeckError(path, None, None, what)


def read_deck(path: str | Path, text: str | None = None) -> Deck:
    """Read a deck (Fortran namelist groups) into raw groups, before validation.

    The text is pre-scanned so that everything f90nml would silently misread is a
    :class:`DeckError` with line and key, and repeat counts are capped before f90nml expands
    them.  Nothing in the deck is evaluated; a number is what Fortran list-directed input
    means by one.

    Parameters
    ----------
    path : str or pathlib.Path
        The deck file; with ``text``, the name the text is attributed to in messages.
    text : str, optional
        The deck's text (then ``path`` is not read).

    Returns
    -------
    Deck
        ``path`` and ``groups``: each namelist group by name (``'fourbar'``, ``'sweep'``, ...)
        as raw key/value pairs with the line each key is on; values are validated (units,
        ranges) only when a study runs them.

    Raises
    ------
    DeckError
        An unreadable or malformed deck (what f90nml would misread, a repeat count too large),
        with file, line and key; a file name holding control or bidi characters
        (:mod:`driver._names`).
    """
    path = Path(path)
    why = name_problem(path, "the deck's file name")
    if why:   # printed in every message and naming every output: refused, and shown escaped
        raise DeckError(shown(path), None, None, why)
    if text is None:
        text = _read_text(path)
    text = _normalise(text)
    if _is_legacy_shape(text):   # non-ASCII is an error in legacy decks too (namelist decks: in the pre-scan)
        for n, text_line in enumerate(text.split("\n"), start=1):
            _code_mask(path, n, text_line)
    if _is_legacy(text):
        return _read_legacy(path, text)
    order, items = _prescan(path, text)
    if not order:
        raise DeckError(path, None, None, "no namelist group found (a deck starts a group with '&name')")
    seen: dict[str, int] = {}
    for name, line in order:
        if name in seen:
            raise DeckError(path, line, None, f"group &{name} given twice (first on line {seen[name]})")
        seen[name] = line
    # f90nml reads the same text without its comments (it reads '2!note' as text: f90nml issue
    # 182) as a second reader: the values are the pre-scan's (Fortran's reading, compared with
    # gfortran's own reader in tests/test_fortran_reader.py); where the two disagree the deck is
    # refused rather than one of them believed
    code = "\n".join(_code_mask(path, n, text_line)[1] for n, text_line in enumerate(text.split("\n"), start=1))
    try:
        nml, warned = _f90nml_reads(code)
    except Exception as exc:  # f90nml raises ValueError, StopIteration, IndexError, AssertionError...
        raise _locate(path, items, exc) from None
    if warned:
        raise _locate(path, items, None)
    key_lines: dict[str, dict[str, int]] = {}
    mine: dict[str, dict[str, Any]] = {}
    for it in items:
        key_lines.setdefault(it.group, {})[it.key] = it.line
        mine.setdefault(it.group, {})[it.key] = it.value
    groups: dict[str, RawGroup] = {}
    for name, line in order:
        raw = nml.get(name, {}) or {}
        theirs = {k.lower(): _plain(v) for k, v in raw.items()}
        values = mine.get(name, {})
        if set(theirs) != set(values):   # f90nml read keys the pre-scan did not see
            raise DeckError(path, line, None, f"cannot read &{name}: its keys are "
                            f"{sorted(values)} but the namelist reader found {sorted(theirs)}")
        for key, v in values.items():
            if not _same(v, theirs[key]):
                raise DeckError(path, key_lines[name][key], key, f"cannot read the value: two namelist readers "
                                f"disagree ({shown_value(v)} and {shown_value(theirs[key])})")
        groups[name] = RawGroup(name, values, key_lines.get(name, {}), line)
    return Deck(path, groups)


# --------------------------------------------------------------------------- validation

def _as_float(v: Any) -> float | None:
    """A number as a float; a string only when it spells a Fortran number (:func:`is_number`:
    not '5_0', not fullwidth or Arabic-Indic digits); None otherwise.  A Python int beyond a
    float is returned as inf (refused by the caller as not finite)."""
    if isinstance(v, bool) or v is None:
        return None
    if isinstance(v, int):
        try:
            return float(v)
        except OverflowError:
            return math.inf if v > 0 else -math.inf
    if isinstance(v, float):
        return v
    if isinstance(v, QuotedText):   # '5' in a deck is text, as Fortran reads it
        return None
    if isinstance(v, str):
        if not is_number(v):
            return None
        return float(v.strip(" \t").replace("d", "e").replace("D", "e"))
    return None


def shown_value(v: Any) -> str:
    """A value in a message: its repr, cut to 40 characters (a 400-digit integer is not echoed)."""
    r = repr(v)
    return r if len(r) <= 40 else r[:37] + "..."


def _coerce(kind: str, v: Any) -> tuple[Any, str | None]:
    """Convert a raw value to ``kind``; returns (value, error message)."""
    if kind == "list":
        items = v if isinstance(v, list) else [v]
        if any(x is None for x in items):
            return None, "list has an empty entry"
        if len({str if isinstance(x, str) else (bool if isinstance(x, bool) else float) for x in items}) > 1:
            return None, "list mixes numbers, strings and logicals"
        return items, None
    if kind in ("floats", "ints", "strs"):
        items = v if isinstance(v, list) else [v]
        if any(x is None for x in items):
            return None, "list has an empty entry"
        out = []
        for x in items:
            val, err = _coerce(kind[:-1], x)
            if err:
                return None, err
            out.append(val)
        return out, None
    if v is None:
        return None, "no value given"
    if isinstance(v, list):
        return None, f"expected one value, got a list of {len(v)}"
    if kind in ("float", "int"):
        f = _as_float(v)
        if f is None and isinstance(v, QuotedText) and is_number(v):
            return None, (f"not a number: {shown_value(v)} is in quotes, and a quoted value is text (Fortran "
                          f"reads no number from it); write {v.strip()} without the quotes")
        if f is None:
            return None, f"not a number: {shown_value(v)}"
        if not math.isfinite(f):
            return None, f"not a finite number: {shown_value(v)}"
        if abs(f) > (MAX_FLOAT if kind == "float" else MAX_INT):
            limit = MAX_FLOAT if kind == "float" else MAX_INT
            return None, f"{f:g} is beyond +-{limit:g}, outside what any study here computes"
        if kind == "float":
            return f, None
        if not f.is_integer():
            return None, f"not a whole number: {shown_value(v)}"
        return int(f), None
    if kind == "bool":
        if isinstance(v, bool):
            return v, None
        return None, f"not a logical (.true./.false.): {shown_value(v)}"
    if kind == "str":
        if isinstance(v, str):
            bad = next((ch for ch in v if not ch.isprintable()), None)
            if bad is not None:   # ESC, NUL, line breaks: text from a deck is printed in tables
                return None, (f"text holds the control character U+{ord(bad):04X} "
                              f"({unicodedata.name(bad, 'control')}); text is printable characters only")
            return str(v), None
        return None, f"not a quoted string: {shown_value(v)} (text is written in quotes in a deck)"
    raise AssertionError(kind)


def validate(raw: RawGroup, spec: GroupSpec, path: str | Path) -> Params:
    """Check a raw group against its spec: unknown keys, kinds, requirements, choices, checks."""
    path = Path(path)
    values: dict[str, Any] = {}
    for key, v in raw.values.items():
        line = raw.lines.get(key, raw.line)
        if key not in spec.keys:
            known = ", ".join(sorted(spec.keys))
            raise DeckError(path, line, key, f"unknown key in &{spec.name} (known keys: {known})")
        k = spec.keys[key]
        val, err = _coerce(k.kind, v)
        if err:
            raise DeckError(path, line, key, err)
        if k.choices is not None:
            norm = [x.lower() if isinstance(x, str) else x for x in (val if isinstance(val, list) else [val])]
            for x in norm:
                if x not in k.choices:
                    raise DeckError(path, line, key,
                                    f"{shown_value(x)} is not one of {', '.join(map(repr, k.choices))}")
            val = norm if isinstance(val, list) else norm[0]
        if k.check is not None:
            try:
                msg = k.check(val)
            except (ArithmeticError, ValueError) as exc:   # a check overflowing on an extreme value
                msg = f"value out of the range this key can take ({exc.__class__.__name__}: {exc})"
            if msg:
                raise DeckError(path, line, key, msg)
        values[key] = val
    given = set(values)
    for key, k in spec.keys.items():
        if key not in values:
            if k.required:
                raise DeckError(path, raw.line, key, f"missing in &{spec.name} (required{', ' + k.units if k.units else ''})")
            values[key] = k.default
    params = Params(spec.name, path, values, raw.lines, raw.line, given)
    if spec.check is not None:
        try:
            spec.check(params)
        except (ArithmeticError, ValueError) as exc:   # a cross-key check overflowing on extreme values
            if isinstance(exc, DeckError):
                raise
            given_keys = ", ".join(sorted(given)) or "none"
            raise DeckError(path, raw.line, None, f"the values of &{spec.name} are out of the range its checks "
                            f"can compute ({exc}); look for extreme values among: {given_keys}") from None
    return params


# --------------------------------------------------------------------------- common checks

def positive(v: Any) -> str | None:
    """Key check: every value > 0."""
    vals = v if isinstance(v, list) else [v]
    bad = [x for x in vals if not x > 0]
    return f"must be positive (got {bad[0]})" if bad else None


def non_negative(v: Any) -> str | None:
    """Key check: every value >= 0."""
    vals = v if isinstance(v, list) else [v]
    bad = [x for x in vals if x < 0]
    return f"must not be negative (got {bad[0]})" if bad else None


def non_empty(v: Any) -> str | None:
    """Key check: a list with at least one entry."""
    return "must list at least one value" if isinstance(v, list) and not v else None
