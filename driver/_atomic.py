"""Atomic output: write to a temporary file in the target folder, then rename.

The temporary file is removed if writing fails or is interrupted.  A reader (or
``git diff outputs/``) never sees a half-written file, and an interrupted run leaves
the previous complete file in place.

The files of one deck form a set (:func:`output_set`): every file is first written
to its temporary, and only when all are complete are they renamed into place; a
failure or interrupt (Ctrl-C, SIGTERM, a full disk) removes all the temporaries, so a
new ``.out`` never stands beside an old ``.csv``.  Every path written inside a set is
checked to lie inside the set's output folder, every name to fit NAME_MAX (255 bytes:
:class:`NameTooLong` before the file is opened), and no path to hold a control or bidi
character (:class:`UnsafeName`, :mod:`driver._names`).  Temporaries are named
``.<first 40 characters of the file name>.<pid>.<random>.tmp`` (at most 62 bytes, whatever the
output's name); a process killed by SIGKILL cannot remove its
own, so :func:`remove_stale_temporaries` removes those of processes no longer alive
(the next run of the same deck calls it).

Nothing is written through a symbolic link.  A temporary is created with ``O_EXCL``
(``mkstemp``, which never follows a link) and renamed over the final name, so a link planted
there is replaced, its target untouched; the folders the tool makes inside an output set are
never links (:func:`own_folder`); the tool's own append-only and resume files are opened with
``O_NOFOLLOW`` (:func:`open_append` replaces a link at the name, :func:`read_own` reads none).
"""
from __future__ import annotations

import contextlib
import contextvars
import os
import re
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import IO

from driver._errors import DriverError

__all__ = ["atomic_open", "write_text", "output_set", "OutputSet", "inside", "remove_stale_temporaries",
           "file_digest", "DIGEST_CHARS", "own_folder", "refuse_link", "LinkRefused", "NAME_MAX", "NameTooLong",
           "open_append", "read_own", "UnsafeName"]

#: the longest file name the file systems we write to take [bytes]
NAME_MAX = 255


class NameTooLong(DriverError, OSError):
    """An output file's name is longer than :data:`NAME_MAX` bytes: refused before its file (or
    its temporary) is created; inside an output set nothing of the set is renamed into place."""

    def __init__(self, path: str | Path):
        import errno
        n = len(os.fsencode(Path(path).name))
        super().__init__(errno.ENAMETOOLONG, f"the name has {n} bytes and a file name may have {NAME_MAX}",
                         str(path))

    def __reduce__(self) -> tuple[type[NameTooLong], tuple[str]]:
        """Pickle by the path (the message is made from it)."""
        return (type(self), (str(self.filename),))


class UnsafeName(DriverError, OSError):
    """An output's path holds a control or bidi character (:mod:`driver._names`): refused before its
    file is opened, the path shown escaped."""

    def __init__(self, path: str | Path, why: str):
        import errno

        from driver._names import shown
        self.path = str(path)
        super().__init__(errno.EINVAL, why, shown(path))

    def __reduce__(self) -> tuple[type[UnsafeName], tuple[str, str]]:
        """Pickle by the path and the reason (the message is made from them)."""
        return (type(self), (self.path, str(self.strerror)))


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
    if len(os.fsencode(path.name)) > NAME_MAX:
        raise NameTooLong(path)
    _check_name(path)
    current = _CURRENT.get()
    if current is not None and not inside(current.root, path):
        raise PermissionError(1, f"refusing to write outside the output folder {current.root}", str(path))
    tmp = None
    try:   # mkstemp inside the try: an interrupt right after it still removes the file
        try:
            if current is not None:   # folders below the set's folder: made here, never a link
                own_folder(path.parent, current.root)
            else:
                path.parent.mkdir(parents=True, exist_ok=True)
            fd, tmp = tempfile.mkstemp(prefix=_temp_prefix(path), suffix=".tmp", dir=path.parent)
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


def _check_name(path: Path) -> None:
    """Refuse (:class:`UnsafeName`) a path holding a character that must not reach a terminal or a page."""
    from driver._names import name_problem
    why = name_problem(path, "the output's path")
    if why:
        raise UnsafeName(path, why)


#: characters of the final name kept in a temporary's name (a 255-byte deck name still fits)
TEMP_NAME = 40


def _temp_prefix(path: Path) -> str:
    """``.<name>.<pid>.``, the name cut to :data:`TEMP_NAME` characters so that the temporary of
    a file with a long name is no longer than the file system allows."""
    return f".{path.name[:TEMP_NAME]}.{os.getpid()}."


def write_text(path: str | Path, text: str) -> Path:
    """Write ``text`` to ``path`` atomically; returns the path."""
    with atomic_open(path, "w") as fh:
        fh.write(text)
    return Path(path)


@contextlib.contextmanager
def output_set(root: str | Path) -> Iterator[OutputSet]:
    """Write a set of files inside folder ``root`` all or nothing (see the module docstring).

    A set opened while another is being written, for a folder inside that one's (an engine's
    outputs that include a study run's), joins it: its files are renamed into place with the
    outer set's, or not at all.  Before anything is renamed every target is checked: a folder
    where a file is to go fails the whole set, with nothing of it in place."""
    outer = _CURRENT.get()
    if outer is not None and (inside(outer.root, root) or os.path.abspath(root) == os.path.abspath(outer.root)):
        yield outer
        return
    s = OutputSet(Path(root))
    token = _CURRENT.set(s)
    current = True   # this set is the current one until reset
    try:
        yield s
        _CURRENT.reset(token)
        current = False
        done = 0
        try:
            for _, path in s.pending:   # what would fail a rename fails the set before the first one
                if os.path.isdir(path) and not os.path.islink(path):
                    raise IsADirectoryError(21, "exists and is a folder; nothing of this run's outputs was put in "
                                                "place", str(path))
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
        if current:
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
    removed: list[Path] = []
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return removed
    for e in entries:
        m = _TEMP.match(e.name)
        if not m or not e.name.startswith(f".{stem[:TEMP_NAME]}") or not e.is_file(follow_symlinks=False):
            continue
        if not _alive(int(m.group(1))):
            with contextlib.suppress(OSError):
                os.unlink(e.path)
                removed.append(Path(e.path))
    return removed


