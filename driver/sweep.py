"""Sweeps: a ``&sweep`` group turns a deck into a study over many cases.

    &fourbar  fixed_link = 12, crank = 2, coupler = 15, rocker = 9, omega = 5, step_deg = 20 /
    &sweep
      key1 = 'fourbar.crank',   values1 = 2, 3, 4, 5          ! a list ...
      key2 = 'fourbar.coupler', start2 = 14, stop2 = 16, count2 = 3   ! ... or start/stop/count
      zip  = .false.            ! .false.: full grid; .true.: keys varied together
      keep = 'meets_band_40_120 and rocker_swing_deg > 60'   ! optional filter on the summary
      case_outputs = 'all'      ! per-case files for 'all', 'kept' or 'none' of the cases
    /

Every case is a complete deck (the study group with the swept values), validated
and run exactly as a single run would be.  Outputs, for a deck ``<stem>.dat``:

* ``<stem>/case_0001.{dat,out,parquet,json}``: the case deck, its ``.out``, its tidy
  table and its summary (the json is written last and marks the case complete);
* ``<stem>.out``: a fixed-format summary table (one row per case) and failed cases;
* ``<stem>_summary.{csv,parquet}``: one row per case (swept keys + headline figures);
* ``<stem>_cases.{csv,parquet}``: the tidy tables of the written cases, with a
  column for every swept key.

Cases run in worker processes (``--jobs``, default all cores) or on a Dask
cluster (``--scheduler ADDRESS`` or Dask's ``scheduler-address`` configuration; never
the deck: a deck naming a scheduler is refused), in chunks sized so
that scheduling costs little; results are ordered by case whatever the
scheduling.  ``--resume`` skips cases whose outputs are complete.
"""
from __future__ import annotations

import concurrent.futures as cf
import hashlib
import itertools
import json
import math
import os
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterable

import f90nml
import numpy as np
import pandas as pd

from driver import expr, limits, sweep_batch
from driver.atomic import output_set, remove_stale_temporaries, write_text
from driver.deck import Deck, DeckError, GroupSpec, Key, Params, RawGroup, validate
from driver.export import write_tidy
from driver.runner import compute, output_stem, study_of, write_outputs
from driver.study import column_label, load_study
from driver.table import Column, render_table

__all__ = ["SPEC", "Case", "build_cases", "run_sweep_deck", "run_task", "auto_chunk", "MAX_KEYS"]

MAX_KEYS = 9
#: most cases one sweep deck may have (the shipped design search has 102 400)
MAX_CASES = 1_000_000
#: sweeps up to this many cases have every case validated before anything runs
FULL_VALIDATION = 5_000
EXIT_OK, EXIT_FAILED, EXIT_BAD_INPUT = 0, 1, 2


def _no_scheduler_in_deck(value: str) -> str:
    """Key check of ``scheduler``: a deck never chooses where the tool connects."""
    return ("a deck may not choose the Dask scheduler: Dask deserialises what a scheduler sends, so a "
            "hostile address in a shared deck would run code on your machine; remove the key and give "
            "the address on the command line (--scheduler ADDRESS) or in Dask's configuration "
            "(scheduler-address, e.g. the environment variable DASK_SCHEDULER_ADDRESS)")


def _configured_scheduler() -> str:
    """The scheduler address from Dask's own configuration/environment, or ''."""
    try:
        import dask.config
    except ImportError:
        return ""
    return str(dask.config.get("scheduler-address", default=None) or "")


