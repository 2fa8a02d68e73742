"""What the engines return: outcome objects, and the exit codes of the command line (defined here,
once).

Every engine (one study run, :mod:`driver._runner`; a sweep, :mod:`driver.sweep`; an
optimisation, :mod:`driver.optimize`; a synthesis, :mod:`driver.synthesis`) returns an
:class:`Outcome`: what it wrote, its warnings and errors as data (:class:`Message`), the
progress notes a terminal may show, and an :attr:`~Outcome.exit_code`.  Engines never print;
the command line (:mod:`driver._cli`) is the one place that prints outcomes, and the Python API
(:mod:`driver._api`) hands them back.  The shape follows ``scipy.optimize.OptimizeResult``: plain
fields, ``success``/``status``/``message`` where they mean something.
"""
from __future__ import annotations

import enum
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:   # annotations only
    import pandas as pd

    from driver._deck import Params
    from driver._result import Figure, Result
    from driver.optimize._evaluate import Evaluator, Record
    from driver.optimize._methods import HistoryRow, MethodResult
    from driver.optimize._problem import Problem

__all__ = ["ExitCode", "Message", "Outcome", "RunOutcome", "FilesOutcome", "SweepOutcome", "StreamedSummary",
           "OptimizeOutcome", "Optimum", "SynthesisOutcome"]


class ExitCode(enum.IntEnum):
    """The exit status of ``python -m driver`` (and of one deck, and of one sweep case)."""

    OK = 0             #: every deck succeeded
    FAILED = 1         #: a run failed (a case, an optimiser that did not converge, a file system fault)
    BAD_INPUT = 2      #: a deck had bad input (nothing was written for it)
    INTERRUPTED = 130  #: Ctrl-C (finished outputs are complete, no partial file is left)
    TERMINATED = 143   #: SIGTERM, handled like Ctrl-C


@dataclass(frozen=True)
class Message:
    """A warning or an error an engine reports, as data.

    ``str()`` is the line the command line prints (``'warning: ...'``).

    Parameters
    ----------
    level : {'warning', 'error'}
        How bad it is.
    text : str
        What happened; names the deck where it concerns one.
    """

    level: str
    text: str

    def __str__(self) -> str:
        return f"{self.level}: {self.text}"


#: how an outcome shows itself in a notebook, by its type: each engine registers its outcome's
#: (the report page stands above the engines, so the outcome cannot import it; see
#: :meth:`Outcome._repr_html_`)
HTML: dict[type, Callable[[Any], str]] = {}


@dataclass(kw_only=True)
class Outcome:
    """What an engine did: the base of every outcome.

    Parameters
    ----------
    written : list of pathlib.Path, optional
        The files written, in order.
    messages : list of Message, optional
        Warnings and errors, in the order they arose.
    notes : list of str, optional
        Progress lines a terminal shows unless asked to be quiet (``"resume: ..."``).
    late_failure : bool, default False
        A failure after the engine's run (its report page could not be written): exit status 1.
    """

    written: list[Path] = field(default_factory=list)
    messages: list[Message] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    #: a failure after the engine's run (its report page could not be written): exit status 1
    late_failure: bool = False

    @property
    def exit_code(self) -> ExitCode:
        """The exit status this outcome means (see :class:`ExitCode`)."""
        return ExitCode.FAILED if self.late_failure else ExitCode.OK

    @property
    def ok(self) -> bool:
        """True when the exit status is 0."""
        return self.exit_code == ExitCode.OK

    def _repr_html_(self) -> str | None:
        """The outcome as its report page shows it, for a notebook's rich display: the renderer
        its engine registered in :data:`HTML` (the page's own templates), or None (plain repr)."""
        for kind, render in HTML.items():
            if isinstance(self, kind):
                return render(self)
        return None

    def warn(self, text: str) -> None:
        """Record a warning.

        Parameters
        ----------
        text : str
            The warning, naming the deck where it concerns one.
        """
        self.messages.append(Message("warning", text))

    def error(self, text: str) -> None:
        """Record an error.

        Parameters
        ----------
        text : str
            The error, naming the deck where it concerns one.
        """
        self.messages.append(Message("error", text))


@dataclass(kw_only=True)
class RunOutcome(Outcome):
    """One study run: its result and the files written.

    The result's warnings and failure are the result's own (``result.warnings``,
    ``result.failure``); the exit status is 1 when it failed.

    Parameters
    ----------
    result : Result
        What the study's run produced.
    """

    result: Result

    @property
    def exit_code(self) -> ExitCode:
        """The exit status: 1 when the run failed, else the outcome's (see :class:`ExitCode`)."""
        return ExitCode.FAILED if self.result.failure else super().exit_code


