"""A per-case sweep's records on disk: where each case's files go (one folder, or sharded
folders for large sweeps), the resume record (a Parquet dataset of summary rows, appended as
chunks complete), and the removal of case files that are no longer part of the sweep.

The resume record is ``<outdir>/<stem>.sweep/part-r<run>-<seq>.parquet``: one part per
completed chunk, written atomically by the driver, one row per case (case number, status,
kept, the swept values, the files the case wrote, and its summary, error and warnings as
JSON).  Each part carries the sweep's *signature* in its metadata: a hash of the base deck's
study group (without the swept keys), the deck path, keep, case_outputs, the table formats,
whether case figures are drawn, the package version, and the bytes of the study module, the
runner, table and export modules and the kernel extension.  On ``--resume`` a case is
complete when the newest row for its number is in a part of the same signature, has status
ok, holds the values the grid now gives that number, and every file it wrote is still there
in this sweep's layout; every other case runs again.  So a changed base deck or tool build
re-runs every case, a changed grid re-runs the cases whose values changed, and a deleted
``.out`` re-runs its case.

The record is verified, never believed: a part's name ends with the sha256 of its bytes
(``part-r<run>-<seq>-<digest>.parquet``), checked before it is read, and each row holds the
digest of every file its case wrote (``digests``), checked against the file (opened without
following a link) before the case counts as complete.  What fails is redone and counted by
reason (:meth:`Record.redone`).  The record's folders are never symbolic links
(:func:`driver._atomic.own_folder`), and :func:`sweep_lock` lets one run at a time write them.
"""
from __future__ import annotations

import contextlib
import hashlib
import json
import os
import re
import time
from collections.abc import Iterator
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
           "clean_temporaries", "SHARD", "FLAT_MAX"]

#: sweeps up to this many cases keep every case's files in one folder <stem>/
FLAT_MAX = 1000
#: cases per sub-folder <stem>/<first>-<last>/ of a larger sweep
SHARD = 1000

_CASE_FILE = re.compile(r"^case_(\d+)[._]")
_SHARD_DIR = re.compile(r"^(\d+)-(\d+)$")
_PART = re.compile(rf"^part-r(\d+)-(\d+)-([0-9a-f]{{{DIGEST_CHARS}}})\.parquet$")


def json_default(o: Any) -> Any:
    """JSON for numpy scalars (values and summaries of cases)."""
    if isinstance(o, np.bool_):
        return bool(o)
    if isinstance(o, (np.floating, np.integer)):
        return o.item()
    return str(o)


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


def layout_for(case_dir: str | Path, n_cases: int) -> Layout:
    """The layout of a sweep of ``n_cases``: flat up to :data:`FLAT_MAX` cases, else sharded."""
    return Layout(str(case_dir), max(4, len(str(n_cases))), SHARD if n_cases > FLAT_MAX else 0)


def signature(identity: list, module: Any) -> str:
    """The signature a part of a resume record must carry to count, for both kinds of record
    (per case, :func:`case_signature`; batch, :func:`driver.sweep._batch.plan`): a hash of
    ``identity`` (what the rows depend on: the base deck, the sweep's options), the package
    version, and the bytes of every module of the study's package, of the runner, table and
    export modules and of the kernel extension (:func:`driver._output.code_digest`)."""
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
    """The per-case record's signature (module docstring): :func:`signature` of the base deck's
    study group without the swept keys, the deck path, keep, case_outputs, formats and figures."""
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


def clean_temporaries(layout: Layout) -> None:
    """Remove the temporaries of case files whose writer died (SIGKILL), in every case folder."""
    root = Path(layout.root)
    refuse_link(root)
    remove_stale_temporaries(root, "case_")
    with contextlib.suppress(OSError):
        for e in os.scandir(root):
            if e.is_dir(follow_symlinks=False) and _SHARD_DIR.match(e.name):
                remove_stale_temporaries(e.path, "case_")


class _Winners:
    """Per case number, the index of the part holding its newest row (-1: none): an array up
    to :data:`DENSE_MAX` cases, else a dict (a batch sweep's kept cases among 10^10)."""

    def __init__(self, n: int):
        self.n = n
        self.a = np.full(n + 1, -1, dtype=np.int32) if n <= DENSE_MAX else None
        self.d: dict[int, int] = {}

    def get(self, case: int) -> int:
        if not 1 <= case <= self.n:
            return -1
        return int(self.a[case]) if self.a is not None else self.d.get(case, -1)

    def set(self, case: int, k: int) -> None:
        if self.a is not None:
            self.a[case] = k
        elif k < 0:
            self.d.pop(case, None)
        else:
            self.d[case] = k