def _spec() -> GroupSpec:
    keys: dict[str, Key] = {}
    for k in range(1, MAX_KEYS + 1):
        keys[f"key{k}"] = Key("str", doc=f"deck key to vary, 'group.key' (axis {k})")
        keys[f"values{k}"] = Key("list", doc="values of that key (numbers or strings)")
        keys[f"start{k}"] = Key("float", doc="first value (with stop and count)")
        keys[f"stop{k}"] = Key("float", doc="last value (inclusive)")
        keys[f"count{k}"] = Key("int", doc="number of values from start to stop")
    keys.update({
        "zip": Key("bool", default=False, doc=".true.: vary the keys together instead of a full grid"),
        "keep": Key("str", default="", doc="filter on the summary columns in the deck expression language (driver.expr): "
                    "comparisons, and/or/not, arithmetic, abs/min/max/sqrt...; swept keys as group.key"),
        "case_outputs": Key("str", default="all", choices=("all", "kept", "none"),
                            doc="which cases get their own .out/.parquet/.json files"),
        "summary_rows": Key("str", default="all", choices=("all", "kept"),
                            doc="which cases go into the _summary tables (large searches: 'kept')"),
        "scheduler": Key("str", check=_no_scheduler_in_deck,
                         doc="refused: the scheduler comes from --scheduler or Dask's configuration"),
        "chunk": Key("int", default=0, check=lambda v: "must not be negative" if v < 0 else None,
                     doc="cases per task; 0 = chosen from the time of the first case"),
        "plot_x": Key("str", default="", doc="summary column (or expression, driver.expr) on the x axis of the summary plot"),
        "plot_y": Key("strs", default=[], doc="summary columns (or expressions) plotted against plot_x"),
    })
    return GroupSpec("sweep", keys, doc="run a study over a grid or list of deck values")


SPEC = _spec()


@dataclass
class Case:
    """One case of a sweep: its number (from 1) and the swept values {'group.key': value}."""

    index: int
    values: dict[str, Any]


@dataclass
class CaseResult:
    """What a worker returns for one case."""

    index: int
    values: dict[str, Any]
    status: int = EXIT_OK
    error: str = ""
    summary: dict[str, Any] = field(default_factory=dict)
    kept: bool = True
    written: bool = False
    warnings: list[str] = field(default_factory=list)
    tidy: pd.DataFrame | None = None
    seconds: float = 0.0


# ----------------------------------------------------------------------------- cases

def _axes(sw: Params, study_group: str, study_spec: GroupSpec) -> list[tuple[str, list]]:
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
        group, _, key = name.lower().partition(".")
        if not key:
            raise sw.error(f"key{k}", f"write the key as 'group.key' (e.g. '{study_group}.{name}')")
        if group != study_group:
            raise sw.error(f"key{k}", f"group '{group}' is not this deck's study group &{study_group}")
        if key not in study_spec.keys:
            raise sw.error(f"key{k}", f"&{study_group} has no key '{key}'")
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
    """Number of cases of the axes (full grid or zipped), computed before any case is built."""
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


def build_cases(sw: Params, study_group: str, study_spec: GroupSpec) -> list[Case]:
    """All cases of the sweep, numbered from 1: a full grid, or zipped axes.

    A sweep of more than :data:`MAX_CASES` cases is refused before a case is built.
    """
    axes = _axes(sw, study_group, study_spec)
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
        if sw[f"key{k}"] is not None and sw[f"key{k}"].lower() == name:
            key = f"values{k}" if sw[f"values{k}"] is not None else f"start{k}"
            return key, sw.line_of(key)
    return "key1", sw.line_of("key1")


def validate_sweep(sw: Params, raw: RawGroup, module: Any, cases: list[Case] | None,
                   axes: list[tuple[str, list]] | None = None) -> None:
    """Refuse the whole sweep (DeckError naming the sweep line and key) before anything runs
    when a case would be bad input: every value of every axis is validated in the base deck,
    and every case too for sweeps up to FULL_VALIDATION cases (else the grid's corners).
    ``cases`` None: a large batch sweep that lists no cases; its ``axes`` are checked."""
    def check(values: dict[str, Any], case_no: int | None) -> None:
        try:
            limits.check(module, validate(_case_raw(raw, Case(0, values)), module.SPEC, sw.path), "each case ")
        except DeckError as exc:
            name = next((n for n in values if n.partition(".")[2] == exc.key), next(iter(values)))
            key, line = _axis_line(sw, name)
            where = f"case {case_no} (" if case_no else "the value "
            vals = ", ".join(f"{k} = {v!r}" for k, v in values.items())
            raise DeckError(sw.path, line, key, f"{where}{vals}{')' if case_no else ''} is bad input: "
                            f"{exc.key + ': ' if exc.key else ''}{exc.message}; nothing was run") from None
    if cases is not None and not cases:
        return
    if cases is not None and len(cases) <= FULL_VALIDATION:
        for c in cases:
            check(c.values, c.index)
        return
    axis_values: dict[str, list] = {}
    names = [n for n, _ in axes] if cases is None else list(cases[0].values)
    for k, n in enumerate(names):
        uniq: dict[str, Any] = {}
        for v in (axes[k][1] if cases is None else (c.values[n] for c in cases)):
            uniq.setdefault(repr(v), v)
        axis_values[n] = list(uniq.values())
        for v in axis_values[n]:
            check({n: v}, None)
    corners = [[vals[0], vals[-1]] if len(vals) > 1 else vals for vals in axis_values.values()]
    for combo in itertools.islice(itertools.product(*corners), 512):
        check(dict(zip(names, combo)), None)


