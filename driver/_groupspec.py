"""What a deck group may hold and what it holds once validated: the declaration of a key
(:class:`Key`) and of a group (:class:`GroupSpec`), the validated values (:class:`Params`) and
the bad-input error (:class:`DeckError`).  Plain data with no dependency inside the driver (but the
exception base of :mod:`driver._errors` and the rule for names of :mod:`driver._names`), so
that the deck reader (:mod:`driver._deck`, which re-exports them), the budget
(:mod:`driver._limits`) and the study contract (:mod:`driver._study`) can use them without
importing each other."""
from __future__ import annotations

import re
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from driver._errors import DriverError
from driver._names import NAME_CHARS, shown

#: a run of more characters than a file name may have (NAME_MAX, 255 bytes) without a blank or a
#: '/' in a message: not a path's part but a key, group or value echoed from the deck
_LONG_WORD = re.compile(r"[^\s/]{256,}")
#: the longest message shown whole (a path may have PATH_MAX, 4 096 bytes)
_MESSAGE_CHARS = 8192


def bounded_words(text: str) -> str:
    """``text`` with every run of characters longer than a file name may be, without a blank or a
    '/', cut in the middle to :data:`~driver._names.NAME_CHARS` (:func:`driver._names.shown`), and
    the whole bounded to 8 192 characters; the path of a deck is shown whole."""
    text = _LONG_WORD.sub(lambda m: shown(m.group(0), NAME_CHARS), text)
    return text if len(text) <= _MESSAGE_CHARS else shown(text, _MESSAGE_CHARS)

__all__ = ["KINDS", "DeckError", "Key", "GroupSpec", "Params"]

KINDS = ("float", "int", "str", "bool", "floats", "ints", "strs", "list")


class DeckError(DriverError, ValueError):
    """Bad input: names the deck, the line and the key (exit status 2).

    A :class:`driver.DriverError` and a ``ValueError``; ``str()`` is ``'<path>:<line>: key '<key>': <message>'``.

    Parameters
    ----------
    path : str or path-like
        The deck (or a label such as the study group for keyword arguments).
    line : int or None
        Line of the deck where the problem is; None when unknown.
    key : str or None
        The key at fault; None for the whole group.
    message : str
        What is wrong.
    """

    def __init__(self, path: str | Path, line: int | None, key: str | None, message: str):
        self.path, self.line, self.key, self.message = str(path), line, key, message
        super().__init__(str(self))

    def __reduce__(self) -> tuple[type[DeckError], tuple[str, int | None, str | None, str]]:
        """Pickle by the four fields (a worker process's error reaches the driver whole)."""
        return (type(self), (self.path, self.line, self.key, self.message))

    def __str__(self) -> str:
        """The message as the command line prints it: the key and every key, group or value the
        message quotes bounded to :data:`driver._names.NAME_CHARS` characters
        (:func:`driver._names.shown`: a 75 kB key is not echoed whole); the deck's path whole."""
        where = f"{self.path}:{self.line}" if self.line else self.path
        what = f"key '{shown(self.key)}': " if self.key else ""
        return f"{where}: {what}{bounded_words(self.message)}"


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
    check: Callable[[Params], None] | None = None


# where tracebacks and pickles find these: DeckError in the public namespace (``driver.DeckError``),
# the deck's data types in driver._deck (which re-exports them); defined here because this
# module imports nothing of the driver
DeckError.__module__ = "driver"
for _cls in (GroupSpec, Key, Params):
    _cls.__module__ = "driver._deck"
