"""Typed keyword signatures of the studies' ``run``, from each study's SPEC.

A study's ``run`` takes validated :class:`~driver._deck.Params` (the runner's call) or the
deck's keys as keyword arguments (:func:`driver._runner.study_run`).  The keys are declared
once, in the study's :class:`~driver._deck.GroupSpec`; this module turns that declaration into

- the run's runtime signature and numpydoc docstring (every key with its type, units,
  default or "required", and allowed values), so ``help(driver.fourbar.run)``, IDEs and
  :func:`inspect.signature` list the keys -- :func:`sign` attaches them;
- the static signature in the study's own package, ``driver/<study>/_keywords.pyi``
  (:func:`render_stub`; ``tools/gen_keyword_signatures.py`` writes it, tests/test_keyword_signatures.py
  fails while it is stale), so a type checker refuses a misspelt key:
  ``driver.fourbar.run(fixed_lnik=12)`` is a mypy error.  Only type checkers read it: the
  study's ``__init__`` imports it under ``TYPE_CHECKING``, so a new study imports (and its
  generator runs) before its stub exists.

Types follow what the deck reader accepts: ``float``/``int``/``str``/``bool`` keys their
scalar (an int for a float), list keys a scalar, a sequence or a numpy array, keys with
allowed values a ``Literal`` of them (a deck also accepts them in any case).
"""
from __future__ import annotations

import inspect
import textwrap
from collections.abc import Callable
from typing import Any

from driver._deck import GroupSpec, Key

__all__ = ["NOT_GIVEN", "key_type", "unit_text", "run_docstring", "run_signature", "sign", "render_stub"]

#: the Python type of each Key.kind, as annotation text (a study's _keywords.pyi imports these names)
KIND_TYPES = {
    "float": "float",
    "int": "int",
    "str": "str",
    "bool": "bool",
    "floats": "float | Sequence[float] | NDArray[Any]",
    "ints": "int | Sequence[int] | NDArray[Any]",
    "strs": "str | Sequence[str]",
    "list": "Sequence[Any]",
}
#: the same in numpydoc words
KIND_WORDS = {"float": "float", "int": "int", "str": "str", "bool": "bool",
              "floats": "float or sequence of float", "ints": "int or sequence of int",
              "strs": "str or sequence of str", "list": "sequence"}


class _NotGiven:
    """Default of a key the deck may leave out and whose default the study works out itself."""

    def __repr__(self) -> str:
        return "<not given>"


#: the signature's default of a key without a fixed default value (leave the key out)
NOT_GIVEN: Any = _NotGiven()


def key_type(key: Key) -> str:
    """Annotation text of one deck key (``Literal[...]`` when it has allowed values)."""
    if key.choices and key.kind in ("str", "int", "bool"):
        return f"Literal[{', '.join(_py(c) for c in key.choices)}]"
    if key.choices and key.kind in ("strs", "ints"):
        lit = f"Literal[{', '.join(_py(c) for c in key.choices)}]"
        return f"{lit} | Sequence[{lit}]"
    return KIND_TYPES[key.kind]


def _py(value: Any) -> str:
    """``repr`` of a default or an allowed value, strings in double quotes (the code's style)."""
    if isinstance(value, str) and '"' not in value and "\\" not in value:
        return f'"{value}"'
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_py(v) for v in value) + "]"
    return repr(value)


def _has_default(key: Key) -> bool:
    return not key.required and key.default is not None


def _default_text(key: Key) -> str:
    return _py(key.default)


#: how a SPEC unit reads in a docstring: dimensionless marks become a word, the four-bar's
#: free length unit says what it is; any other unit is printed as the SPEC gives it
UNIT_WORDS = {"1": "dimensionless", "-": "dimensionless", "length": "length unit of the deck"}


def unit_text(units: str) -> str:
    """How a key's SPEC ``units`` read in its docstring entry: ``'[rad/s]'``, ``'[dimensionless]'``,
    or ``''`` for a key without units (text, counts, switches)."""
    return f"[{UNIT_WORDS.get(units, units)}]" if units else ""


def _sentence(name: str, doc: str) -> str:
    """A key's description as a sentence starting with a capital letter (numpydoc PR08): the
    SPEC's words, led by the key's name where they start with a quote, a bracket or a symbol
    (a symbol's case is its meaning: ``m_B`` is not ``M_B``, so it is never capitalised)."""
    words = name.replace("_", " ")
    label = words[0].upper() + words[1:]
    text = doc.strip() or words
    first = text.split()[0].rstrip(",:;")
    symbol = first[:1].islower() and (any(c.isdigit() or c == "_" for c in first) or (len(first) == 1 and first != "a"))
    if text.startswith("("):
        return f"{label} {text}"
    if not text[0].isalpha() or symbol:
        return f"{label}: {text}"
    return text[0].upper() + text[1:]


def _entry(name: str, key: Key) -> list[str]:
    """The numpydoc entry of one key: ``name : type, default X`` and its description with units."""
    if key.choices:
        kind = "{" + ", ".join(_py(c) for c in key.choices) + "}"
        if key.kind in ("strs", "list"):
            kind += " or sequence of them"
    else:
        kind = KIND_WORDS[key.kind]
    head = f"{name} : {kind}" + (f", default {_default_text(key)}" if _has_default(key) else
                                  "" if key.required else ", optional")
    text = _sentence(name, key.doc)
    if key.units:
        text += f" {unit_text(key.units)}"
    text += "." if not text.endswith(".") else ""
    if key.required:
        text += " Required."
    body = textwrap.wrap(text, 84, break_on_hyphens=False)
    return [head] + [f"    {line}" for line in body]


