"""The ``--json`` record: one schema for every engine, built from its outcome (docs/json.md).

Every record has the same top-level keys, then a section of its own engine's::

    {"engine": "run" | "sweep" | "optimize" | "synthesis" | "compare",
     "study": "fourbar", "name": "crank5", "deck": "inputs/crank5.dat",
     "ok": true, "exit_code": 0,
     "messages": [{"level": "warning", "text": "..."}],
     "summary": {...flat headline figures, units in their names...},
     "files": ["crank5.out", ...],          # the files written with it, relative to its folder
     "run": {...}}                          # the engine's own section, named after the engine

The schema is shipped as ``driver/record.schema.json`` (JSON Schema 2020-12, :data:`SCHEMA`).
Values are strict JSON: a number that is not finite is ``null``.  Records are built from the
engines' outcomes alone (nothing is read back from the files).
"""
from __future__ import annotations

import json
import os
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from driver._export import json_safe
from driver._outcome import OptimizeOutcome, Outcome, RunOutcome, StreamedSummary, SweepOutcome, SynthesisOutcome
from driver._result import Result

__all__ = ["SCHEMA", "ENGINES", "record", "result_record", "compare_record", "record_text", "write_record"]

#: the JSON Schema every record follows (shipped with the package)
SCHEMA = Path(__file__).with_name("record.schema.json")
#: the engines, as the records name them (and their sections)
ENGINES = ("run", "sweep", "optimize", "synthesis", "compare")


def _files(paths: Iterable[Path], folder: Path | None) -> list[str]:
    """The paths relative to ``folder`` (the record's own), with forward slashes."""
    return [Path(os.path.relpath(p, folder) if folder is not None else p).as_posix() for p in paths]


def _head(engine: str, study: str | None, name: str | None, deck: Any, ok: bool, exit_code: int,
          messages: Iterable[Mapping[str, str]], summary: Mapping[str, Any], files: list[str],
          section: Mapping[str, Any] | None) -> dict[str, Any]:
    return json_safe({"engine": engine, "study": study or None, "name": name or None,
                      "deck": None if deck is None else str(deck), "ok": bool(ok), "exit_code": int(exit_code),
                      "messages": [dict(m) for m in messages], "summary": dict(summary), "files": files,
                      engine: None if section is None else dict(section)})


def result_record(result: Result, files: Iterable[Path] = (), folder: Path | None = None,
                  name: str | None = None) -> dict[str, Any]:
    """The record of one study run: the result's summary, its warnings and failure as
    messages, the files written with it (``files``, relative to ``folder``); ``name`` the
    outputs' stem when it is not the result's name."""
    params = result.params
    messages = [{"level": "warning", "text": w} for w in result.warnings if w != result.failure]
    if result.failure:
        messages.append({"level": "error", "text": result.failure})
    return _head("run", result.study, name or result.name, getattr(params, "path", None), result.ok,
                 0 if result.ok else 1, messages, result.summary, _files(files, folder),
                 {"failure": result.failure, "warnings": list(result.warnings), "figures": result.figure_names})


def _messages(outcome: Outcome) -> list[dict[str, str]]:
    return [{"level": m.level, "text": m.text} for m in outcome.messages]


def _sweep(outcome: SweepOutcome, files: list[str]) -> dict[str, Any]:
    s = outcome.summary   # a frame, or a lazy handle on streamed rows (only its status column is read)
    section: dict[str, Any] = {"cases": outcome.n_cases, "batch": outcome.batch,
                               "summary_table": next((f for f in files if f.endswith("_summary.parquet")), None),
                               "failed": [{"case": c, "values": v, "error": e} for c, v, e in outcome.failed]}
    study = outcome.study
    if s is not None:
        columns = [str(c) for c in s.columns]
        section.update(rows=len(s), columns=columns, swept_keys=[c for c in columns if "." in c])
        if "status" in columns:
            status = s.to_pandas(["status"])["status"] if isinstance(s, StreamedSummary) else s["status"]
            section["status_counts"] = {str(k): int(v) for k, v in status.value_counts().sort_index().items()}
        study = study or next((c.partition(".")[0] for c in columns if "." in c), "")
    summary = {"cases": outcome.n_cases, "ok": outcome.n_ok, "kept": outcome.n_kept, "failed": outcome.n_failed,
               "resumed": outcome.n_resumed, "redone": outcome.n_redone}
    return _head("sweep", study, outcome.name, outcome.deck, outcome.ok, outcome.exit_code, _messages(outcome),
                 summary, files, section)


