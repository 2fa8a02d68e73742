"""Atomic output: write to a temporary file in the target folder, then rename.

The temporary file is removed if writing fails or is interrupted.

A reader (or ``git diff outputs/``) never sees a half-written file, and an
interrupted run leaves the previous complete file in place.
"""
from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path
from typing import IO, Iterator

__all__ = ["atomic_open", "write_text"]


@contextlib.contextmanager
def atomic_open(path: str | Path, mode: str = "w") -> Iterator[IO]:
    """Open a temporary sibling of ``path``; on success rename it over ``path``."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = None
    try:   # mkstemp inside the try: an interrupt right after it still removes the file
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
        with os.fdopen(fd, mode) as fh:
            yield fh
        # no fsync: the rename alone means a reader never sees a partial file after an
        # interrupt or a crash of this process (durability across power loss is not the
        # point, and fsync per file serialises parallel sweep workers on the disk)
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        if tmp is not None:
            with contextlib.suppress(FileNotFoundError):
                os.unlink(tmp)
        raise


def write_text(path: str | Path, text: str) -> Path:
    """Write ``text`` to ``path`` atomically; returns the path."""
    with atomic_open(path, "w") as fh:
        fh.write(text)
    return Path(path)
