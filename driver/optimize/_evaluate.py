"""Design evaluations of an optimisation: study summaries -> objective, constraint values, margins.

Every design the optimiser asks for goes through :class:`Evaluator`, which

* validates the design as a complete deck (the study group with the variables replaced) and
  computes the study's summary: in one batched call where the study has a batch path
  (``summarise_batch``), otherwise case by case, on a Dask cluster (``--scheduler``) or in
  worker processes when that pays;
* never raises for a bad design: a case that cannot be validated, fails, or leaves the
  objective undefined is *infeasible*, with its reason recorded and counted;
* evaluates the objective and constraints (deck expression language) over the whole batch
  at once, and keeps every evaluation (so a design is never computed twice, and ``--resume``
  replays a deterministic run from its journal without recomputing).
"""
from __future__ import annotations

import concurrent.futures as cf
import math
import os
import re
import time
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any

import numpy as np
import pandas as pd

from driver import _blas as blas
from driver import _expr as expr
from driver import _limits as limits
from driver._atomic import open_append
from driver._deck import DeckError, Params, RawGroup, validate
from driver._runner import NUMERICAL, CaseFailure, compute, numerical_error
from driver._study import load_study
from driver.optimize import _journal as journal_file
from driver.optimize._problem import Problem

if TYPE_CHECKING:   # pragma: no cover - dask is an optional dependency
    from dask.distributed import Client

__all__ = ["Evaluator", "evaluate_cases", "FAILED_VIOLATION", "rerun_agrees"]

#: constraint violation given to a design whose case failed (ranks below every evaluated design)
FAILED_VIOLATION = 1e6
#: violation of a design whose constraints are met but the study's own run refuses (ranks it just
#: below the feasible designs, so the polish steps back to one the study accepts)
REFUSED_VIOLATION = 1e-300
#: objective given to failed designs in the local methods (which need a finite number)
FAILED_OBJECTIVE = 1e12
#: a batch of designs goes to worker processes (-j) when it is estimated to take longer than
#: this [s] in this process (the first batch is timed here); the route never changes a result
POOL_MIN_SECONDS = 0.2


def _design_raw(raw: RawGroup, keys: list[str], kinds: list[str], x: np.ndarray) -> RawGroup:
    """The raw study group with the variables set; ``keys`` entries are 'key' or 'key(i)'."""
    values = dict(raw.values)
    for key, kind, v in zip(keys, kinds, x):
        name, _, idx = key.partition("(")
        if idx:
            items = list(values[name]) if isinstance(values.get(name), list) else [values.get(name)]
            items[int(idx.rstrip(")")) - 1] = float(v)
            values[name] = items
        else:
            values[name] = [float(v)] if kind == "floats" else float(v)
    return RawGroup(raw.name, values, raw.lines, raw.line)


def design_params(problem: Problem, x: np.ndarray) -> Params:
    """The validated study group of design ``x`` (DeckError if the design is not a valid deck)."""
    kinds = [problem.study.spec.keys[v.key].kind for v in problem.variables]
    raw = _design_raw(problem.raw, _slots(problem), kinds, x)
    return validate(raw, problem.study.spec, problem.deck.path)


@blas.one_thread()
def evaluate_cases(group: str, deck_path: str, raw: RawGroup, keys: list[str], kinds: list[str],
                   xs: list[list[float]], budget: limits.Budget | None = None) -> list[tuple[str, str, dict]]:
    """Summaries of designs ``xs`` case by case: [(status, reason, summary)] (worker entry point).

    status is 'ok', 'bad_input' (the design is not a valid deck, or the study refuses it),
    'refused' (over the work or memory ``budget`` of one run, :mod:`driver._limits`; default this
    process's) or 'failed' (the run failed, numerically or by the study's own verdict).
    Every case goes through the runner's checks (:func:`driver._runner.compute`): the budget
    before it runs, numerical failures in words, no NaN/inf/'****' in what it would write.
    """
    module = load_study(group)
    if module is None:   # the problem was built from this study's deck
        raise ValueError(f"no study reads namelist group &{group}")
    out: list[tuple[str, str, dict]] = []
    # a library's warning about one design is not printed from a worker: the design is judged by its
    # own checks (numerical failures in words, finite numbers), the same on every route
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for x in xs:
            try:
                params = validate(_design_raw(raw, keys, kinds, np.asarray(x)), module.spec, deck_path)
            except DeckError as exc:
                out.append(("bad_input", _deck_reason(exc), {}))
                continue
            try:
                limits.check(module, params, lim=budget)
            except DeckError as exc:
                out.append(("refused", _deck_reason(exc), {}))
                continue
            try:
                if module.summarise is not None:
                    try:
                        with np.errstate(all="ignore"):
                            summary = dict(module.summarise(params))
                    except NUMERICAL as exc:
                        raise numerical_error(params, exc) from None
                    out.append(("ok", "", summary))
                else:
                    result = compute(module, params, budget=budget)
                    out.append(("failed", str(result.failure), dict(result.summary)) if result.failure
                               else ("ok", "", dict(result.summary)))
            except CaseFailure as exc:   # a numerical failure, or a non-finite number bound for a table
                out.append(("failed", _deck_reason(exc), {}))
            except DeckError as exc:     # the study refuses the design (e.g. an arm that cannot reach)
                out.append(("bad_input", _deck_reason(exc), {}))
            except Exception as exc:   # a failing design is infeasible, never the end of the run
                out.append(("failed", f"{exc.__class__.__name__}: {exc}", {}))
    return out


