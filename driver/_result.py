"""What one deck run produced: :class:`Result` with its :class:`Figure` s, its :class:`Tidy`
table, and the figure formats of ``--plot``.  Plain data: it imports nothing of the driver at
module level, so that the study contract (:mod:`driver._study`), the runner and the studies can
all name it (re-exported by :mod:`driver._output`); nor pandas: a run's tidy table is built into
a DataFrame only when someone reads ``result.tidy`` (a CSV or Parquet file, the API, the report
page), so a deck run that writes only its ``.out`` never imports pandas (docs/performance.md,
*Start-up*)."""
from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from driver._formats import ANIMATION_FORMATS, PLOT_FORMATS, plot_format

if TYPE_CHECKING:   # annotations only: keeps `python -m driver --help` light
    import matplotlib.figure
    import pandas as pd

__all__ = ["Figure", "PLOT_FORMATS", "ANIMATION_FORMATS", "Result", "Tidy", "plot_format"]


class Tidy:
    """A run's tidy table before it is a DataFrame: its columns as numpy arrays (or scalars that
    broadcast), in one or more parts stacked row-wise, and the units the names do not say.

    :meth:`frame` builds the pandas DataFrame exactly as ``with_units(pd.concat([pd.DataFrame(part)
    for part in parts], ignore_index=True), units)`` (one part: without the concat) would, so a
    study hands its columns over and pays for pandas only when the table is read.
    :meth:`infinite_column` finds an infinite number without pandas (the runner's check that no
    infinity reaches a table; NaN is a missing value, allowed as in a DataFrame's numeric columns).

    Parameters
    ----------
    *parts : mapping of str to array or scalar
        The columns of each part, in order; a scalar fills its part's rows.
    units : mapping of str to str, optional
        Units of the columns whose names do not say them (``'length'``, ``'1'``), as
        :func:`driver._export.with_units` takes them.
    records : sequence of mapping or sequence, optional
        Instead of parts: the rows as records (``pd.DataFrame.from_records(records,
        columns=columns)``).
    columns : sequence of str, optional
        The column order of ``records``.
    """

    def __init__(self, *parts: Mapping[str, Any], units: Mapping[str, str] | None = None,
                 records: Sequence[Sequence[Any] | Mapping[str, Any]] | None = None,
                 columns: Sequence[str] | None = None) -> None:
        if records is not None and parts:
            raise TypeError("Tidy takes column parts or records, not both")
        self.parts = [dict(p) for p in parts]
        self.units = dict(units or {})
        self.records = None if records is None else list(records)
        self.columns = None if columns is None else list(columns)

    def _record_names(self) -> list[str]:
        if self.columns is not None:
            return self.columns
        return list(dict.fromkeys(k for r in self.records or [] if isinstance(r, Mapping) for k in r))

    @property
    def shape(self) -> tuple[int, int]:
        """(rows, columns) of the table, without building it."""
        import numpy as np  # here, not at import: `python -m driver --help` needs no numpy
        if self.records is not None:
            return len(self.records), len(self._record_names())
        rows = sum(max([np.size(v) for v in p.values() if np.ndim(v) > 0] or [1 if p else 0]) for p in self.parts)
        return rows, len(dict.fromkeys(k for p in self.parts for k in p))

    def _values(self) -> list[tuple[str, Any]]:
        if self.records is not None:
            names = self._record_names()
            return [kv for r in self.records for kv in (r.items() if isinstance(r, Mapping) else zip(names, r))]
        return [(k, v) for p in self.parts for k, v in p.items()]

    def infinite_column(self) -> str | None:
        """The first column holding an infinite number (None: every number finite or NaN)."""
        import numpy as np
        for name, value in self._values():
            if isinstance(value, str) or value is None:
                continue
            a = np.asarray(value)
            if a.dtype.kind in "fc":
                if np.isinf(a).any():
                    return name
            elif a.dtype.kind == "O":
                if any(isinstance(v, float | np.floating) and math.isinf(v) for v in a.ravel()):
                    return name
        return None

    def frame(self) -> pd.DataFrame:
        """The pandas DataFrame, units in ``attrs["units"]``."""
        import pandas as pd

        from driver._export import with_units
        if self.records is not None:
            records: Any = self.records   # records as pandas takes them: tuples or mappings
            frame = pd.DataFrame.from_records(records, columns=self.columns)
        elif len(self.parts) == 1:
            frame = pd.DataFrame(self.parts[0])
        else:
            frame = pd.concat([pd.DataFrame(p) for p in self.parts], ignore_index=True)
        return with_units(frame, self.units)


class _TidyField:
    """The ``tidy`` field of :class:`Result`: set to a DataFrame or a :class:`Tidy`, read as a
    DataFrame (a Tidy is built on first read and kept)."""

    def __set_name__(self, owner: type, name: str) -> None:
        self.slot = "_" + name

    def __get__(self, obj: Any, owner: type | None = None) -> pd.DataFrame:
        if obj is None:
            raise AttributeError("tidy")   # no class-level default: the field is required
        value = obj.__dict__[self.slot]
        if isinstance(value, Tidy):
            value = obj.__dict__[self.slot] = value.frame()
        return value

    def __set__(self, obj: Any, value: pd.DataFrame | Tidy) -> None:
        obj.__dict__[self.slot] = value





