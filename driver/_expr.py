"""The one safe expression language of the decks: filters, objectives, constraints, plot columns.

A deck may name a computation over a table's columns, e.g. a sweep's ``keep`` filter::

    keep = 'meets_transmission_band and rocker_swing_deg >= 60 and abs(mu_min_deg - 45) < 10'

The text is parsed with :mod:`ast` and checked against a whitelist; nothing in it is ever
evaluated by Python.  Allowed:

* column names (``rocker_swing_deg``), dotted names of swept keys (``fourbar.crank``) and any
  name in backticks (```fourbar.crank```);
* numbers, strings in quotes, ``True``/``False`` (also Fortran's ``.true.``/``.false.``);
* comparisons ``== != < <= > >=`` (chains like ``40 <= mu_min_deg < 120`` too);
* ``and``, ``or``, ``not`` (also ``.and.``, ``.or.``, ``.not.``), parentheses;
* arithmetic ``+ - * / // % **`` and unary minus;
* the functions in :data:`FUNCTIONS` (``abs``, ``min``, ``max``, ``sqrt``, ...).

Anything else (attribute access, other calls, ``@`` references, subscripts, lambdas,
comprehensions, dunder names, assignment, f-strings) is an :class:`ExprError` that names the
offending token.  Evaluation is vectorised with numpy over whole columns, in float64 (so no
Python integer arithmetic can be made to run for ever), with floating-point warnings silenced:
``x / 0`` is ``inf``, and any comparison with a missing value (``None``/NaN), ``!=`` included, is false.
"""
from __future__ import annotations

import ast
import math
import re
import unicodedata
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from driver._errors import DriverError

__all__ = ["Expr", "ExprError", "FUNCTIONS", "parse", "kinds_of", "MAX_LENGTH", "MAX_NODES"]

#: longest expression text accepted (characters) and largest syntax tree (nodes)
MAX_LENGTH, MAX_NODES = 2000, 500
#: digits a number in an expression may have
MAX_DIGITS = 40
_DECIMAL = re.compile(r"(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?", re.ASCII)


class ExprError(DriverError, ValueError):
    """An expression the language does not allow; ``token`` is the offending piece of text."""

    def __init__(self, message: str, token: str | None = None):
        self.message, self.token = message, token
        super().__init__(message)


def _minmax(reduce: Callable) -> Callable:
    def f(*args: np.ndarray) -> np.ndarray:
        if len(args) < 2:
            raise ExprError("min/max take two or more arguments (element-wise over columns)")
        out = args[0]
        for a in args[1:]:
            out = reduce(out, a)
        return out
    return f


#: the named functions an expression may call: name -> (function, number of arguments or None)
FUNCTIONS: dict[str, tuple[Callable, int | None]] = {
    "abs": (np.abs, 1),
    "sqrt": (np.sqrt, 1),
    "exp": (np.exp, 1),
    "log": (np.log, 1),
    "log10": (np.log10, 1),
    "sin": (np.sin, 1),
    "cos": (np.cos, 1),
    "tan": (np.tan, 1),
    "radians": (np.radians, 1),
    "degrees": (np.degrees, 1),
    "floor": (np.floor, 1),
    "ceil": (np.ceil, 1),
    "min": (_minmax(np.fmin), None),
    "max": (_minmax(np.fmax), None),
}

_FORTRAN = {".and.": " and ", ".or.": " or ", ".not.": " not ", ".true.": " True ", ".false.": " False "}
_TOKEN = re.compile(r"('[^']*'|\"[^\"]*\"|`[^`]*`)")   # quoted pieces are left alone
_BACKTICK = re.compile(r"`([^`]*)`")

_COMPARE: dict[type, Callable] = {
    ast.Eq: np.equal, ast.NotEq: np.not_equal, ast.Lt: np.less, ast.LtE: np.less_equal,
    ast.Gt: np.greater, ast.GtE: np.greater_equal,
}
_BINARY: dict[type, Callable] = {
    ast.Add: np.add, ast.Sub: np.subtract, ast.Mult: np.multiply, ast.Div: np.true_divide,
    ast.FloorDiv: np.floor_divide, ast.Mod: np.mod, ast.Pow: np.power,
}
_SYMBOL = {ast.MatMult: "@", ast.BitAnd: "&", ast.BitOr: "|", ast.BitXor: "^", ast.LShift: "<<",
           ast.RShift: ">>", ast.Invert: "~", ast.In: "in", ast.NotIn: "not in", ast.Is: "is",
           ast.IsNot: "is not"}