#: hex characters of a content digest kept in names and records (sha256, 80 bits)
DIGEST_CHARS = 20


def file_digest(path: str | Path, follow: bool = False) -> str | None:
    """sha256 of a file's bytes (first :data:`DIGEST_CHARS` hex characters), or None when it
    cannot be read or is not a regular file (a symlink is not followed unless ``follow``)."""
    import hashlib
    flags = os.O_RDONLY | (0 if follow else getattr(os, "O_NOFOLLOW", 0))
    try:
        fd = os.open(path, flags)
    except OSError:
        return None
    h = hashlib.sha256()
    try:
        import stat as _stat
        if not _stat.S_ISREG(os.fstat(fd).st_mode):
            return None
        while True:
            block = os.read(fd, 1 << 20)
            if not block:
                break
            h.update(block)
    except OSError:
        return None
    finally:
        os.close(fd)
    return h.hexdigest()[:DIGEST_CHARS]


class LinkRefused(DriverError, PermissionError):
    """A symbolic link where the tool keeps a folder or file of its own (one line)."""

    def __init__(self, path: str | Path):
        super().__init__(1, "is a symbolic link where this tool keeps its own files; it creates and deletes "
                            "files only in folders it made (remove the link, or give the real folder as -o OUTDIR)",
                         str(path))

    def __reduce__(self) -> tuple[type[LinkRefused], tuple[str]]:
        """Pickle by the path (the message is made from it)."""
        return (type(self), (str(self.filename),))


def refuse_link(path: str | Path) -> None:
    """Raise :class:`LinkRefused` when ``path`` is a symbolic link (a missing path is fine)."""
    if os.path.islink(path):
        raise LinkRefused(path)


def own_folder(path: str | Path, base: str | Path) -> Path:
    """Make folder ``path`` inside ``base`` (which the user gave: it may be a symbolic link), with
    every folder between them made by this tool or already a real folder: a symbolic link
    there is refused (:class:`LinkRefused`), never followed."""
    path, base = Path(path), Path(base)
    if not inside(base, path):
        if os.path.abspath(path) == os.path.abspath(base):
            base.mkdir(parents=True, exist_ok=True)
            return path
        raise PermissionError(1, f"refusing a folder outside the output folder {base}", str(path))
    base.mkdir(parents=True, exist_ok=True)
    current = base
    for part in Path(os.path.relpath(os.path.abspath(path), os.path.abspath(base))).parts:
        current = current / part
        try:
            os.mkdir(current)
        except FileExistsError:
            pass
        except OSError as exc:
            raise _fault(exc, current) from None
        refuse_link(current)
        if not current.is_dir():
            raise NotADirectoryError(20, "exists and is not a folder", str(current))
    return path


_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)
_CLOEXEC = getattr(os, "O_CLOEXEC", 0)


def open_append(path: str | Path) -> IO[str]:
    """Open the tool's own log file ``path`` (an optimisation's journal) for appending, never
    through a symbolic link: a link planted at its name is removed and a new file made in its
    place (``O_NOFOLLOW``; ``O_EXCL`` for the new one), so nothing is written outside the folder
    and the file a link points to is untouched.  Anything but a regular file there is refused."""
    import errno
    import stat as _stat
    path = Path(path)
    if len(os.fsencode(path.name)) > NAME_MAX:
        raise NameTooLong(path)
    _check_name(path)
    flags = os.O_WRONLY | os.O_APPEND | _CLOEXEC
    for _ in range(3):
        try:
            fd = os.open(path, flags | _NOFOLLOW)
        except FileNotFoundError:
            try:
                fd = os.open(path, flags | os.O_CREAT | os.O_EXCL | _NOFOLLOW, 0o644)
            except FileExistsError:   # made (or planted) meanwhile: look again
                continue
        except OSError as exc:
            if exc.errno == errno.ELOOP or os.path.islink(path):   # a link in its place: replaced, not followed
                with contextlib.suppress(FileNotFoundError):
                    os.unlink(path)
                continue
            raise _fault(exc, path) from None
        if not _stat.S_ISREG(os.fstat(fd).st_mode):
            os.close(fd)
            raise IsADirectoryError(errno.EISDIR, "exists and is not a regular file", str(path))
        return os.fdopen(fd, "a", encoding="utf-8")
    raise PermissionError(errno.EPERM, "a link keeps reappearing in place of the file", str(path))


def read_own(path: str | Path, limit: int | None = None) -> bytes | None:
    """The bytes of the tool's own file ``path`` (a resume record), or None when it is missing,
    is a symbolic link (never followed: a record is not read from elsewhere), is not a regular
    file, or has more than ``limit`` bytes."""
    import stat as _stat
    try:
        fd = os.open(path, os.O_RDONLY | _NOFOLLOW | _CLOEXEC)
    except OSError:
        return None
    try:
        st = os.fstat(fd)
        if not _stat.S_ISREG(st.st_mode) or (limit is not None and st.st_size > limit):
            return None
        chunks = []
        while True:
            block = os.read(fd, 1 << 20)
            if not block:
                break
            chunks.append(block)
        return b"".join(chunks)
    except OSError:
        return None
    finally:
        os.close(fd)
