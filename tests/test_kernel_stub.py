"""driver/_kernels.pyi, the type stub of the f2py extension, says what the built module accepts.

The stub is generated (tools/gen_kernel_stub.py) from the signatures f2py documents on
each wrapper; these tests fail when the committed stub is stale, and check its reading of
the f2py signatures against the module itself: every routine and parameter named, the
argument count the wrapper really enforces, the result count and dtypes it really returns.
"""
from __future__ import annotations

import ast
import importlib.util
from pathlib import Path

import numpy as np
import pytest

from driver import _kernels

ROOT = Path(__file__).resolve().parents[1]
STUB = ROOT / "driver" / "_kernels.pyi"


def _generator():
    spec = importlib.util.spec_from_file_location("gen_kernel_stub", ROOT / "tools" / "gen_kernel_stub.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _stub_classes() -> dict[str, dict[str, ast.FunctionDef]]:
    tree = ast.parse(STUB.read_text())
    return {c.name: {f.name: f for f in c.body if isinstance(f, ast.FunctionDef)}
            for c in tree.body if isinstance(c, ast.ClassDef)}


def test_committed_stub_is_fresh():
    """Regenerating from the built module gives the committed file (else: run the tool)."""
    assert STUB.read_text() == _generator().render(_kernels), \
        "driver/_kernels.pyi is stale: run .venv/bin/python tools/gen_kernel_stub.py"


def test_stub_names_every_module_and_routine():
    classes = _stub_classes()
    for mname in dir(_kernels):
        mod = getattr(_kernels, mname)
        if type(mod).__name__ != "fortran":
            continue
        routines = {a for a in dir(mod) if type(getattr(mod, a)).__name__ == "fortran"}
        assert set(classes[f"_{mname}"]) == routines, mname


@pytest.mark.parametrize("mname,routine", [("fourbar", "listing_table"), ("ujoint", "chain_speed"),
                                           ("slidercrank", "analytic_frequencies")])
def test_stub_arity_is_what_the_wrapper_enforces(mname, routine):
    """One argument fewer than the stub's required ones is refused by the real wrapper."""
    fn = _stub_classes()[f"_{mname}"][routine]
    required = len(fn.args.args) - len(fn.args.defaults)
    real = getattr(getattr(_kernels, mname), routine)
    with pytest.raises(TypeError, match="argument|takes"):
        real(*[0] * (required - 1))


def test_listing_table_results_match_the_stub():
    """A real call: the stub's tuple of (float64 2-D, int32 1-D) is what comes back."""
    fn = _stub_classes()["_fourbar"]["listing_table"]
    assert ast.unparse(fn.returns) == "tuple[NDArray[np.float64], NDArray[np.int32]]"
    table, status = _kernels.fourbar.listing_table(12.0, 5.0, 15.0, 9.0, 5.0, 0, 20, 18)
    assert table.dtype == np.float64 and table.shape == (18, 10)
    assert status.dtype == np.int32 and status.shape == (18,)
