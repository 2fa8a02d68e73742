"""Decks from Python: a deck file, a deck's text, or ``{group: {key: value}}`` with Python and numpy
values, as the one deck type (:class:`~driver._deck.Deck`) the runner validates.

Sizes are checked before anything is converted (a ``range(10**9)`` is refused, not
materialised); a value is what a deck can hold: a number, a string, a logical or a flat
list of them.  Used by the Python API (:mod:`driver._api`) and by the keyword face of every
study's ``run`` (:func:`driver._runner.keyword_run`).
"""
from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any, TypeAlias, cast

import numpy as np

from driver._deck import MAX_DECK_BYTES, MAX_VALUES, Deck, DeckError, RawGroup, read_deck, shown_value

__all__ = ["DeckSource", "deck_of", "source_deck", "group_from_dict", "is_text", "plain_value"]

#: what :func:`driver.run` and :func:`driver.run_sweep` accept: a deck file, a deck's text, or {group: {key: value}}
DeckSource: TypeAlias = str | os.PathLike | Mapping[str, Mapping[str, Any]]


def _scalar(value: np.generic, where: str, key: str | None) -> Any:
    """A numpy scalar as a plain Python value: a float of any precision (``longdouble`` too) as
    the nearest double, as a deck's number is read; complex numbers, bytes, dates and records
    are refused naming the key (``.item()`` of a ``longdouble`` is a ``longdouble`` again: it
    is converted here, never by recursion)."""
    if isinstance(value, np.bool_):
        return bool(value)
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.floating):
        with np.errstate(over="ignore"):   # beyond a double: inf, refused as not finite by the reader
            return float(np.float64(value))
    if isinstance(value, np.str_):
        return str(value)
    what = {"c": "a complex number", "S": "bytes", "M": "a date", "m": "a time span", "V": "a record"}
    raise DeckError(where, None, key, f"value {shown_value(value)} of numpy type {type(value).__name__} is "
                                      f"{what.get(value.dtype.kind, 'not a deck value')}: a deck value is a number, "
                                      "a string, a logical or a flat list of them")


def plain_value(value: Any, where: str, key: str | None = None, depth: int = 0) -> Any:
    """A Python/numpy value as the deck reader's plain types (lists for sequences).

    Sizes are checked from ``len()`` and ``shape`` before anything is converted (a
    ``range(10**9)`` is refused, not materialised); a list of lists is one level deep at most
    (a deck value is a number, a string, a logical or a list of them).  numpy scalars and arrays
    of every dtype are converted (``longdouble`` to the nearest double, an object array element
    by element) or refused with a DeckError naming the key (complex, bytes, dates, records)."""
    if isinstance(value, np.ndarray):
        if value.size > MAX_VALUES or value.ndim > 1:
            raise DeckError(where, None, key, f"array of shape {value.shape}: a deck value is at most a flat "
                            f"list of {MAX_VALUES} values")
        if value.dtype.kind == "O":   # element by element (tolist() would recurse into nested arrays)
            items = list(value.flat)
            if value.ndim == 0:
                return plain_value(items[0], where, key, depth)
            value = items
        elif value.ndim == 0:
            return _scalar(cast(np.generic, value[()]), where, key)
        else:
            value = [_scalar(v, where, key) for v in value]   # every element a numpy scalar of the dtype
            if depth >= 1:
                raise DeckError(where, None, key, "a list inside a list: a deck value is a number, a string, "
                                "a logical or a flat list of them")
            return value
    if isinstance(value, (list, tuple, range)):
        if len(value) > MAX_VALUES:
            raise DeckError(where, None, key, f"{len(value)} values; at most {MAX_VALUES} are read per key "
                            "(checked before anything is converted)")
        if depth >= 1:
            raise DeckError(where, None, key, "a list inside a list: a deck value is a number, a string, "
                            "a logical or a flat list of them")
        return [plain_value(v, where, key, depth + 1) for v in value]
    if isinstance(value, np.generic):
        return _scalar(value, where, key)
    if isinstance(value, Path):
        return str(value)
    if isinstance(value, str) and len(value) > MAX_DECK_BYTES:
        raise DeckError(where, None, key, f"a text of {len(value)} characters; a deck is at most {MAX_DECK_BYTES}")
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    raise DeckError(where, None, key, f"value {shown_value(value)} of type {type(value).__name__} is not a deck value "
                                       "(give numbers, strings, logicals or lists of them)")


def group_from_dict(group: str, values: Mapping[str, Any], label: str) -> RawGroup:
    if not isinstance(values, Mapping):
        raise DeckError(label, None, None, f"group &{group} must be a dict of keys, got {type(values).__name__}")
    plain = {}
    for k, v in values.items():
        if not isinstance(k, str):
            raise DeckError(label, None, None, f"key {k!r} of &{group} is not a name")
        plain[k.lower()] = plain_value(v, label, k.lower())
    return RawGroup(group, plain, {}, 0)


def is_text(source: str) -> bool:
    return "\n" in source or source.lstrip().startswith(("&", "$", "!"))


def deck_of(source: DeckSource | Deck, name: str | None) -> Deck:
    """The deck for ``source``: a file path, a deck's text, a {group: {key: value}} dict."""
    if isinstance(source, Deck):
        return source
    if isinstance(source, Mapping):
        if not source:
            raise DeckError(name or "<dict>", None, None, "deck has no study group")
        named = [str(g).lower().lstrip("&") for g in source]
        label = name or next((g for g in named if g != "sweep"), "sweep")
        groups = {}
        for g, values in source.items():
            g = str(g).lower().lstrip("&")
            groups[g] = group_from_dict(g, values, label)
        return Deck(Path(label), groups)
    if isinstance(source, str) and is_text(source):
        return read_deck(Path(name or "deck"), text=source)
    if isinstance(source, (str, os.PathLike)):
        return read_deck(Path(source))
    raise TypeError(f"a deck is a path, a deck's text or a dict of groups, not {type(source).__name__}")


def source_deck(source: DeckSource | Deck, name: str | None = None) -> Deck:
    """The deck of any Python entry point's ``source`` (:data:`DeckSource`: a deck file, a deck's
    text, a {group: {key: value}} dict; or a parsed Deck), named ``name``, else after its file,
    else after its first study group (as :func:`driver.run` names a deck's text): the stem of the
    files an engine writes for it.  DeckError for bad input, TypeError for a source of another type."""
    deck = deck_of(source, name)
    if name is None and isinstance(source, str) and is_text(source):
        study = [g for g in deck.groups if g not in ("sweep", "optimize", "synthesis")] or list(deck.groups)
        deck = Deck(Path(study[0] if study else "deck"), deck.groups)
    return deck
