"""The studies' ``run`` show their deck keys to help(), IDEs and type checkers (driver._signatures).

Truth is each study's SPEC (the keys the deck reader validates against): the runtime
signature and docstring must name every key with its default (or say it is required), its
units and its allowed values; each study's committed static signature (``_keywords.pyi`` in its
own package) must be what the generator makes of its SPEC today; and mypy must refuse a
misspelt key or a value outside a key's choices, and accept a correct call.
"""
from __future__ import annotations

import importlib.util
import inspect
import pydoc
import subprocess
import sys
from pathlib import Path

import pytest

from driver._deck import DeckError, GroupSpec
from driver._runner import available_studies
from driver._signatures import NOT_GIVEN, render_stub, unit_text

ROOT = Path(__file__).resolve().parents[1]
STUDIES = sorted(available_studies())
#: studies whose run carries the generated signature: every one
TYPED = [g for g in STUDIES if hasattr(available_studies()[g].run, "__signature__")]


def _spec(group: str) -> GroupSpec:
    """The deck keys of study ``group`` (its study contract's spec)."""
    return available_studies()[group].spec


def _tool():
    spec = importlib.util.spec_from_file_location("gen_keyword_signatures", ROOT / "tools" / "gen_keyword_signatures.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.mark.parametrize("group", STUDIES)
def test_each_study_has_its_static_signature_fresh_in_its_own_package(group):
    study = available_studies()[group]
    stub = Path(study.module.__file__).parent / "_keywords.pyi"
    written = _tool().stubs([group])
    assert list(written) == [stub]
    assert stub.is_file() and stub.read_text() == written[stub], \
        f"{stub.relative_to(ROOT)} is stale: run .venv/bin/python tools/gen_keyword_signatures.py {group}"


def test_no_shared_generated_signature_file():
    """Nothing outside the studies' packages holds a study's signature (a new study edits no shared file)."""
    assert not (ROOT / "driver" / "_keywords.py").exists()
    assert sorted(p.parent.name for p in (ROOT / "driver").rglob("_keywords.pyi")) == STUDIES


def test_a_study_imports_without_its_stub(tmp_path, monkeypatch):
    """The stub is read by type checkers only: a study package whose ``_keywords.pyi`` is not
    written yet imports and runs (the generator imports the study to write it)."""
    import shutil

    import driver
    from driver._deck import read_deck
    from driver._runner import study_of
    from driver._study import REGISTRY, load_study
    from driver.robust_example import SPEC
    pkg = tmp_path / "nostub"
    shutil.copytree(Path(available_studies()["robust_example"].module.__file__).parent, pkg,
                    ignore=shutil.ignore_patterns("_keywords.pyi", "__pycache__"))
    for f in pkg.glob("*.py"):   # the copy is a package of its own: its absolute imports point at itself
        f.write_text(f.read_text().replace("driver.robust_example", "nostub"))
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setitem(REGISTRY, "robust_example", "nostub")
    try:
        study = load_study("robust_example")
        assert study is not None and study.package == "nostub" and not (pkg / "_keywords.pyi").exists()
        assert list(_tool().stubs(["robust_example"]).values()) == [render_stub(SPEC)]
        deck = read_deck(ROOT / "inputs" / "robust_example.dat")
        result = study.run(study_of(deck)[1])
        assert result.ok and result.summary == driver.robust_example.run(study_of(deck)[1]).summary
    finally:
        for name in [m for m in sys.modules if m == "nostub" or m.startswith("nostub.")]:
            del sys.modules[name]


@pytest.mark.parametrize("group", TYPED)
def test_signature_names_every_key_with_its_default(group):
    params = inspect.signature(available_studies()[group].run).parameters
    assert list(params)[:2] == ["params", "progress"]
    assert list(params)[2:] == list(_spec(group).keys)
    for name, key in _spec(group).keys.items():
        p = params[name]
        assert p.kind is inspect.Parameter.KEYWORD_ONLY
        if key.required:
            assert p.default is inspect.Parameter.empty, name
        elif key.default is None:
            assert p.default is NOT_GIVEN, name
        else:
            assert p.default == key.default, name


def _entries(doc: str) -> dict[str, tuple[str, str]]:
    """The numpydoc Parameters entries of a help text: name -> (head, description)."""
    section = doc.split("Parameters\n", 1)[1].split("Returns\n", 1)[0]
    out: dict[str, tuple[str, str]] = {}
    name = None
    for line in section.splitlines():
        stripped = line.strip()
        if " : " in stripped and not line.startswith(" " * 8):
            name, _, head = stripped.partition(" : ")
            out[name] = (head, "")
        elif name is not None and stripped:
            out[name] = (out[name][0], (out[name][1] + " " + stripped).strip())
    return out


@pytest.mark.parametrize("group", TYPED)
def test_help_lists_keys_units_defaults_and_choices(group):
    entries = _entries(pydoc.render_doc(available_studies()[group].run, renderer=pydoc.plaintext))
    assert list(entries) == ["params", "progress", *_spec(group).keys]
    for name, key in _spec(group).keys.items():
        head, desc = entries[name]
        if key.required:
            assert desc.endswith("Required."), name
        elif key.default is not None:
            assert head.endswith(f"default {key.default!r}".replace("'", '"')) or "default [" in head, (name, head)
        else:
            assert head.endswith("optional"), (name, head)
        if key.units:   # "[rad/s]"; "1" and "-" read "[dimensionless]"
            assert unit_text(key.units) in desc, (name, key.units, desc)
        for choice in key.choices or ():
            assert repr(choice).replace("'", '"') in head, (name, choice)


def test_keyword_call_still_validates_like_a_deck():
    """The signature changes what tools see, not the call: keys are still checked by the SPEC."""
    import driver
    with pytest.raises(DeckError, match="unknown key"):
        driver.ujoint.run(rmp=30.0)
    r = driver.ujoint.run(beta=[10.0, 20.0], phi=[90.0], rpm=30.0)
    assert r.failure is None and r.summary


def test_mypy_refuses_a_misspelt_key_and_a_value_outside_the_choices(tmp_path):
    snippet = tmp_path / "calls.py"
    snippet.write_text(
        "import driver.ujoint\n"
        "import driver.slidercrank\n"
        "driver.ujoint.run(beta=[10.0, 20.0], phi=[90.0], rpm=30.0, model='exact')\n"   # line 3: fine
        "driver.ujoint.run(beta=[10.0, 20.0], rmp=30.0)\n"                              # 4: misspelt
        "driver.ujoint.run(beta=[10.0, 20.0], model='exakt')\n"                         # 5: not a choice
        "driver.slidercrank.run(speeds=[100.0], n_elements=4.5)\n"                      # 6: an int key
        "driver.slidercrank.run(speeds=[100.0, 150.0], n_elements=4)\n"                # 7: fine
        "import driver.fourbar\n"
        "driver.fourbar.run(fixed_link=12, crank=5, coupler=15, rocker=9, step_deg=20)\n"  # 9: fine
        "driver.fourbar.run(fixed_lnik=12, crank=5, coupler=15, rocker=9, step_deg=20)\n")  # 10: misspelt
    proc = subprocess.run([sys.executable, "-m", "mypy", "--follow-imports=silent", "--no-error-summary",
                           "--cache-dir", str(tmp_path / "cache"), str(snippet)],
                          cwd=ROOT, capture_output=True, text=True, timeout=600)
    errors = [line for line in proc.stdout.splitlines() if ": error:" in line]
    lines = sorted({int(line.split(":")[1]) for line in errors})
    assert lines == [4, 5, 6, 10], proc.stdout
    assert any('Unexpected keyword argument "rmp"' in line for line in errors), proc.stdout
    assert any('Unexpected keyword argument "fixed_lnik"' in line for line in errors), proc.stdout


def test_every_study_run_carries_its_signature():
    assert TYPED == STUDIES