@dataclass(kw_only=True)
class FilesOutcome(Outcome):
    """What an engine that writes a set of files and may fail after writing them did (a synthesis).

    Parameters
    ----------
    failure : str or None, optional
        Why the engine's result failed its check; None on success.
    value : object, optional
        The engine's own result (a :class:`driver.synthesis.Synthesis`).
    """

    failure: str | None = None
    value: Any = None

    @property
    def exit_code(self) -> ExitCode:
        """The exit status: 1 when the engine's result failed, else the outcome's."""
        return ExitCode.FAILED if self.failure else super().exit_code


class StreamedSummary:
    """The summary of a sweep too large to hold, read from its record's parts when asked.

    A lazy handle over the parts of the sweep's resume record that hold its rows (one part at
    a time where it can).  Valid while the sweep's output folder is; :func:`driver.run_sweep` without an output
    folder gives a DataFrame instead.

    Parameters
    ----------
    paths : list of pathlib.Path
        The record's parts that hold rows, in case order.
    metadata : dict of bytes to bytes
        The summary table's schema metadata (the pandas columns and ``attrs``), as written to
        ``<stem>_summary.parquet``.
    num_rows : int
        Rows of the summary.
    """

    def __init__(self, paths: list[Path], metadata: dict[bytes, bytes], num_rows: int):
        self.paths, self.metadata, self.num_rows = list(paths), dict(metadata), int(num_rows)

    def __len__(self) -> int:
        return self.num_rows

    def __repr__(self) -> str:
        return f"<StreamedSummary: {self.num_rows} rows in {len(self.paths)} parts>"

    @property
    def columns(self) -> list[str]:
        """The summary's column names, in order."""
        import pyarrow.parquet as pq
        return list(pq.read_schema(self.paths[0]).names) if self.paths else []

    def _table(self, path: Path, columns: list[str] | None = None) -> Any:
        import pyarrow.parquet as pq
        t = pq.read_table(path, columns=columns)
        return t.replace_schema_metadata(self.metadata)

    def to_pandas(self, columns: list[str] | None = None) -> pd.DataFrame:
        """Read the summary into one DataFrame, as pandas reads ``<stem>_summary.parquet``.

        Parameters
        ----------
        columns : list of str, optional
            The columns to read; default all.

        Returns
        -------
        pandas.DataFrame
            Every row, in case order, with the summary's ``attrs``.
        """
        import json

        import pandas as pd
        import pyarrow as pa
        if not self.paths:
            return pd.DataFrame()
        frame = pa.concat_tables([self._table(p, columns) for p in self.paths]).to_pandas()
        attrs = self.metadata.get(b"PANDAS_ATTRS")
        if attrs:
            frame.attrs = json.loads(attrs)
        return frame

    def kept(self, columns: list[str] | None = None) -> pd.DataFrame:
        """Read the rows the deck's ``keep`` filter kept, one part at a time.

        Parameters
        ----------
        columns : list of str, optional
            The columns to read; default all.

        Returns
        -------
        pandas.DataFrame
            The kept rows, in case order.
        """
        import pandas as pd
        import pyarrow as pa
        import pyarrow.compute as pc
        read = None if columns is None else list(dict.fromkeys([*columns, "kept"]))
        pieces = []
        for p in self.paths:
            t = self._table(p, read)
            pieces.append(t.filter(pc.fill_null(t.column("kept"), False)))
        if not pieces:
            return pd.DataFrame()
        frame = pa.concat_tables(pieces).to_pandas()
        return frame if columns is None or "kept" in columns else frame.drop(columns=["kept"])


