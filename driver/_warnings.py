"""What a library warned while a deck ran, said in words (one rule for every process).

A SciPy ``RuntimeWarning`` or a NumPy overflow is meant for the program's user, not for a
developer: instead of Python's raw ``file:line: Category: text`` line on the terminal, each kind is
said once, in words, as a warning of the deck's outcome.  The command line's process
(:func:`driver._dispatch.run_deck`) and every sweep worker (:func:`driver.sweep._chunks.run_chunk`,
whose chunk result carries the words back to the driver) catch them with :func:`caught`.
"""
from __future__ import annotations

import contextlib
import warnings
from collections.abc import Iterator
from pathlib import Path

__all__ = ["WORDED", "caught", "library_warnings"]

#: warnings meant for a program's user (NumPy and SciPy numerical warnings, SciPy's
#: OptimizeWarning and IntegrationWarning, pandas' FutureWarning): said in words
WORDED = (RuntimeWarning, UserWarning, FutureWarning)

_LIBRARIES = ("scipy", "numpy", "pandas", "matplotlib", "pyarrow", "f90nml", "dask", "distributed")


@contextlib.contextmanager
def caught() -> Iterator[list[str]]:
    """Catch the warnings the block raises: the worded kinds (:data:`WORDED`) are appended to
    the yielded list in words (:func:`library_warnings`) when the block ends; any other
    (a developer's DeprecationWarning) goes on as it would have."""
    said: list[str] = []
    with warnings.catch_warnings(record=True) as got:   # the filters in force decide what is heard
        try:
            yield said
        finally:
            pass
    for w in got:
        if not issubclass(w.category, WORDED):
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno, source=w.source)
    said += library_warnings([w for w in got if issubclass(w.category, WORDED)])


def library_warnings(got: list[warnings.WarningMessage]) -> list[str]:
    """What a library said while a deck ran (a SciPy RuntimeWarning, a NumPy overflow), each kind
    once, in words: which library, what it said, and that the run went on; the command line
    prints them as warnings instead of Python's raw ``file:line: Category: text`` lines."""
    seen: dict[tuple[str, str, str], int] = {}
    for w in got:
        module = Path(str(w.filename)).parts
        lib = next((m for m in _LIBRARIES if m in module), "driver" if "driver" in module else "a library")
        text = " ".join(str(w.message).split())
        text = text if len(text) <= 160 else text[:157] + "..."
        key = (lib, w.category.__name__, text)
        seen[key] = seen.get(key, 0) + 1
    return [f"{lib} warned while the deck ran ({category}: {text}); the run went on, and its results were checked "
            f"as always (finite numbers, the study's own checks)" for (lib, category, text) in seen]
