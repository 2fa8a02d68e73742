"""The example decks that ship inside the package (the repository's ``inputs/``).

``python -m driver --examples`` lists them with their first comment line;
``python -m driver --example crank5 [-o DIR]`` copies ``crank5.dat`` into DIR
(default: the current folder) so an installed user can start without the repository.
An installed package holds them in ``driver/examples/``; an editable install reads
the checkout's ``inputs/``.
"""
from __future__ import annotations

import os
from pathlib import Path

from driver._atomic import atomic_open

__all__ = ["examples_dir", "list_examples", "example_path", "describe", "copy_example"]

_PKG = Path(__file__).resolve().parent


def examples_dir() -> Path:
    """The folder holding the example decks (installed copy first, then the source checkout)."""
    for folder in (_PKG / "examples", _PKG.parent / "inputs"):
        if folder.is_dir() and any(folder.glob("*.dat")):
            return folder
    raise FileNotFoundError(f"no example decks found beside {_PKG} (a broken install: reinstall mechanism-driver)")


def list_examples() -> list[str]:
    """Names (deck stems) of every example deck, sorted."""
    return sorted(p.stem for p in examples_dir().glob("*.dat"))


def example_path(name: str) -> Path:
    """The example deck called ``name`` (with or without ``.dat``); KeyError naming the choices."""
    stem = name[:-4] if name.endswith(".dat") else name
    path = examples_dir() / f"{stem}.dat"
    if "/" in stem or "\\" in stem or not path.is_file():
        raise KeyError(f"no example deck {name!r}; choose one of: {', '.join(list_examples())}")
    return path


def describe(name: str) -> str:
    """What the deck is: its leading comment block as one line, without the ``!``."""
    words = []
    for line in example_path(name).read_text().splitlines():
        text = line.strip()
        if not text.startswith("!"):
            break
        words.append(text.lstrip("!").strip())
    return " ".join(w for w in words if w)


def copy_example(name: str, dest: Path | str = ".", overwrite: bool = False) -> Path:
    """Copy example ``name`` into folder ``dest`` (created when missing); returns the new path.

    Refuses (FileExistsError) to overwrite a deck the user may have edited unless ``overwrite``;
    a symbolic link at the name counts as a file there, and is replaced, never written through.
    """
    src = example_path(name)
    dest = Path(dest)
    dest.mkdir(parents=True, exist_ok=True)
    target = dest / src.name
    if os.path.lexists(target) and not overwrite:   # a symbolic link there (even a dangling one) counts
        raise FileExistsError(f"{target} exists; not overwritten (delete it or copy to another folder with -o)")
    with atomic_open(target, "wb") as fh:   # a link at the name is replaced, never written through
        fh.write(src.read_bytes())
    return target