@dataclass(kw_only=True)
class SynthesisOutcome(FilesOutcome):
    """What a synthesis did (:func:`driver.synthesis.run_synthesis_deck`).

    The linkage, its tables and its run, the files written, and the failure of its check as
    data.

    Parameters
    ----------
    value : Synthesis
        The synthesis (:class:`driver.synthesis.Synthesis`); its parts are the properties below.
    name : str
        The outputs' stem.
    text : str
        The report, as ``<stem>.out`` holds it.
    linkage_deck : str
        The linkage as a complete ``&fourbar`` deck (``<stem>.linkage.dat``); '' without one.
    figures : list of Figure
        The synthesis's own figures (the structural error, the path through the targets),
        drawn on demand; the linkage's are ``result.figures``.
    """

    name: str = ""
    text: str = ""
    linkage_deck: str = ""
    figures: list[Figure] = field(default_factory=list)

    @property
    def task(self) -> str:
        """``'function'``, ``'crank_rocker'`` or ``'path'``."""
        return str(self.value.params.task)

    @property
    def linkage(self) -> dict[str, Any] | None:
        """The linkage's ``&fourbar`` deck values; None when no linkage was found.

        Lengths are in the deck's length unit, angles in deg.
        """
        return self.value.linkage

    @property
    def table(self) -> pd.DataFrame:
        """The task's table: structural error (function), family (crank-rocker), targets (path)."""
        return self.value.table

    @property
    def table_name(self) -> str:
        """The table's file suffix (``'_error'``, ``'_family'``, ``'_targets'``)."""
        return str(self.value.table_name)

    @property
    def checks(self) -> dict[str, float]:
        """The exact kernel's checks of the design, units in the names where they have one."""
        return dict(self.value.checks)

    @property
    def result(self) -> Result | None:
        """The four-bar study's run of the linkage (its tables, summary and figures)."""
        return self.value.study_result

    @property
    def params(self) -> Params | None:
        """The linkage's validated ``&fourbar`` keys (what :attr:`result` was run from)."""
        return None if self.result is None else self.result.params


@dataclass(kw_only=True)
class SweepOutcome(Outcome):
    """What a sweep did (:func:`driver.sweep.run_sweep_deck`, :func:`driver.run_sweep`), with its data.

    ``driver.SweepResult`` is this class.

    Attributes
    ----------
    deck : str
        The sweep deck's path.
    name : str
        Its stem (the outputs' names).
    outdir : pathlib.Path or None
        Where the files are; None from :func:`driver.run_sweep` without ``outdir`` (they were
        written to a temporary folder, now gone).
    n_cases : int
        Cases of the sweep.
    n_ok : int
        Cases that succeeded.
    n_kept : int
        Cases the deck's ``keep`` filter kept.
    n_resumed : int
        Cases found complete in the resume record (``--resume``) and not run again.
    n_redone : int
        Cases run again because their record or files failed a check.
    n_failed : int
        Cases that failed.
    failed : list of tuple
        The failed cases as ``(case, {swept key: value}, error)``; all of them, or the first
        ones when the batch path streamed its tables (``n_failed`` counts them all).
    bad_input : bool
        Some cases had bad values (exit status 2).
    batch : bool
        The study's batch path ran the sweep (else case by case).
    workers : str
        Where the cases ran (``"2 worker(s)"``, ``"dask ADDRESS"``).
    chunk : int
        Cases per chunk (a function of the number of cases only: the resume record's parts).
    seconds : float
        Wall time of the cases, s.
    phases : dict of str to float
        The driver's CPU time per phase (``prepare_cpu``, ``run_cpu``, ``finish_cpu`` ...), s.
    summary : pandas.DataFrame or StreamedSummary or None
        The ``<stem>_summary`` table: one row per case (with ``summary_rows = 'kept'`` the kept
        and failed ones), exactly the columns of ``<stem>_summary.parquet``: case number, the
        swept keys, status, kept, the study's headline figures (units in their names), error;
        its ``attrs`` hold the base deck's settings the columns depend on.  For a batch sweep
        whose rows were too many to hold, a :class:`StreamedSummary` (``to_pandas()``,
        ``num_rows``, ``kept()``).
    cases : pandas.DataFrame or None
        The ``<stem>_cases`` table: the tidy rows of every case that wrote its outputs, a
        column per swept key; None when no case did, or too many for one table.
    text : str or None
        The fixed-format summary ``.out``; None when the tables were streamed (read
        :attr:`out`).
    study : str
        The study group swept.
    sweep : Params or None
        The validated ``&sweep`` group (its plotted columns, keep filter, rows).
    best_case : int or None
        The best kept case: the largest or smallest value of the first plotted summary
        column (``plot_y``, else the study's first ``sweep_plot`` column) where the study says
        which end is better (``sweep_best``), else the first kept case; None when no case was
        kept.  The design-space maps mark the same case.
    best_metric : str or None
        The column (or plotted expression) ``best_case`` is best by; None when it is the first
        kept case.
    best : Result or None
        The run of ``best_case`` (its tables, figures, summary and ``params``: the case the
        report page draws), when asked for (``best=True``; the command line's ``--report``).
    """

    deck: str = ""
    name: str = ""
    outdir: Path | None = None
    n_cases: int = 0
    n_ok: int = 0
    n_kept: int = 0
    n_resumed: int = 0
    n_redone: int = 0
    n_failed: int = 0
    failed: list[tuple[int, dict, str]] = field(default_factory=list)
    bad_input: bool = False
    batch: bool = False
    workers: str = ""
    chunk: int = 0
    seconds: float = 0.0
    phases: dict[str, float] = field(default_factory=dict)
    summary: pd.DataFrame | StreamedSummary | None = None
    cases: pd.DataFrame | None = None
    text: str | None = ""
    study: str = ""
    sweep: Params | None = None
    best_case: int | None = None
    best_metric: str | None = None
    best: Result | None = None

    @property
    def exit_code(self) -> ExitCode:
        """0 every case ok, 2 a case had bad values, else 1 a case failed."""
        worst = ExitCode.BAD_INPUT if self.bad_input else ExitCode.FAILED if self.n_failed else ExitCode.OK
        return max(super().exit_code, worst)

    @property
    def warnings(self) -> list[str]:
        """The sweep's warnings and errors, one line each as the command line prints them."""
        return [str(m) for m in self.messages]

    @property
    def status(self) -> int:
        """The exit status as a number (0, 1 or 2), as the command line returns it."""
        return int(self.exit_code)

    @property
    def out(self) -> str:
        """The fixed-format summary ``.out`` text (of a streamed sweep: read from its file)."""
        if self.text is None and self.outdir is not None:
            return (self.outdir / f"{self.name}.out").read_text()
        return self.text or ""

    @property
    def kept(self) -> pd.DataFrame:
        """The summary rows of the cases the deck's ``keep`` filter kept (all ok cases without one)."""
        if isinstance(self.summary, StreamedSummary):
            return self.summary.kept()
        assert self.summary is not None, "a sweep outcome carries its summary"
        return self.summary[self.summary["kept"].astype(bool)]

    def __repr__(self) -> str:
        return (f"<SweepResult {self.name!r}: {self.n_cases} cases, {self.n_ok} ok, {self.n_kept} kept; "
                f"status {self.status}" + (f"; files in {self.outdir}" if self.outdir else "") + ">")