def _deck_reason(exc: DeckError) -> str:
    return exc.message if exc.key is None else f"{exc.key}: {exc.message}"


def _non_finite(row: tuple[str, str, dict]) -> tuple[str, str, dict]:
    """A summary value NaN is a missing figure (None); an infinite one fails the design, with its
    column named: no such number is ranked or reaches the evaluations table."""
    status, reason, summary = row
    if not summary:
        return row
    clean = {}
    for k, v in summary.items():
        if isinstance(v, (float, np.floating)) and not math.isfinite(v):
            if math.isnan(v):
                v = None
            elif status == "ok":
                return ("failed", f"a result that is not a finite number ({k} = {float(v)})", {})
        clean[k] = v
    return (status, reason, clean)


def _ignore_sigint() -> None:
    import signal
    signal.signal(signal.SIGINT, signal.SIG_IGN)


@dataclass
class Record:
    """One evaluated design."""

    index: int
    x: tuple[float, ...]
    status: str
    reason: str
    summary: dict
    objective: float = math.nan     # the expression's value (not sign-flipped)
    feasible: bool = False
    violation: float = math.inf     # total constraint violation (0 when feasible)
    margins: tuple[float, ...] = ()
    met: tuple[bool, ...] = ()
    why: str = ""                   # infeasibility reason (counted in the report)
    tols: tuple[float, ...] = ()    # feasibility tolerance of each constraint (its units; 0: a condition)
    values: tuple[float, ...] = ()  # left side of each numeric constraint (NaN for a condition)
    signed: tuple[float, ...] = ()  # a - b of each numeric constraint (NaN for a condition)
    terms: tuple[float, ...] = ()   # epigraph terms of the objective (Problem.terms), if any


