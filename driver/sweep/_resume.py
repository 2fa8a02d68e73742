"""What a sweep keeps on disk between runs: its resume record, the folders of its case files,
and the lock that lets one run at a time write them.

**The record, one format for both kinds of chunk.**  ``<outdir>/<stem>.sweep/`` (for the kept
cases' files of a batch sweep, ``<stem>.sweep/cases/``) holds one Parquet part per chunk of the
sweep's chunk layout, named ``part-<first>-<digest>.parquet``: the chunk's first position
(0-based) in the sweep's sequence of cases, and the sha256 of the part's bytes.  The layout is
a function of the number of cases only (:func:`driver.sweep._plan.chunk_size`), so a part is
found again whatever ``-j`` or scheduler resumes the sweep.  The part's metadata (key
``sweep``) holds the sweep's *signature*, the kind of chunk (``'batch'`` or ``'cases'``), the
chunk's span and its counts; its rows are what the chunk function returned
(:mod:`driver.sweep._chunks`): for a batch chunk the summary rows themselves (only the kept
and failed ones with ``summary_rows = 'kept'``), for a per-case chunk one row per case with
its status, values, summary, the files it wrote and the digest of each.  Parts are written
atomically, by the worker that computed the chunk (the driver writes the part of a chunk it
had to assemble: a worker died, rows were reused, or Dask workers cannot see the folder).

The signature (:func:`signature`) hashes what the rows depend on: the base deck, the sweep's
options, the package version and the bytes of the study package, the runner, table and
export modules and the kernel extension; a part of another signature is removed.

**Verified, never believed.**  On ``--resume`` (:meth:`Record.open`) a part counts only when
its bytes match the checksum its name carries and its signature and kind are this sweep's.  A
batch part then stands for its whole chunk.  A per-case part's rows count one by one: a case is
complete when its newest row has status ok, holds the values the grid now gives that case, and
every file it wrote is still there byte for byte (opened without following a link); so a
changed grid re-runs the cases whose values changed, and a deleted ``.out`` re-runs its case.
Whatever fails verification runs again and is counted by reason (:attr:`Record.redone`); a
part cut short counts every case of its chunk (its span from the layout, its start from its
name).  The record's folders are never symbolic links, and :func:`sweep_lock` lets one run at
a time write them.
"""
from __future__ import annotations

import contextlib
import hashlib
import json
import os
import re
import time
from collections import Counter
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

import driver
from driver._atomic import DIGEST_CHARS, atomic_open, file_digest, own_folder, refuse_link, remove_stale_temporaries
from driver._deck import RawGroup
from driver._errors import DriverError
from driver._outcome import ExitCode
from driver.sweep._spec import CaseResult, Grid, case_at

__all__ = ["Layout", "layout_for", "Record", "signature", "case_signature", "json_default", "remove_stale_case_files",
           "clean_temporaries", "sweep_lock", "SweepBusy", "write_part", "SHARD", "FLAT_MAX"]

#: sweeps up to this many cases keep every case's files in one folder <stem>/
FLAT_MAX = 1000
#: cases per sub-folder <stem>/<first>-<last>/ of a larger sweep
SHARD = 1000

_CASE_FILE = re.compile(r"^case_(\d+)[._]")
_SHARD_DIR = re.compile(r"^(\d+)-(\d+)$")
_PART = re.compile(rf"^part-(\d{{12}})-([0-9a-f]{{{DIGEST_CHARS}}})\.parquet$")
#: why a case runs again although the record held it (the command line's warning says so)
DAMAGED = "a record part failed its checksum"
UNREADABLE = "a record part was cut short or cannot be read"


def json_default(o: Any) -> Any:
    """JSON for numpy scalars (values and summaries of cases)."""
    if isinstance(o, np.bool_):
        return bool(o)
    if isinstance(o, (np.floating, np.integer)):
        return o.item()
    return str(o)


# ----------------------------------------------------------------------------- case files

@dataclass(frozen=True)
class Layout:
    """Where case ``index`` writes its files: ``root/case_0001.*`` (flat) or
    ``root/<first>-<last>/case_000001.*`` with ``shard`` cases per folder."""

    root: str
    width: int
    shard: int = 0

    def name(self, index: int) -> str:
        return f"case_{index:0{self.width}d}"

    def folder(self, index: int) -> str:
        """The folder of case ``index`` relative to the root ('' when flat)."""
        if not self.shard:
            return ""
        lo = (index - 1) // self.shard * self.shard + 1
        return f"{lo:0{self.width}d}-{lo + self.shard - 1:0{self.width}d}"

    def stem(self, index: int) -> Path:
        return Path(self.root) / self.folder(index) / self.name(index)

    def rel(self, index: int) -> str:
        """The stem of case ``index``'s files relative to the root, '/'-separated."""
        folder = self.folder(index)
        return f"{folder}/{self.name(index)}" if folder else self.name(index)