def _optimize(outcome: OptimizeOutcome, files: list[str]) -> dict[str, Any]:
    p = outcome.problem
    summary: dict[str, Any] = {"objective": outcome.fun, "success": outcome.success, "status": outcome.status,
                               "nfev": outcome.nfev, "nit": outcome.nit}
    summary.update(outcome.x or {})
    return _head("optimize", p.study.name, outcome.name, p.deck.path, outcome.ok, outcome.exit_code,
                 _messages(outcome), summary, files, outcome.to_dict())


def _synthesis(outcome: SynthesisOutcome, files: list[str]) -> dict[str, Any]:
    syn = outcome.value
    section = {"task": outcome.task, "failure": outcome.failure, "warnings": list(syn.warnings),
               "linkage": outcome.linkage, "checks": outcome.checks,
               "linkage_summary": None if outcome.result is None else dict(outcome.result.summary)}
    study = None if outcome.result is None else outcome.result.study   # the study of the linkage designed
    return _head("synthesis", study, outcome.name, syn.params.path, outcome.ok, outcome.exit_code,
                 _messages(outcome), outcome.checks, files, section)


def compare_record(outcome: Any, deck: str | os.PathLike) -> dict[str, Any]:
    """The record of one deck's comparison with the published tables (a part of
    :func:`driver._compare.compare_decks`, ``deck`` the deck it compared)."""
    section: dict[str, Any] | None = None
    summary: dict[str, Any] = {}
    study = None
    for c in outcome.comparisons:
        frame = c.frame
        counts = frame["status"].value_counts()
        summary = {"cells": len(frame), **{str(k): int(v) for k, v in counts.sort_index().items()}}
        tables = {str(t): {str(k): int(v) for k, v in g["status"].value_counts().sort_index().items()}
                  for t, g in frame.groupby("table", sort=False)}
        off = frame[~frame["status"].isin(["identical", "agrees"])]
        section = {"variant": c.variant, "note": c.note, "tables": tables,
                   "cells": off.drop(columns=["deck"]).to_dict("records")}
        study = c.group if c.params is not None else None   # a control deck (&sweep ...) has no study of its own
    return _head("compare", study, Path(deck).stem, deck, outcome.ok, outcome.exit_code, _messages(outcome),
                 summary, [], section)


def record(outcome: Outcome, folder: Path | None = None) -> dict[str, Any]:
    """The ``--json`` record of an engine's outcome (``folder``: where the record is written;
    the files are named relative to it).

    Parameters
    ----------
    outcome : Outcome
        A :class:`~driver._outcome.RunOutcome`, :class:`~driver._outcome.SweepOutcome`,
        :class:`~driver._outcome.OptimizeOutcome` or :class:`~driver._outcome.SynthesisOutcome`.
    folder : pathlib.Path, optional
        The record's folder; default the file names as the outcome holds them.

    Returns
    -------
    dict
        The record, JSON-safe (no NaN: a number that is not finite is None).
    """
    files = _files(outcome.written, folder)
    if isinstance(outcome, RunOutcome):
        return result_record(outcome.result, outcome.written, folder)
    if isinstance(outcome, SweepOutcome):
        return _sweep(outcome, files)
    if isinstance(outcome, OptimizeOutcome):
        return _optimize(outcome, files)
    if isinstance(outcome, SynthesisOutcome):
        return _synthesis(outcome, files)
    raise TypeError(f"no --json record for {type(outcome).__name__}")


def record_text(rec: Mapping[str, Any], indent: int | None = 1) -> str:
    """A record as strict JSON text (``indent`` None: one line, for JSON Lines)."""
    return json.dumps(rec, indent=indent, allow_nan=False) + "\n"


def write_record(outcome: Outcome, stem: Path) -> Path:
    """Write ``<stem>.json``, the record of ``outcome``; returns its path."""
    from driver._atomic import write_text
    return write_text(stem.with_name(stem.name + ".json"), record_text(record(outcome, stem.parent)))
