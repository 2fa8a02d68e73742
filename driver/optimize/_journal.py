"""The resume records of an ``&optimize`` run, each with a checksum of its content that is
verified on ``--resume`` (a resume record is verified, never believed: issue 23).

Two records can replay a run (:func:`read`):

* ``<stem>.journal.jsonl`` -- while the run goes, one line per computed design:
  ``{"sha256": d, "record": r}``, r = {"base", "code", "x", "status", "reason", "summary"} and d
  the first :data:`~driver._atomic.DIGEST_CHARS` hex characters of the sha256 of r's canonical
  JSON (sorted keys, no spaces: :func:`canonical`).  A JSON round trip gives the same text back
  (floats print as their shortest repr), so the reader recomputes d from what it parsed.
* ``<stem>_evals.parquet`` -- a finished run's table (the journal is removed then).  Its
  ``attrs`` (kept in the Parquet file's pandas metadata) carry ``code_sha256`` and
  ``record_sha256``: one digest per row, of the record that row replays (:func:`table_records`),
  computed from the frame as it is written (:func:`stamp`); Parquet gives the same values back.

A record is bound to everything that decides its values: ``base`` is the problem's fingerprint
(:meth:`~driver.optimize._problem.Problem.fingerprint`: the study group as written, the
variables in order with their bounds, the objective, the constraints and the method's
settings) and ``code`` the digest of the code that computes a design
(:meth:`~driver.optimize._problem.Problem.code_digest`).  It is replayed only into the same
problem computed by the same code.

Nothing is believed that fails a check: a line that is not complete JSON (cut by an interrupt,
a damaged byte), a record whose digest does not match its content (an edited digit), a record
not of the shape this tool writes (a summary that is not a table of numbers, texts and
logicals, a design of another length), a record of another problem or of other code, a table
row without a matching digest, a table that cannot be read, a journal or table that is a
symbolic link.  Its design is computed again when the run asks for it, and
:attr:`Resumed.redone` counts them by reason for the command line's warning.
"""
from __future__ import annotations

import hashlib
import io
import json
import math
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from driver._atomic import DIGEST_CHARS, read_own

if TYPE_CHECKING:   # pragma: no cover
    from driver.optimize._problem import Problem

__all__ = ["SUFFIX", "DIGEST_KEY", "CODE_KEY", "STATUSES", "Resumed", "canonical", "digest", "journal_path", "line",
           "read", "record", "stamp", "table_digests", "table_records", "shape_error"]

#: the journal's name is the deck's stem plus this
SUFFIX = ".journal.jsonl"
#: the key of the ``_evals`` table's attrs holding its rows' digests
DIGEST_KEY = "record_sha256"
#: the key of the ``_evals`` table's attrs holding the digest of the code that computed it
CODE_KEY = "code_sha256"
#: the outcomes an evaluation records (driver.optimize._evaluate.evaluate_cases)
STATUSES = ("ok", "bad_input", "refused", "failed")
#: the largest journal or table read back [bytes] (a run of MAX_EVALS designs writes less)
MAX_RECORD_BYTES = 1 << 31
#: why a record of another problem or of other code is not replayed
ANOTHER_PROBLEM = ("it was written for another problem (the study group, the variables, their order or bounds, "
                   "the objective, the constraints or the method's settings differ)")
OTHER_CODE = "it was computed by other code (the tool changed since)"


def journal_path(stem: Path) -> Path:
    """``<stem>.journal.jsonl`` beside the run's outputs."""
    return stem.with_name(stem.name + SUFFIX)


def _plain(o: Any) -> Any:
    if isinstance(o, (np.floating, np.integer)):
        return o.item()
    if isinstance(o, np.bool_):
        return bool(o)
    return str(o)


def record(base: str, code: str, x: tuple[float, ...] | list[float], status: str, reason: str,
           summary: dict) -> dict:
    """One evaluation as a resume record: the problem's fingerprint, the code's digest, the design
    x, the outcome."""
    return {"base": base, "code": code, "x": [float(v) for v in x], "status": status, "reason": reason,
            "summary": summary}