@dataclass
class Figure:
    """A figure of a run, drawn on demand.

    Attributes
    ----------
    name : str
        The figure's name: it is written as ``<stem>_<name>.<format>`` (``'linkage'``,
        ``'curves'``, ...).
    draw : callable
        ``draw()`` builds and returns the matplotlib ``Figure``, drawn in the house style of
        :mod:`driver.plotting` and never through pyplot; nothing is drawn until it is called.
    """

    name: str
    draw: Callable[[], Any]


@dataclass
class Result:
    """Everything one deck run produced.

    What :func:`driver.run` and ``driver.<study>.run`` return.  Units are those of the study's
    deck keys; tidy and summary columns carry them in their names (``theta_deg``,
    ``rocker_omega_rad_s``, ``tau1_Nm``) or in ``tidy.attrs["units"]``.

    Attributes
    ----------
    text : str
        The fixed-format ``.out`` file content (also :attr:`out`).
    tidy : pandas.DataFrame
        Tidy table, one row per output point, for CSV/Parquet; units in the column names or
        in ``tidy.attrs["units"]`` (``'1'`` dimensionless).
    summary : dict
        Headline figures of the case, a flat dict of scalars (used by sweeps); units in the
        names; None for a figure that does not exist.
    warnings : list of str
        Messages for the terminal (also written into ``text`` by the study).
    failure : str or None
        Set when the run completed but did not succeed (e.g. an optimiser did not converge):
        outputs are written, the exit status is 1.
    design_failure : bool
        The failure is the design's own answer (a four-bar chain that cannot move, or that
        assembles nowhere in its crank range), not a computation that failed: a single run
        still fails (exit 1), but in a sweep, a design search, the case is a design its summary
        classifies (status ok, on both the batch and the per-case path).
    figures : list of Figure
        Figures for ``--plot``, drawn only on demand (:meth:`figure`).
    extra : dict of str to str
        Further files: suffix -> text, written as ``<stem><suffix>``.
    name : str
        Output stem (the deck's file stem; set by the runner).
    study : str
        Namelist group of the study (set by the runner).
    params : Params or None
        The validated deck keys the run was made from (set by the runner).
    data : dict of str to object
        Arrays of the run that no table holds, for its study's figures and the report page's
        animation (the slider-crank's nonlinear rod: ``'rod'``, its nodes' lateral deflection
        over the recorded revolution); never written to a file.
    """

    text: str
    tidy: _TidyField = _TidyField()
    summary: dict[str, Any] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)
    failure: str | None = None
    figures: list[Figure] = field(default_factory=list)
    extra: dict[str, str] = field(default_factory=dict)
    name: str = ""
    study: str = ""
    #: the validated deck keys the run was made from (set by the runner; the report page's
    #: animation and comparison use them)
    params: Any = field(default=None, repr=False, compare=False)
    #: arrays no table holds, for the study's figures and the page's animation (not written)
    data: dict[str, Any] = field(default_factory=dict, repr=False, compare=False)
    #: the failure is the design's answer (docs above): a sweep records the case as ok
    design_failure: bool = False

    @property
    def tidy_pending(self) -> Tidy | None:
        """The :class:`Tidy` not yet built into a DataFrame (None once built, or when given as one)."""
        value = self.__dict__.get("_tidy")
        return value if isinstance(value, Tidy) else None

    @property
    def out(self) -> str:
        """The fixed-format ``.out`` text, exactly as the command line writes it."""
        return self.text

    @property
    def ok(self) -> bool:
        """True when the run succeeded (``failure`` is None)."""
        return self.failure is None

    @property
    def summary_frame(self) -> pd.DataFrame:
        """The summary as a one-row DataFrame (columns in summary order; None becomes missing)."""
        import pandas as pd
        return pd.DataFrame([self.summary])

    @property
    def figure_names(self) -> list[str]:
        """Names of the figures this result can draw (``<stem>_<name>.png`` with --plot)."""
        return [f.name for f in self.figures]

    def figure(self, name: str | None = None) -> matplotlib.figure.Figure:
        """Draw one figure of the run as a new matplotlib Figure.

        It is drawn in the house style inside an ``rc_context``; the matplotlib backend and
        the global rcParams are left as they were (figures show inline in Jupyter).

        Parameters
        ----------
        name : str, optional
            One of :attr:`figure_names`; default the first.

        Returns
        -------
        matplotlib.figure.Figure
            The figure, drawn in the house style.

        Raises
        ------
        LookupError
            The result has no figures, or none called ``name``.
        """
        if not self.figures:
            raise LookupError(f"{self.name or 'this result'} has no figures")
        if name is None:
            return self.figures[0].draw()
        for f in self.figures:
            if f.name == name:
                return f.draw()
        raise LookupError(f"no figure {name!r}; this result draws {', '.join(self.figure_names)}")

    def _repr_html_(self) -> str:
        """The run as its report page shows it (animation, figures, headline figures, tables),
        for a notebook's rich display (made by :func:`driver._report_page.fragment`)."""
        from driver._report_page._fragment import fragment
        return fragment(self)

    def __repr__(self) -> str:
        state = "ok" if self.ok else f"failed: {self.failure}"
        pending = self.tidy_pending
        shape = pending.shape if pending is not None else self.tidy.shape
        return (f"<Result {self.study or '?'} {self.name!r}: {state}; .out {len(self.text.splitlines())} lines, "
                f"tidy {shape[0]}x{shape[1]}, summary {len(self.summary)} values, "
                f"{len(self.warnings)} warning(s), figures {self.figure_names}>")
