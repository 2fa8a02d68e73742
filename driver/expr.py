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
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

__all__ = ["Expr", "ExprError", "FUNCTIONS", "parse", "MAX_LENGTH", "MAX_NODES"]

#: longest expression text accepted (characters) and largest syntax tree (nodes)
MAX_LENGTH, MAX_NODES = 2000, 500


class ExprError(ValueError):
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
            ident = f"_bq{len(names)}_"
            names[ident] = name
            pieces.append(f" {ident} ")
        elif piece.startswith(("'", '"')):
            pieces.append(piece)
        else:
            if "@" in piece:
                raise ExprError("'@' references are not allowed in a deck expression", "@")
            for word, repl in _FORTRAN.items():
                piece = re.sub(re.escape(word), repl, piece, flags=re.IGNORECASE)
            pieces.append(piece)
    return "".join(pieces), names


def _segment(text: str, node: ast.AST) -> str:
    seg = ast.get_source_segment(text, node)
    return seg if seg else node.__class__.__name__


def _dotted(node: ast.Attribute) -> str | None:
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
        with np.errstate(all="ignore"):
            out = _Evaluator(columns, dict(self._aliases), self._source).visit(self._tree.body)
        out = np.asarray(out)
        return np.broadcast_to(out, (n,)).copy() if out.ndim == 0 else out

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
        if fname not in FUNCTIONS or node.func.id in aliases:
            raise ExprError(f"call of '{tok(node.func)}' is not allowed "
                            f"(functions: {', '.join(sorted(FUNCTIONS))})", tok(node.func))
        if node.keywords:
            raise ExprError("keyword arguments are not allowed", tok(node))
        nargs = FUNCTIONS[fname][1]
        if nargs is not None and len(node.args) != nargs:
            raise ExprError(f"{fname}() takes {nargs} argument(s)", tok(node))
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
        out = None
        for op, comp in zip(node.ops, node.comparators):
            right = self.visit(comp)
            part = self._compare(op, left, right)
            out = part if out is None else out & part
            left = right
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
        return self.columns[_dotted(node)]

    def visit_Call(self, node: ast.Call) -> np.ndarray:
        fn, _ = FUNCTIONS[node.func.id]
        return fn(*(_number(self.visit(a)) for a in node.args))

    def generic_visit(self, node: ast.AST) -> Any:   # unreachable after _check
        raise ExprError(f"{type(node).__name__} is not allowed", _segment(self.source, node))