def _case_raw(raw: RawGroup, case: Case) -> RawGroup:
    values = dict(raw.values)
    for name, v in case.values.items():
        values[name.partition(".")[2]] = v
    return RawGroup(raw.name, values, raw.lines, raw.line)


def _case_deck_text(study_group: str, params: Params, case: Case, deck_path: Path) -> str:
    """A complete deck for the case (the validated study group, swept values included)."""
    nml = f90nml.Namelist({study_group: {k: v for k, v in params.items() if v is not None and v != [] and v != ""}})
    head = (f"! case {case.index} of sweep deck {deck_path}: "
            + ", ".join(f"{k} = {v!r}" for k, v in case.values.items()) + "\n")
    return head + str(nml) + "\n"


# ----------------------------------------------------------------------------- worker

@dataclass
class Task:
    """A chunk of cases for one worker (picklable: plain data only)."""

    deck_path: str
    raw: RawGroup
    cases: list[Case]
    case_dir: str
    width: int
    keep: str
    case_outputs: str
    formats: list[str]
    plot: bool
    base_hash: str


def _case_name(index: int, width: int) -> str:
    return f"case_{index:0{width}d}"


def _keep_mask(keep: str, rows: pd.DataFrame) -> np.ndarray:
    """The deck's ``keep`` filter (safe expression language, :mod:`driver.expr`) on summary rows.

    A row whose figures are missing (a failed case) is not kept.
    """
    if not keep:
        return np.ones(len(rows), dtype=bool)
    try:
        return expr.parse(keep).mask(rows)
    except expr.ExprError:   # a column absent from every row of this chunk: nothing kept
        return np.zeros(len(rows), dtype=bool)


def _json_default(o: Any) -> Any:
    if isinstance(o, (np.floating, np.integer)):
        return o.item()
    if isinstance(o, np.bool_):
        return bool(o)
    return str(o)


def _compute(task: Task, case: Case, module) -> tuple[CaseResult, Any, Params | None]:
    """Validate and run (or only summarise) one case; never raises for a case failure."""
    t0 = time.perf_counter()
    res = CaseResult(case.index, case.values)
    result, params = None, None
    try:
        params = validate(_case_raw(task.raw, case), module.SPEC, task.deck_path)
        full = task.case_outputs == "all" or (task.case_outputs == "kept" and not task.keep)
        if full or not hasattr(module, "summarise"):
            result = compute(module, params)
            res.summary = dict(result.summary)
            if result.failure:
                res.status, res.error = EXIT_FAILED, result.failure
        else:
            res.summary = dict(module.summarise(params))
    except DeckError as exc:   # bad input is refused before a sweep runs (validate_sweep): a case
        res.status, res.error = EXIT_FAILED, f"bad input: {exc}"   # failing here fails, the others go on
    except Exception as exc:  # a case that fails is reported, the others go on
        res.status, res.error = EXIT_FAILED, f"{exc.__class__.__name__}: {exc}"
    res.seconds = time.perf_counter() - t0
    return res, result, params


def _kept_many(keep: str, results: list[CaseResult]) -> list[bool]:
    """The keep filter on a chunk of cases at once (vectorised over the chunk)."""
    ok = [r.status == EXIT_OK for r in results]
    if not keep or not results:
        return ok
    rows = pd.DataFrame([{**r.values, **r.summary} for r in results])
    return [o and bool(k) for o, k in zip(ok, _keep_mask(keep, rows))]


