"""Both kinds of sweep resume record (batch parts and per-case parts) are invalidated by an edit
to *any* module of a study package, not only its ``__init__.py`` (an edit to a study's report
module changes what the tables say, so a record made before it must be redone)."""
from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

from driver.deck import RawGroup
from driver.study import code_digest
from driver.sweep import store
from driver import sweep_batch


@pytest.fixture
def fake_study(tmp_path: Path):
    pkg = tmp_path / "fakestudy"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("from fakestudy.report import TEXT\n")
    (pkg / "report.py").write_text("TEXT = 'v1'\n")
    sys.path.insert(0, str(tmp_path))
    try:
        spec = importlib.util.spec_from_file_location("fakestudy", pkg / "__init__.py",
                                                      submodule_search_locations=[str(pkg)])
        assert spec and spec.loader
        mod = importlib.util.module_from_spec(spec)
        sys.modules["fakestudy"] = mod
        spec.loader.exec_module(mod)
        yield mod, pkg
    finally:
        sys.path.remove(str(tmp_path))
        for name in [n for n in sys.modules if n == "fakestudy" or n.startswith("fakestudy.")]:
            del sys.modules[name]


def _both(mod) -> tuple[str, str]:
    raw = RawGroup("fakestudy", {"a": 1.0, "b": 2.0}, {"a": 2, "b": 3}, 1)
    per_case = store.signature(raw, ["fakestudy.a"], "deck.dat", "", "none", [], False, mod)
    grid = sweep_batch.Grid(["fakestudy.a"], [[1.0, 2.0]], False)
    batch = sweep_batch._signature(raw, grid, "", "all", mod)
    return per_case, batch


def test_editing_a_report_module_invalidates_both_record_kinds(fake_study):
    mod, pkg = fake_study
    before = _both(mod)
    assert _both(mod) == before                       # deterministic
    (pkg / "report.py").write_text("TEXT = 'v2'\n")   # the package's __init__.py is unchanged
    after = _both(mod)
    assert after[0] != before[0], "per-case resume signature ignores the study's report module"
    assert after[1] != before[1], "batch resume signature ignores the study's report module"


def test_code_digest_covers_every_module_of_a_real_study_package():
    import driver.ujoint as uj
    files = sorted(Path(uj.__file__).parent.rglob("*.py"))
    assert any(f.name == "report.py" for f in files)
    assert len(code_digest(uj)) == 32
    assert code_digest(uj) != code_digest(None)
