"""The &sweep group: its keys, the swept axes, the cases (generated lazily from the grid) and the
validation of every case before anything runs."""
from __future__ import annotations

import itertools
import math
import os
import re
import sys
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import f90nml
import numpy as np

from driver import _limits as limits
from driver._deck import DeckError, GroupSpec, Key, Params, RawGroup, shown_value, validate
from driver._outcome import ExitCode

__all__ = ["SPEC", "Case", "CaseResult", "MAX_KEYS", "MAX_CASES", "FULL_VALIDATION", "build_cases", "grid_of", "case_at",
           "iter_cases", "case_count", "validate_sweep", "checked_key", "split_key", "deck_key", "set_swept"]

MAX_KEYS = 9
#: most cases one per-case sweep deck may have (a batch sweep lists no case: driver.sweep._plan.BATCH_MAX_CASES)
MAX_CASES = 1_000_000
#: most values one start/stop/count axis may have (about 0.3 GB as Python floats)
MAX_AXIS_VALUES = 10_000_000
#: sweeps up to this many cases have every case validated before anything runs
FULL_VALIDATION = 5_000

def _no_scheduler_in_deck(value: str) -> str:
    """Key check of ``scheduler``: a deck never chooses where the tool connects."""
    return ("a deck may not choose the Dask scheduler: Dask deserialises what a scheduler sends, so a "
            "hostile address in a shared deck would run code on your machine; remove the key and give "
            "the address on the command line (--scheduler ADDRESS) or in Dask's configuration "
            "(scheduler-address, e.g. the environment variable DASK_SCHEDULER_ADDRESS)")


def _dask_configured() -> bool:
    """Whether any Dask configuration exists: a DASK_* environment variable or a configuration
    file in one of the folders Dask reads (dask.config.paths and $DASK_CONFIG)."""
    if "dask" in sys.modules or any(k.startswith("DASK_") for k in os.environ):
        return True
    folders = [os.environ.get("DASK_ROOT_CONFIG", "/etc/dask"), os.path.join(sys.prefix, "etc", "dask"),
               os.path.join(os.path.expanduser("~"), ".config", "dask")]
    for folder in folders:
        try:
            if any(e.name.endswith((".yaml", ".yml", ".json")) for e in os.scandir(folder)):
                return True
        except OSError:
            continue
    return False


def configured_scheduler() -> str:
    """The scheduler address from Dask's own configuration/environment, or ''.  Dask is imported
    (0.2 s) only when some Dask configuration exists."""
    if not _dask_configured():
        return ""
    try:
        import dask.config
    except ImportError:
        return ""
    return str(dask.config.get("scheduler-address", default=None) or "")



def _spec() -> GroupSpec:
    keys: dict[str, Key] = {}
    for k in range(1, MAX_KEYS + 1):
        keys[f"key{k}"] = Key("str", doc=f"deck key to vary (axis {k}): 'group.key', or one element of a list "
                                          "key 'group.key(i)'")
        keys[f"values{k}"] = Key("list", doc="values of that key (numbers or strings)")
        keys[f"start{k}"] = Key("float", doc="first value (with stop and count)")
        keys[f"stop{k}"] = Key("float", doc="last value (inclusive)")
        keys[f"count{k}"] = Key("int", doc="number of values from start to stop")
    keys.update({
        "zip": Key("bool", default=False, doc=".true.: vary the keys together instead of a full grid"),
        "keep": Key("str", default="", doc="filter on the summary columns in the deck expression language (docs/decks.md): "
                    "comparisons, and/or/not, arithmetic, abs/min/max/sqrt...; swept keys as group.key"),
        "case_outputs": Key("str", default="all", choices=("all", "kept", "none"),
                            doc="which cases get their own .out/.parquet/.json files"),
        "summary_rows": Key("str", default="all", choices=("all", "kept"),
                            doc="which cases go into the _summary tables (large searches: 'kept')"),
        "scheduler": Key("str", check=_no_scheduler_in_deck,
                         doc="refused: the scheduler comes from --scheduler or Dask's configuration"),
        "chunk": Key("int", default=0, check=lambda v: "must not be negative" if v < 0 else None,
                     doc="cases per chunk; 0 = chosen by the tool from the number of cases alone (each chunk "
                         "is a part of the resume record, found again with any -j or scheduler; on the batch "
                         "path a small sweep runs in the driver when workers would not pay)"),
        "case_plots": Key("bool", default=False,
                          doc="with --plot, also draw every written case's own figures (by default --plot "
                              "draws the sweep's summary only: per-case figures cost more than the sweep)"),
        "plot_x": Key("str", default="",
                      doc="summary column (or expression in the deck language) on the x axis of the summary plot"),
        "plot_y": Key("strs", default=[], doc="summary columns (or expressions) plotted against plot_x"),
        "summary_columns": Key("strs", default=[],
                               doc="the summary columns the tables show (default: all); with keep and the "
                                   "plot_* columns they decide what a batch sweep computes (a column nobody "
                                   "asks for is not computed)"),
    })
    return GroupSpec("sweep", keys, doc="run a study over a grid or list of deck values")