def _write_case(task: Task, case: Case, res: CaseResult, result, params: Params, module) -> None:
    """Per-case files: deck, .out (+ extras, figures), tidy parquet, json marker last."""
    t0 = time.perf_counter()
    try:
        if result is None:
            result = compute(module, params)
            if result.failure:
                res.status, res.error = EXIT_FAILED, result.failure
        res.warnings = list(result.warnings)
        stem = Path(task.case_dir) / _case_name(case.index, task.width)
        write_text(stem.with_suffix(".dat"), _case_deck_text(task.raw.name, params, case, Path(task.deck_path)))
        tidy = result.tidy.copy()
        for name, v in reversed(case.values.items()):
            tidy.insert(0, name, v)
        write_outputs(result, stem, [f for f in task.formats if f != "parquet"], task.plot)
        write_tidy(tidy, stem, "parquet")
        res.tidy = tidy
        res.written = True
        record = {"index": case.index, "values": case.values, "base": task.base_hash,
                  "status": res.status, "error": res.error, "summary": res.summary,
                  "kept": res.kept, "warnings": res.warnings}
        write_text(stem.with_suffix(".json"), json.dumps(record, default=_json_default, indent=1))
    except Exception as exc:
        res.status, res.error, res.kept = EXIT_FAILED, f"{exc.__class__.__name__}: {exc}", False
    res.seconds += time.perf_counter() - t0


def run_task(task: Task) -> list[CaseResult]:
    """Run a chunk of cases (the unit of work sent to a process or a Dask worker)."""
    module = load_study(task.raw.name)
    writable = lambda res, result, params: params is not None and (result is not None or res.status == EXIT_OK)
    if task.case_outputs == "all":
        # write each case as soon as it is computed: an interrupt loses at most one case
        # ('kept' is decided once, over all cases, by the caller)
        results = []
        for c in task.cases:
            res, result, params = _compute(task, c, module)
            if writable(res, result, params):
                _write_case(task, c, res, result, params, module)
            results.append(res)
        return results
    computed = [_compute(task, c, module) for c in task.cases]
    results = [r for r, _, _ in computed]
    for r, k in zip(results, _kept_many(task.keep, results)):
        r.kept = k
    if task.case_outputs == "kept":
        for case, (res, result, params) in zip(task.cases, computed):
            if res.kept and writable(res, result, params):
                _write_case(task, case, res, result, params, module)
    return results


# ----------------------------------------------------------------------------- execution

def _chunks(cases: list[Case], size: int) -> list[list[Case]]:
    return [cases[i:i + size] for i in range(0, len(cases), size)]


def auto_chunk(seconds_per_case: float, n_cases: int, workers: int, target: float = 0.1) -> int:
    """Cases per task: enough for ~``target`` s of work, but at least 4 tasks per worker."""
    by_time = math.ceil(target / max(seconds_per_case, 1e-6))
    by_balance = math.ceil(n_cases / (4 * max(workers, 1)))
    return max(1, min(by_time, by_balance))