_RECORD_KEYS = frozenset(("base", "code", "x", "status", "reason", "summary"))


def shape_error(rec: Any, nvars: int) -> str:
    """'' when ``rec`` has the shape :func:`record` gives (whatever its checksum says), else what
    is wrong: a record is replayed only when every field is of its kind."""
    if not isinstance(rec, dict) or set(rec) != _RECORD_KEYS:
        return "its fields are not those of a record"
    if not isinstance(rec["base"], str) or not isinstance(rec["code"], str):
        return "its fingerprint is not a text"
    x = rec["x"]
    if not isinstance(x, list) or len(x) != nvars or not all(
            isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in x):
        return f"its design is not {nvars} finite number(s)"
    if rec["status"] not in STATUSES or not isinstance(rec["reason"], str):
        return "its status is not one of " + ", ".join(STATUSES)
    summary = rec["summary"]
    if not isinstance(summary, dict) or not all(
            isinstance(k, str) and (v is None or isinstance(v, (bool, int, float, str))) for k, v in summary.items()):
        return "its summary is not a table of numbers, texts and logicals"
    if rec["status"] == "ok" and not summary:
        return "it has no summary"
    return ""


def canonical(rec: dict) -> str:
    """The record's canonical JSON text (sorted keys, no spaces; numpy scalars made plain)."""
    return json.dumps(rec, default=_plain, sort_keys=True, separators=(",", ":"))


def digest(rec: dict) -> str:
    """sha256 of the canonical text (first DIGEST_CHARS hex characters)."""
    return hashlib.sha256(canonical(rec).encode()).hexdigest()[:DIGEST_CHARS]


def line(rec: dict) -> str:
    """The journal line of a record, newline included."""
    text = canonical(rec)
    return '{"sha256":"' + hashlib.sha256(text.encode()).hexdigest()[:DIGEST_CHARS] + '","record":' + text + "}\n"


def table_records(frame: Any, names: list[str], code: str) -> list[dict]:
    """The resume record each row of an ``_evals`` table replays (variables ``names``, computed by
    code ``code``); NaN in a summary column is None, numpy scalars are plain."""
    summ = [c for c in frame.columns if c.startswith("summary.")]
    out = []
    for rec in frame.to_dict("records"):
        summary = {c[len("summary."):]: (None if isinstance(rec[c], float) and math.isnan(rec[c]) else rec[c])
                   for c in summ}
        summary = {k: (v.item() if v is not None and hasattr(v, "item") else v) for k, v in summary.items()}
        reason = rec["case_error"]
        out.append(record(str(rec["base"]), code, [rec[n] for n in names], str(rec["status"]),
                          "" if reason is None or (isinstance(reason, float) and math.isnan(reason)) else str(reason),
                          summary))
    return out


def table_digests(frame: Any, names: list[str], code: str) -> list[str]:
    """The digests to keep in ``frame.attrs[DIGEST_KEY]`` before the table is written."""
    return [digest(r) for r in table_records(frame, names, code)]


def stamp(frame: Any, problem: Problem) -> None:
    """Bind an ``_evals`` table (its ``base`` column written) to its problem and code: the code's
    digest and one digest per row in its attrs, verified on ``--resume``."""
    code = problem.code_digest()
    frame.attrs[CODE_KEY] = code
    frame.attrs[DIGEST_KEY] = table_digests(frame, problem.names, code)


@dataclass
class Resumed:
    """What a resume found: the records believed, and the ones not, counted by reason."""

    rows: list[dict] = field(default_factory=list)
    redone: Counter = field(default_factory=Counter)

    def note(self) -> str:
        """'' when every record was verified, else one sentence: how many and why."""
        if not self.redone:
            return ""
        n = sum(self.redone.values())
        why = "; ".join(f"{c} because {w}" for w, c in self.redone.items())
        return (f"{n} evaluation record(s) not replayed, their designs computed again ({why}): the record is "
                "verified, never believed")


