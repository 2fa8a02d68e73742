"""Mechanism-analysis studies driven by namelist decks: a batch program and a Python library.

Batch: ``python -m driver inputs/crank5.dat`` (see :mod:`driver.cli`).  Python::

    import driver
    r = driver.run("inputs/crank5.dat")           # or deck text, or {"fourbar": {...}}
    r = driver.fourbar.run(fixed_link=12, crank=5, coupler=15, rocker=9, step_deg=20)
    r.out, r.tidy, r.summary, r.summary_frame, r.figure("linkage"), r.warnings, r.write("out")
    s = driver.run_sweep("inputs/fourbar_paper_sweep.dat", jobs=1); s.summary
    driver.studies(), driver.keys("fourbar")

Studies (one module each, named after their namelist group: ``driver.fourbar``,
``driver.ujoint``, ``driver.slidercrank``, ``driver.manipulator``, ``driver.robust_example``)
run Fortran 90 kernels through :mod:`driver.kernels`.  Names are imported on first use, so
``import driver`` stays cheap.
"""
from __future__ import annotations

import importlib
import importlib.util
from typing import TYPE_CHECKING, Any

__version__ = "0.1.0"

__all__ = ["run", "run_sweep", "studies", "keys", "Result", "SweepResult", "DeckError"]

_API = {"run": "driver.api", "run_sweep": "driver.api", "studies": "driver.api", "keys": "driver.api",
        "Result": "driver.study", "SweepResult": "driver.api", "DeckError": "driver.deck"}

if TYPE_CHECKING:   # pragma: no cover - for type checkers and IDEs only
    from driver.api import SweepResult, keys, run, run_sweep, studies
    from driver.deck import DeckError
    from driver.study import Result


def __getattr__(name: str) -> Any:
    """PEP 562: the public names and the modules (``driver.fourbar``, ``driver.optimize``) on first use."""
    if name in _API:
        value = getattr(importlib.import_module(_API[name]), name)
        globals()[name] = value
        return value
    if name.isidentifier() and not name.startswith("_") and importlib.util.find_spec(f"driver.{name}"):
        return importlib.import_module(f"driver.{name}")   # a study (driver.fourbar) or a subpackage
    raise AttributeError(f"module 'driver' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