def _execute(cases: list[Case], task_of, jobs: int, scheduler: Any, chunk: int, progress: bool,
             total: int, done0: int) -> tuple[list[CaseResult], int]:
    """Run cases locally (process pool) or on Dask; returns results (any order) and the chunk used.

    With ``chunk == 0`` the first ``jobs`` cases go out as single-case tasks and the chunk
    size is chosen from the first one that returns, so timing it costs no parallelism.
    """
    from tqdm import tqdm
    bar = tqdm(total=total, initial=done0, unit="case", disable=not progress, dynamic_ncols=True)
    results: list[CaseResult] = []
    workers = jobs if not scheduler else max(jobs, 1)
    first = cases[:max(1, workers)] if not chunk else []
    rest = cases[len(first):]

    def collect(part: list[CaseResult]) -> None:
        results.extend(part)
        bar.update(len(part))

    try:
        if not scheduler and (jobs <= 1 or len(cases) <= 1):
            if not chunk and cases:   # time the first case, then chunks of ~0.1 s (progress granularity)
                collect(run_task(task_of(cases[:1])))
                chunk = auto_chunk(results[-1].seconds, len(cases) - 1, 1)
                cases = cases[1:]
            for cs in _chunks(cases, chunk or 1):
                collect(run_task(task_of(cs)))
            return results, chunk or 1
        if scheduler:
            from dask.distributed import Client, wait
            client = scheduler if not isinstance(scheduler, str) else Client(scheduler)
            submit = lambda t: client.submit(run_task, t, pure=False)
            wait_any = lambda fs: wait(list(fs), return_when="FIRST_COMPLETED")
            workers = len(client.scheduler_info().get("workers", {})) or workers
            close = (lambda: client.close()) if isinstance(scheduler, str) else (lambda: None)
        else:
            # workers ignore Ctrl-C: the parent cancels queued chunks and lets running ones finish,
            # so every case a worker started is written completely
            pool = cf.ProcessPoolExecutor(max_workers=jobs, initializer=sweep_batch.worker_init)
            submit = lambda t: pool.submit(run_task, t)
            wait_any = lambda fs: cf.wait(fs, return_when=cf.FIRST_COMPLETED)
            close = lambda: pool.shutdown(wait=True)
        try:
            pending = {submit(task_of([c])) for c in first}
            if chunk:
                pending |= {submit(task_of(cs)) for cs in _chunks(rest, chunk)}
            while pending:
                done, not_done = wait_any(pending)
                pending = set(not_done)
                for fut in done:
                    part = fut.result()
                    collect(part)
                    if not chunk:   # first result: choose the chunk for everything else
                        chunk = auto_chunk(part[0].seconds, len(rest), workers)
                        pending |= {submit(task_of(cs)) for cs in _chunks(rest, chunk)}
        except KeyboardInterrupt:
            print("interrupt: cancelling queued cases, finishing the running ones", file=sys.stderr)
            if scheduler:
                client.cancel(list(pending))
            else:
                pool.shutdown(wait=True, cancel_futures=True)
            raise
        finally:
            close()
    finally:
        bar.close()
    return results, chunk or 1


# ----------------------------------------------------------------------------- driver entry

def _base_hash(raw: RawGroup) -> str:
    text = json.dumps(raw.values, sort_keys=True, default=str)
    return hashlib.sha256(f"{raw.name}:{text}".encode()).hexdigest()[:16]


def _resumed(case_dir: Path, case: Case, width: int, base: str) -> CaseResult | None:
    """A complete earlier result for this case (same deck values), or None."""
    stem = case_dir / _case_name(case.index, width)
    try:
        rec = json.loads(stem.with_suffix(".json").read_text())
    except (OSError, ValueError):
        return None
    if rec.get("base") != base or rec.get("values") != json.loads(json.dumps(case.values, default=_json_default)):
        return None
    res = CaseResult(case.index, case.values, rec["status"], rec["error"], rec["summary"], rec["kept"], True,
                     rec.get("warnings", []))
    try:
        res.tidy = pd.read_parquet(stem.with_suffix(".parquet"))
    except Exception:
        return None
    return res


def summary_frame(results: list[CaseResult], names: list[str]) -> pd.DataFrame:
    """One row per case: case, swept keys, status, error, kept, headline figures."""
    rows = []
    for r in results:
        row = {"case": r.index, **{n: r.values[n] for n in names},
               "status": {EXIT_OK: "ok", EXIT_FAILED: "failed", EXIT_BAD_INPUT: "bad input"}[r.status],
               "kept": bool(r.kept and r.status == EXIT_OK)}
        row.update(r.summary)
        row["error"] = r.error
        rows.append(row)
    return pd.DataFrame(rows)


