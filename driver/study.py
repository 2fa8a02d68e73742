"""What a study is, and how the driver finds one.

A study is a module ``driver/<group>.py`` named after its namelist group.  It
defines

* ``SPEC``: a :class:`driver.deck.GroupSpec` for its keys, and
* ``run(params, progress=False) -> Result``: the physics (through its kernel);

and may define, for figures of sweeps over it,

* ``LABELS``: ``{name: (words, units)}`` for summary columns and deck keys, the
  axis labels a reader sees instead of identifiers (``{i}`` in a name stands for a
  case number, e.g. ``peak_tensile_{i}_deg``); deck keys default to their
  ``SPEC`` units, and
* ``SWEEP_PLOT``: the summary columns a sweep summary plots when the deck names none.

Nothing else in the driver changes when a study is added: the group name of a
deck selects the module.
"""
from __future__ import annotations

import importlib
import re
from dataclasses import dataclass, field
from types import ModuleType
from typing import Any, Callable

import pandas as pd

__all__ = ["Figure", "PLOT_FORMATS", "Result", "column_label", "load_study", "plot_format"]

_CORE = {"cli", "limits", "deck", "study", "table", "export", "plotting", "atomic", "kernels", "sweep", "runner", "expr",
         "optimize", "synthesis", "published", "compare"}


#: file formats of ``--plot`` figures (``--plot-format``); the first is the default
PLOT_FORMATS = ("png", "svg", "pdf")


def plot_format(plot: bool | str | None) -> str | None:
    """The figure format a ``plot`` argument asks for: None (no figures), or one of
    :data:`PLOT_FORMATS` (``True`` means PNG).  Raises ValueError for any other format."""
    if not plot:
        return None
    fmt = PLOT_FORMATS[0] if plot is True else str(plot).lower().lstrip(".")
    if fmt not in PLOT_FORMATS:
        raise ValueError(f"figure format {plot!r} is not one of {', '.join(PLOT_FORMATS)}")
    return fmt


@dataclass
class Figure:
    """A figure to write as ``<stem>_<name>.<format>``; ``draw`` builds it lazily (matplotlib Figure)."""

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


#: units read off a column name's suffix when a study declares none (longest first)
_SUFFIX_UNITS = (("_rad_s2", "rad/s^2"), ("_rad_s", "rad/s"), ("_microstrain", "microstrain"), ("_deg", "deg"),
                 ("_rpm", "rpm"), ("_Nm", "N m"), ("_m2", "m^2"), ("_mm", "mm"), ("_m", "m"), ("_N", "N"),
                 ("_s", "s"))


def column_label(module: ModuleType | None, name: str) -> str:
    """The axis label of summary column or deck key ``name`` (``group.key`` or ``key``) of
    study ``module``: words and units from its ``LABELS``, else the key's ``SPEC`` units, else
    units read off the name's suffix (``_deg``, ``_rad_s``, ...).  E.g. ``'crank speed [rad/s]'``."""
    if not re.fullmatch(r"([a-z_][a-z0-9_]*\.)?[A-Za-z_][A-Za-z0-9_]*", name):
        return name   # an expression of columns (driver.expr) is its own label
    group, _, key = name.rpartition(".")
    if module is not None and group and group != getattr(module.SPEC, "name", group):
        module = None
    labels: dict = getattr(module, "LABELS", {}) if module is not None else {}
    entry = labels.get(key)
    for pattern, value in labels.items() if entry is None else ():
        m = re.fullmatch(re.escape(pattern).replace(r"\{i\}", "([0-9]+)"), key) if "{i}" in pattern else None
        if m:
            entry = (value[0].replace("{i}", m.group(1)), value[1])
            break
    spec_key = getattr(module.SPEC, "keys", {}).get(key) if module is not None else None
    if entry is None:
        words, units = key, ""
        for suffix, u in _SUFFIX_UNITS:
            if key.endswith(suffix) and len(key) > len(suffix):
                words, units = key[: -len(suffix)], u
                break
        entry = (words.replace("_", " "), units)
    words, units = entry
    if not units and spec_key is not None:
        units = spec_key.units
    return f"{words} [{units}]" if units else words