def _prepare(text: str) -> tuple[str, dict[str, str]]:
    """Fortran logical words to Python ones and backtick names to placeholders (outside quotes)."""
    names: dict[str, str] = {}
    pieces = []
    for piece in _TOKEN.split(text):
        if piece.startswith("`"):
            name = piece[1:-1].strip()
            if not name:
                raise ExprError("empty name in backticks", piece)
            if not name.isascii() or not name.isprintable():
                raise ExprError("a name in backticks is printable ASCII", piece)
            ident = f"_bq{len(names)}_"
            names[ident] = name
            pieces.append(f" {ident} ")
        elif piece.startswith(("'", '"')):
            pieces.append(piece)
        else:
            if "@" in piece:
                raise ExprError("'@' references are not allowed in a deck expression", "@")
            if "#" in piece:
                raise ExprError("'#' is not a comment inside an expression (the whole text is the "
                                "expression); remove it and what follows, or quote it", piece[piece.index("#"):][:40])
            for ch in piece:
                if not (" " <= ch <= "~" or ch == "\t"):
                    raise ExprError(f"character {ch!r} (U+{ord(ch):04X} {unicodedata.name(ch, 'control')}) is "
                                    "not allowed outside quotes: names and numbers are ASCII (a fullwidth or "
                                    "accented look-alike would read another column)", ch)
            for word, repl in _FORTRAN.items():
                piece = re.sub(re.escape(word), repl, piece, flags=re.IGNORECASE)
            pieces.append(piece)
    return "".join(pieces), names


def _segment(text: str, node: ast.AST) -> str:
    seg = ast.get_source_segment(text, node)
    return seg if seg else node.__class__.__name__


def _dotted(node: ast.expr) -> str | None:
    parts = []
    while isinstance(node, ast.Attribute):
        parts.append(node.attr)
        node = node.value
    if isinstance(node, ast.Name):
        parts.append(node.id)
        return ".".join(reversed(parts))
    return None


@dataclass(frozen=True)
class Expr:
    """A checked expression: its text, the column names it reads, and its syntax tree.

    ``evaluate(data)`` returns a numpy array (one value per row of ``data``, a DataFrame or a
    mapping of column name -> array); ``mask(data)`` its truth as a boolean array (missing
    values are false).
    """

    text: str
    names: frozenset[str]
    _tree: ast.Expression
    _source: str
    _aliases: tuple[tuple[str, str], ...]

    # -------------------------------------------------------------- evaluation
    def evaluate(self, data: Any) -> np.ndarray:
        """The expression over every row of ``data`` (DataFrame or mapping of columns)."""
        n = _length(data)
        columns = {name: _column(data, name, n) for name in self.names}
        _Kinds(_kinds_of_columns(columns), dict(self._aliases), self._source).of(self._tree.body)
        with np.errstate(all="ignore"):
            out = _Evaluator(columns, dict(self._aliases), self._source).visit(self._tree.body)
        out = np.asarray(out)
        return np.broadcast_to(out, (n,)).copy() if out.ndim == 0 else out

    def check_kinds(self, kinds: Mapping[str, str]) -> str:
        """Check the expression against column kinds (``{'mu_min_deg': 'number', 'grashof_class':
        'text'}``, see :func:`kinds_of`) before anything is evaluated: arithmetic, functions and
        order on numbers and logicals only, text compared with text only, and the result one
        number or logical per row.  Returns the result's kind ('number' or 'bool'); raises
        :class:`ExprError` naming the offending token."""
        result = _Kinds(kinds, dict(self._aliases), self._source).of(self._tree.body)
        if result == "text":
            raise ExprError(f"'{self._source[:60]}' gives text, not a number or a logical", self._source[:60])
        return result

    def mask(self, data: Any) -> np.ndarray:
        """Truth of the expression for every row: a boolean array (NaN/None count as false)."""
        return _truth(self.evaluate(data))

    def __str__(self) -> str:
        return self.text


