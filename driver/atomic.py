"""Atomic output: write to a temporary file in the target folder, then rename.

The temporary file is removed if writing fails or is interrupted.  A reader (or
``git diff outputs/``) never sees a half-written file, and an interrupted run leaves
the previous complete file in place.

The files of one deck form a set (:func:`output_set`): every file is first written
to its temporary, and only when all are complete are they renamed into place; a
failure or interrupt (Ctrl-C, SIGTERM, a full disk) removes all the temporaries, so a
new ``.out`` never stands beside an old ``.csv``.  Every path written inside a set is
checked to lie inside the set's output folder.  Temporaries are named
``.<file name>.<pid>.<random>.tmp``; a process killed by SIGKILL cannot remove its
own, so :func:`remove_stale_temporaries` removes those of processes no longer alive
(the next run of the same deck calls it).
"""
from __future__ import annotations

import contextlib
import contextvars
import os
import re
import tempfile
from pathlib import Path
from typing import IO, Iterator

__all__ = ["atomic_open", "write_text", "output_set", "OutputSet", "inside", "remove_stale_temporaries"]


class OutputSet:
    """Files written but not yet renamed into place: (temporary, final path) pairs."""

    def __init__(self, root: Path):
        self.root = Path(os.path.abspath(root))
        self.pending: list[tuple[str, Path]] = []


_CURRENT: contextvars.ContextVar[OutputSet | None] = contextvars.ContextVar("output_set", default=None)


def inside(root: str | Path, path: str | Path) -> bool:
    """True when ``path`` (resolved lexically, '..' included) lies inside folder ``root``."""
    root_abs = os.path.abspath(root)
    path_abs = os.path.abspath(path)
    return os.path.commonpath([root_abs, path_abs]) == root_abs and path_abs != root_abs


def _fault(exc: OSError, path: Path) -> OSError:
    """The same error, naming the output file instead of its temporary."""
    new = exc.__class__(exc.errno, exc.strerror or str(exc), str(path))
    return new


@contextlib.contextmanager
def atomic_open(path: str | Path, mode: str = "w") -> Iterator[IO]:
    """Open a temporary sibling of ``path``; on success rename it over ``path``.

    Inside :func:`output_set` the rename waits until the whole set is complete.
    """
    path = Path(path)
    current = _CURRENT.get()
    if current is not None and not inside(current.root, path):
        raise PermissionError(1, f"refusing to write outside the output folder {current.root}", str(path))
    tmp = None
    try:   # mkstemp inside the try: an interrupt right after it still removes the file
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.{os.getpid()}.", suffix=".tmp", dir=path.parent)
        except FileExistsError as exc:   # a file where a folder should be
            raise NotADirectoryError(exc.errno, "exists and is not a folder", exc.filename) from None
        except OSError as exc:
            raise _fault(exc, Path(exc.filename) if exc.filename else path) from None
        try:
            with os.fdopen(fd, mode) as fh:
                yield fh
            # no fsync: the rename alone means a reader never sees a partial file after an
            # interrupt or a crash of this process (durability across power loss is not the
            # point, and fsync per file serialises parallel sweep workers on the disk)
            os.chmod(tmp, 0o644)
            if current is not None:
                current.pending.append((tmp, path))
            else:
                os.replace(tmp, path)
        except OSError as exc:
            raise _fault(exc, path) from None
    except BaseException:
        if tmp is not None and (current is None or (tmp, path) not in current.pending):
            with contextlib.suppress(FileNotFoundError):
                os.unlink(tmp)
        raise


def write_text(path: str | Path, text: str) -> Path:
    """Write ``text`` to ``path`` atomically; returns the path."""
    with atomic_open(path, "w") as fh:
        fh.write(text)
    return Path(path)


@contextlib.contextmanager
def output_set(root: str | Path) -> Iterator[OutputSet]:
    """Write a set of files inside folder ``root`` all or nothing (see the module docstring)."""
    s = OutputSet(Path(root))
    token = _CURRENT.set(s)
    try:
        yield s
        _CURRENT.reset(token)
        token = None
        done = 0
        try:
            for tmp, path in s.pending:
                try:
                    os.replace(tmp, path)
                except OSError as exc:
                    raise _fault(exc, path) from None
                done += 1
        finally:
            for tmp, _ in s.pending[done:]:
                with contextlib.suppress(OSError):
                    os.unlink(tmp)
    except BaseException:
        for tmp, _ in s.pending:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
        raise
    finally:
        if token is not None:
            _CURRENT.reset(token)


_TEMP = re.compile(r"^\..+\.(\d+)\.[^.]+\.tmp$")


def _alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    try:   # a killed process stays a zombie until reaped (its parent may be dead too): not alive
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().rpartition(")")[2].split()[0] not in ("Z", "X")
    except (OSError, IndexError):
        return True


def remove_stale_temporaries(folder: str | Path, stem: str) -> list[Path]:
    """Remove this tool's temporaries for outputs ``<stem>*`` in ``folder`` whose writer is dead."""
    folder = Path(folder)
    removed = []
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return removed
    for e in entries:
        m = _TEMP.match(e.name)
        if not m or not e.name.startswith(f".{stem}") or not e.is_file(follow_symlinks=False):
            continue
        if not _alive(int(m.group(1))):
            with contextlib.suppress(OSError):
                os.unlink(e.path)
                removed.append(Path(e.path))
    return removed
