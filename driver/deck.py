"""The one deck reader: Fortran namelist decks (f90nml) with validation.

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
"""
from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Iterator

import f90nml

__all__ = ["DeckError", "Key", "GroupSpec", "Params", "RawGroup", "Deck", "read_deck", "validate"]

KINDS = ("float", "int", "str", "bool", "floats", "ints", "strs", "list")
#: magnitudes no deck value of any study needs; larger ones only overflow the kernels
MAX_FLOAT, MAX_INT = 1e15, 10**9


class DeckError(ValueError):
    """Bad input: names the deck, the line and the key (exit status 2).

    Attributes ``path``, ``line`` (None when unknown) and ``key`` (None for the whole group)
    locate the problem; ``message`` says what it is.
    """

    def __init__(self, path: str | Path, line: int | None, key: str | None, message: str):
        self.path, self.line, self.key, self.message = str(path), line, key, message
        super().__init__(str(self))

    def __str__(self) -> str:
        where = f"{self.path}:{self.line}" if self.line else self.path
        what = f"key '{self.key}': " if self.key else ""
        return f"{where}: {what}{self.message}"


@dataclass(frozen=True)
class Key:
    """Declaration of one deck key.

    kind      one of float, int, str, bool (scalars) or floats, ints, strs (lists;
              a single value is accepted as a list of one); ``list`` is a list of
              scalars of any one type, left uncoerced (sweep values)
    required  the deck must give it; otherwise ``default`` is used
    choices   allowed values (strings compared case-insensitively, stored lower-case)
    check     extra test: returns an error message or None
    units     for --help and docs, e.g. 'rad/s'
    """

    kind: str
    required: bool = False
    default: Any = None
    choices: tuple | None = None
    check: Callable[[Any], str | None] | None = None
    units: str = ""
    doc: str = ""

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"unknown key kind {self.kind!r}")


@dataclass(frozen=True)
class GroupSpec:
    """A namelist group of a study: its keys and a cross-key check on the Params."""

    name: str
    keys: dict[str, Key]
    doc: str = ""
    check: Callable[["Params"], None] | None = None


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


class Params(Mapping):
    """Validated values of one group (defaults filled in), with their deck lines."""

    def __init__(self, group: str, path: Path, values: dict[str, Any], lines: dict[str, int],
                 line: int, given: set[str] | None = None):
        self.group, self.path, self.line = group, Path(path), line
        self._values, self._lines = dict(values), dict(lines)
        self.given = set(given if given is not None else values)

    def __getitem__(self, key: str) -> Any:
        return self._values[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self._values)

    def __len__(self) -> int:
        return len(self._values)

    def __getattr__(self, key: str) -> Any:
        try:
            return self.__dict__["_values"][key]
        except KeyError:
            raise AttributeError(key) from None

    def line_of(self, key: str) -> int:
        """Line of ``key`` in the deck, or the group's line when it was defaulted."""
        return self._lines.get(key, self.line)

    def error(self, key: str | None, message: str) -> DeckError:
        """A DeckError located at ``key`` (for cross-key checks in studies)."""
        return DeckError(self.path, self.line_of(key) if key else self.line, key, message)


# --------------------------------------------------------------------------- parsing

_GROUP_RE = re.compile(r"^\s*[&$]\s*([A-Za-z_]\w*)")
_END_RE = re.compile(r"^\s*(/|[&$]\s*end\b)", re.IGNORECASE)
_KEY_RE = re.compile(r"(?:^|[\s,])([A-Za-z_]\w*)\s*(?:\([^)]*\))?\s*=")


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


def _blank_strings(line: str) -> str:
    """Replace quoted text by blanks so key scanning ignores ``=`` inside strings."""
    return re.sub(r"'[^']*'|\"[^\"]*\"", lambda m: " " * len(m.group()), line)


