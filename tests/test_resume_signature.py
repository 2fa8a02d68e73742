"""Both kinds of sweep resume record (batch parts and per-case parts) are invalidated by an edit
to *any* module of a study package, not only its ``__init__.py`` (an edit to a study's report
module changes what the tables say, so a record made before it must be redone).

Both kinds carry the one signature :func:`driver.sweep._resume.signature`; checked on the
functions (a synthetic study package edited on disk) and end to end (a Hooke-joint sweep run
on the batch path and case by case, resumed before and after an edit of
``driver/ujoint/_report.py`` as the digest reads it)."""
from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path

import pyarrow.parquet as pq
import pytest

from driver._cli import main
from driver._deck import RawGroup
from driver._output import code_digest
from driver.sweep import _plan as plan
from driver.sweep import _resume as store
from driver.sweep._spec import Grid


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
    per_case = store.case_signature(raw, ["fakestudy.a"], "deck.dat", "", "none", [], False, mod)
    grid = Grid(["fakestudy.a"], [[1.0, 2.0]], False)
    batch = plan.batch_signature(raw, grid, "", "all", mod)
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
    assert any(f.name == "_report.py" for f in files)
    assert len(code_digest(uj)) == 32
    assert code_digest(uj) != code_digest(None)


DECK = """&ujoint
  model = 'exact'
  beta = 25.0, 25.0
  phi = 90.0
  rho = 0.0
  rpm = 25.0
/
&sweep
  key1 = 'ujoint.rho', values1 = 0, 30
  key2 = 'ujoint.phi', values2 = 0, 90, 120
  keep = 'pp_ratio < 1e-9'
  case_outputs = '{outputs}'
/
"""


def _resumed(capsys, deck: Path, out: Path) -> str:
    capsys.readouterr()
    assert main([str(deck), "-o", str(out), "-j", "1", "--resume"]) == 0
    return [line for line in capsys.readouterr().out.splitlines() if line.startswith("resume:")][0]


@pytest.mark.parametrize("outputs, engine", [("none", "batch"), ("all", "case")])
def test_an_edit_of_the_report_module_redoes_a_resumed_sweep(tmp_path, capsys, monkeypatch, outputs, engine):
    import driver.ujoint._report as report
    deck = tmp_path / "usw.dat"
    deck.write_text(DECK.format(outputs=outputs))
    out = tmp_path / "out"
    assert main([str(deck), "-o", str(out), "-q", "-j", "1"]) == 0
    kinds = {json.loads(pq.read_schema(p).metadata[b"sweep"])["kind"] for p in (out / "usw.sweep").glob("part-*")}
    assert kinds == {"batch" if engine == "batch" else "cases"}, kinds
    assert _resumed(capsys, deck, out) == "resume: 6 of 6 cases complete, 0 to run"
    target = Path(report.__file__).resolve()
    real = Path.read_bytes
    monkeypatch.setattr(Path, "read_bytes",
                        lambda self: real(self) + (b"\n# edited\n" if self.resolve() == target else b""))
    assert _resumed(capsys, deck, out) == "resume: 0 of 6 cases complete, 6 to run"
    assert _resumed(capsys, deck, out) == "resume: 6 of 6 cases complete, 0 to run"
