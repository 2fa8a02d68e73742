"""The ``&optimize`` group: design variables, objective and constraints of an optimisation.

    &fourbar   fixed_link = 12, crank = 3, coupler = 15, rocker = 9, omega = 5, step_deg = 10 /
    &optimize
      var1 = 'fourbar.crank',   lower1 = 1,  upper1 = 7
      var2 = 'fourbar.coupler', lower2 = 6,  upper2 = 20
      maximize    = 'mu_min_deg'
      constraint1 = 'rocker_swing_deg >= 60'
      constraint2 = 'grashof_class == "crank-rocker"'
      method = 'differential_evolution', seed = 1
    /

Objective and constraints are written in the deck expression language
(:mod:`driver._expr`) over the study's summary columns (``python -m driver --keys
fourbar`` and the ``_summary`` tables of a sweep list them); nothing is evaluated as
code.  A constraint ``a >= b`` (or ``<=``, ``>``, ``<``) has the margin ``a - b``
(``b - a``), in the units of its columns; any other constraint (a logical column, a text
comparison, ``and``/``or``) is satisfied or not, with margin 0 or -1.
"""
from __future__ import annotations

import ast
import hashlib
import json
import math
import re
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from driver import _expr as expr
from driver._deck import Deck, DeckError, GroupSpec, Key, Params, RawGroup, validate

__all__ = ["SPEC", "MAX_VARS", "MAX_CONSTRAINTS", "METHODS", "Variable", "Constraint", "Problem", "problem_of"]

MAX_VARS = 9
MAX_CONSTRAINTS = 9
METHODS = ("differential_evolution", "slsqp", "trust-constr", "grid")
#: hard ceiling on evaluations of one run (absurd requests are refused before anything runs)
MAX_EVALS = 2_000_000


def _at_least(n: int):
    return lambda v: None if v >= n else f"must be at least {n} (got {v})"


def _spec() -> GroupSpec:
    keys: dict[str, Key] = {}
    for k in range(1, MAX_VARS + 1):
        keys[f"var{k}"] = Key("str", doc=f"design variable {k}: a numeric deck key 'group.key', or one "
                                         "element of a list key 'group.key(i)'")
        keys[f"lower{k}"] = Key("float", doc=f"lower bound of var{k} (deck units)")
        keys[f"upper{k}"] = Key("float", doc=f"upper bound of var{k} (deck units)")
    for k in range(1, MAX_CONSTRAINTS + 1):
        keys[f"constraint{k}"] = Key("str", doc="a condition on the summary columns that the design must meet")
    keys.update({
        "minimize": Key("str", doc="expression over the summary columns to minimise"),
        "maximize": Key("str", doc="expression over the summary columns to maximise"),
        "method": Key("str", default="differential_evolution", choices=METHODS,
                      doc="'differential_evolution' (global), 'slsqp' / 'trust-constr' (multi-start local), "
                          "'grid' (every point of a grid_count^n grid)"),
        "seed": Key("int", default=1, doc="random seed of the population / start set (runs are deterministic)"),
        "maxiter": Key("int", default=300, check=_at_least(1),
                       doc="generations (differential_evolution) or iterations per start (local methods)"),
        "popsize": Key("int", default=10, check=_at_least(2),
                       doc="differential_evolution: population = popsize x number of variables"),
        "tol": Key("float", default=1e-3, check=lambda v: None if v >= 0 else "must not be negative",
                   doc="differential_evolution: stop when the population's spread of objective values "
                       "falls below tol x |mean| (+ atol); local methods: ftol of the optimiser"),
        "atol": Key("float", default=1e-3, check=lambda v: None if v >= 0 else "must not be negative",
                    doc="differential_evolution: absolute part of the stopping rule (objective units)"),
        "polish": Key("bool", default=False,
                      doc="differential_evolution: finish with a local constrained search from the best member"),
        "starts": Key("int", default=8, check=_at_least(1), doc="local methods: number of starts"),
        "start": Key("str", default="sobol", choices=("sobol", "grid"),
                     doc="local methods: starts from a seeded Sobol' set, or the best feasible points of "
                         "a grid_count^n grid"),
        "grid_count": Key("int", default=11, check=_at_least(2),
                          doc="points per variable of the grid (method = 'grid' or start = 'grid')"),
        "max_evals": Key("int", default=200_000, check=_at_least(1),
                         doc="refuse a run that could need more design evaluations than this"),
        "constraint_tol": Key("float", default=1e-7, check=lambda v: None if 0 <= v < 1 else "must be in [0, 1)",
                              doc="feasibility tolerance, relative: a constraint a >= b (<=, ==) is met when "
                                  "it is violated by at most constraint_tol x max(1, |a|, |b|) (in its units)"),
        "resolution": Key("float", default=1e-7, check=lambda v: None if 0 < v < 1 else "must be in (0, 1)",
                          doc="local methods and polish: the reported design is a point of the lattice of step "
                              "10^floor(log10(resolution x (upper - lower))) per variable, polished there by a "
                              "deterministic pattern search (the same design on every machine)"),
        "jobs": Key("int", default=0, check=lambda v: None if v >= 0 else "must not be negative",
                    doc="worker processes for studies without a batch path (0: all cores, 1: serial)"),
        "summary_columns": Key("strs", default=[],
                               doc="the summary columns the evaluations table records besides those the objective "
                                   "and constraints read (default: all); on a study's batch path only the kernel "
                                   "passes these columns need run"),
    })
    return GroupSpec("optimize", keys, doc="optimise a study's design over bounded deck keys")