def layout_for(case_dir: str | Path, n_cases: int) -> Layout:
    """The layout of a sweep of ``n_cases``: flat up to :data:`FLAT_MAX` cases, else sharded."""
    return Layout(str(case_dir), max(4, len(str(n_cases))), SHARD if n_cases > FLAT_MAX else 0)


def clean_temporaries(layout: Layout) -> None:
    """Remove the temporaries of case files whose writer died (SIGKILL), in every case folder."""
    root = Path(layout.root)
    refuse_link(root)
    remove_stale_temporaries(root, "case_")
    with contextlib.suppress(OSError):
        for e in os.scandir(root):
            if e.is_dir(follow_symlinks=False) and _SHARD_DIR.match(e.name):
                remove_stale_temporaries(e.path, "case_")


def remove_stale_case_files(layout: Layout, has_files: np.ndarray) -> int:
    """Remove case files (``case_<n>.*``, ``case_<n>_*``) in the case folder that are not this
    sweep's: beyond its last case (a shrunken grid), of a case that writes no files now, or in
    another layout (numbering width, sharding); then empty shard folders and an empty case
    folder.  Other files are left alone.  Returns the number of files removed."""
    root = Path(layout.root)
    n = len(has_files) - 1
    removed = 0

    def sweep_folder(path: Path, folder: str) -> None:
        nonlocal removed
        with contextlib.suppress(OSError):
            for e in os.scandir(path):
                m = _CASE_FILE.match(e.name)
                if not m or not e.is_file(follow_symlinks=False):
                    continue
                k = int(m.group(1))
                ours = (len(m.group(1)) == layout.width and 1 <= k <= n and bool(has_files[k])
                        and layout.folder(k) == folder)
                if not ours:
                    with contextlib.suppress(OSError):
                        os.unlink(e.path)
                        removed += 1

    refuse_link(root)
    if not root.is_dir():
        return 0
    sweep_folder(root, "")
    with contextlib.suppress(OSError):
        for e in os.scandir(root):
            if e.is_dir(follow_symlinks=False) and _SHARD_DIR.match(e.name):
                sweep_folder(Path(e.path), e.name)
                with contextlib.suppress(OSError):
                    os.rmdir(e.path)   # only when empty
    with contextlib.suppress(OSError):
        os.rmdir(root)
    return removed


# ----------------------------------------------------------------------------- signature and lock

def signature(identity: list, module: Any) -> str:
    """The signature a part of a resume record must carry to count, for both kinds of chunk
    (per case, :func:`case_signature`; batch, :func:`driver.sweep._plan.batch_signature`): a
    hash of ``identity`` (what the rows depend on: the base deck, the sweep's options), the
    package version, and the bytes of every module of the study's package, of the runner,
    table and export modules and of the kernel extension (:func:`driver._output.code_digest`)."""
    h = hashlib.sha256()
    h.update(json.dumps([*identity, driver.__version__], sort_keys=True, default=str).encode())
    from driver import _export as export
    from driver import _runner as runner
    from driver import _table as table
    from driver._output import code_digest
    h.update(code_digest(module, runner, table, export))
    return h.hexdigest()[:20]


def case_signature(raw: RawGroup, swept: list[str], deck_path: str, keep: str, case_outputs: str,
                   formats: list[str], case_plot: bool | str, module: Any) -> str:
    """The per-case record's signature: :func:`signature` of the base deck's study group without
    the swept keys, the deck path, keep, case_outputs, formats and figures."""
    keys = {n.partition(".")[2] for n in swept}
    return signature(["per-case", raw.name, {k: v for k, v in raw.values.items() if k not in keys}, deck_path,
                      keep, case_outputs, sorted(formats), str(case_plot)], module)


class SweepBusy(DriverError, OSError):
    """Another run holds the lock of this sweep's record (one line)."""

    def __init__(self, folder: Path):
        super().__init__(16, "another run is writing this sweep; wait for it to finish (or give another -o OUTDIR)",
                         str(folder))

    def __reduce__(self) -> tuple[type[SweepBusy], tuple[Path]]:
        """Pickle by the folder (the message is made from it)."""
        return (type(self), (Path(self.filename),))


