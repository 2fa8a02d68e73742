"""What a study returns: :class:`Result` and its :class:`Figure` s; labels.

What a study *is* (the :class:`~driver._study.Study` every study package declares as ``STUDY``)
and the registry of studies are in :mod:`driver._study`.  This module holds what a study's run
produces (:class:`Result`), the code digest that signs resume records, and the axis labels of
summary columns from a study's ``labels``; the decorator that gives ``run`` its keyword form is
:func:`driver.runner.keyword_run`.
"""
from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING, Any

from driver._study import Study

if TYPE_CHECKING:   # annotations only: keeps `python -m driver --help` light
    import pandas as pd

if TYPE_CHECKING:
    import matplotlib.figure

__all__ = ["Figure", "PLOT_FORMATS", "Result", "code_digest", "column_label", "expression_label", "plot_format"]


#: file formats of ``--plot`` figures (``--plot-format``); the first is the default
PLOT_FORMATS = ("png", "svg", "pdf")


def plot_format(plot: bool | str | None) -> str | None:
    """The figure format a ``plot`` argument asks for: None (no figures), or one of
    :data:`PLOT_FORMATS` (``True`` means PNG).  Raises ValueError for any other format."""
    if not plot:
        return None
    fmt = PLOT_FORMATS[0] if plot is True else str(plot).lower().lstrip(".")
    if fmt not in PLOT_FORMATS:
        raise ValueError(f"figure format {plot!r} is not one of {', '.join(PLOT_FORMATS)}")
    return fmt


@dataclass
class Figure:
    """A figure to write as ``<stem>_<name>.<format>``; ``draw`` builds it lazily (matplotlib Figure,
    drawn in the house style by :mod:`driver.plotting`, never through pyplot)."""

    name: str
    draw: Callable[[], Any]


@dataclass
class Result:
    """Everything one deck run produced.

    text      the fixed-format ``.out`` file content
    tidy      tidy table (one row per output point) for CSV/Parquet
    summary   headline figures of the case (flat dict of scalars; used by sweeps)
    warnings  messages for the terminal (also written into ``text`` by the study)
    failure   set when the run completed but did not succeed (e.g. an optimiser
              did not converge): outputs are written, the exit status is 1
    figures   figures for --plot (drawn only on demand: :meth:`figure`)
    extra     further files: suffix -> text, written as ``<stem><suffix>``
    name      output stem (the deck's file stem; set by the runner)
    study     namelist group of the study (set by the runner)

    Units are those of the study's deck keys; tidy and summary columns carry
    them in their names (``omega3_rad_s``) or in ``tidy.attrs["units"]``.
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
        """Draw one figure (the first when ``name`` is None) as a new matplotlib Figure.

        It is drawn in the house style inside an ``rc_context``; the matplotlib backend and
        the global rcParams are left as they were (figures show inline in Jupyter).
        """
        if not self.figures:
            raise LookupError(f"{self.name or 'this result'} has no figures")
        if name is None:
            return self.figures[0].draw()
        for f in self.figures:
            if f.name == name:
                return f.draw()
        raise LookupError(f"no figure {name!r}; this result draws {', '.join(self.figure_names)}")

    def __repr__(self) -> str:
        state = "ok" if self.ok else f"failed: {self.failure}"
        return (f"<Result {self.study or '?'} {self.name!r}: {state}; .out {len(self.text.splitlines())} lines, "
                f"tidy {self.tidy.shape[0]}x{self.tidy.shape[1]}, summary {len(self.summary)} values, "
                f"{len(self.warnings)} warning(s), figures {self.figure_names}>")


def code_digest(module: Study | ModuleType | None, *others: ModuleType | None) -> bytes:
    """SHA-256 of the source of study ``module`` (a :class:`~driver._study.Study` or its package)
    -- every ``.py`` file of its package when it is one, so an edit to any module of the study counts -- of the other modules ``others``,
    and of the compiled kernels.  Both kinds of sweep resume record (batch and per-case) carry
    it in their signature: a record made by other code is redone, never believed."""
    import hashlib
    import sys

    def files(mod: ModuleType | None) -> list[Path]:
        path = getattr(mod, "__file__", None)
        if not path:
            return []
        p = Path(path)
        if p.name == "__init__.py":
            return sorted(p.parent.rglob("*.py"))
        return [p]

    if isinstance(module, Study):
        module = module.module
    h = hashlib.sha256()
    kernels = sys.modules.get("driver._kernels")
    for mod in (module, *others, kernels):
        for f in files(mod):
            h.update(str(f.name).encode())
            try:
                h.update(f.read_bytes())
            except OSError:
                h.update(b"<unreadable>")
    return h.digest()


def column_label(study: Study | None, name: str) -> str:
    """The axis label of summary column or deck key ``name`` (``group.key`` or ``key``) of
    ``study``: words and units from its ``labels``, else the key's ``SPEC`` units, else
    units read off the name's suffix (``_deg``, ``_rad_s``, ...).  E.g. ``'crank speed [rad/s]'``."""
    if not re.fullmatch(r"([a-z_][a-z0-9_]*\.)?[A-Za-z_][A-Za-z0-9_]*", name):
        return name   # an expression of columns (driver.expr) is its own label
    group, _, key = name.rpartition(".")
    if study is not None and group and group != study.name:
        study = None
    labels = study.labels if study is not None else {}
    entry = labels.get(key)
    for pattern, value in labels.items() if entry is None else ():
        m = re.fullmatch(re.escape(pattern).replace(r"\{i\}", "([0-9]+)"), key) if "{i}" in pattern else None
        if m:
            entry = (value[0].replace("{i}", m.group(1)), value[1])
            break
    spec_key = study.spec.keys.get(key) if study is not None else None
    if entry is None:
        words, units = key, ""
        from driver.export import SUFFIX_UNITS  # the one suffix table (tidy units and labels)

        for suffix, u in SUFFIX_UNITS:
            if key.endswith(suffix) and len(key) > len(suffix):
                words, units = key[: -len(suffix)], u
                break
        entry = (words.replace("_", " "), units)
    words, units = entry
    if not units and spec_key is not None:
        units = spec_key.units
    return f"{words} [{units}]" if units else words


def expression_label(study: Study | None, text: str) -> str:
    """The axis words of an objective: a summary column's words and unit, or for an expression
    the expression in words with the unit its columns share (``min(mu_min_deg, ...) [deg]``)."""
    from driver.export import SUFFIX_UNITS
    if re.fullmatch(r"[A-Za-z_][A-Za-z0-9_.]*", text.strip()):
        return column_label(study, text.strip())
    names = set(re.findall(r"[A-Za-z_][A-Za-z0-9_]*", text)) - {"min", "max", "abs", "sqrt", "and", "or", "not"}
    labels = study.labels if study is not None else {}
    units = set()
    for n in names:
        for suffix, u in SUFFIX_UNITS:
            if n.endswith(suffix):
                units.add(u)
                break
        else:
            if n in labels:
                units.add(labels[n][1])
    words = text.strip().replace("$", r"\$")   # the deck's text is never mathtext (driver.plotting.plain_text)
    for n in sorted(names, key=len, reverse=True):
        entry = labels.get(n)
        if entry:
            words = re.sub(rf"\b{re.escape(n)}\b", entry[0], words)
    return f"{words} [{units.pop()}]" if len(units) == 1 and "" not in units else words
