"""One rule for names and text from anywhere that the tool prints or writes.

A deck's file name, an output folder, a name given to the Python API, a title or a design name
reaches the terminal, the ``.out``, figures and the report page.  Characters that are not text
there are never passed on raw: control characters (C0 and C1: ESC starts a terminal's escape and
OSC sequences, BEL ends one), format characters (the bidi overrides, embeddings, isolates and
marks that reorder what a reader sees -- a right-to-left override spoofs a page title -- and
zero-width characters), line and paragraph separators, surrogates (bytes of a file name that are
not UTF-8) and unassigned or private code points.

* :func:`unsafe` finds them;
* :func:`name_problem` says why a name is refused (a deck's file name and every output's name
  are refused when they hold one: :func:`driver._deck.read_deck`,
  :func:`driver._runner.output_stem`; a deck's text values are printable characters only,
  :func:`driver._deck.validate`);
* :func:`shown` escapes them (``\\x1b``, ``\\u202e``) and bounds a text's length, for every place
  that prints or writes a name it did not refuse (a message naming a refused file, a page
  showing a long design name).
"""
from __future__ import annotations

import os
import unicodedata
from pathlib import Path

__all__ = ["UNSAFE_CATEGORIES", "unsafe", "shown", "name_problem", "NAME_CHARS"]

#: Unicode categories never passed on raw: controls, format characters (bidi, zero width), line
#: and paragraph separators, surrogates, private use, unassigned
UNSAFE_CATEGORIES = frozenset(("Cc", "Cf", "Zl", "Zp", "Cs", "Co", "Cn"))
#: characters of a name shown in full; a longer one is cut in the middle (:func:`shown`)
NAME_CHARS = 200


def unsafe(text: str) -> list[str]:
    """The characters of ``text`` that are not passed on raw, in order, each once."""
    seen: dict[str, None] = {}
    for ch in text:
        if ch not in seen and unicodedata.category(ch) in UNSAFE_CATEGORIES:
            seen[ch] = None
    return list(seen)


def _escape(ch: str) -> str:
    o = ord(ch)
    return f"\\x{o:02x}" if o < 0x100 else (f"\\u{o:04x}" if o < 0x10000 else f"\\U{o:08x}")


def shown(text: str | os.PathLike, limit: int | None = NAME_CHARS) -> str:
    """``text`` as it may be printed or written: every unsafe character escaped (``\\x1b``,
    ``\\u202e``), and, beyond ``limit`` characters (None: no limit), its head and tail with the
    number of characters left out between them."""
    text = os.fspath(text)
    if isinstance(text, bytes):
        text = os.fsdecode(text)
    out = "".join(_escape(ch) if unicodedata.category(ch) in UNSAFE_CATEGORIES else ch for ch in text)
    if limit is not None and len(out) > limit:
        keep = max(limit - 30, 10)
        head, tail = out[: keep * 2 // 3], out[len(out) - keep // 3:]
        out = f"{head}... ({len(out) - len(head) - len(tail)} characters) ...{tail}"
    return out


def name_problem(name: str | os.PathLike, what: str = "the name") -> str | None:
    """Why ``name`` (a file or folder name, or a path) cannot name what the tool prints or writes,
    or None: the first unsafe character, named and escaped."""
    bad = unsafe(os.fsdecode(os.fspath(name)) if isinstance(os.fspath(name), bytes) else str(Path(name)))
    if not bad:
        return None
    ch = bad[0]
    kind = {"Cc": "a control character", "Cf": "a format (bidi or zero-width) character",
            "Zl": "a line separator", "Zp": "a paragraph separator", "Cs": "a byte that is not UTF-8",
            "Co": "a private-use character", "Cn": "an unassigned character"}[unicodedata.category(ch)]
    label = unicodedata.name(ch, "") if unicodedata.category(ch) != "Cs" else ""
    return (f"{what} holds {kind} ({_escape(ch)}{', ' + label if label else ''}), which would reach the terminal, "
            "the outputs and the report page: rename it with printable characters")