def _finite(v: Any) -> float | None:
    """``v`` as a float, or None when it is missing or not finite."""
    return float(v) if v is not None and math.isfinite(v) else None


@dataclass(frozen=True)
class Optimum:
    """The design an optimisation reports, run through the full study.

    Attributes
    ----------
    x : dict of str to float
        The design, ``{'group.key': value}`` in the variables' deck units.
    objective : float
        Its objective, in the objective expression's units.
    constraints : list of dict
        Each constraint's kind, value, margin, tolerance and whether it is met.
    result : Result
        The study's full run of the design (its tables, summary and figures).
    params : Params
        The validated study group of the design (what ``result`` was run from).
    deck : str
        The design as a complete deck (``<stem>.optimum.dat``).
    converged : bool
        The method converged: the design is an optimum, not only the best found.
    """

    x: dict[str, float]
    objective: float
    constraints: list[dict]
    result: Result
    params: Params
    deck: str
    converged: bool


@dataclass
class OptimizeOutcome(Outcome):
    """Result of an optimisation, shaped like ``scipy.optimize.OptimizeResult``.

    Also an :class:`~driver._outcome.Outcome`: files written, warnings and errors as messages,
    notes.  Values are in the units of the deck keys and summary columns they name.
    ``driver.optimize.OptimizeOutcome`` is this class.

    Attributes
    ----------
    problem : Problem
        The problem the ``&optimize`` group declared (variables, objective, constraints).
    x : DesignVector or None
        Best feasible design, ``{'group.key': value}`` in the variables' deck units (and an
        array by ``np.asarray(x)``, names in ``x.names``); None when none is feasible.
    fun : float or None
        Its objective value, in the objective expression's units (not sign-flipped).
    success : bool
        The method converged and ``x`` is feasible: ``x`` is an optimum.
    message : str
        The method's words.
    nfev : int
        Designs evaluated (each distinct design once).
    best : Record or None
        The evaluation record of ``x``.
    check : Record or None
        The optimum re-run by the full study.
    method : MethodResult
        What the method returned (iterations, convergence, starts, polish).
    history : list of HistoryRow
        The best feasible design after each generation, iteration or grid batch.
    evaluator : Evaluator
        Every design evaluated (``evaluator.frame()``: feasibility, reason, margins, summary).
    study_result : Result or None
        The study's full run at the optimum (also ``optimum.result``).
    name : str
        The outputs' stem (the deck's file stem).
    history_table : pandas.DataFrame or None
        The history as a table (``<stem>_history.csv``): step, evaluations, feasible,
        objective and the variables.
    evaluations : pandas.DataFrame or None
        Every design evaluated (``<stem>_evals.parquet``): variables, feasibility and reason,
        objective, margins and the study's summary columns.
    text : str
        The report, as ``<stem>.out`` holds it.
    optimum : Optimum or None
        The reported design with its full run; None when no design is feasible.
    figures : list of Figure
        The convergence plot and the map of the designs evaluated, drawn on demand.
    check_agrees : bool
        The full study's re-run of ``x`` agrees with its evaluation (True without a re-run); when
        it does not, the run failed (exit 1): the evaluation did not compute what the study does.
    """

    problem: Problem
    x: dict[str, float] | None
    fun: float | None
    success: bool
    message: str
    nfev: int
    best: Record | None
    check: Record | None
    method: MethodResult
    history: list[HistoryRow]
    evaluator: Evaluator
    study_result: Any = None
    name: str = ""
    history_table: pd.DataFrame | None = None
    evaluations: pd.DataFrame | None = None
    text: str = ""
    optimum: Optimum | None = None
    figures: list[Figure] = field(default_factory=list)
    check_agrees: bool = True

    @property
    def status(self) -> int:
        """0 optimum, 1 not converged (``x`` the best feasible design found), 2 no feasible design."""
        return 0 if self.success else (2 if self.x is None else 1)

    @property
    def exit_code(self) -> ExitCode:
        """1 when the method failed or the optimum's re-run failed or differs, else 0.

        Failed: the method did not converge, or the optimum's full run by the study failed or
        differs from its evaluation (:attr:`check_agrees`).
        """
        failed = not self.success or not self.check_agrees or (
            self.check is not None and self.study_result is not None and bool(self.study_result.failure))
        return ExitCode.FAILED if failed else super().exit_code

    @property
    def nit(self) -> int:
        """Iterations: generations for differential evolution, all starts' for local methods."""
        return int(self.method.iterations)

    @property
    def constraints(self) -> list[dict]:
        """Constraint values and margins at x (empty without a feasible design)."""
        if self.best is None:
            return []
        r, out = self.best, []
        for k, c in enumerate(self.problem.constraints):
            kind = "equality" if c.equality else ("inequality" if c.sense else "condition")
            out.append({"constraint": c.text, "kind": kind,
                        "value": _finite(r.values[k]) if (c.numeric and r.values) else None,
                        "margin": _finite(r.margins[k]) if r.margins else None,
                        "tolerance": _finite(r.tols[k]) if (c.numeric and r.tols) else None,
                        "met": bool(r.met[k]) if r.met else False})
        return out

    def to_dict(self) -> dict:
        """Return the result as plain data: the ``optimize`` section of the ``--json`` record.

        Returns
        -------
        dict
            Scipy's fields, the constraints at ``x``, the starts of a local method and the
            polish of differential evolution (JSON-safe; values in their deck units).
        """
        p = self.problem
        rec = {"objective": p.objective_text,
               "x": None if self.x is None else [float(v) for v in self.x.values()], "x_names": p.names,
               "fun": self.fun, "success": self.success, "status": self.status, "message": self.message,
               "nit": self.nit, "nfev": self.nfev, "constraint_tol": p.opts.constraint_tol,
               "constraints": self.constraints,
               "warnings": list(self.study_result.warnings) if self.study_result is not None else []}
        if self.method.starts:
            rec["starts"] = [{"start": r["start"], "x0": [float(v) for v in r["x0"]],
                              "end": [float(v) for v in r["x"]], "objective": _finite(_float(r["objective"])),
                              "feasible": bool(r["feasible"]), "settled": bool(r["settled"]),
                              "reached": bool(r.get("reached", False)), "method_success": bool(r["success"]),
                              "method_message": r["message"], "iterations": r["iterations"]} for r in self.method.starts]
        if self.method.polish is not None:
            rec["polish"] = self.method.polish["text"]
        return rec


def _float(v: Any) -> float | None:
    try:
        return float(v)
    except (TypeError, ValueError):
        return None