def _scan_lines(text: str) -> tuple[list[tuple[str, int]], dict[str, dict[str, int]]]:
    """Groups (name, line) in order and the first line of every key in each group."""
    groups: list[tuple[str, int]] = []
    keys: dict[str, dict[str, int]] = {}
    current = None
    for n, raw in enumerate(text.splitlines(), start=1):
        line = _blank_strings(_strip_comment(raw))
        m = _GROUP_RE.match(line)
        if m and not _END_RE.match(line):
            current = m.group(1).lower()
            groups.append((current, n))
            keys.setdefault(current, {})
            line = line[m.end():]
        if current is None:
            continue
        for km in _KEY_RE.finditer(line):
            keys[current].setdefault(km.group(1).lower(), n)
        if re.search(r"(^|\s)/\s*$", line) or _END_RE.match(line):
            current = None
    return groups, keys


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
            try:
                values[key] = float(tok.replace("d", "e").replace("D", "e"))
            except ValueError:
                raise DeckError(path, n, key, f"not a number: {tok!r}") from None
            lines[key] = n
    return Deck(path, {"fourbar": RawGroup("fourbar", values, lines, content[0][0])}, legacy=True)


def _plain(value: Any) -> Any:
    """f90nml values -> plain Python (lists with None for skipped entries kept)."""
    if isinstance(value, list):
        return [_plain(v) for v in value]
    return value


def read_deck(path: str | Path, text: str | None = None) -> Deck:
    """Parse a deck file (or ``text`` attributed to ``path``) into raw groups."""
    path = Path(path)
    if text is None:
        try:
            text = path.read_text()
        except OSError as exc:
            raise DeckError(path, None, None, f"cannot read deck: {exc.strerror}") from None
        except UnicodeDecodeError:
            raise DeckError(path, None, None, "deck is not a text file") from None
    if _is_legacy(text):
        return _read_legacy(path, text)
    order, key_lines = _scan_lines(text)
    if not order:
        raise DeckError(path, None, None, "no namelist group found (a deck starts a group with '&name')")
    seen: dict[str, int] = {}
    for name, line in order:
        if name in seen:
            raise DeckError(path, line, None, f"group &{name} given twice (first on line {seen[name]})")
        seen[name] = line
    try:
        nml = f90nml.reads(text)
    except Exception as exc:  # f90nml raises ValueError, StopIteration, IndexError, ...
        msg = str(exc) or exc.__class__.__name__
        m = re.search(r"line (\d+)", msg)
        raise DeckError(path, int(m.group(1)) if m else None, None,
                        f"namelist syntax error: {msg}") from None
    groups: dict[str, RawGroup] = {}
    for name, line in order:
        raw = nml.get(name, {}) or {}
        values = {k.lower(): _plain(v) for k, v in raw.items()}
        groups[name] = RawGroup(name, values, key_lines.get(name, {}), line)
    return Deck(path, groups)


# --------------------------------------------------------------------------- validation

def _as_float(v: Any) -> float | None:
    if isinstance(v, bool) or v is None:
        return None
    if isinstance(v, (int, float)):
        return float(v)
    if isinstance(v, str):
        try:
            return float(v.strip().replace("d", "e").replace("D", "e"))
        except ValueError:
            return None
    return None


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
    if kind == "float":
        f = _as_float(v)
        if f is None:
            return None, f"not a number: {v!r}"
        if not math.isfinite(f):
            return None, f"not a finite number: {v!r}"
        if abs(f) > MAX_FLOAT:
            return None, f"{f:g} is beyond +-{MAX_FLOAT:g}, outside what any study here computes"
        return f, None
    if kind == "int":
        f = _as_float(v)
        if f is None or not f.is_integer():
            return None, f"not a whole number: {v!r}"
        if abs(f) > MAX_INT:
            return None, f"{f:g} is beyond +-{MAX_INT:g}"
        return int(f), None
    if kind == "bool":
        if isinstance(v, bool):
            return v, None
        return None, f"not a logical (.true./.false.): {v!r}"
    if kind == "str":
        if isinstance(v, str):
            return v, None
        return None, f"not a quoted string: {v!r}"
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
                                    f"{x!r} is not one of {', '.join(map(repr, k.choices))}")
            val = norm if isinstance(val, list) else norm[0]
        if k.check is not None:
            msg = k.check(val)
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
        spec.check(params)
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