class Evaluator:
    """Evaluates designs for one :class:`Problem`; keeps every evaluation in order."""

    def __init__(self, problem: Problem, jobs: int = 1, journal: Path | None = None,
                 resumed: list[dict] | None = None, scheduler: Any = None):
        self.problem = problem
        self.scheduler = scheduler      # a Dask scheduler address or Client: batches go to its workers
        self._client: Client | None = None
        self.jobs = jobs if jobs > 0 else (os.cpu_count() or 1)
        self.records: list[Record] = []
        self.cache: dict[tuple[float, ...], int] = {}
        self.replayed: dict[tuple[float, ...], dict] = {}
        self.keys = _slots(problem)
        self.kinds = [problem.study.spec.keys[v.key].kind for v in problem.variables]
        self.journal = journal
        self._journal_fh: IO[str] | None = None
        #: what a resume found wrong with the records it was given (driver.optimize._journal), or ''
        self.resume_note = ""
        self._pool: cf.ProcessPoolExecutor | None = None
        self.seconds_per_case: float | None = None
        self.compute_seconds = 0.0
        self.computed = 0
        #: designs computed by route: 'batch', 'dask', 'processes', 'serial'
        self.routes: dict[str, int] = {}
        #: the budget of one design's run, this process's (Dask workers do not inherit it)
        self.budget = limits.budget()
        for row in resumed or []:
            self.replayed[tuple(float(v) for v in row["x"])] = row

    # ------------------------------------------------------------------ lifecycle
    def close(self) -> None:
        if self._client is not None and isinstance(self.scheduler, str):
            self._client.close()
        self._client = None
        if self._pool is not None:
            self._pool.shutdown(wait=True, cancel_futures=True)
            self._pool = None
        if self._journal_fh is not None:
            self._journal_fh.close()
            self._journal_fh = None

    def __enter__(self) -> Evaluator:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    # ------------------------------------------------------------------ computing
    def _compute(self, xs: list[tuple[float, ...]]) -> list[tuple[str, str, dict]]:
        """Summaries of new designs: the study's batch path, else case by case on the Dask cluster,
        in worker processes (when a batch costs enough to pay for them) or in this process.

        Whatever the route, the same designs give the same rows (cases are independent and
        deterministic), so a run's optimum and history do not depend on where it ran.
        """
        t0 = time.perf_counter()
        out = _batch_summaries(self.problem, xs)
        route = "batch"
        if out is None:
            args = (self.problem.raw.name, str(self.problem.deck.path), self.problem.raw, self.keys, self.kinds)
            slow = self.seconds_per_case is not None and self.seconds_per_case * len(xs) > POOL_MIN_SECONDS
            if self.scheduler and len(xs) > 1:
                route = "dask"
                if self._client is None:
                    from dask.distributed import Client
                    self._client = self.scheduler if not isinstance(self.scheduler, str) else \
                        Client(self.scheduler, timeout="60s")
                workers = max(1, sum(w.get("nthreads", 1) for w in
                                     self._client.scheduler_info().get("workers", {}).values()))
                size = max(1, math.ceil(len(xs) / (2 * workers)))
                parts = [list(map(list, xs[i:i + size])) for i in range(0, len(xs), size)]
                # the whole generation is submitted at once and gathered in order
                futures = [self._client.submit(evaluate_cases, *args, part, self.budget, pure=False)
                           for part in parts]
                out = [r for part in self._client.gather(futures) for r in part]
            elif self.jobs > 1 and len(xs) > 1 and slow:
                route = "processes"
                if self._pool is None:
                    self._pool = cf.ProcessPoolExecutor(self.jobs, initializer=_ignore_sigint)
                size = max(1, math.ceil(len(xs) / self.jobs))
                parts = [list(map(list, xs[i:i + size])) for i in range(0, len(xs), size)]
                out = [r for part in self._pool.map(evaluate_cases, *zip(*[args + (p, self.budget) for p in parts]))
                       for r in part]
            else:
                route = "serial"
                out = evaluate_cases(*args, [list(x) for x in xs], self.budget)
        out = [_non_finite(row) for row in out]
        dt = time.perf_counter() - t0
        self.compute_seconds += dt
        self.computed += len(xs)
        self.routes[route] = self.routes.get(route, 0) + len(xs)
        if self.seconds_per_case is None and xs:
            self.seconds_per_case = dt / len(xs)
        return out

    def evaluate(self, X: np.ndarray) -> list[Record]:
        """Records of designs ``X`` (rows), evaluating the ones not seen before in one batch."""
        X = np.atleast_2d(np.asarray(X, dtype=np.float64))
        keys = [tuple(float(v) for v in row) for row in X]
        new = list(dict.fromkeys(k for k in keys if k not in self.cache))
        if new:
            todo = [k for k in new if k not in self.replayed]
            computed = dict(zip(todo, self._compute(todo))) if todo else {}
            rows = []
            for k in new:
                if k in computed:
                    rows.append(computed[k])
                else:
                    r = self.replayed[k]
                    rows.append((r["status"], r["reason"], r["summary"]))
            self._add(new, rows, journal=[k in computed for k in new])
        return [self.records[self.cache[k]] for k in keys]

    def _add(self, xs: list[tuple[float, ...]], rows: list[tuple[str, str, dict]], journal: list[bool]) -> None:
        first = len(self.records)
        recs = [Record(first + i, x, st, reason, summary) for i, (x, (st, reason, summary)) in enumerate(zip(xs, rows))]
        self._score(recs)
        for r in recs:
            self.cache[r.x] = r.index
            self.records.append(r)
        if self.journal is not None and any(journal):
            if self._journal_fh is None:   # never through a link planted at its name
                self.journal.parent.mkdir(parents=True, exist_ok=True)
                self._journal_fh = open_append(self.journal)
            fp, code = self.problem.fingerprint(), self.problem.code_digest()
            for r, j in zip(recs, journal):
                if j:   # one checksummed line per computed design (driver.optimize._journal)
                    self._journal_fh.write(journal_file.line(journal_file.record(fp, code, r.x, r.status, r.reason,
                                                                                 r.summary)))
            self._journal_fh.flush()

    def _score(self, recs: list[Record]) -> None:
        """Objective, margins and feasibility of new records (vectorised over the batch)."""
        p = self.problem
        ok = [r for r in recs if r.status == "ok"]
        for r in recs:
            if r.status != "ok":
                word = {"bad_input": "not a valid design", "refused": "refused, over the budget of one run"}
                r.why = f"{word.get(r.status, 'case failed')}: {_short(r.reason)}"
                r.violation = FAILED_VIOLATION
                r.margins = tuple(-math.inf for _ in p.constraints)
                r.met = tuple(False for _ in p.constraints)
        if not ok:
            return
        names = _names(p)
        for r in list(ok):
            miss = sorted(n for n in names if n not in r.summary)
            if miss:
                r.why = f"no '{miss[0]}' in the case's summary"
                r.violation = FAILED_VIOLATION
                r.margins = tuple(-math.inf for _ in p.constraints)
                r.met = tuple(False for _ in p.constraints)
                ok.remove(r)
        if not ok:
            return
        frame = pd.DataFrame([r.summary for r in ok])
        for name in _names(p):
            if name not in frame:
                frame[name] = np.nan
        f = _values(p.objective, frame)
        terms = [_values(t, frame) for t in p.terms]
        ctol = p.opts.constraint_tol
        margins, met, tols, lefts, diffs = [], [], [], [], []
        nan = np.full(len(frame), math.nan)
        for c in p.constraints:
            numeric = c.numeric
            if numeric:
                assert c.left is not None and c.right is not None   # set on every numeric constraint
                try:
                    a, b = _values(c.left, frame), _values(c.right, frame)
                except expr.ExprError:      # 'a == b' over text columns: a condition after all
                    numeric = False
            if numeric:
                # met within constraint_tol x max(1, |a|, |b|): the scale of the constraint's own numbers
                tol = ctol * np.fmax(1.0, np.fmax(np.abs(a), np.abs(b)))
                m = -np.abs(a - b) if c.equality else c.sense * (a - b)
                m = np.where(np.isnan(m), -math.inf, m)
                truth = m >= -tol
                tol = np.where(np.isfinite(tol), tol, 0.0)
                left, diff = a, a - b
            else:
                truth = c.whole.mask(frame)
                m = np.where(truth, 0.0, -1.0)
                tol, left, diff = np.zeros(len(frame)), nan, nan
            margins.append(m)
            met.append(truth)
            tols.append(tol)
            lefts.append(left)
            diffs.append(diff)
        for i, r in enumerate(ok):
            r.objective = float(f[i])
            r.terms = tuple(float(t[i]) for t in terms)
            r.margins = tuple(float(m[i]) for m in margins)
            r.met = tuple(bool(t[i]) for t in met)
            r.tols = tuple(float(t[i]) for t in tols)
            r.values = tuple(float(v[i]) for v in lefts)
            r.signed = tuple(float(v[i]) for v in diffs)
            viol = [0.0 if t else (min(-m, FAILED_VIOLATION) if math.isfinite(m) and m < 0 else
                                   (1.0 if math.isfinite(m) else FAILED_VIOLATION))
                    for m, t in zip(r.margins, r.met)]
            r.violation = float(sum(viol))
            if not math.isfinite(r.objective):
                r.why = "objective undefined"
                r.violation = max(r.violation, 1.0)
            elif not all(r.met):
                k = r.met.index(False)
                r.why = f"violates constraint{_constraint_number(p, k)}"
            elif r.reason:      # the study's own run refuses it (a batch row's verdict)
                r.why = f"not a valid design: {_short(r.reason)}"
                r.violation = max(r.violation, REFUSED_VIOLATION)
            r.feasible = not r.why

    # ------------------------------------------------------------------ views for the methods
    def best(self) -> Record | None:
        """Best feasible record so far; ties go to the design evaluated first."""
        sense = self.problem.sense
        feas = [r for r in self.records if r.feasible]
        if not feas:
            return None
        return min(feas, key=lambda r: (sense * r.objective, r.index))

    def least_infeasible(self) -> Record | None:
        if not self.records:
            return None
        return min(self.records, key=lambda r: (r.violation, r.index))

    def reasons(self) -> dict[str, int]:
        """Infeasible designs counted by reason (most frequent first)."""
        out: dict[str, int] = {}
        for r in self.records:
            if not r.feasible:
                out[r.why] = out.get(r.why, 0) + 1
        return dict(sorted(out.items(), key=lambda kv: (-kv[1], kv[0])))

    def frame(self) -> pd.DataFrame:
        """Every evaluation as a tidy table: variables, status, objective, margins, summary columns
        (in name order: the same whether a design was computed or replayed from a resume record,
        whose summary has sorted keys)."""
        p = self.problem
        rows = []
        names = sorted({k for r in self.records for k in r.summary})
        for r in self.records:
            row: dict[str, Any] = {"eval": r.index + 1, **dict(zip(p.names, r.x)), "status": r.status,
                                   "feasible": r.feasible, "infeasible_reason": r.why,
                                   "objective": r.objective if math.isfinite(r.objective) else np.nan,
                                   "violation": r.violation}   # inf never reaches a table: null, reason given
            for k, m in enumerate(r.margins):
                row[f"margin{_constraint_number(p, k)}"] = m if math.isfinite(m) else np.nan
            row["case_error"] = r.reason
            row.update({f"summary.{k}": r.summary[k] for k in names if k in r.summary})
            rows.append(row)
        return pd.DataFrame(rows)