SPEC = _spec()


@dataclass
class Grid:
    """The swept axes: names ('group.key'), values per axis, full grid or zipped."""

    names: list[str]
    values: list[list]
    zipped: bool

    @property
    def n(self) -> int:
        return len(self.values[0]) if self.zipped else int(np.prod([len(v) for v in self.values]))

    def indices(self, start: int, stop: int) -> list[np.ndarray]:
        """Per axis, the value index of cases start..stop-1 (0-based; product order)."""
        return self.indices_at(np.arange(start, stop, dtype=np.int64))

    def indices_at(self, positions: np.ndarray) -> list[np.ndarray]:
        """Per axis, the value index of the cases at 0-based ``positions`` (case number - 1)."""
        idx = np.asarray(positions, dtype=np.int64)
        if self.zipped:
            return [idx] * len(self.names)
        return list(np.unravel_index(idx, [len(v) for v in self.values]))

    def columns(self, start: int, stop: int) -> dict[str, np.ndarray]:
        """The swept values of cases start..stop-1 (0-based), one array per swept key."""
        return self.columns_at(np.arange(start, stop, dtype=np.int64))

    def columns_at(self, positions: np.ndarray) -> dict[str, np.ndarray]:
        """The swept values of the cases at 0-based ``positions``, one array per swept key."""
        return {name: _array(vals)[ix] for name, vals, ix in zip(self.names, self.values, self.indices_at(positions))}


def _array(vals: list) -> np.ndarray:
    a = np.asarray(vals)
    return a if a.dtype.kind in "fiub" else np.asarray(vals, dtype=object)


@dataclass
class CaseResult:
    """What a worker returns for one case (``files``: what it wrote, relative to the case folder)."""

    index: int
    values: dict[str, Any]
    status: ExitCode = ExitCode.OK
    error: str = ""
    summary: dict[str, Any] = field(default_factory=dict)
    kept: bool = True
    written: bool = False
    warnings: list[str] = field(default_factory=list)
    tidy: Any = None
    seconds: float = 0.0                 # wall time of the case in its worker [s]
    files: list[str] = field(default_factory=list)
    cpu: float = 0.0                     # CPU time of the case in its worker [s]


@dataclass
class Case:
    """One case of a sweep.

    Attributes
    ----------
    index : int
        The case's number, from 1.
    values : dict
        The swept values ``{'group.key': value}``, in the keys' deck units.
    """

    index: int
    values: dict[str, Any]



#: a swept element of a list key: 'key(i)', i from 1
_ELEMENT = re.compile(r"([a-z_][a-z0-9_]*)\((\d+)\)")
_LIST_KINDS = ("floats", "ints", "strs", "list")


def split_key(swept: str) -> tuple[str, int | None]:
    """The study key and the element index (from 1; None for the whole key) of a swept name
    ``'group.key'`` or ``'group.key(i)'`` (the group may be left out)."""
    name = swept.partition(".")[2] if "." in swept else swept
    m = _ELEMENT.fullmatch(name)
    return (m.group(1), int(m.group(2))) if m else (name, None)


def deck_key(swept: str) -> str:
    """The study key a swept name varies (``'linkage.dyad_dims(3)'`` -> ``'dyad_dims'``)."""
    return split_key(swept)[0]


