"""What a deck group may hold: the declaration of a key (:class:`Key`) and of a group
(:class:`GroupSpec`).  Plain data with no dependency inside the driver, so that both the deck
reader (:mod:`driver.deck`, which re-exports them) and the study contract
(:mod:`driver._study`) can use them without importing each other."""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:   # annotations only
    from driver.deck import Params

__all__ = ["KINDS", "Key", "GroupSpec"]

KINDS = ("float", "int", "str", "bool", "floats", "ints", "strs", "list")


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
