"""One exception base (driver.DriverError) and one wrapper of every kernel's status word.

Truth: the classes themselves, found by reading every module of driver/ (a new exception class
anywhere is in this test without being named here); pickling round trips (a worker process's
error must reach the driver whole: type, message, fields); and the Fortran kernels' own argument
checks (a column of an odd number of elements is refused by fortran/slidercrank_nl.f90, which the
wrapper must turn into a KernelError).
"""
from __future__ import annotations

import ast
import importlib
import pickle
from enum import IntEnum
from pathlib import Path

import pytest

import driver
from conftest import ROOT
from driver._errors import DriverError, KernelError
from driver._fortran import KernelStatus, kernel_status

#: exceptions that are no errors of the driver, with the reason
OUTSIDE = {"driver._cli.Terminated": "SIGTERM handled as Ctrl-C: a KeyboardInterrupt, which every "
                                     "'except Exception' must let pass"}


def _exception_classes() -> dict[str, type[BaseException]]:
    """Every exception class defined in driver/, by dotted name."""
    found = {}
    for path in sorted((ROOT / "driver").rglob("*.py")):
        parts = path.relative_to(ROOT).with_suffix("").parts
        module = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        for node in ast.parse(path.read_text()).body:
            if isinstance(node, ast.ClassDef) and node.bases:
                obj = getattr(importlib.import_module(module), node.name)
                if isinstance(obj, type) and issubclass(obj, BaseException):
                    found[f"{module}.{node.name}"] = obj
    return found


def test_every_exception_of_the_driver_derives_from_driver_error_and_keeps_its_builtin():
    classes = _exception_classes()
    assert len(classes) >= 13, sorted(classes)    # the eleven of issue 34, the base and KernelError
    builtins = {"DeckError": ValueError, "CaseFailure": ValueError, "ExprError": ValueError,
                "TableValueError": ValueError, "PublishedError": ValueError, "FitError": ValueError,
                "MissingExtra": ImportError, "NameTooLong": OSError, "LinkRefused": PermissionError,
                "SweepBusy": OSError, "KernelError": RuntimeError, "UnsafeName": OSError}
    for name, cls in classes.items():
        if name in OUTSIDE:
            assert not issubclass(cls, DriverError) and not issubclass(cls, Exception), name
            continue
        if cls is DriverError:
            continue
        assert issubclass(cls, DriverError), f"{name} is not a driver.DriverError"
        short = name.rpartition(".")[2]
        assert short in builtins, f"{name}: a new exception class; say which built-in it is in this test"
        assert issubclass(cls, builtins[short]), name
    assert driver.DriverError is DriverError and "DriverError" in driver.__all__
    assert issubclass(driver.DeckError, driver.DriverError)


def _instances() -> list[BaseException]:
    from driver._atomic import LinkRefused, NameTooLong, UnsafeName
    from driver._expr import ExprError
    from driver._extras import MissingExtra
    from driver._published import PublishedError
    from driver._runner import CaseFailure
    from driver._table import TableValueError
    from driver.robust_example._analysis import FitError
    from driver.sweep._resume import SweepBusy
    return [driver.DeckError("a.dat", 3, "crank", "must be positive"), CaseFailure("b.dat", 4, None, "diverged"),
            ExprError("not allowed", "__import__"), TableValueError("nan"), PublishedError("missing"),
            FitError("singular"), MissingExtra("parquet", ImportError("No module named 'pyarrow'")),
            NameTooLong("/tmp/" + "x" * 300 + ".out"), LinkRefused("/tmp/link"),
            UnsafeName("/tmp/a\x1b[31m.out", "the name holds a control character"),
            SweepBusy(Path("/tmp/s.sweep")),
            KernelError("slidercrank_nl.column_static", 4, "BAD ARGUMENTS: the kernel refused its arguments")]


@pytest.mark.parametrize("exc", _instances(), ids=lambda e: type(e).__name__)
def test_each_error_pickles_whole(exc):
    back = pickle.loads(pickle.dumps(exc))
    assert type(back) is type(exc) and str(back) == str(exc) and back.args == exc.args
    fields = {k: v for k, v in vars(exc).items() if not isinstance(v, BaseException)}
    assert {k: v for k, v in vars(back).items() if k in fields} == fields
    for attr in ("errno", "filename", "name"):   # the built-ins' own fields (OSError, ImportError)
        assert getattr(back, attr, None) == getattr(exc, attr, None), attr
    assert isinstance(back, DriverError)


class _Toy(KernelStatus):
    ok = 0, "ok"
    slow = 1, "SLOW", "took its time"
    refused = 4, "BAD ARGUMENTS", "the kernel refused its arguments", True


def test_kernel_status_names_outcomes_and_raises_for_refusals_and_unknown_codes():
    assert kernel_status(_Toy, 1, "toy.run") is _Toy.slow and _Toy.slow == 1 and isinstance(_Toy.slow, IntEnum)
    assert (_Toy.slow.what, _Toy.slow.why, _Toy.slow.refused) == ("SLOW", "took its time", False)
    assert _Toy["slow"] is _Toy.slow   # by the Fortran parameter's name, as the dicts it replaced
    with pytest.raises(KernelError, match=r"toy.run: status 4: BAD ARGUMENTS: the kernel refused") as exc:
        kernel_status(_Toy, 4, "toy.run")
    assert (exc.value.routine, exc.value.code) == ("toy.run", 4)
    with pytest.raises(KernelError, match=r"status 7: not a status of _Toy \(0 ok, 1 slow, 4 refused\)"):
        kernel_status(_Toy, 7, "toy.run")


def test_a_kernel_that_refuses_its_call_raises_a_driver_error():
    """fortran/slidercrank_nl.f90 column_static refuses an odd number of elements (nl_bad_args)."""
    from driver.slidercrank import _kernel as kernel
    mid, short, iters, status = kernel.slidercrank_column_static(4, 1.0, 1e6, 10.0, 1.0, 1e-3)
    assert status is kernel.NonlinearStatus.ok and iters >= 1
    with pytest.raises(KernelError, match="slidercrank_nl.column_static: status 4: BAD ARGUMENTS") as exc:
        kernel.slidercrank_column_static(3, 1.0, 1e6, 10.0, 1.0, 1e-3)
    assert isinstance(exc.value, driver.DriverError) and exc.value.code == int(kernel.NonlinearStatus.bad_args)


def test_every_kernel_status_table_holds_the_fortran_parameters():
    """Each table's codes are the Fortran modules' parameters (read from the built extension),
    and only a bad-arguments code is a refusal."""
    from driver._fortran import _kernels
    from driver.fourbar import _kernel as fk
    from driver.manipulator import _kernel as mk
    from driver.slidercrank import _kernel as sk
    from driver.ujoint import _kernel as uk
    tables = [(fk.FourbarStatus, _kernels.fourbar, "st_"), (mk.ManipulatorStatus, _kernels.manipulator, "st_"),
              (sk.SimulateStatus, _kernels.slidercrank, "st_"), (sk.NonlinearStatus, _kernels.slidercrank_nl, "nl_"),
              (uk.UjointStatus, _kernels.ujoint, "st_")]
    for table, module, prefix in tables:
        params = {a[len(prefix):]: int(getattr(module, a)) for a in dir(module) if a.startswith(prefix)}
        assert {m.name: m.value for m in table} == params, table.__name__
        assert {m.name for m in table if m.refused} <= {"bad_args"}, table.__name__