SPEC = _spec()


@dataclass(frozen=True)
class Variable:
    """A design variable: the deck key 'group.key' and its bounds (deck units)."""

    name: str
    key: str
    lower: float
    upper: float
    index: int | None = None   # element (from 1) of a list key, 'group.key(i)'


@dataclass(frozen=True)
class Constraint:
    """A constraint expression; ``left``/``right`` set when it is a numeric inequality or equality.

    ``sense`` is +1 for ``left >= right`` (margin left - right), -1 for ``left <= right``
    (margin right - left); ``equality`` for ``left == right`` (margin -|left - right|).  Met
    within the problem's tolerance ``constraint_tol x max(1, |left|, |right|)``.
    """

    text: str
    whole: expr.Expr
    left: expr.Expr | None = None
    right: expr.Expr | None = None
    sense: int = 0
    equality: bool = False

    @property
    def numeric(self) -> bool:
        return bool(self.sense or self.equality)


@dataclass
class Problem:
    """A validated optimisation problem over one study."""

    deck: Deck
    study: Any                 # the study (driver._study.Study)
    raw: RawGroup              # the study group as written (variables replaced per design)
    base: Params               # the study group as validated (the starting design)
    opts: Params               # the &optimize group
    variables: list[Variable]
    objective: expr.Expr
    sense: int                 # +1 minimise, -1 maximise
    constraints: list[Constraint] = field(default_factory=list)
    #: epigraph terms: 'maximize = min(a, b, ...)' / 'minimize = max(a, b, ...)' -> [a, b, ...]
    #: (gradient methods then solve min s subject to s >= sense x term, smooth at the optimum)
    terms: list[expr.Expr] = field(default_factory=list)
    _code: str | None = field(default=None, repr=False, compare=False)

    @property
    def names(self) -> list[str]:
        return [v.name for v in self.variables]

    @property
    def lower(self) -> np.ndarray:
        return np.array([v.lower for v in self.variables])

    @property
    def upper(self) -> np.ndarray:
        return np.array([v.upper for v in self.variables])

    @property
    def steps(self) -> np.ndarray:
        """Lattice step of each variable (deck units): 10^floor(log10(resolution x span))."""
        return np.array([10.0 ** self.exponents[i] for i in range(len(self.variables))])

    @property
    def exponents(self) -> list[int]:
        r = self.opts.resolution
        return [math.floor(math.log10(r * (v.upper - v.lower))) for v in self.variables]

    def snap(self, x: Any) -> np.ndarray:
        """The lattice point nearest ``x`` inside the bounds, each value the double nearest its
        decimal text (so the design and the deck written from it read the same)."""
        out = []
        for v, e, xi in zip(self.variables, self.exponents, np.asarray(x, dtype=np.float64)):
            k = round(float(xi) / 10.0 ** e)
            val = float(f"{k * 10.0 ** e:.{max(0, -e)}f}") if e < 0 else float(k * 10 ** e)
            if val < v.lower or val > v.upper:
                val = min(max(val, v.lower), v.upper)
            out.append(val)
        return np.array(out)

    def x_text(self, i: int, value: float) -> str:
        """Variable i's value with the lattice's decimals."""
        e = self.exponents[i]
        return f"{value:.{max(0, -e)}f}"

    @property
    def objective_text(self) -> str:
        return f"{'minimize' if self.sense > 0 else 'maximize'} {self.objective.text}"

    def fingerprint(self) -> str:
        """Hash of the whole problem, everything that decides which design gets which values:
        the study group as written (the variables' own values included), the variables in
        order with their bounds, the objective and its sense, the constraints, and every
        setting of the method (all of &optimize but ``jobs``, which never changes a result).
        A resume record is replayed only into a problem with the same fingerprint (and code:
        :meth:`code_digest`)."""
        values = sorted(((k, self.raw.values[k]) for k in self.raw.values), key=lambda kv: kv[0])
        settings = {k: self.opts[k] for k in sorted(SPEC.keys) if k != "jobs"}
        parts: dict[str, Any] = {
            "study": self.raw.name, "deck": values,
            "variables": [[v.name, v.lower, v.upper] for v in self.variables],
            "objective": [self.sense, self.objective.text], "constraints": [c.text for c in self.constraints],
            "settings": settings}
        blob = json.dumps(parts, default=repr, sort_keys=True)
        return hashlib.sha256(blob.encode()).hexdigest()[:16]

    def code_digest(self) -> str:
        """Digest of the code that computes a design's values (the study, the evaluation, the
        runner, the deck reader, the expression language; the kernels' Fortran sources): a
        resume record computed by other code is not replayed.  The same on every machine
        (:func:`driver._output.source_digest`), so a committed ``_evals`` table carries it."""
        if self._code is None:
            from pathlib import Path

            import driver._deck
            import driver._expr
            import driver._runner
            from driver._output import source_digest
            engine = Path(__file__).with_name("__init__.py")   # the whole optimize package, not imported here
            self._code = source_digest(self.study, engine, driver._runner, driver._deck, driver._expr)[:16]
        return self._code