def set_swept(values: dict[str, Any], swept: str, value: Any) -> None:
    """Set swept ``'group.key'`` (or one element, ``'group.key(i)'``) in a group's ``values``;
    DeckError (no path) when the element does not exist in the list the deck gives."""
    key, index = split_key(swept)
    if index is None:
        values[key] = value
        return
    cur = values.get(key)
    items = list(cur) if isinstance(cur, (list, tuple)) else ([] if cur is None else [cur])
    if not 1 <= index <= len(items):
        raise DeckError("", None, key, f"element {index} does not exist: the deck gives {key} "
                                       f"{len(items)} value{'s' * (len(items) != 1)}")
    items[index - 1] = value
    values[key] = items


def swept_axes(sw: Params, study_group: str, study_spec: GroupSpec) -> list[tuple[str, list]]:
    """The swept axes [(‘group.key’, values)], checked against the study's keys."""
    axes = []
    for k in range(1, MAX_KEYS + 1):
        name = sw[f"key{k}"]
        has_values = sw[f"values{k}"] is not None
        has_range = any(sw[f"{w}{k}"] is not None for w in ("start", "stop", "count"))
        if name is None:
            for w in ("values", "start", "stop", "count"):
                if sw[f"{w}{k}"] is not None:
                    raise sw.error(f"{w}{k}", f"given without key{k}")
            continue
        group, _, key = name.lower().replace(" ", "").partition(".")
        if not key:
            raise sw.error(f"key{k}", f"write the key as 'group.key' (e.g. '{study_group}.{name}')")
        if group != study_group:
            raise sw.error(f"key{k}", f"group '{group}' is not this deck's study group &{study_group}")
        base_key, index = split_key(key)
        if base_key not in study_spec.keys:
            raise sw.error(f"key{k}", f"&{study_group} has no key '{base_key}'")
        if "(" in key and index is None:
            raise sw.error(f"key{k}", f"write one element of a list key as '{study_group}.key(i)', i from 1")
        if index is not None and (index < 1 or study_spec.keys[base_key].kind not in _LIST_KINDS):
            raise sw.error(f"key{k}", f"'{base_key}' is not a list key: sweep it whole, '{study_group}.{base_key}'"
                           if index >= 1 else "elements count from 1")
        if has_values and has_range:
            raise sw.error(f"values{k}", f"give values{k} or start{k}/stop{k}/count{k}, not both")
        if has_values:
            values = list(sw[f"values{k}"])
        elif has_range:
            missing = [w for w in ("start", "stop", "count") if sw[f"{w}{k}"] is None]
            if missing:
                raise sw.error(f"{missing[0]}{k}", f"start{k}, stop{k} and count{k} go together")
            if sw[f"count{k}"] < 1:
                raise sw.error(f"count{k}", "must be at least 1")
            if sw[f"count{k}"] > MAX_AXIS_VALUES:   # refused before the values are allocated
                raise sw.error(f"count{k}", f"{sw[f'count{k}']} values on one axis is beyond the {MAX_AXIS_VALUES} "
                                            "one axis may have; a grid multiplies its axes")
            values = [float(v) for v in np.linspace(sw[f"start{k}"], sw[f"stop{k}"], sw[f"count{k}"])]
        else:
            raise sw.error(f"key{k}", f"needs values{k} or start{k}/stop{k}/count{k}")
        if not values:
            raise sw.error(f"values{k}", "must list at least one value")
        axes.append((f"{group}.{key}", values))
    if not axes:
        raise sw.error("key1", "a sweep needs at least key1 with its values")
    names = [a[0] for a in axes]
    dup = {n for n in names if names.count(n) > 1}
    if dup:
        raise sw.error(f"key{names.index(sorted(dup)[0]) + 1}", f"{sorted(dup)[0]} is swept twice")
    return axes


def case_count(sw: Params, axes: list[tuple[str, list]]) -> int:
    """Count the cases of the axes (full grid or zipped) before any case is built.

    Parameters
    ----------
    sw : Params
        The validated ``&sweep`` group (``zip``).
    axes : list of tuple
        The swept axes ``('group.key', values)``.

    Returns
    -------
    int
        The number of cases.
    """
    return len(axes[0][1]) if sw.zip else math.prod(len(v) for _, v in axes)