def _summary_table(frame: pd.DataFrame, limit: int = 2000, n_cases: int | None = None,
                   rows: str = "all") -> list[str]:
    """Fixed-format rendering of the summary frame (kept and failed cases only above ``limit``
    cases; ``frame`` may hold only those already, then ``n_cases`` is the study's total)."""
    n_cases = len(frame) if n_cases is None else n_cases
    show = frame if n_cases <= limit else frame[frame["kept"] | (frame["status"] != "ok")]
    cols, keys = [], []
    for name in frame.columns:
        if name in ("error",):
            continue
        s = frame[name]
        if pd.api.types.is_bool_dtype(s) or s.map(lambda v: isinstance(v, (bool, np.bool_))).all():
            cols.append(Column(name, "s", max(4, len(name)), 0))
        elif pd.api.types.is_integer_dtype(s):
            cols.append(Column(name, "i", max(5, len(name)), 0))
        elif pd.api.types.is_numeric_dtype(s):
            cols.append(Column(name, "f", max(10, len(name)), 4))
        else:
            cols.append(Column(name, "s", max(6, len(name)), 0))
        keys.append(name)
    rows = []
    for _, r in show.iterrows():
        row = []
        for c, k in zip(cols, keys):
            v = r[k]
            if v is None or (isinstance(v, float) and not math.isfinite(v)):
                row.append("-")
            elif isinstance(v, (bool, np.bool_)):
                row.append("yes" if v else "no")
            elif c.kind == "s":
                row.append(str(v))
            else:
                row.append(v)
        rows.append(row)
    lines = render_table(cols, rows)
    if len(show) < n_cases:
        where = "are in the _summary table only" if rows == "all" else "are not listed (summary_rows = 'kept')"
        lines.append(f"  ({n_cases - len(show)} cases not kept {where})")
    return lines


def run_sweep_deck(deck: Deck, outdir: Path, formats: list[str], plot: bool, progress: bool,
                   quiet: bool = False, jobs: int | None = None, scheduler: Any = None,
                   resume: bool = False) -> int:
    """Run a deck with a &sweep group; returns the exit status (see driver.cli)."""
    sw = validate(deck.groups["sweep"], SPEC, deck.path)
    study_raw = {n: g for n, g in deck.groups.items() if n != "sweep"}
    module, base_params = study_of(Deck(deck.path, study_raw))   # the base deck must be valid on its own
    raw = study_raw[base_params.group]
    axes = _axes(sw, base_params.group, module.SPEC)
    names = [a[0] for a in axes]
    _check_zip(sw, axes)
    grid = sweep_batch.Grid(names, [v for _, v in axes], bool(sw.zip))
    batchable = sweep_batch.batchable(module, names, sw.keep, sw.case_outputs)
    if batchable and grid.n > FULL_VALIDATION:   # no case list: memory stays flat in the number of cases
        if grid.n > sweep_batch.MAX_CASES:
            raise sw.error("key1", f"{grid.n} cases is beyond the {sweep_batch.MAX_CASES} cases of one sweep deck")
        cases = None
        validate_sweep(sw, raw, module, None, axes)
    else:
        cases = build_cases(sw, base_params.group, module.SPEC)
        validate_sweep(sw, raw, module, cases)
    named = [(k, v) for k, v in [("keep", sw.keep), ("plot_x", sw.plot_x)] + [("plot_y", y) for y in sw.plot_y] if v]
    if named:   # check the filter and plotted columns on the base deck's summary before running anything
        probe = (module.summarise(base_params) if hasattr(module, "summarise")
                 else compute(module, base_params).summary)
        columns = [*names, *probe, "case"]
        for key, text in named:
            try:
                expr.parse(text, columns)
            except expr.ExprError as exc:
                raise sw.error(key, f"{exc.message}" + (f" (at '{exc.token}')" if exc.token else "")
                               + ("" if key == "keep" else f"; summary columns: {', '.join(columns)}")) from None
    stem_path = output_stem(outdir, deck.path)
    stem = stem_path.name
    case_dir = stem_path
    width = max(4, len(str(grid.n)))
    base = _base_hash(raw)
    scheduler = scheduler or _configured_scheduler()
    jobs = jobs or os.cpu_count() or 1
    task_of = lambda cs: Task(str(deck.path), raw, cs, str(case_dir), width, sw.keep, sw.case_outputs,
                              formats, plot, base)
    if batchable:
        bplan = sweep_batch.plan(module, raw, str(deck.path), grid, sw.keep, sw.summary_rows)
        if bplan is not None:
            return _run_batch(deck, sw, base_params, bplan, axes, outdir, stem, task_of, plot, progress,
                              quiet, jobs, scheduler, resume)
        if cases is None:
            cases = build_cases(sw, base_params.group, module.SPEC)

    done: list[CaseResult] = []
    todo = cases
    if resume:
        done = [r for r in (_resumed(case_dir, c, width, base) for c in cases) if r is not None]
        skip = {r.index for r in done}
        todo = [c for c in cases if c.index not in skip]
        if not quiet:
            print(f"resume: {len(skip)} of {len(cases)} cases complete, {len(todo)} to run")
    t_start = time.perf_counter()
    ran, chunk = _execute(todo, task_of, jobs, scheduler, sw.chunk, progress, len(cases), len(cases) - len(todo))
    done += ran
    elapsed = time.perf_counter() - t_start
    done.sort(key=lambda r: r.index)
    for r, k in zip(done, _kept_many(sw.keep, done)):   # one vectorised filter over every case
        r.kept = k

    frame = summary_frame(done, names)
    table = frame if sw.summary_rows == "all" else frame[frame["kept"] | (frame["status"] != "ok")]
    failed = [r for r in done if r.status != EXIT_OK]
    text = _sweep_text(deck, sw, base_params, axes, len(cases), frame, int(frame["kept"].sum()),
                       [(r.index, r.values, r.error) for r in failed], sw.summary_rows)
    remove_stale_temporaries(outdir, stem)
    with output_set(outdir):   # the sweep's own files: all renamed into place together, or none
        for fmt in ("csv", "parquet"):
            write_tidy(table, outdir / f"{stem}_summary", fmt)
        tidies = [r.tidy for r in done if r.tidy is not None]
        if tidies:
            allcases = pd.concat(tidies, ignore_index=True)
            for fmt in ("csv", "parquet"):
                write_tidy(allcases, outdir / f"{stem}_cases", fmt)
        write_text(outdir / f"{stem}.out", text)
        if plot:
            from driver.plotting import save_figure, sweep_summary
            shown = frame.copy()
            for name in [sw.plot_x, *sw.plot_y]:   # a plotted expression becomes a column
                if name and name not in shown.columns:
                    shown[name] = expr.parse(name).evaluate(shown)
            labels = {c: column_label(module, c) for c in shown.columns}
            save_figure(sweep_summary(shown, names, sw.plot_x, sw.plot_y, stem, labels,
                                      getattr(module, "SWEEP_PLOT", ())), outdir / f"{stem}_summary.png", plot)
    for r in done:
        for w in r.warnings:
            print(f"warning: {deck.path}: case {r.index}: {w}", file=sys.stderr)
    for r in failed:
        vals = ", ".join(f"{k} = {v!r}" for k, v in r.values.items())
        print(f"error: {deck.path}: case {r.index} ({vals}): {r.error}", file=sys.stderr)
    if not quiet:
        n_ok = len(done) - len(failed)
        print(f"sweep {deck.path}: {n_ok} of {len(cases)} cases ok, {int(frame['kept'].sum())} kept, "
              f"{elapsed:.2f} s ({'dask ' + str(scheduler) if scheduler else f'{jobs} worker(s)'}, chunk {chunk})")
        print(f"wrote {outdir / (stem + '.out')} and {outdir / stem}_summary.{{csv,parquet}}")
    return max([EXIT_OK] + [r.status for r in failed])


