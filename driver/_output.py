"""The code digest that signs resume records, summary columns' axis labels, a summary's best design.

What a study *is* (the :class:`~driver._study.Study` every study package declares as ``STUDY``)
and the registry of studies are in :mod:`driver._study`; what a run returns (``Result`` and its
``Figure`` s) in :mod:`driver._result`.  This module holds the code digest of a study (resume
records carry it), the axis labels of summary columns and objectives from a study's
``labels``, and the one rule for a summary's best design (:func:`best_index`: the case a
sweep reports as its best and its design-space maps mark).
"""
from __future__ import annotations

import re
from pathlib import Path
from types import ModuleType
from typing import Any

from driver._study import Study

__all__ = ["code_digest", "source_digest", "column_label", "expression_label", "best_index"]


def code_digest(module: Study | ModuleType | None, *others: ModuleType | None) -> bytes:
    """SHA-256 of the source of study ``module`` (a :class:`~driver._study.Study` or its package)
    -- every ``.py`` file of its package when it is one, so an edit to any module of the study
    counts -- of the other modules ``others``,
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


def source_digest(module: Study | ModuleType | None, *others: ModuleType | Path | None) -> str:
    """Hex SHA-256 of the Python source of study ``module`` (every ``.py`` of its package), of
    the modules ``others`` (a package's ``__init__.py`` path stands for the whole package, read
    without importing it) and of the kernels' Fortran sources (``fortran/*.f90`` of a source
    tree; an installed package's version instead).

    Unlike :func:`code_digest` it does not read the compiled kernel, whose bytes differ between
    machines and builds that compute the same numbers: a record that outputs/ keeps (an
    optimisation's ``_evals`` table) carries it and stays the same on every machine, while an
    edit to the code that computes the values changes it."""
    import hashlib

    import driver

    def files(mod: ModuleType | Path | None) -> list[Path]:
        path = mod if isinstance(mod, Path) else getattr(mod, "__file__", None)
        if not path:
            return []
        p = Path(path)
        return sorted(p.parent.rglob("*.py")) if p.name == "__init__.py" else [p]

    if isinstance(module, Study):
        module = module.module
    h = hashlib.sha256()
    for mod in (module, *others):
        for f in files(mod):
            h.update(f.name.encode())
            try:
                h.update(f.read_bytes())
            except OSError:
                h.update(b"<unreadable>")
    fortran = Path(driver.__file__).resolve().parents[1] / "fortran"
    sources = sorted(fortran.glob("*.f90")) if fortran.is_dir() else []
    for f in sources:
        h.update(f.name.encode() + f.read_bytes())
    if not sources:
        h.update(str(getattr(driver, "__version__", "")).encode())
    return h.hexdigest()


def column_label(study: Study | None, name: str) -> str:
    """The axis label of summary column or deck key ``name`` (``group.key`` or ``key``) of
    ``study``: words and units from its ``labels``, else the key's ``SPEC`` units, else
    units read off the name's suffix (``_deg``, ``_rad_s``, ...).  E.g. ``'crank speed [rad/s]'``."""
    element = re.fullmatch(r"(([a-z_][a-z0-9_]*\.)?[A-Za-z_][A-Za-z0-9_]*)\(([0-9]+)\)", name)
    if element:   # one element of a list key (an optimiser's variable 'ujoint.phi(1)'): the key's words, numbered
        words, _, units = column_label(study, element.group(1)).partition(" [")
        return f"{words} ({element.group(3)})" + (f" [{units}" if units else "")
    if not re.fullmatch(r"([a-z_][a-z0-9_]*\.)?[A-Za-z_][A-Za-z0-9_]*", name):
        return name   # an expression of columns (driver._expr) is its own label
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
        from driver._export import SUFFIX_UNITS  # the one suffix table (tidy units and labels)

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
    from driver._export import SUFFIX_UNITS
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


def best_index(frame: Any, metric: str, sense: str | None) -> Any:
    """The frame index of the kept, ok design with the best ``metric``.

    Parameters
    ----------
    frame : pandas.DataFrame
        Summary rows (``status`` and ``kept`` columns, where present, select the kept, ok ones).
    metric : str
        The column to judge by (non-numbers count as missing).
    sense : str or None
        ``'max'`` or ``'min'``: which end is better (the study's ``sweep_best``).

    Returns
    -------
    index label or None
        The row of the largest (``'max'``) or smallest (``'min'``) value, the first of equal
        ones; None when the sense is not known or no kept, ok row has a number there.
    """
    import pandas as pd
    if sense not in ("min", "max") or metric not in frame:
        return None
    ok = frame
    if "status" in ok:
        ok = ok[ok["status"] == "ok"]
    if "kept" in ok:
        ok = ok[ok["kept"].astype(bool)]
    m = pd.to_numeric(ok[metric], errors="coerce")
    if not m.notna().any():
        return None
    return m.idxmax() if sense == "max" else m.idxmin()
