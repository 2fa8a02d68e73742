"""The resume records of an ``&optimize`` run, each with a checksum of its content that is
verified on ``--resume`` (a resume record is verified, never believed: issue 23).

Two records can replay a run (:func:`read`):

* ``<stem>.journal.jsonl`` -- while the run goes, one line per computed design:
  ``{"sha256": d, "record": r}``, r = {"base", "x", "status", "reason", "summary"} and d the
  first :data:`~driver._atomic.DIGEST_CHARS` hex characters of the sha256 of r's canonical JSON
  (sorted keys, no spaces: :func:`canonical`).  A JSON round trip gives the same text back
  (floats print as their shortest repr), so the reader recomputes d from what it parsed.
* ``<stem>_evals.parquet`` -- a finished run's table (the journal is removed then).  Its
  ``attrs`` (kept in the Parquet file's pandas metadata) carry ``record_sha256``: one digest per
  row, of the record that row replays (:func:`table_records`), computed from the frame as it is
  written; Parquet gives the same values back.

A line that is not complete JSON (cut by an interrupt, a damaged byte), a record whose digest
does not match its content (an edited digit), a table row without a matching digest, or a table
that cannot be read is not replayed: its design is computed again when the run asks for it, and
:attr:`Resumed.redone` counts them by reason for the command line's warning.  Records of another
problem (the deck changed since: a different ``base`` fingerprint) are ignored silently, as
before.
"""
from __future__ import annotations

import hashlib
import json
import math
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from driver._atomic import DIGEST_CHARS

__all__ = ["SUFFIX", "DIGEST_KEY", "Resumed", "canonical", "digest", "journal_path", "line", "read",
           "record", "table_digests", "table_records"]

#: the journal's name is the deck's stem plus this
SUFFIX = ".journal.jsonl"
#: the key of the ``_evals`` table's attrs holding its rows' digests
DIGEST_KEY = "record_sha256"


def journal_path(stem: Path) -> Path:
    """``<stem>.journal.jsonl`` beside the run's outputs."""
    return stem.with_name(stem.name + SUFFIX)


def _plain(o: Any) -> Any:
    if isinstance(o, (np.floating, np.integer)):
        return o.item()
    if isinstance(o, np.bool_):
        return bool(o)
    return str(o)


def record(base: str, x: tuple[float, ...] | list[float], status: str, reason: str, summary: dict) -> dict:
    """One evaluation as a resume record: the problem's fingerprint, the design x, the outcome."""
    return {"base": base, "x": [float(v) for v in x], "status": status, "reason": reason, "summary": summary}


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


def table_records(frame: Any, names: list[str]) -> list[dict]:
    """The resume record each row of an ``_evals`` table replays (variables ``names``); NaN in a
    summary column is None, numpy scalars are plain."""
    summ = [c for c in frame.columns if c.startswith("summary.")]
    out = []
    for rec in frame.to_dict("records"):
        summary = {c[len("summary."):]: (None if isinstance(rec[c], float) and math.isnan(rec[c]) else rec[c])
                   for c in summ}
        summary = {k: (v.item() if v is not None and hasattr(v, "item") else v) for k, v in summary.items()}
        reason = rec["case_error"]
        out.append(record(str(rec["base"]), [rec[n] for n in names], str(rec["status"]),
                          "" if reason is None or (isinstance(reason, float) and math.isnan(reason)) else str(reason),
                          summary))
    return out


def table_digests(frame: Any, names: list[str]) -> list[str]:
    """The digests to keep in ``frame.attrs[DIGEST_KEY]`` before the table is written."""
    return [digest(r) for r in table_records(frame, names)]


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


def _journal_rows(path: Path, fp: str, nvars: int, found: Resumed) -> None:
    try:
        text = path.read_bytes().decode("utf-8", errors="replace")
    except OSError:
        found.redone["the journal cannot be read"] += 1
        return
    for raw in text.splitlines():
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
        if rec.get("base") != fp or not isinstance(rec.get("x"), list) or len(rec["x"]) != nvars:
            continue                    # another problem's record (the deck has changed)
        found.rows.append(rec)


def _table_rows(path: Path, fp: str, names: list[str], found: Resumed) -> None:
    import pandas as pd
    try:
        frame = pd.read_parquet(path)
    except Exception:               # any damage: pyarrow raises several kinds
        found.redone[f"{path.name} cannot be read"] += 1
        return
    if "base" not in frame or "case_error" not in frame or "status" not in frame \
            or not set(names) <= set(frame.columns):
        return                          # another problem's table
    digests = frame.attrs.get(DIGEST_KEY)
    mine = (frame["base"] == fp).to_numpy()
    if not isinstance(digests, list) or len(digests) != len(frame):
        if mine.any():
            found.redone[f"{path.name} carries no checksums"] += int(mine.sum())
        return
    for rec, d, ok in zip(table_records(frame, names), digests, mine):
        if not ok:
            continue
        if digest(rec) != d:
            found.redone[f"a row of {path.name} failed its checksum"] += 1
            continue
        found.rows.append(rec)


def read(fingerprint: str, names: list[str], stem: Path) -> Resumed:
    """The verified records of an earlier run of the problem (fingerprint, variables ``names``):
    its journal, and a finished run's ``_evals`` table."""
    found = Resumed()
    journal = journal_path(stem)
    if journal.is_file():
        _journal_rows(journal, fingerprint, len(names), found)
    table = stem.with_name(stem.name + "_evals.parquet")
    if table.is_file():
        _table_rows(table, fingerprint, names, found)
    return found
