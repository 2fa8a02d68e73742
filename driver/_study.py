"""The study contract and the registry: what a study declares, and the list of studies.

A study is one package ``driver/<group>/`` named after its namelist group.  It declares
everything the engines (runner, sweep, optimiser, comparison, report page, deck reader)
may use of it once, in a :class:`Study` bound to the name ``STUDY`` in its ``__init__``::

    STUDY = Study(name="fourbar", package=__name__, spec=SPEC, run=run, estimate=estimate,
                  summarise=summarise, batch=BatchSummary(summarise_batch, keys=BATCH_KEYS, ...),
                  labels=LABELS, sweep_plot=SWEEP_PLOT, ...)

and is listed in :data:`REGISTRY`.  The engines reach a study only through its ``Study``
(:func:`load_study`): they never probe a module for optional names.  What a study declares is
checked when the package is imported (:meth:`Study.__post_init__`): a study without an
``estimate`` cannot register (the absurd-request budget of :mod:`driver._limits` applies to every
study), a misspelt batch key or a pass table naming an unknown pass raises at import.

Adding a study: the package in the layers of :data:`LAYERS` (spec, analysis, figures, report,
published; kernel with a kernel, batch with a batch summary), its Fortran kernel with its line in
``fortran/meson.build``, and one line in :data:`REGISTRY`.
"""
from __future__ import annotations

import importlib
import re
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType, ModuleType
from typing import TYPE_CHECKING, Any

from driver._docs import fill_doc
from driver._extras import missing_extra
from driver._groupspec import GroupSpec, Params

if TYPE_CHECKING:
    from driver._limits import Estimate
    from driver._mechanism import MechanismFrames
    from driver._result import Result

__all__ = ["Study", "BatchSummary", "REGISTRY", "ENGINES", "LAYERS", "REQUIRED_LAYERS", "layer_of", "load_study",
           "study_names", "registered", "group_spec", "batch_error"]

#: the studies, by namelist group: group -> the package that binds ``STUDY``.  Imported only
#: when a deck (or a caller) names the group, so ``python -m driver --help`` stays light.
REGISTRY: dict[str, str] = {
    "fourbar": "driver.fourbar",
    "linkage": "driver.linkage",
    "manipulator": "driver.manipulator",
    "robust_example": "driver.robust_example",
    "slidercrank": "driver.slidercrank",
    "ujoint": "driver.ujoint",
}

#: the engines' control groups, by group: the package whose ``SPEC`` declares the group's keys (a
#: deck with one of them is run by that engine: driver._dispatch decides which).  Imported only
#: when a deck (or a caller) names the group.
ENGINES: dict[str, str] = {
    "sweep": "driver.sweep",
    "optimize": "driver.optimize",
    "synthesis": "driver.synthesis",
}

#: the layers of a study package, in dependency order (docs/layout.md): a module may import only
#: modules of an earlier layer or of its own.  A module is its layer (``_report``) or an extra of
#: it named after it (``_report_nl``, ``_analysis_forces``); ``__init__``, and any module that only
#: hands names on (the four-bar's ``_forces``), is the package's face, above every layer.
LAYERS = ("_kernel", "_spec", "_analysis", "_tables", "_batch", "_figures", "_report", "_published")
#: the layers every study has (``_kernel`` too when it has a kernel, ``_batch`` a batch path)
REQUIRED_LAYERS = ("_spec", "_analysis", "_figures", "_report", "_published")


def layer_of(module: str) -> str | None:
    """The layer (:data:`LAYERS`) of a study module by its name (``'_report_nl'`` -> ``'_report'``),
    or None for a module of no layer (the package's face)."""
    name = module.rpartition(".")[2]
    mine = [layer for layer in LAYERS if name == layer or name.startswith(layer + "_")]
    return max(mine, key=len) if mine else None


_SENSES = ("max", "min")


def _names(what: str, values: Any, allowed: Mapping[str, Any] | None = None) -> tuple[str, ...]:
    """``values`` as a tuple of names; TypeError unless each is a str, ValueError when ``allowed``
    is given and a name is not among its keys (a misspelt key fails at import, not at run time)."""
    out = tuple(values)
    for v in out:
        if not isinstance(v, str):
            raise TypeError(f"{what}: {v!r} is not a name")
        if allowed is not None and v not in allowed:
            raise ValueError(f"{what}: {v!r} is not a key of the study's group")
    return out