def _journal_rows(path: Path, fp: str, code: str, nvars: int, found: Resumed) -> None:
    data = read_own(path, MAX_RECORD_BYTES)
    if data is None:
        found.redone["the journal cannot be read (a symbolic link, not a regular file, or unreadable)"] += 1
        return
    for raw in data.decode("utf-8", errors="replace").splitlines():
        if not raw.strip():
            continue
        try:
            obj = json.loads(raw)
        except ValueError:
            found.redone["a journal line is not complete (cut by an interrupt, or damaged)"] += 1
            continue
        rec = obj.get("record") if isinstance(obj, dict) else None
        if not isinstance(rec, dict) or not isinstance(obj.get("sha256"), str):
            found.redone["a journal line carries no checksummed record"] += 1
            continue
        if digest(rec) != obj["sha256"]:
            found.redone["a journal record failed its checksum"] += 1
            continue
        why = shape_error(rec, nvars)
        if why:
            found.redone[f"a journal record is not of the shape this tool writes ({why})"] += 1
            continue
        if rec["base"] != fp:
            found.redone[ANOTHER_PROBLEM] += 1
            continue
        if rec["code"] != code:
            found.redone[OTHER_CODE] += 1
            continue
        found.rows.append(rec)


def _table_rows(path: Path, fp: str, code: str, names: list[str], found: Resumed) -> None:
    import pandas as pd
    data = read_own(path, MAX_RECORD_BYTES)
    try:
        if data is None:
            raise OSError("not read")
        frame = pd.read_parquet(io.BytesIO(data))
    except Exception:               # any damage: pyarrow raises several kinds
        found.redone[f"{path.name} cannot be read (damaged, a symbolic link or not a regular file)"] += 1
        return
    if "base" not in frame or "case_error" not in frame or "status" not in frame \
            or not set(names) <= set(frame.columns):
        if "base" in frame:
            found.redone[f"{path.name}: {ANOTHER_PROBLEM}"] += len(frame)
        else:
            found.redone[f"{path.name} is not an evaluations table"] += 1
        return
    digests = frame.attrs.get(DIGEST_KEY)
    mine = (frame["base"] == fp).to_numpy()
    if (~mine).any():
        found.redone[f"{path.name}: {ANOTHER_PROBLEM}"] += int((~mine).sum())
    if not mine.any():
        return
    if not isinstance(digests, list) or len(digests) != len(frame):
        found.redone[f"{path.name} carries no checksums"] += int(mine.sum())
        return
    if frame.attrs.get(CODE_KEY) != code:
        found.redone[f"{path.name}: {OTHER_CODE}"] += int(mine.sum())
        return
    try:
        recs = table_records(frame, names, code)
    except Exception:               # a column of the wrong kind: not this tool's table
        found.redone[f"{path.name} is not an evaluations table"] += int(mine.sum())
        return
    for rec, d, ok in zip(recs, digests, mine):
        if not ok:
            continue
        if digest(rec) != d:
            found.redone[f"a row of {path.name} failed its checksum"] += 1
            continue
        why = shape_error(rec, len(names))
        if why:
            found.redone[f"a row of {path.name} is not of the shape this tool writes ({why})"] += 1
            continue
        found.rows.append(rec)


def read(problem: Problem, stem: Path) -> Resumed:
    """The verified records of an earlier run of ``problem`` (the same fingerprint and code): its
    journal, and a finished run's ``_evals`` table beside ``stem``; neither is read through a
    symbolic link."""
    import os
    found = Resumed()
    fp, code, names = problem.fingerprint(), problem.code_digest(), problem.names
    journal = journal_path(stem)
    if os.path.lexists(journal):
        _journal_rows(journal, fp, code, len(names), found)
    table = stem.with_name(stem.name + "_evals.parquet")
    if os.path.lexists(table):
        _table_rows(table, fp, code, names, found)
    return found