def rerun_agrees(best: Record, check: Record) -> bool:
    """Whether the full study's re-run of a design (``check``) agrees with its evaluation
    (``best``): the same feasibility and the objective within 1e-9 x max(1, |f|).  A re-run that
    differs means the evaluation did not compute what the study computes (a resume record of
    another problem, a batch path out of step with the study): the run fails, never succeeds."""
    if check.feasible != best.feasible:
        return False
    if check.objective == best.objective:
        return True
    return abs(check.objective - best.objective) <= 1e-9 * max(1.0, abs(best.objective))


def _slots(problem: Problem) -> list[str]:
    """Where each variable goes in the raw group: 'key' or 'key(i)'."""
    return [v.key if v.index is None else f"{v.key}({v.index})" for v in problem.variables]


def _batch_summaries(problem: Problem, xs: list[tuple[float, ...]]) -> list[tuple[str, str, dict]] | None:
    """The study's batch path (``Study.batch``), when it has one; None otherwise."""
    batch = problem.study.batch
    if batch is None or not xs or any(v.index is not None and v.key not in batch.elements for v in problem.variables):
        return None
    fn, applies = batch.fn, batch.applies
    if applies is not None and not applies(problem.base):
        return None
    columns = {slot: np.array([x[i] for x in xs]) for i, slot in enumerate(_slots(problem))}
    wanted = None
    if problem.opts.summary_columns and batch.passes is not None:
        # only what the objective, the constraints and summary_columns read: only their passes run
        wanted = sorted(_names(problem) | set(problem.opts.summary_columns))
    try:
        frame = fn(problem.base, columns) if wanted is None else fn(problem.base, columns, wanted=wanted)
    except DeckError:
        return None                     # some design is not a valid deck: case by case says which
    rows = frame.to_dict("records") if hasattr(frame, "to_dict") else list(frame)
    # a design the study's own run refuses (DeckError case by case, e.g. an arm that cannot reach) is
    # a batch row with a status: infeasible here too, so the optimum is a design the study accepts
    refusal = batch.refusal
    out = []
    for row in rows:
        row = {k: (None if isinstance(v, float) and math.isnan(v) else v) for k, v in row.items()}
        err = row.pop("error", None) or row.pop("case_error", None)
        why = refusal(row) if (refusal is not None and not err) else None
        # the row keeps its summary (its margins stay smooth for a gradient method) and its reason:
        # _score makes it infeasible
        out.append(("failed", str(err), row) if err else ("ok", why or "", row))
    return out


def _constraint_number(p: Problem, k: int) -> int:
    """The deck's number N of the k-th given constraint (constraintN)."""
    nums = [n for n in range(1, 10) if p.opts[f"constraint{n}"] is not None]
    return nums[k]


def _names(p: Problem) -> set[str]:
    names = set(p.objective.names)
    for c in p.constraints:
        names |= set(c.whole.names)
    return names


def _values(e: expr.Expr, frame: pd.DataFrame) -> np.ndarray:
    v = np.asarray(e.evaluate(frame))
    if v.dtype.kind == "b":
        return v.astype(np.float64)
    if v.dtype.kind not in "iuf":
        try:
            return v.astype(np.float64)
        except (TypeError, ValueError):
            raise expr.ExprError("the expression is not a number (a text column?)", e.text) from None
    return v.astype(np.float64)


_NUMBER = re.compile(r"(?<![\w.])[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


def _short(text: str, n: int = 90) -> str:
    """A reason to count: one line, numbers replaced by '#' (so the same failure counts once)."""
    text = _NUMBER.sub("#", " ".join(str(text).split()))
    return text if len(text) <= n else text[: n - 3] + "..."
