"""Each study's kernel stub (``driver/<study>/_kernels.pyi``) says what the built module accepts.

The stubs are generated (tools/gen_kernel_stub.py) from the signatures f2py documents on
each wrapper, one per study in its own package (the Fortran modules named after the study);
these tests fail when a committed stub is stale, and check its reading of the f2py signatures
against the module itself: every module of a study and every routine and parameter named, the
argument count the wrapper really enforces, the result count and dtypes it really returns.
The shared ``driver/_kernels.pyi`` names no study (adding one leaves it as it is).
"""
from __future__ import annotations

import ast
import importlib.util
from pathlib import Path

import numpy as np
import pytest

from driver._fortran import _kernels
from driver._study import load_study, study_names

ROOT = Path(__file__).resolve().parents[1]


def _generator():
    spec = importlib.util.spec_from_file_location("gen_kernel_stub", ROOT / "tools" / "gen_kernel_stub.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _stub_classes() -> dict[str, dict[str, ast.FunctionDef]]:
    """Every class of every study's committed stub, by name (``_fourbar``): its routines."""
    out = {}
    for stub in sorted((ROOT / "driver").glob("*/_kernels.pyi")):
        tree = ast.parse(stub.read_text())
        out |= {c.name: {f.name: f for f in c.body if isinstance(f, ast.FunctionDef)}
                for c in tree.body if isinstance(c, ast.ClassDef)}
    return out


def test_committed_stubs_are_fresh_and_in_their_studies_packages():
    """Regenerating from the built module gives each study's committed file (else: run the tool),
    and there is no stub but the studies'."""
    written = _generator().stubs(_kernels)
    assert written, "no study has a kernel stub"
    for path, text in written.items():
        rel = path.relative_to(ROOT)
        assert path.is_file() and path.read_text() == text, \
            f"{rel} is stale: run .venv/bin/python tools/gen_kernel_stub.py {path.parent.name}"
        assert load_study(path.parent.name).kernel is not None, rel
    assert set(written) == set((ROOT / "driver").glob("*/_kernels.pyi"))
    shared = (ROOT / "driver" / "_kernels.pyi").read_text()
    assert not [s for s in study_names() if s in shared]


def test_every_fortran_module_belongs_to_one_study_or_is_a_shared_building_block():
    gen = _generator()
    owners = {m: gen.owner(m, study_names()) for m in gen.fortran_modules(_kernels)}
    assert {m for m, o in owners.items() if o is None} == {"kinds", "vecmath"}, owners
    assert gen.owner("fourbar_forces", ["fourbar", "fourbar_forces"]) == "fourbar_forces"   # the longest name
    assert gen.owner("fourbarx", ["fourbar"]) is None


def test_stub_names_every_module_and_routine():
    classes = _stub_classes()
    gen = _generator()
    for mname in gen.fortran_modules(_kernels):
        if gen.owner(mname, study_names()) is None:
            continue
        mod = getattr(_kernels, mname)
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