def _run_batch(deck: Deck, sw: Params, base_params: Params, bplan, axes, outdir: Path, stem: str, task_of,
               plot: bool, progress: bool, quiet: bool, jobs: int, scheduler: Any, resume: bool) -> int:
    """A sweep on the study's batch path (driver.sweep_batch); same outputs as case by case."""
    names = [a[0] for a in axes]
    n = bplan.grid.n
    t_start = time.perf_counter()

    def announce(resumed: int) -> None:
        if resume and not quiet:
            print(f"resume: {resumed} of {n} cases complete, {n - resumed} to run")

    rows, counts, chunk = sweep_batch.run(bplan, outdir / f"{stem}.sweep", jobs, scheduler, resume, progress,
                                          sw.chunk, announce)
    elapsed = time.perf_counter() - t_start
    if rows.empty:
        rows = pd.DataFrame(columns=["case", *names, "status", "kept", "error"])
    tidies = []
    if sw.case_outputs == "kept" and counts["kept"]:   # the kept cases' own files, case by case
        kept = rows[rows["kept"]]
        cases = [Case(int(r["case"]), {k: (r[k].item() if hasattr(r[k], "item") else r[k]) for k in names})
                 for _, r in kept.iterrows()]
        done, _ = _execute(cases, task_of, jobs, scheduler, 0, False, len(cases), 0)
        done.sort(key=lambda r: r.index)
        tidies = [r.tidy for r in done if r.tidy is not None]
        for r in done:
            if r.status != EXIT_OK:
                rows.loc[rows["case"] == r.index, ["status", "kept", "error"]] = ["failed", False, r.error]
    bad = rows[rows["status"] != "ok"]
    failed = [(int(r["case"]), {k: r[k] for k in names}, r["error"]) for _, r in bad.iterrows()]
    text = _sweep_text(deck, sw, base_params, axes, n, rows, int(rows["kept"].sum()), failed, sw.summary_rows)
    remove_stale_temporaries(outdir, stem)
    with output_set(outdir):   # the sweep's own files: all renamed into place together, or none
        for fmt in ("csv", "parquet"):
            write_tidy(rows, outdir / f"{stem}_summary", fmt)
        if tidies:
            allcases = pd.concat(tidies, ignore_index=True)
            for fmt in ("csv", "parquet"):
                write_tidy(allcases, outdir / f"{stem}_cases", fmt)
        write_text(outdir / f"{stem}.out", text)
        if plot:   # the summary only (per-case figures only for case_outputs with --plot)
            from driver.plotting import save_figure, sweep_summary
            shown = rows.copy()
            for name in [sw.plot_x, *sw.plot_y]:   # a plotted expression becomes a column
                if name and name not in shown.columns:
                    shown[name] = expr.parse(name).evaluate(shown)
            save_figure(sweep_summary(shown, names, sw.plot_x, sw.plot_y, stem), outdir / f"{stem}_summary.png")
    for index, values, error in failed[:20]:
        vals = ", ".join(f"{k} = {v!r}" for k, v in values.items())
        print(f"error: {deck.path}: case {index} ({vals}): {error}", file=sys.stderr)
    if len(failed) > 20:
        print(f"error: {deck.path}: ... and {len(failed) - 20} more failed cases (see {stem}.out)", file=sys.stderr)
    if not quiet:
        print(f"sweep {deck.path}: {n - len(failed)} of {n} cases ok, {int(rows['kept'].sum())} kept, "
              f"{elapsed:.2f} s, {n / max(elapsed, 1e-9):.0f} cases/s "
              f"({'dask ' + str(scheduler) if scheduler else f'{jobs} worker(s)'}, batch path, chunk {chunk})")
        print(f"wrote {outdir / (stem + '.out')} and {outdir / stem}_summary.{{csv,parquet}}")
    if failed:
        return EXIT_BAD_INPUT if (bad["status"] == "bad input").any() else EXIT_FAILED
    return EXIT_OK