#: case numbers up to which the record keeps an array (4 bytes a case) rather than a dict
DENSE_MAX = 10_000_000


class Record:
    """The resume record ``<folder>`` of one sweep run (module docstring)."""

    def __init__(self, folder: Path, signature: str, n_cases: int, base: Path | None = None):
        self.folder = Path(folder)
        #: the output folder the record lives in (the user's: it may be a link; the record's
        #: own folders below it never are)
        self.base = Path(base) if base is not None else self.folder.parent
        self.signature = signature
        self.parts: list[Path] = []
        #: per case number, the index in ``parts`` of its newest row (-1: none)
        self.winner = _Winners(n_cases)
        self.run = time.time_ns()
        self.seq = 0
        #: cases whose record or files failed verification on resume: case -> why (see :meth:`redone`)
        self.suspect: dict[int, str] = {}
        self.damaged_parts = 0

    # -- start: clean and find what is complete
    def start(self, resume: bool) -> None:
        """Remove stray temporaries, and parts of another signature (all parts without ``resume``)."""
        kept = []
        refuse_link(self.folder)   # never list or delete where a link points
        if self.folder.exists():
            remove_stale_temporaries(self.folder, "part-")   # of a driver killed while writing a part
            for f in self.folder.iterdir():
                if not f.name.startswith("part-"):
                    continue
                m = _PART.match(f.name)
                meta = self._meta(f) if (resume and m) else None
                if m and meta and meta.get("signature") == self.signature:
                    if file_digest(f) == m.group(3):
                        kept.append(((int(m.group(1)), int(m.group(2))), f))
                        continue
                    for case in self._cases_of(f):   # its cases run again, and the tool says why
                        self.suspect[case] = "a resume record part failed its checksum"
                    self.damaged_parts += 1
                f.unlink(missing_ok=True)
        self.parts = [f for _, f in sorted(kept)]

    @staticmethod
    def _cases_of(path: Path) -> list[int]:
        """The case numbers a (damaged) part lists, as far as it can still be read."""
        import pyarrow.parquet as pq
        try:
            return [int(c) for c in pq.read_table(path, columns=["case"]).column("case").to_pylist()]
        except Exception:   # unreadable: its cases are found missing instead
            return []

    @staticmethod
    def _meta(path: Path) -> dict | None:
        import pyarrow.parquet as pq
        try:
            raw = pq.read_schema(path).metadata or {}
            return json.loads(raw.get(b"sweep", b"{}"))
        except Exception:
            return None

    def scan(self, grid: Grid, layout: Layout) -> np.ndarray:
        """Cases complete in the record (bool array indexed by case number, [0] unused; empty
        above DENSE_MAX cases: ask :meth:`complete`)."""
        import pyarrow.parquet as pq
        n = grid.n
        root = Path(layout.root)
        good: list[Path] = []
        for part in self.parts:
            try:
                t = pq.read_table(part, columns=["case", "status", "values", "files", "digests"]).to_pydict()
            except Exception:   # an unreadable part (its checksum held, yet): its cases run again
                self.damaged_parts += 1
                continue
            k = len(good)
            good.append(part)
            for case, status, values, files, digests in zip(t["case"], t["status"], t["values"], t["files"],
                                                            t["digests"]):
                if not 1 <= case <= n:
                    continue
                ok = status == "ok"
                if ok:
                    ok = values == json.dumps(case_at(grid, case).values, default=json_default)
                if ok:
                    stem = self._rel(layout, case)
                    names, sums = json.loads(files), json.loads(digests)
                    ok = len(names) == len(sums) and all(
                        f.startswith(stem) and f[len(stem):len(stem) + 1] in (".", "_") for f in names)
                    if ok:   # every file the case wrote is still there, byte for byte
                        bad = [f for f, d in zip(names, sums) if d is None or file_digest(root / f) != d]
                        if bad:
                            ok = False
                            missing = not (root / bad[0]).exists()
                            self.suspect[case] = (f"its file {Path(bad[0]).name} is missing" if missing else
                                                  f"its file {Path(bad[0]).name} failed its checksum")
                self.winner.set(case, k if ok else -1)
        self.parts = good
        return self.winner.a >= 0 if self.winner.a is not None else np.zeros(0, dtype=bool)

    def redone(self) -> dict[str, int]:
        """After :meth:`scan`: the cases found in the record that failed verification and run
        again, counted by reason."""
        out: dict[str, int] = {}
        for case, why in self.suspect.items():
            if not self.complete(case):
                out[why] = out.get(why, 0) + 1
        return dict(sorted(out.items(), key=lambda kv: (-kv[1], kv[0])))

    def complete(self, case: int) -> bool:
        """Whether case ``case`` has a valid row (after :meth:`scan` and :meth:`append`)."""
        return self.winner.get(case) >= 0

    @staticmethod
    def _rel(layout: Layout, case: int) -> str:
        folder = layout.folder(case)
        return f"{folder}/{layout.name(case)}" if folder else layout.name(case)

    # -- during the run
    def append(self, results: list[CaseResult], layout: Layout) -> None:
        """Write the rows of a completed chunk as one part (atomically)."""
        import pyarrow as pa
        import pyarrow.parquet as pq
        if not results:
            return
        status = {0: "ok", 1: "failed", 2: "bad input"}
        table = pa.table({
            "case": pa.array([r.index for r in results], pa.int64()),
            "status": [status.get(r.status, "failed") for r in results],
            "kept": pa.array([bool(r.kept and r.status == 0) for r in results], pa.bool_()),
            "values": [json.dumps(r.values, default=json_default) for r in results],
            "files": [json.dumps(r.files) for r in results],
            # the content of each file as written, checked on resume (file_digest)
            "digests": [json.dumps([file_digest(Path(layout.root) / f) for f in r.files]) for r in results],
            "seconds": pa.array([float(r.seconds) for r in results], pa.float64()),
            "cpu": pa.array([float(r.cpu) for r in results], pa.float64()),
            "record": [json.dumps({"status": r.status, "error": r.error, "summary": r.summary,
                                   "warnings": r.warnings}, default=json_default) for r in results],
        })
        self.seq += 1
        meta = {"signature": self.signature, "run": self.run, "seq": self.seq}
        table = table.replace_schema_metadata({b"sweep": json.dumps(meta).encode()})
        own_folder(self.folder, self.base)
        buf = pa.BufferOutputStream()
        pq.write_table(table, buf)
        data = buf.getvalue().to_pybytes()
        digest = hashlib.sha256(data).hexdigest()[:DIGEST_CHARS]   # the part's name carries its checksum
        path = self.folder / f"part-r{self.run}-{self.seq:06d}-{digest}.parquet"
        with atomic_open(path, "wb") as fh:
            fh.write(data)
        self.parts.append(path)
        k = len(self.parts) - 1
        for r in results:
            self.winner.set(r.index, k)

    # -- at the end
    def results(self, wanted: np.ndarray | None = None) -> Iterator[CaseResult]:
        """The newest row of every case (or of the cases ``wanted[case]``), as CaseResults,
        part by part (memory: one part at a time plus what the caller keeps)."""
        import pyarrow.parquet as pq
        codes = {"ok": ExitCode.OK, "failed": ExitCode.FAILED, "bad input": ExitCode.BAD_INPUT}
        for k, part in enumerate(self.parts):
            t = pq.read_table(part).to_pydict()
            for i, case in enumerate(t["case"]):
                if self.winner.get(case) != k or (wanted is not None and not wanted[case]):
                    continue
                rec = json.loads(t["record"][i])
                yield CaseResult(case, json.loads(t["values"][i]), codes[t["status"][i]], rec["error"], rec["summary"],
                                 bool(t["kept"][i]), warnings=rec["warnings"], seconds=t["seconds"][i],
                                 files=json.loads(t["files"][i]), cpu=t["cpu"][i])

    def columns(self, names: list[str]) -> dict[str, np.ndarray]:
        """Columns ``names`` (of 'case', 'status', 'kept', 'seconds', 'cpu') of every case's newest row, by case."""
        import pyarrow.parquet as pq
        out: dict[str, list] = {c: [] for c in names}
        for k, part in enumerate(self.parts):
            t = pq.read_table(part, columns=sorted({"case", *names})).to_pydict()
            sel = [i for i, c in enumerate(t["case"]) if self.winner.get(c) == k]
            for c in names:
                out[c] += [t[c][i] for i in sel]
        return {c: np.asarray(v) for c, v in out.items()}


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
