"""Optional features and the extra that installs each one.

The core (decks, kernels, ``.out`` tables, CSV) needs numpy, scipy, pandas, f90nml
and tqdm only.  Figures, Parquet (and so sweeps and optimisations, which keep their
cases in Parquet) and
Dask clusters need the extras below; :func:`require` imports a feature's module or
raises :class:`MissingExtra` with the one command that installs it.
"""
from __future__ import annotations

import importlib
from types import ModuleType

from driver._errors import DriverError

__all__ = ["EXTRAS", "MissingExtra", "available", "require", "missing_extra"]

#: extra -> (module it provides, what needs it)
EXTRAS: dict[str, tuple[str, str]] = {
    "plot": ("matplotlib", "figures (--plot)"),
    "parquet": ("pyarrow", "Parquet tables (--format parquet), sweeps and optimisations"),
    "dask": ("distributed", "running sweeps on a Dask cluster (--scheduler)"),
}


class MissingExtra(DriverError, ImportError):
    """A feature's optional dependency is not installed; the message says how to install it."""

    def __init__(self, extra: str, cause: ImportError | None = None):
        module, what = EXTRAS[extra]
        super().__init__(f"{what} need the Python package '{module}', which is not installed "
                         f"({cause}); install it with: pip install 'mechanism-driver[{extra}]' "
                         f"(or [all] for every optional feature)", name=module)
        self.extra, self.cause = extra, cause

    def __reduce__(self) -> tuple[type[MissingExtra], tuple[str, ImportError | None]]:
        """Pickle by the extra and its cause (the message is made from them)."""
        return (type(self), (self.extra, self.cause))


def require(extra: str) -> ModuleType:
    """The module behind ``extra`` (imported), or :class:`MissingExtra`."""
    module, _ = EXTRAS[extra]
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        raise MissingExtra(extra, exc) from exc


def missing_extra(exc: ImportError) -> MissingExtra | None:
    """The :class:`MissingExtra` for an import that failed because an extra's module is not
    installed (``exc.name`` is that module or one of its submodules); None for any other failure."""
    name = (exc.name or "").partition(".")[0]
    extra = next((e for e, (module, _) in EXTRAS.items() if module == name), None)
    return None if extra is None else MissingExtra(extra, exc)


def available(extra: str) -> bool:
    """Whether ``extra``'s module can be imported."""
    try:
        require(extra)
    except MissingExtra:
        return False
    return True