def parse(text: str, columns: Iterable[str] | None = None) -> Expr:
    """Check ``text`` against the language; with ``columns``, every name must be one of them.

    Raises :class:`ExprError` naming the offending token.
    """
    if not isinstance(text, str):
        raise ExprError("an expression must be a string")
    if len(text) > MAX_LENGTH:
        raise ExprError(f"expression longer than {MAX_LENGTH} characters", text[:40] + "...")
    if not text.strip():
        raise ExprError("empty expression")
    source, aliases = _prepare(text)
    try:
        tree = ast.parse(source.strip(), mode="eval")
    except SyntaxError as exc:
        bad = (exc.text or source).strip()
        raise ExprError(f"not a valid expression ({exc.msg})", bad[:60]) from None
    source = source.strip()
    nodes = list(ast.walk(tree))
    if len(nodes) > MAX_NODES:
        raise ExprError(f"expression too large ({len(nodes)} syntax nodes; at most {MAX_NODES})")
    names: set[str] = set()
    _check(tree.body, source, aliases, names)
    _Kinds({}, aliases, source, "any").of(tree.body)   # text constants in arithmetic ('x' * 10**9)
    _fold(tree.body, source, aliases)
    if columns is not None:
        known = set(columns)
        for name in sorted(names):
            if name not in known:
                shown = ", ".join(sorted(known)[:40]) + (", ..." if len(known) > 40 else "")
                raise ExprError(f"unknown column '{name}' (columns: {shown})", name)
    return Expr(text, frozenset(names), tree, source, tuple(aliases.items()))


def _check(node: ast.AST, source: str, aliases: dict[str, str], names: set[str]) -> None:
    """Walk the tree; raise ExprError at the first construct outside the whitelist."""
    tok = lambda n: _segment(source, n)
    if isinstance(node, ast.BoolOp):
        for v in node.values:
            _check(v, source, aliases, names)
    elif isinstance(node, ast.UnaryOp):
        if not isinstance(node.op, (ast.Not, ast.USub, ast.UAdd)):
            raise ExprError(f"operator '{_SYMBOL.get(type(node.op), type(node.op).__name__)}' is not allowed", tok(node))
        _check(node.operand, source, aliases, names)
    elif isinstance(node, ast.BinOp):
        if type(node.op) not in _BINARY:
            raise ExprError(f"operator '{_SYMBOL.get(type(node.op), type(node.op).__name__)}' is not allowed", tok(node))
        _check(node.left, source, aliases, names)
        _check(node.right, source, aliases, names)
    elif isinstance(node, ast.Compare):
        for op in node.ops:
            if type(op) not in _COMPARE:
                raise ExprError(f"comparison '{_SYMBOL.get(type(op), type(op).__name__)}' is not allowed "
                                "(use == != < <= > >=)", tok(node))
        _check(node.left, source, aliases, names)
        for c in node.comparators:
            _check(c, source, aliases, names)
    elif isinstance(node, ast.Constant):
        if not isinstance(node.value, (bool, int, float, str)) or isinstance(node.value, complex):
            raise ExprError("only numbers, strings and True/False are allowed as constants", tok(node))
        if isinstance(node.value, (int, float)) and not isinstance(node.value, bool):
            spelt = tok(node)
            if not _DECIMAL.fullmatch(spelt):
                raise ExprError(f"'{spelt[:40]}' is not a number as a deck writes one (decimal digits, '.', "
                                "an e exponent; no '_', 0x, 0o, 0b or j)", spelt[:40])
            if sum(c.isdigit() for c in spelt) > MAX_DIGITS:
                raise ExprError(f"number with more than {MAX_DIGITS} digits", spelt[:40] + "...")
            if not math.isfinite(float(node.value)):
                raise ExprError(f"'{spelt[:40]}' is not a finite float64 number", spelt[:40])
    elif isinstance(node, ast.Name):
        name = aliases.get(node.id, node.id)
        if node.id not in aliases and (node.id.startswith("__") or node.id.startswith("_bq")):
            raise ExprError("names starting with '__' are not allowed", node.id)
        if node.id in ("True", "False"):
            return
        names.add(name)
    elif isinstance(node, ast.Attribute):
        dotted = _dotted(node)
        if dotted is None or "__" in dotted:
            raise ExprError("attribute access is not allowed", tok(node))
        names.add(dotted)   # a dotted column name such as fourbar.crank, never an attribute
    elif isinstance(node, ast.Call):
        fname = node.func.id if isinstance(node.func, ast.Name) else None
        if fname is None or fname not in FUNCTIONS or fname in aliases:
            raise ExprError(f"call of '{tok(node.func)}' is not allowed "
                            f"(functions: {', '.join(sorted(FUNCTIONS))})", tok(node.func))
        if node.keywords:
            raise ExprError("keyword arguments are not allowed", tok(node))
        nargs = FUNCTIONS[fname][1]
        if nargs is not None and len(node.args) != nargs:
            raise ExprError(f"{fname}() takes {nargs} argument(s)", tok(node))
        if nargs is None and len(node.args) < 2:
            raise ExprError(f"{fname}() takes two or more arguments: it is element-wise over the columns of "
                            "one case (one value per case), not a reduction over the cases", tok(node))
        for a in node.args:
            if isinstance(a, ast.Starred):
                raise ExprError("'*' arguments are not allowed", tok(a))
            _check(a, source, aliases, names)
    else:
        what = {ast.Subscript: "subscripts", ast.Lambda: "lambdas", ast.ListComp: "comprehensions",
                ast.SetComp: "comprehensions", ast.DictComp: "comprehensions",
                ast.GeneratorExp: "comprehensions", ast.NamedExpr: "assignment",
                ast.JoinedStr: "f-strings", ast.IfExp: "if-expressions", ast.List: "lists",
                ast.Tuple: "tuples", ast.Dict: "dicts", ast.Set: "sets", ast.Await: "await",
                ast.Yield: "yield", ast.Starred: "'*'", ast.Slice: "slices"}.get(type(node), type(node).__name__)
        raise ExprError(f"{what} are not allowed in a deck expression", tok(node))