def _sweep_text(deck: Deck, sw: Params, base: Params, axes: list[tuple[str, list]], n_cases: int,
                frame: pd.DataFrame, n_kept: int, failed: list[tuple[int, dict, str]], rows: str) -> str:
    """The sweep's fixed-format .out: axes, counts, the summary table, failed cases."""
    lines = [f"  sweep over &{base.group} from deck {deck.path}", ""]
    for name, values in axes:
        vals = list(dict.fromkeys(values))   # deck order
        fmt = lambda v: v if isinstance(v, str) else f"{v:.6g}"
        shown = (", ".join(map(fmt, vals[:8])) if len(vals) <= 8 else
                 f"{fmt(vals[0])}, {fmt(vals[1])}, ..., {fmt(vals[-1])} ({len(vals)} values)")
        lines.append(f"    {name:<28} {shown}")
    lines += [f"    {'cases':<28} {n_cases} ({'zipped' if sw.zip else 'full grid'})",
              f"    {'case outputs':<28} {sw.case_outputs}" + (f"   keep: {sw.keep}" if sw.keep else ""),
              f"    {'kept':<28} {n_kept}",
              f"    {'failed':<28} {len(failed)}", ""]
    lines += _summary_table(frame, n_cases=n_cases, rows=rows)
    if failed:
        lines += ["", "  Failed cases"]
        for index, values, error in failed[:1000]:
            vals = ", ".join(f"{k} = {v!r}" for k, v in values.items())
            lines.append(f"    case {index} ({vals}): {error}")
        if len(failed) > 1000:
            lines.append(f"    ... and {len(failed) - 1000} more (status column of the _summary table)")
    return "\n".join(lines) + "\n"