def _sub(e: expr.Expr, node: ast.expr) -> expr.Expr:
    """The sub-expression ``node`` of ``e`` (reads a subset of e's columns)."""
    return expr.Expr(e.text, e.names, ast.Expression(body=node), e._source, e._aliases)


def _split(e: expr.Expr) -> tuple[expr.Expr | None, expr.Expr | None, int, bool]:
    """A single numeric comparison ``a OP b`` -> (a, b, sense, equality), else (None, None, 0, False).

    ``a == b`` is an equality unless a side is a text or logical constant (``grashof_class ==
    "crank-rocker"`` is a condition, met or not)."""
    body = e._tree.body
    if not (isinstance(body, ast.Compare) and len(body.ops) == 1):
        return None, None, 0, False
    op = body.ops[0]
    if isinstance(op, ast.Eq):
        sides = (body.left, body.comparators[0])
        if any(isinstance(n, ast.Constant) and not isinstance(n.value, (int, float)) or
               isinstance(n, ast.Constant) and isinstance(n.value, bool) for n in sides):
            return None, None, 0, False
        return _sub(e, body.left), _sub(e, body.comparators[0]), 0, True
    sense = 1 if isinstance(op, (ast.Gt, ast.GtE)) else (-1 if isinstance(op, (ast.Lt, ast.LtE)) else 0)
    if not sense:
        return None, None, 0, False
    return _sub(e, body.left), _sub(e, body.comparators[0]), sense, False


def _terms(e: expr.Expr, sense: int) -> list[expr.Expr]:
    """Arguments of a top-level min(...) maximised or max(...) minimised (an epigraph form)."""
    body = e._tree.body
    if (isinstance(body, ast.Call) and isinstance(body.func, ast.Name) and not body.keywords
            and body.func.id == ("min" if sense < 0 else "max") and len(body.args) >= 2):
        return [_sub(e, a) for a in body.args]
    return []


def _parse_expr(opts: Params, key: str) -> expr.Expr:
    try:
        return expr.parse(opts[key])
    except expr.ExprError as exc:
        raise opts.error(key, str(exc)) from None