def _reads_columns(node: ast.AST) -> bool:
    """Whether the part reads a column (a function's own name is not one)."""
    if isinstance(node, ast.Attribute):
        return True
    if isinstance(node, ast.Name):
        return node.id not in ("True", "False")
    if isinstance(node, ast.Call):
        return any(_reads_columns(a) for a in node.args)
    return any(_reads_columns(c) for c in ast.iter_child_nodes(node))


def _fold(node: ast.AST, source: str, aliases: dict[str, str]) -> None:
    """Evaluate every largest part that reads no column (a constant) now: it must be a finite
    number, a logical or a text (``9**9**9**9``, ``log(0.0)``, ``'x' * 10**9`` are refused here)."""
    if _reads_columns(node):
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.expr):
                _fold(child, source, aliases)
        return
    if isinstance(node, ast.Constant):
        return
    with np.errstate(all="ignore"):
        value = np.asarray(_Evaluator({}, aliases, source).visit(node))
    if value.dtype.kind in "iuf" and not np.all(np.isfinite(value)):
        raise ExprError(f"'{_segment(source, node)[:60]}' is {value.item()!r}, not a finite number",
                        _segment(source, node)[:60])


#: the kinds of value a column holds, for :meth:`Expr.check_kinds`
KINDS = ("number", "bool", "text")


def kinds_of(sample: Mapping[str, Any]) -> dict[str, str]:
    """Column kinds from one row (a case's summary): text for strings, bool for logicals,
    number otherwise (None/NaN included)."""
    out = {}
    for k, v in sample.items():
        if isinstance(v, (bool, np.bool_)):
            out[k] = "bool"
        elif isinstance(v, str):
            out[k] = "text"
        else:
            out[k] = "number"
    return out