#: the sections of the contract's hook docstrings, written once (SciPy's doccer, in small): a
#: study's ``estimate`` or ``summarise`` keeps its own summary and notes in its docstring and ends
#: it with ``%(estimate)s`` or ``%(summarise)s`` (a batch summary's Raises: ``%(batch_raises)s``),
#: which :func:`contract_doc` fills
_PARAMS_RETURNS = """Parameters
    ----------
    params : Params
        Validated keys of the study's group.

    Returns
    -------
"""
HOOK_SECTIONS = {
    "estimate": _PARAMS_RETURNS + """    Estimate
        Bytes and seconds the run needs, each with the key that drives it
        (``driver._limits`` refuses an absurd request with it).""",
    "summarise": _PARAMS_RETURNS + """    dict
        The run's headline figures (``run(params).summary`` wherever the run succeeds), units
        in the names; None for a figure that does not exist.""",
    "batch_raises": """Raises
    ------
    DeckError
        A bad value, when ``base`` is a deck's Params (deck, line and key of the base deck,
        the design's index in the message).
    ValueError
        A bad value otherwise.""",
}

#: fills the ``%(estimate)s``/``%(summarise)s``/``%(batch_raises)s`` fields of a study hook's
#: docstring with the contract's sections
contract_doc = fill_doc(**HOOK_SECTIONS)


def batch_error(base: Mapping[str, Any], key: str | None, message: str) -> Exception:
    """The error a batch summary raises for a bad value (``%(batch_raises)s`` of the contract): a
    DeckError at the key's deck line when ``base`` is a deck's Params, else a ValueError."""
    if isinstance(base, Params):
        return base.error(key, message)
    return ValueError(f"{key}: {message}" if key else message)


@dataclass(frozen=True)
class BatchSummary:
    """A study's batch path: the summary of many designs in one kernel call (sweeps, &optimize).

    fn           ``fn(base, columns, n=None, *, wanted=None, ...) -> DataFrame``: the summary row of
                 each design; ``base`` the validated base deck, ``columns`` {key: values} of the
                 keys that vary (one value per design); ``wanted`` the summary columns asked for
                 (None: all), when the study has a pass table
    keys         deck keys a batch may vary (one value per design)
    ignored      keys accepted in a batch that leave the summary unchanged
    independent  keys whose deck checks involve no other key (a sweep validates each value once)
    passes       column -> the kernel passes it needs (None: no table; every column computed);
                 "compute only what the deck asks for"
    pass_names   the passes the kernel knows (every pass named in ``passes`` must be one)
    applies      ``applies(base) -> bool``: False when the batch path does not fit the base deck
                 (e.g. a deck that optimises per case); None: always
    elements     list keys whose single elements ('key(i)') a batch may set
    refusal      ``refusal(row) -> str | None``: the reason the study's own run would refuse the
                 design of a summary row (an &optimize design then counts as infeasible)
    """

    fn: Callable[..., Any]
    keys: tuple[str, ...]
    ignored: tuple[str, ...] = ()
    independent: tuple[str, ...] = ()
    passes: Mapping[str, tuple[str, ...]] | None = None
    pass_names: tuple[str, ...] = ()
    applies: Callable[[Any], bool] | None = None
    elements: tuple[str, ...] = ()
    refusal: Callable[[Mapping[str, Any]], str | None] | None = None

    def __post_init__(self) -> None:
        if not callable(self.fn):
            raise TypeError("BatchSummary.fn must be callable")
        for name in ("applies", "refusal"):
            v = getattr(self, name)
            if v is not None and not callable(v):
                raise TypeError(f"BatchSummary.{name} must be callable or None")
        for name in ("keys", "ignored", "independent", "pass_names", "elements"):
            object.__setattr__(self, name, _names(f"BatchSummary.{name}", getattr(self, name)))
        if not self.keys:
            raise ValueError("BatchSummary.keys: a batch varies at least one key")
        both = set(self.keys) & set(self.ignored)
        if both:
            raise ValueError(f"BatchSummary: {sorted(both)[0]!r} is both a batch key and ignored")
        stray = [e for e in self.elements if e not in self.keys]
        if stray:
            raise ValueError(f"BatchSummary.elements: {stray[0]!r} is not a batch key")
        if self.passes is not None:
            table = {}
            for col, ps in self.passes.items():
                table[_names("BatchSummary.passes column", (col,))[0]] = _names(f"BatchSummary.passes[{col!r}]", ps)
            unknown = sorted({p for ps in table.values() for p in ps} - set(self.pass_names))
            if unknown:
                raise ValueError(f"BatchSummary.passes: pass {unknown[0]!r} is not one of pass_names "
                                 f"{self.pass_names}")
            object.__setattr__(self, "passes", MappingProxyType(table))

    def check_keys(self, spec: GroupSpec) -> None:
        """ValueError unless every key the batch names is a key of ``spec``."""
        for name in ("keys", "ignored", "independent", "elements"):
            _names(f"{spec.name} BatchSummary.{name}", getattr(self, name), spec.keys)

    @property
    def accepted(self) -> frozenset[str]:
        """Keys a batch accepts: the keys it varies and those it ignores."""
        return frozenset(self.keys) | frozenset(self.ignored)