def problem_of(deck: Deck) -> Problem:
    """Validate the deck's study group and its &optimize group into a problem.

    Parameters
    ----------
    deck : Deck
        A read deck with one study group and an ``&optimize`` group.

    Returns
    -------
    Problem
        The variables (deck keys, in their units, with bounds), the objective and the
        constraints, checked against the study's summary columns.

    Raises
    ------
    DeckError
        Bad input, naming the deck, line and key; the deck's own design beyond the budget of one
        run (``--max-work``, ``--max-memory``).
    """
    from driver._runner import study_of
    study, base = study_of(deck)
    opts = validate(deck.groups["optimize"], SPEC, deck.path)
    if "sweep" in deck.groups:
        raise DeckError(deck.path, deck.groups["sweep"].line, None,
                        "a deck has either &sweep or &optimize, not both")
    raw = deck.groups[study.spec.name]
    variables: list[Variable] = []
    for k in range(1, MAX_VARS + 1):
        name = opts[f"var{k}"]
        if name is None:
            for w in ("lower", "upper"):
                if opts[f"{w}{k}"] is not None:
                    raise opts.error(f"{w}{k}", f"given without var{k}")
            continue
        group, _, key = name.lower().replace(" ", "").partition(".")
        if not key:
            raise opts.error(f"var{k}", f"write the key as 'group.key' (e.g. '{study.spec.name}.{name}')")
        index = None
        m = re.fullmatch(r"([a-z_][a-z0-9_]*)\((\d+)\)", key)
        if m:
            key, index = m.group(1), int(m.group(2))
        if group != study.spec.name:
            raise opts.error(f"var{k}", f"group '{group}' is not this deck's study group &{study.spec.name}")
        spec_key = study.spec.keys.get(key)
        if spec_key is None:
            raise opts.error(f"var{k}", f"&{group} has no key '{key}'")
        if spec_key.kind not in ("float", "floats"):
            raise opts.error(f"var{k}", f"&{group} key '{key}' is not a real number ({spec_key.kind}); "
                                        "only real-valued keys can be design variables")
        current = base[key]
        if spec_key.kind == "float" and index is not None:
            raise opts.error(f"var{k}", f"&{group} key '{key}' is one number, not a list: write '{group}.{key}'")
        if spec_key.kind == "floats":
            size = len(current) if isinstance(current, list) else 0
            if index is None and size > 1:
                raise opts.error(f"var{k}", f"&{group} key '{key}' is a list of {size}: name one element, "
                                            f"'{group}.{key}(1)' ... '{group}.{key}({size})'")
            if index is not None and not 1 <= index <= size:
                raise opts.error(f"var{k}", f"&{group} key '{key}' has {size} value(s) in the deck; "
                                            f"element {index} does not exist")
        lo, hi = opts[f"lower{k}"], opts[f"upper{k}"]
        for w, v in (("lower", lo), ("upper", hi)):
            if v is None:
                raise opts.error(f"var{k}", f"needs {w}{k}")
        if not lo < hi:
            raise opts.error(f"upper{k}", f"must exceed lower{k} ({hi:g} <= {lo:g})")
        full = f"{group}.{key}" + (f"({index})" if index is not None else "")
        if any(v.name == full for v in variables):
            raise opts.error(f"var{k}", f"{full} is a variable twice")
        variables.append(Variable(full, key, float(lo), float(hi), index))
    if not variables:
        raise opts.error("var1", "an optimisation needs at least var1 with lower1 and upper1")
    if (opts.minimize is None) == (opts.maximize is None):
        raise opts.error("maximize" if opts.maximize is not None else "minimize",
                         "give exactly one of minimize and maximize")
    okey = "minimize" if opts.minimize is not None else "maximize"
    objective = _parse_expr(opts, okey)
    constraints = []
    for k in range(1, MAX_CONSTRAINTS + 1):
        if opts[f"constraint{k}"] is None:
            continue
        whole = _parse_expr(opts, f"constraint{k}")
        left, right, sense, eq = _split(whole)
        constraints.append(Constraint(whole.text, whole, left, right, sense, eq))
    n = len(variables)
    worst = _worst_evals(opts, n)
    if worst > opts.max_evals or worst > MAX_EVALS:
        key = "grid_count" if opts.method == "grid" or (opts.method != "differential_evolution"
                                                       and opts.start == "grid") else "maxiter"
        raise opts.error(key, f"this run may need {worst:.3g} design evaluations, more than max_evals = "
                              f"{min(opts.max_evals, MAX_EVALS)}; reduce it or raise max_evals (at most {MAX_EVALS})")
    sense = 1 if okey == "minimize" else -1
    # every design is one run of the study under the budget (--max-work, --max-memory): the deck's
    # own design is checked before anything starts (a design the search reaches beyond it is
    # refused on its own and counted as infeasible, driver.optimize._evaluate)
    from driver import _limits as limits
    limits.check(study, base, "each design of this optimisation (the deck's own design) ")
    return Problem(deck, study, raw, base, opts, variables, objective, sense, constraints, _terms(objective, sense))


def _worst_evals(opts: Params, n: int) -> float:
    """An upper bound of the evaluations a run can use (checked before anything runs)."""
    grid = float(opts.grid_count) ** n
    if opts.method == "grid":
        return grid
    if opts.method == "differential_evolution":
        pop = opts.popsize * n
        return pop * (opts.maxiter + 1) + (50 * (n + 1) * 20 if opts.polish else 0)
    starts = grid if opts.start == "grid" else 0.0
    # each iteration: one line search (a few points) and one forward-difference Jacobian
    return starts + opts.starts * opts.maxiter * (n + 1 + 5) + opts.starts * (n + 1)


def is_finite(x: Any) -> bool:
    try:
        return math.isfinite(float(x))
    except (TypeError, ValueError):
        return False