def _kinds_of_columns(columns: Mapping[str, np.ndarray]) -> dict[str, str]:
    out = {}
    for k, a in columns.items():
        if a.dtype.kind == "b":
            out[k] = "bool"
        elif a.dtype.kind in "iuf":
            out[k] = "number"
        else:
            out[k] = "text" if any(isinstance(v, str) for v in a.ravel()) else "number"
    return out


class _Kinds:
    """Static type check of a tree against column kinds (number, bool, text)."""

    def __init__(self, kinds: Mapping[str, str], aliases: dict[str, str], source: str, unknown: str = "number"):
        self.kinds, self.aliases, self.source = kinds, aliases, source
        self.unknown = unknown   # the kind of a column not in ``kinds`` ('any': not known yet)

    def tok(self, node: ast.AST) -> str:
        return _segment(self.source, node)[:60]

    def numeric(self, node: ast.AST, what: str) -> None:
        if self.of(node) == "text":
            raise ExprError(f"{what} on text ('{self.tok(node)}' is text, not a number)", self.tok(node))

    def of(self, node: ast.AST) -> str:
        if isinstance(node, ast.Constant):
            return "bool" if isinstance(node.value, bool) else ("text" if isinstance(node.value, str) else "number")
        if isinstance(node, ast.Name):
            if node.id in ("True", "False"):
                return "bool"
            return self.kinds.get(self.aliases.get(node.id, node.id), self.unknown)
        if isinstance(node, ast.Attribute):
            return self.kinds.get(_dotted(node) or "", self.unknown)
        if isinstance(node, ast.BoolOp):
            for v in node.values:
                self.of(v)
            return "bool"
        if isinstance(node, ast.UnaryOp):
            if isinstance(node.op, ast.Not):
                self.of(node.operand)
                return "bool"
            self.numeric(node.operand, "arithmetic")
            return "number"
        if isinstance(node, ast.BinOp):
            self.numeric(node.left, "arithmetic")
            self.numeric(node.right, "arithmetic")
            return "number"
        if isinstance(node, ast.Compare):
            left = node.left
            for right in node.comparators:
                a, b = self.of(left), self.of(right)
                if "any" not in (a, b) and (a == "text") != (b == "text"):
                    txt, num = (left, right) if a == "text" else (right, left)
                    raise ExprError(f"'{self.tok(txt)}' is text and '{self.tok(num)}' a number: comparing them "
                                    "is always false (compare text with 'quoted text')", self.tok(txt))
                left = right
            return "bool"
        if isinstance(node, ast.Call):
            fname = node.func.id if isinstance(node.func, ast.Name) else "?"   # _check admitted names only
            for arg in node.args:
                self.numeric(arg, f"{fname}()")
            return "number"
        raise ExprError(f"{type(node).__name__} is not allowed", self.tok(node))


def _length(data: Any) -> int:
    if hasattr(data, "shape") and hasattr(data, "columns"):   # DataFrame
        return int(data.shape[0])
    lengths = {len(np.atleast_1d(np.asarray(v, dtype=object))) for v in data.values()} if data else {1}
    lengths.discard(1)
    if len(lengths) > 1:
        raise ValueError(f"columns of different lengths {sorted(lengths)}")
    return lengths.pop() if lengths else 1


def _column(data: Any, name: str, n: int) -> np.ndarray:
    """A column as float64 where it is numeric or boolean (None -> NaN), else as objects."""
    if name not in data:
        raise ExprError(f"unknown column '{name}'", name)
    raw = data[name]
    arr = np.asarray(raw.to_numpy() if hasattr(raw, "to_numpy") else raw)
    if arr.ndim == 0:
        arr = np.full(n, arr.item(), dtype=arr.dtype if arr.dtype != object else object)
    if arr.dtype.kind in "biuf":
        return arr.astype(np.float64) if arr.dtype.kind != "b" else arr
    values = list(arr)
    if all(v is None or isinstance(v, (bool, np.bool_, int, float, np.integer, np.floating)) for v in values):
        return np.array([np.nan if v is None else float(v) for v in values], dtype=np.float64)
    return np.array([None if (isinstance(v, float) and math.isnan(v)) else v for v in values], dtype=object)