def _check_zip(sw: Params, axes: list[tuple[str, list]]) -> None:
    """zip = .true. needs equally long value lists."""
    if not sw.zip:
        return
    n = len(axes[0][1])
    for k, (name, vals) in enumerate(axes):
        if len(vals) != n:
            raise sw.error(f"values{k + 1}" if sw[f"values{k + 1}"] is not None else f"count{k + 1}",
                           f"zip = .true. needs equally long value lists ({axes[0][0]}: {n}, {name}: {len(vals)})")


def case_at(grid: Grid, index: int) -> Case:
    """Case ``index`` (from 1) of the grid, its values the deck's own objects (an integer stays
    an integer), computed from the index alone (product order, or zipped)."""
    if grid.zipped:
        picks = [index - 1] * len(grid.values)
    else:
        picks = [int(j) for j in np.unravel_index(index - 1, [len(v) for v in grid.values])]
    return Case(index, {name: vals[j] for name, vals, j in zip(grid.names, grid.values, picks)})


def iter_cases(grid: Grid, indices: Iterable[int] | None = None) -> Iterator[Case]:
    """The cases ``indices`` (default all, in order), generated one at a time."""
    if indices is None:
        combos = zip(*grid.values) if grid.zipped else itertools.product(*grid.values)
        for i, combo in enumerate(combos, start=1):
            yield Case(i, dict(zip(grid.names, combo)))
        return
    for i in indices:
        yield case_at(grid, int(i))


def grid_of(sw: Params, study_group: str, study_spec: GroupSpec) -> Grid:
    """The swept axes of the &sweep group as a :class:`Grid` (no case is built)."""
    axes = swept_axes(sw, study_group, study_spec)
    _check_zip(sw, axes)
    return Grid([a[0] for a in axes], [a[1] for a in axes], bool(sw.zip))


def build_cases(sw: Params, study_group: str, study_spec: GroupSpec) -> list[Case]:
    """Build all cases of the sweep, numbered from 1: a full grid, or zipped axes.

    Parameters
    ----------
    sw : Params
        The validated ``&sweep`` group.
    study_group : str
        The study's namelist group.
    study_spec : GroupSpec
        The study's keys (the swept keys are checked against them).

    Returns
    -------
    list of Case
        The cases, values in the keys' deck units.

    Raises
    ------
    DeckError
        An unknown key, unequal zipped lists, or more than :data:`MAX_CASES` cases (refused
        before a case is built).
    """
    axes = swept_axes(sw, study_group, study_spec)
    names = [a[0] for a in axes]
    n_cases = case_count(sw, axes)
    if n_cases > MAX_CASES:
        sizes = " x ".join(f"{len(v)} ({n})" for n, v in axes)
        raise sw.error("key1", f"{n_cases} cases ({sizes}) is beyond the {MAX_CASES} cases one sweep deck "
                       "may have; split the sweep into several decks or coarsen the grid")
    _check_zip(sw, axes)
    if sw.zip:
        combos: Iterable = zip(*(v for _, v in axes))
    else:
        combos = itertools.product(*(v for _, v in axes))
    return [Case(i + 1, dict(zip(names, c))) for i, c in enumerate(combos)]


def _axis_line(sw: Params, name: str) -> tuple[str, int]:
    """The sweep key (values<k> or start<k>) and line that produced swept key ``name``."""
    for k in range(1, MAX_KEYS + 1):
        if sw[f"key{k}"] is not None and sw[f"key{k}"].lower().replace(" ", "") == name:
            key = f"values{k}" if sw[f"values{k}"] is not None else f"start{k}"
            return key, sw.line_of(key)
    return "key1", sw.line_of("key1")