@dataclass(frozen=True)
class Study:
    """What a study offers the engines; every study package binds one as ``STUDY``.

    Required:

    name         namelist group (``&name`` in a deck); the key of :data:`REGISTRY`
    package      the study's package (``__name__``): its code digest signs resume records
    spec         the deck keys (:class:`driver._deck.GroupSpec`, ``spec.name == name``)
    run          ``run(params, progress=False) -> Result``: the physics of one deck
    estimate     ``estimate(params) -> driver._limits.Estimate``: memory [bytes] and work [s] of a
                 run from the keys alone, for the absurd-request budget

    Optional:

    summarise    ``summarise(params) -> dict``: the summary of one case without the tables and
                 figures (sweeps and &optimize use it instead of a full run)
    batch        the batch path (:class:`BatchSummary`), or None
    labels       ``{name: (words, units)}`` axis labels of summary columns and deck keys
                 (``{i}`` in a name stands for a case number)
    sweep_plot   summary columns a sweep plots when the deck names none
    sweep_best   ``{column: 'max' | 'min'}``: which end of a column is the better design
    summary_settings  deck keys the summary columns depend on: a sweep's and an optimisation's .out
                 state their base values, their tables record them
    renamed      ``{old column: new name}`` of summary and tidy columns that were renamed: an old
                 name in a deck, a sweep filter or an &optimize expression is refused with the
                 new one named (:meth:`renamed_in`)
    blame        ``blame(params, exc) -> (key, message) | None``: the key a numerical failure
                 is due to
    published    ``published(params, result) -> list[dict]``: the run compared cell by cell
                 with the published tables (:mod:`driver._compare`), or None
    animation    ``animation(params, result, n) -> MechanismFrames``: the mechanism's motion for
                 the report page's animation, about ``n`` frames (a crank turn), ``result`` the
                 run of ``params`` when there is one (its deflections, its optimum): per frame the
                 named points, once the links between them, fixed pivots, guides and traced paths
                 (:class:`driver._mechanism.MechanismFrames`); or None
    figures      the dotted name of the study's figure module (drawn in the house style of
                 :mod:`driver.plotting`; imported only when a figure is drawn, matplotlib being
                 the optional [plot] extra), or None
    kernel       the study's kernel wrappers (module over ``driver._kernels``), or None
    """

    name: str
    package: str
    spec: GroupSpec
    run: Callable[..., Result]
    estimate: Callable[[Params], Estimate]
    summarise: Callable[[Params], Mapping[str, Any]] | None = None
    batch: BatchSummary | None = None
    labels: Mapping[str, tuple[str, str]] = field(default_factory=dict)
    sweep_plot: tuple[str, ...] = ()
    sweep_best: Mapping[str, str] = field(default_factory=dict)
    summary_settings: tuple[str, ...] = ()
    renamed: Mapping[str, str] = field(default_factory=dict)
    blame: Callable[[Params, BaseException], tuple[str, str] | None] | None = None
    published: Callable[[Params, Result], list[dict]] | None = None
    animation: Callable[[Params, Result | None, int], MechanismFrames] | None = None
    figures: str | None = None
    kernel: ModuleType | None = None

    def __post_init__(self) -> None:
        if not (isinstance(self.name, str) and re.fullmatch(r"[a-z][a-z0-9_]*", self.name)):
            raise ValueError(f"Study.name {self.name!r} is not a namelist group name")
        if not isinstance(self.spec, GroupSpec):
            raise TypeError(f"{self.name}: Study.spec must be a driver._deck.GroupSpec")
        if self.spec.name != self.name:
            raise ValueError(f"{self.name}: Study.spec declares group &{self.spec.name}")
        for attr in ("run", "estimate"):
            if not callable(getattr(self, attr)):
                raise TypeError(f"{self.name}: Study.{attr} is required and must be callable")
        for attr in ("summarise", "blame", "published", "animation"):
            v = getattr(self, attr)
            if v is not None and not callable(v):
                raise TypeError(f"{self.name}: Study.{attr} must be callable or None")
        if self.kernel is not None and not isinstance(self.kernel, ModuleType):
            raise TypeError(f"{self.name}: Study.kernel must be a module or None")
        if self.figures is not None and not (isinstance(self.figures, str)
                                             and self.figures.startswith(self.package + ".")):
            raise TypeError(f"{self.name}: Study.figures must name a module of the study's package")
        if self.batch is not None:
            if not isinstance(self.batch, BatchSummary):
                raise TypeError(f"{self.name}: Study.batch must be a BatchSummary or None")
            self.batch.check_keys(self.spec)
        labels = {}
        for k, v in dict(self.labels).items():
            if not (isinstance(k, str) and isinstance(v, tuple) and len(v) == 2 and all(isinstance(x, str) for x in v)):
                raise TypeError(f"{self.name}: Study.labels[{k!r}] must be (words, units)")
            labels[k] = v
        object.__setattr__(self, "labels", MappingProxyType(labels))
        object.__setattr__(self, "sweep_plot", _names(f"{self.name}: Study.sweep_plot", self.sweep_plot))
        object.__setattr__(self, "summary_settings", _names(f"{self.name}: Study.summary_settings",
                                                            self.summary_settings, self.spec.keys))
        bad = {k: v for k, v in dict(self.sweep_best).items() if v not in _SENSES}
        if bad:
            raise ValueError(f"{self.name}: Study.sweep_best[{next(iter(bad))!r}] must be 'max' or 'min'")
        object.__setattr__(self, "sweep_best", MappingProxyType(dict(self.sweep_best)))
        object.__setattr__(self, "renamed", MappingProxyType(dict(self.renamed)))
        stale = [c for c in self.renamed if self.batch is not None and self.batch.passes is not None
                 and c in self.batch.passes]
        if stale:
            raise ValueError(f"{self.name}: column {stale[0]!r} is renamed, yet the batch pass table names it")

    def renamed_in(self, names: Iterable[str]) -> str | None:
        """The refusal of the first of ``names`` that is a renamed column (:attr:`renamed`), in
        words naming its new name; None when none is.

        Parameters
        ----------
        names : iterable of str
            Column names a deck, filter or expression reads.

        Returns
        -------
        str or None
            ``"column 'old' of &study is now new"``, or None.
        """
        for n in names:
            if n in self.renamed:
                return f"column '{n}' of &{self.name} is now {self.renamed[n]}"
        return None

    @property
    def module(self) -> ModuleType:
        """The study's package (imported)."""
        return importlib.import_module(self.package)

    def __repr__(self) -> str:
        offers = [n for n in ("summarise", "batch", "blame", "published", "animation", "figures", "kernel")
                  if getattr(self, n) is not None]
        return f"<Study &{self.name} ({self.package}): {len(self.spec.keys)} keys; {', '.join(offers) or 'run only'}>"