def _truth(a: Any) -> np.ndarray:
    a = np.asarray(a)
    if a.dtype.kind == "b":
        return a
    if a.dtype.kind in "iuf":
        return (a != 0) & ~np.isnan(a.astype(np.float64))
    return np.array([bool(v) and not (isinstance(v, float) and math.isnan(v)) for v in a.ravel()],
                    dtype=bool).reshape(a.shape)


def _number(a: Any) -> np.ndarray:
    a = np.asarray(a)
    if a.dtype.kind in "biuf":
        return a.astype(np.float64)
    raise ExprError("arithmetic on a text column")


class _Evaluator(ast.NodeVisitor):
    """Evaluates a checked tree over numpy columns (only the node types _check admits)."""

    def __init__(self, columns: dict[str, np.ndarray], aliases: dict[str, str], source: str):
        self.columns, self.aliases, self.source = columns, aliases, source

    def visit_BoolOp(self, node: ast.BoolOp) -> np.ndarray:
        values = [_truth(self.visit(v)) for v in node.values]
        combine = np.logical_and if isinstance(node.op, ast.And) else np.logical_or
        out = values[0]
        for v in values[1:]:
            out = combine(out, v)
        return out

    def visit_UnaryOp(self, node: ast.UnaryOp) -> np.ndarray:
        v = self.visit(node.operand)
        if isinstance(node.op, ast.Not):
            return ~_truth(v)
        return -_number(v) if isinstance(node.op, ast.USub) else _number(v)

    def visit_BinOp(self, node: ast.BinOp) -> np.ndarray:
        return _BINARY[type(node.op)](_number(self.visit(node.left)), _number(self.visit(node.right)))

    def visit_Compare(self, node: ast.Compare) -> np.ndarray:
        left = self.visit(node.left)
        out: np.ndarray | None = None
        for op, comp in zip(node.ops, node.comparators):
            right = self.visit(comp)
            part = self._compare(op, left, right)
            out = part if out is None else out & part
            left = right
        assert out is not None   # a Compare node has at least one operator
        return out

    @staticmethod
    def _compare(op: ast.cmpop, a: Any, b: Any) -> np.ndarray:
        a, b = np.asarray(a), np.asarray(b)
        if a.dtype.kind in "biuf" and b.dtype.kind in "biuf":
            return _COMPARE[type(op)](a.astype(np.float64), b.astype(np.float64))
        # text (or mixed) columns: equality by value, order only between strings; missing -> false
        fn = _COMPARE[type(op)]
        a_b = np.broadcast_arrays(a.astype(object), b.astype(object))

        def one(x: Any, y: Any) -> bool:
            if x is None or y is None:
                return False
            if isinstance(x, str) != isinstance(y, str):
                return isinstance(op, ast.NotEq)
            return bool(fn(x, y))
        return np.array([one(x, y) for x, y in zip(a_b[0].ravel(), a_b[1].ravel())], dtype=bool).reshape(a_b[0].shape)

    def visit_Constant(self, node: ast.Constant) -> np.ndarray:
        v = node.value
        if isinstance(v, bool):
            return np.asarray(v)
        if isinstance(v, (int, float)):
            return np.asarray(float(v))   # float64 only: no unbounded integer arithmetic
        return np.asarray(v, dtype=object)

    def visit_Name(self, node: ast.Name) -> np.ndarray:
        if node.id in ("True", "False"):
            return np.asarray(node.id == "True")
        return self.columns[self.aliases.get(node.id, node.id)]

    def visit_Attribute(self, node: ast.Attribute) -> np.ndarray:
        dotted = _dotted(node)
        assert dotted is not None   # _check admitted only dotted names
        return self.columns[dotted]

    def visit_Call(self, node: ast.Call) -> np.ndarray:
        assert isinstance(node.func, ast.Name)   # _check admitted only calls of FUNCTIONS by name
        fn, _ = FUNCTIONS[node.func.id]
        return fn(*(_number(self.visit(a)) for a in node.args))

    def generic_visit(self, node: ast.AST) -> Any:   # unreachable after _check
        raise ExprError(f"{type(node).__name__} is not allowed", _segment(self.source, node))