def validate_sweep(sw: Params, raw: RawGroup, module: Any, grid: Grid,
                   checked: set[tuple] | None = None) -> dict[int, float]:
    """Refuse the whole sweep (DeckError naming the sweep line and key) before anything runs
    when a case would be bad input.

    Up to FULL_VALIDATION cases every case is validated.  Above, every value of every axis is
    validated alone, and every combination of the values of the *coupled* axes (keys whose deck
    checks involve other keys: all of them, unless the study's batch path names a key
    ``independent``) is validated as a case would be: a check between two swept keys (a start
    angle past a stop angle) is found in the inner cases too, not only at the grid's corners.

    Returns {case: estimated seconds of work} (driver._limits) when every case was validated
    and the study estimates its work (the engine runs the longest cases first), else {}.
    ``checked``, when given, receives the :func:`checked_key` of every set of values found
    good here, so that the batch path's own check (driver.sweep._plan.batch_plan) does not
    validate them a second time."""
    def check(values: dict[str, Any], case_no: int | None) -> limits.Estimate | None:
        try:
            est = limits.check(module, validate(case_raw(raw, Case(0, values)), module.spec, sw.path), "each case ")
            if checked is not None:
                checked.add(checked_key(values))
            return est
        except DeckError as exc:
            name = next((n for n in values if deck_key(n) == exc.key), next(iter(values)))
            key, line = _axis_line(sw, name)
            where = f"case {case_no} (" if case_no else "the value "
            vals = ", ".join(f"{k} = {shown_value(v)}" for k, v in values.items())
            raise DeckError(sw.path, line, key, f"{where}{vals}{')' if case_no else ''} is bad input: "
                            f"{exc.key + ': ' if exc.key else ''}{exc.message}; nothing was run") from None
    estimates: dict[int, float] = {}
    if grid.n <= FULL_VALIDATION:
        for c in iter_cases(grid):
            est = check(c.values, c.index)
            if est is not None:
                estimates[c.index] = est.seconds
        return estimates
    axis_values: dict[str, list] = {}
    for n, vals in zip(grid.names, grid.values):
        axis_values[n] = _unique(vals)
        for v in axis_values[n]:
            check({n: v}, None)
    for combo in _coupled_combinations(sw, module, grid, axis_values):
        check(combo, None)
    return {}


def checked_key(values: dict[str, Any]) -> tuple:
    """The key of a set of swept values (name -> value, in order) that :func:`validate_sweep`
    found good: the names and the values' reprs (as the sweep tells equal values apart)."""
    return tuple((n, repr(v)) for n, v in values.items())


def _unique(values: Iterable[Any]) -> list[Any]:
    """The distinct values of an axis, in their first order."""
    uniq: dict[str, Any] = {}
    for v in values:
        uniq.setdefault(repr(v), v)
    return list(uniq.values())


def _coupled_combinations(sw: Params, module: Any, grid: Grid, axis_values: dict[str, list]) -> Iterator[dict[str, Any]]:
    """Every distinct combination of the coupled axes' values a case of the grid holds (none
    with fewer than two coupled axes: a value alone was validated).  Refused (DeckError) when
    there are more than MAX_CASES of them: a sweep that cannot be validated is not run."""
    independent = set(module.batch.independent) if module.batch is not None else set()
    coupled = [i for i, n in enumerate(grid.names) if deck_key(n) not in independent]
    if len(coupled) < 2:
        return
    names = [grid.names[i] for i in coupled]
    if grid.zipped:
        seen: dict[str, dict[str, Any]] = {}
        for combo in zip(*(grid.values[i] for i in coupled)):
            seen.setdefault(repr(combo), dict(zip(names, combo)))
        yield from seen.values()
        return
    count = math.prod(len(axis_values[n]) for n in names)
    if count > MAX_CASES:
        raise sw.error("key1", f"the swept keys {', '.join(deck_key(n) for n in names)} are checked together "
                       f"by the study, and their {count} combinations are beyond the {MAX_CASES} a sweep validates "
                       "before it runs; coarsen the grid or split the sweep")
    for combo in itertools.product(*(axis_values[n] for n in names)):
        yield dict(zip(names, combo))


def case_raw(raw: RawGroup, case: Case) -> RawGroup:
    """The study group of a case: the base deck's with the case's swept values (whole keys or
    single elements of list keys) in place."""
    values = dict(raw.values)
    for name, v in case.values.items():
        set_swept(values, name, v)
    return RawGroup(raw.name, values, raw.lines, raw.line)


def case_deck_text(study_group: str, params: Params, case: Case, deck_path: Path) -> str:
    """A complete deck for the case (the validated study group, swept values included)."""
    nml = f90nml.Namelist({study_group: {k: v for k, v in params.items() if v is not None and v != [] and v != ""}})
    head = (f"! case {case.index} of sweep deck {deck_path}: "
            + ", ".join(f"{k} = {v!r}" for k, v in case.values.items()) + "\n")
    return head + str(nml) + "\n"