@contextlib.contextmanager
def sweep_lock(outdir: Path, stem: str) -> Iterator[None]:
    """Hold an exclusive lock on ``<outdir>/<stem>.sweep/.lock`` while a run writes the sweep's
    record, cases and tables; :class:`SweepBusy` at once when another run holds it.  The lock
    is the kernel's (flock): it goes with the process, so a killed run leaves none behind."""
    import fcntl
    folder = Path(outdir) / f"{stem}.sweep"
    refuse_link(folder)
    own_folder(folder, outdir)
    fd = os.open(folder / ".lock", os.O_RDWR | os.O_CREAT | getattr(os, "O_NOFOLLOW", 0), 0o644)
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise SweepBusy(folder) from None
        yield
    finally:
        os.close(fd)


# ----------------------------------------------------------------------------- parts

def write_part(folder: Path, rows: Any, meta: dict[str, Any]) -> Path:
    """Write one part of a record atomically: ``rows`` (a DataFrame or an Arrow table) with
    ``meta`` in its metadata, named by its first position and the checksum of its bytes.
    Called by the worker that computed the chunk, or by the driver."""
    import pyarrow as pa
    import pyarrow.parquet as pq
    table = rows if isinstance(rows, pa.Table) else pa.Table.from_pandas(rows, preserve_index=False)
    meta = {**meta, "n_rows": table.num_rows, "written": time.time_ns()}
    table = table.replace_schema_metadata({**(table.schema.metadata or {}), b"sweep": json.dumps(meta).encode()})
    own_folder(folder, folder.parent)
    buf = pa.BufferOutputStream()
    pq.write_table(table, buf)
    data = buf.getvalue().to_pybytes()
    path = folder / f"part-{int(meta['start']):012d}-{hashlib.sha256(data).hexdigest()[:DIGEST_CHARS]}.parquet"
    with atomic_open(path, "wb") as fh:
        fh.write(data)
    return path


def _meta(path: Path) -> dict | None:
    import pyarrow.parquet as pq
    try:
        raw = pq.read_schema(path).metadata or {}
        meta = json.loads(raw.get(b"sweep", b"{}"))
        return meta if isinstance(meta, dict) and {"signature", "start", "stop"} <= set(meta) else None
    except Exception:   # pyarrow raises several kinds for a damaged file
        return None


@dataclass
class Part:
    """A verified part of the record: its file and metadata (span, counts)."""

    path: Path
    meta: dict

    @property
    def start(self) -> int:
        return int(self.meta["start"])

    @property
    def stop(self) -> int:
        return int(self.meta["stop"])


#: verdict of a per-case row on resume: '' complete, a reason (it runs again, and the tool says
#: why), or None (it runs again silently: it failed, or the grid gives its number other values)
RowCheck = Callable[[dict[str, Any]], "str | None"]


def case_row_check(grid: Grid, layout: Layout) -> RowCheck:
    """The check of a per-case record row on resume (module docstring)."""
    root = Path(layout.root)

    def check(row: dict[str, Any]) -> str | None:
        case = int(row["case"])
        if row["status"] != "ok" or row["values"] != json.dumps(case_at(grid, case).values, default=json_default):
            return None
        stem = layout.rel(case)
        names, sums = json.loads(row["files"]), json.loads(row["digests"])
        if len(names) != len(sums) or not all(f.startswith(stem) and f[len(stem):len(stem) + 1] in (".", "_")
                                              for f in names):
            return None
        for f, d in zip(names, sums):   # every file the case wrote is still there, byte for byte
            if d is None or file_digest(root / f) != d:
                what = "is missing" if not (root / f).exists() else "failed its checksum"
                return f"its file {Path(f).name} {what}"
        return ""
    return check


