"""What a study is, and how the driver finds one.

A study is a module ``driver/<group>.py`` named after its namelist group.  It
defines

* ``SPEC``: a :class:`driver.deck.GroupSpec` for its keys, and
* ``run(params, progress=False) -> Result``: the physics (through its kernel).

Nothing else in the driver changes when a study is added: the group name of a
deck selects the module.
"""
from __future__ import annotations

import importlib
import re
from dataclasses import dataclass, field
from types import ModuleType
from typing import TYPE_CHECKING, Any, Callable

if TYPE_CHECKING:   # annotations only: keeps `python -m driver --help` light
    import pandas as pd

__all__ = ["Figure", "Result", "load_study", "study_names"]

_CORE = {"cli", "limits", "deck", "study", "table", "export", "plotting", "atomic", "kernels", "sweep", "runner", "expr",
         "optimize", "synthesis", "published", "compare", "extras", "example_decks", "examples"}


@dataclass
class Figure:
    """A figure to write as ``<stem>_<name>.png``; ``draw`` builds it lazily (matplotlib Figure)."""

    name: str
    draw: Callable[[], Any]


@dataclass
class Result:
    """Everything one deck run produced.

    text      the fixed-format ``.out`` file content
    tidy      tidy table (one row per output point) for CSV/Parquet
    summary   headline figures of the case (flat dict of scalars; used by sweeps)
    warnings  messages for the terminal (also written into ``text`` by the study)
    failure   set when the run completed but did not succeed (e.g. an optimiser
              did not converge): outputs are written, the exit status is 1
    figures   figures for --plot
    extra     further files: suffix -> text, written as ``<stem><suffix>``
    """

    text: str
    tidy: pd.DataFrame
    summary: dict[str, Any] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)
    failure: str | None = None
    figures: list[Figure] = field(default_factory=list)
    extra: dict[str, str] = field(default_factory=dict)


def load_study(group: str) -> ModuleType | None:
    """The study module for namelist group ``group``, or None if there is none."""
    if not re.fullmatch(r"[a-z_][a-z0-9_]*", group) or group in _CORE or group.startswith("_"):
        return None
    try:
        module = importlib.import_module(f"driver.{group}")
    except ModuleNotFoundError as exc:
        if exc.name == f"driver.{group}":
            return None
        raise
    if not (hasattr(module, "SPEC") and hasattr(module, "run")):
        return None
    return module


def study_names() -> list[str]:
    """Group names of every study module in the package, found without importing them."""
    import pkgutil

    import driver
    return sorted(info.name for info in pkgutil.iter_modules(driver.__path__)
                  if info.name not in _CORE and not info.name.startswith("_"))