def load_study(group: str) -> Study | None:
    """The registered study of namelist group ``group``, or None if there is none.

    Raises TypeError when the package does not bind a :class:`Study` named after the group
    (a registry entry that does not fulfil the contract is an error, never skipped).
    """
    package = REGISTRY.get(group)
    if package is None:
        return None
    study = getattr(importlib.import_module(package), "STUDY", None)
    if not isinstance(study, Study) or study.name != group:
        raise TypeError(f"{package} is registered as study &{group} but binds no STUDY = Study(name={group!r}, ...)")
    return study


def group_spec(group: str) -> GroupSpec | None:
    """The keys of namelist group ``group``: a registered study's spec or an engine's ``SPEC``; None
    when no one declares the group (the runner refuses it, naming the known groups).

    A registered package that fails to import, or binds no study, raises (a broken study is a bug
    to see, never a group silently unknown); an engine whose optional package is not installed
    raises :class:`~driver._extras.MissingExtra`, which names the extra that installs it."""
    if group in ENGINES:
        try:
            engine = importlib.import_module(ENGINES[group])
        except ImportError as exc:
            extra = missing_extra(exc)
            if extra is None:
                raise
            raise extra from exc
        spec = getattr(engine, "SPEC", None)
        if not isinstance(spec, GroupSpec) or spec.name != group:
            raise TypeError(f"{ENGINES[group]} is registered as engine &{group} but binds no SPEC of that group")
        return spec
    study = load_study(group)
    return None if study is None else study.spec


def study_names() -> list[str]:
    """Group names of every registered study (nothing is imported)."""
    return sorted(REGISTRY)


def registered() -> dict[str, Study]:
    """Every registered study, by group name (imports them all)."""
    return {name: s for name in study_names() if (s := load_study(name)) is not None}