class Record:
    """The resume record of one sweep run (module docstring): the parts of the chunks of a
    sequence of ``n`` cases (``cases``: their numbers, default 1..n) in chunks of ``size``.

    Per-case records (``check`` given) reuse verified rows case by case, across parts of any
    layout; batch records reuse whole parts of this layout."""

    def __init__(self, folder: Path, base: Path, signature: str, kind: str, n: int, size: int,
                 cases: np.ndarray | None = None, check: RowCheck | None = None):
        self.folder, self.base = Path(folder), Path(base)
        self.signature, self.kind, self.n, self.size = signature, kind, n, size
        self.cases = cases
        self.check = check
        #: chunk start -> its part, for the chunks complete in the record (or written since)
        self.parts: dict[int, Part] = {}
        #: cases run again although the record held them, counted by reason
        self.redone: Counter[str] = Counter()
        #: per-case: chunk start -> {case: part path} of its rows reused from the record
        self.reuse: dict[int, dict[int, Path]] = {}
        self._todo: list[tuple[int, int, Sequence[int]]] = []

    # -- the sequence of cases
    def _numbers(self, start: int, stop: int) -> Sequence[int]:
        """The case numbers at positions start..stop-1 of the sequence."""
        if self.cases is None:
            return range(start + 1, stop + 1)
        return [int(c) for c in self.cases[start:stop]]

    def _case_at(self, pos: int) -> int:
        return pos + 1 if self.cases is None else int(self.cases[pos])

    def _position(self, case: int) -> int:
        if self.cases is None:
            return case - 1 if 1 <= case <= self.n else -1
        k = int(np.searchsorted(self.cases, case))
        return k if k < self.n and int(self.cases[k]) == case else -1

    def spans(self) -> list[tuple[int, int]]:
        """The chunk layout: (start, stop) positions of every chunk."""
        return [(s, min(s + self.size, self.n)) for s in range(0, self.n, self.size)]

    # -- start: verify what an earlier run left, find what is complete
    def open(self, resume: bool) -> int:
        """Remove stray temporaries, parts of another signature, kind or format (every part
        without ``resume``) and parts that fail verification; find the complete chunks.
        Returns the number of cases complete."""
        refuse_link(self.folder)   # never list or delete where a link points
        found: list[Part] = []
        damaged: list[tuple[int, int, str]] = []
        if self.folder.exists():
            for f in self.folder.iterdir():
                if f.name.startswith(".") and f.name.endswith(".tmp"):   # the lock is held: no writer is alive
                    f.unlink(missing_ok=True)
                    continue
                if not f.name.startswith("part-"):
                    continue
                part = self._verified(f, damaged) if resume else None
                if part is None:
                    f.unlink(missing_ok=True)
                else:
                    found.append(part)
        spans = dict(self.spans())
        if self.check is None:   # batch: a verified part of this layout stands for its chunk
            for part in sorted(found, key=lambda p: p.meta.get("written", 0)):
                if spans.get(part.start) == part.stop:
                    old = self.parts.get(part.start)
                    if old is not None:
                        old.path.unlink(missing_ok=True)
                    self.parts[part.start] = part
                else:
                    part.path.unlink(missing_ok=True)
            done = np.zeros(0, dtype=bool)
        else:
            done = self._rows(found, spans)
        for start, stop, why in damaged:   # the cases of a damaged part that run again
            if spans.get(start) != stop or start in self.parts:
                continue
            self.redone[why] += stop - start if self.check is None else int((~done[start:stop]).sum())
        self.redone = Counter(dict(sorted(self.redone.items(), key=lambda kv: (-kv[1], kv[0]))))
        complete = sum(stop - start for start, stop in self.spans() if start in self.parts) + \
            sum(len(r) for r in self.reuse.values())
        self._todo = [(s, e, self._left(s, e)) for s, e in self.spans() if s not in self.parts]
        return complete

    def _verified(self, f: Path, damaged: list[tuple[int, int, str]]) -> Part | None:
        """The part in file ``f`` when its name, checksum, signature and kind hold; a damaged
        one of this sweep is noted in ``damaged`` with its span."""
        m = _PART.match(f.name)
        if not m:
            return None
        meta = _meta(f)
        if file_digest(f) != m.group(2):
            if meta is None:   # cut short: its span is the layout's chunk at its start
                start = int(m.group(1))
                damaged.append((start, min(start + self.size, self.n), UNREADABLE))
            elif meta.get("signature") == self.signature:
                damaged.append((int(meta["start"]), int(meta["stop"]), DAMAGED))
            return None
        if meta is None or meta.get("signature") != self.signature or meta.get("kind") != self.kind \
                or int(meta["start"]) != int(m.group(1)):
            return None
        return Part(f, meta)

    def _rows(self, found: list[Part], spans: dict[int, int]) -> np.ndarray:
        """Per-case: verify every row of the parts found (the newest row of a case counts);
        the chunks whose every case is complete in one part of this layout keep that part, the
        others reuse their complete rows.  Returns a bool per position: complete."""
        import pyarrow.parquet as pq
        assert self.check is not None
        winner = np.full(self.n, -1, dtype=np.int64)
        why: dict[int, str] = {}
        found = sorted(found, key=lambda p: p.meta.get("written", 0))
        for k, part in enumerate(found):
            try:
                t = pq.read_table(part.path, columns=["case", "status", "values", "files", "digests"]).to_pylist()
            except Exception:   # its checksum held, yet unreadable: its cases run again
                continue
            for row in t:
                pos = self._position(int(row["case"]))
                if pos < 0:
                    continue
                verdict = self.check(row)
                winner[pos] = k if verdict == "" else -1
                if verdict:
                    why[pos] = verdict
                elif verdict == "":
                    why.pop(pos, None)
        done = winner >= 0
        for pos, reason in why.items():
            if not done[pos]:
                self.redone[reason] += 1
        for start, stop in spans.items():
            ks = set(winner[start:stop].tolist())
            if len(ks) == 1 and -1 not in ks:
                part = found[ks.pop()]
                if (part.start, part.stop) == (start, stop) and part.meta.get("n_rows") == stop - start:
                    self.parts[start] = part
                    continue
            reused = {self._case_at(p): found[winner[p]].path for p in range(start, stop) if winner[p] >= 0}
            if reused:
                self.reuse[start] = reused
        return done

    def _left(self, start: int, stop: int) -> Sequence[int]:
        """The cases of chunk start..stop that must run (all, or those not reused)."""
        cases = self._numbers(start, stop)
        reused = self.reuse.get(start)
        return cases if not reused else [c for c in cases if c not in reused]

    def todo(self) -> list[tuple[int, int, Sequence[int]]]:
        """After :meth:`open`: the chunks to run, (start, stop, the case numbers to compute),
        in sequence order.  A chunk whose every case is reused needs no computation: its
        part is assembled from the record (:meth:`add` of an empty result)."""
        return list(self._todo)

    # -- during the run
    def add(self, start: int, stop: int, rows: Any, path: str, counts: dict[str, int]) -> Path:
        """A chunk returned: its part (the worker's ``path``, or written here with the chunk's
        reused rows merged in case order)."""
        reused = self.reuse.pop(start, None)
        if path and not reused:
            p = Path(path)
        else:
            if reused:
                rows = _merge_tables([*self._reused_rows(reused), *([rows] if rows is not None else [])])
                counts = _case_counts(rows)
            p = write_part(self.folder, rows, {"signature": self.signature, "kind": self.kind,
                                               "start": start, "stop": stop, **counts})
        n_rows = rows.num_rows if hasattr(rows, "num_rows") else len(rows) if rows is not None else 0
        self.parts[start] = Part(p, {"start": start, "stop": stop, **counts, "n_rows": n_rows})
        return p

    @staticmethod
    def _reused_rows(reused: dict[int, Path]) -> list[Any]:
        import pyarrow as pa
        import pyarrow.compute as pc
        import pyarrow.parquet as pq
        by_part: dict[Path, list[int]] = {}
        for case, path in reused.items():
            by_part.setdefault(path, []).append(case)
        out = []
        for path, cases in by_part.items():
            t = pq.read_table(path).replace_schema_metadata(None)
            out.append(t.filter(pc.is_in(t.column("case"), pa.array(cases, pa.int64()))))
        return out

    def finish(self) -> None:
        """After a complete run: remove the parts no chunk of this layout holds (an earlier
        layout's, or a chunk's part that was replaced)."""
        keep = {p.path.name for p in self.parts.values()}
        refuse_link(self.folder)
        if self.folder.exists():
            for f in self.folder.iterdir():
                if f.name.startswith("part-") and f.name not in keep:
                    f.unlink(missing_ok=True)

    def paths(self, with_rows: bool = False) -> list[Path]:
        """The parts of the chunks (only those that hold rows), in sequence order."""
        return [p.path for _, p in sorted(self.parts.items()) if not with_rows or int(p.meta.get("n_rows", 1))]

    # -- at the end (per case)
    def results(self) -> Iterator[CaseResult]:
        """Every case's row as a CaseResult, part by part in sequence order (memory: one part
        at a time plus what the caller keeps)."""
        import pyarrow.parquet as pq
        codes = {"ok": ExitCode.OK, "failed": ExitCode.FAILED, "bad input": ExitCode.BAD_INPUT}
        for path in self.paths():
            for row in pq.read_table(path).to_pylist():
                rec = json.loads(row["record"])
                yield CaseResult(row["case"], json.loads(row["values"]), codes[row["status"]], rec["error"],
                                 rec["summary"], bool(row["kept"]), warnings=rec["warnings"], seconds=row["seconds"],
                                 files=json.loads(row["files"]), cpu=row["cpu"])


def _merge_tables(tables: list[Any]) -> Any:
    """Per-case rows of several tables as one, in case order."""
    import pyarrow as pa
    t = pa.concat_tables([x.replace_schema_metadata(None) for x in tables])
    return t.sort_by("case")


def _case_counts(rows: Any) -> dict[str, int]:
    status = rows.column("status").to_pylist()
    kept = rows.column("kept").to_pylist()
    n_ok = sum(s == "ok" for s in status)
    return {"n_ok": n_ok, "n_kept": sum(bool(k) and s == "ok" for s, k in zip(status, kept)),
            "n_failed": len(status) - n_ok}
