"""Docstring sections written once and filled in where they are used (SciPy's ``doccer``, in small).

Functions that share parameters (the kernel wrappers of one study, the hooks every study
declares) document them once: the docstring holds ``%(name)s`` where the section goes, at the
indentation of a section line, and :func:`fill_doc` replaces it when the module is imported, so
``help()``, numpydoc and the docs see the whole text.  A section is written as it reads in a
function's docstring (four spaces before a parameter line, eight before its description),
without the indentation of its first line.
"""
from __future__ import annotations

from collections.abc import Callable
from typing import Any, TypeVar

__all__ = ["fill_doc"]

_F = TypeVar("_F", bound=Callable[..., Any])


def fill_doc(**sections: str) -> Callable[[_F], _F]:
    """A decorator that fills the ``%(name)s`` fields of a docstring with ``sections[name]``.

    A field whose name is not given stays as it is (and fails the numpydoc check of the public
    docstrings); a docstring without fields, or none (``python -OO``), is left alone.
    """
    def fill(fn: _F) -> _F:
        if fn.__doc__:
            doc = fn.__doc__
            for name, text in sections.items():
                doc = doc.replace(f"%({name})s", text)
            fn.__doc__ = doc
        return fn
    return fill