def run_docstring(spec: GroupSpec, summary: str = "") -> str:
    """Numpydoc docstring of a study's ``run``: ``summary``, then every key of ``spec``.

    Parameters
    ----------
    spec : GroupSpec
        The study's deck keys: each becomes a Parameters entry with its type, default (or
        "Required."), allowed values and units in brackets (:func:`unit_text`).
    summary : str, optional
        The run's own docstring: a one-line summary and any paragraphs after it.  An
        ``Examples`` section in it is moved to the end, after Returns and Raises.

    Returns
    -------
    str
        The docstring (numpydoc), ending with a newline.
    """
    text = inspect.cleandoc(summary) or f"Run the &{spec.name} study: {spec.doc}."
    text, _, examples = text.partition("\nExamples\n--------\n")
    lines = [text.rstrip(), "",
             f"Give either validated ``params`` (the runner's call) or the keys of a ``&{spec.name}``",
             "deck group as keyword arguments, in the deck's units: they are checked exactly like a deck.",
             "Units are in brackets after each key's description.", "",
             "Parameters", "----------",
             "params : Params, optional",
             f"    Validated values of a ``&{spec.name}`` group (positional only; then no keys).",
             "progress : bool, default False",
             "    Show a progress bar on the terminal."]
    for name, key in spec.keys.items():
        lines += _entry(name, key)
    lines += ["", "Returns", "-------", "Result",
              "    The run's fixed-format text, tidy table, summary, figures and warnings",
              "    (:class:`driver.Result`); units in the tidy and summary column names.",
              "", "Raises", "------", "DeckError",
              "    A key is unknown, missing or has a bad value (the message names the key).",
              "TypeError",
              "    Both ``params`` and keys are given."]
    if examples.strip():
        lines += ["", "Examples", "--------", examples.strip("\n")]
    return "\n".join(lines) + "\n"


def run_signature(spec: GroupSpec) -> inspect.Signature:
    """Runtime signature of a study's ``run``: ``(params=None, /, progress=False, *, <keys>)``."""
    P = inspect.Parameter
    params = [P("params", P.POSITIONAL_ONLY, default=None, annotation="Params | None"),
              P("progress", P.POSITIONAL_OR_KEYWORD, default=False, annotation="bool")]
    for name, key in spec.keys.items():
        default = P.empty if key.required else (key.default if _has_default(key) else NOT_GIVEN)
        params.append(P(name, P.KEYWORD_ONLY, default=default, annotation=key_type(key)))
    return inspect.Signature(params, return_annotation="Result")


def sign(run: Callable[..., Any], spec: GroupSpec) -> None:
    """Give a study's ``run`` the signature and docstring of ``spec``'s keys at run time (for
    ``help()``, IDEs and :func:`inspect.signature`); :func:`driver._runner.study_run` calls it."""
    run.__signature__ = run_signature(spec)  # type: ignore[attr-defined]  # a function takes any attribute; inspect reads it
    run.__doc__ = run_docstring(spec, run.__doc__ or "")


def render_stub(spec: GroupSpec) -> str:
    """Text of a study's ``_keywords.pyi`` (in its own package): the overloaded static signature
    of its ``run`` -- validated Params, or the keys of ``spec`` as keyword-only arguments with
    their types and defaults.  Only type checkers read it (the study's ``__init__`` imports it
    under ``TYPE_CHECKING``), so a study imports and runs before its stub exists."""
    keys = []
    for name, key in spec.keys.items():
        scalar_default = _has_default(key) and not isinstance(key.default, (list, tuple))
        keys.append(f"    {name}: {key_type(key)}" + ("" if key.required else
                                                       f" = {_default_text(key)}" if scalar_default else " = ..."))
    body = ["@overload",
            "def run(params: Params, /, progress: bool = False) -> Result: ...",
            "@overload",
            "def run(",
            "    *,",
            "    progress: bool = False,",
            *(k + "," for k in keys),
            ") -> Result: ..."]
    text = "\n".join(body)
    typing_names = sorted({"overload", *(n for n in ("Any", "Literal") if f"{n}[" in text or f"{n}]" in text)})
    imports = (["from collections.abc import Sequence"] if "Sequence[" in text else []) \
        + [f"from typing import {', '.join(typing_names)}", ""] \
        + (["from numpy.typing import NDArray", ""] if "NDArray[" in text else []) \
        + ["from driver._deck import Params", "from driver._result import Result"]
    head = [f'"""Static signature of ``{spec.name}.run`` for type checkers and IDEs: the keys of its SPEC as typed',
            "keyword arguments.  GENERATED from the SPEC by tools/gen_keyword_signatures.py",
            '(driver._signatures.render_stub): do not edit; tests/test_keyword_signatures.py fails while it is stale."""']
    return "\n".join([*head, *imports, "", '__all__ = ["run"]', "", *body]) + "\n"
