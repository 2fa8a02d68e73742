"""What one deck run produced: :class:`Result` with its :class:`Figure` s, and the figure
formats of ``--plot``.  Plain data: it imports nothing of the driver, so that the study contract
(:mod:`driver._study`), the runner and the studies can all name it (re-exported by
:mod:`driver._output`)."""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from driver._formats import ANIMATION_FORMATS, PLOT_FORMATS, plot_format

if TYPE_CHECKING:   # annotations only: keeps `python -m driver --help` light
    import matplotlib.figure
    import pandas as pd

__all__ = ["Figure", "PLOT_FORMATS", "ANIMATION_FORMATS", "Result", "plot_format"]


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
    tidy: pd.DataFrame
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
        return (f"<Result {self.study or '?'} {self.name!r}: {state}; .out {len(self.text.splitlines())} lines, "
                f"tidy {self.tidy.shape[0]}x{self.tidy.shape[1]}, summary {len(self.summary)} values, "
                f"{len(self.warnings)} warning(s), figures {self.figure_names}>")
