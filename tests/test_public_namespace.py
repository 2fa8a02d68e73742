"""The public face, SciPy style: a small public namespace, every other module private.

Public are the names of ``driver.__all__``, the study packages, ``driver.sweep``,
``driver.optimize``, ``driver.synthesis`` and ``driver.plotting`` (``driver.PUBLIC_MODULES``);
every other module's name starts with an underscore (``driver._deck``,
``driver.fourbar._kernel``).  These tests read the files on disk, so a new module that is not
underscored, a public name that does not resolve, or a user-facing text that reaches into a
private module fails here.
"""
from __future__ import annotations

import ast
import importlib
import importlib.util
import pickle
import re
from pathlib import Path

import pytest

import driver
from driver._study import study_names

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "driver"


def _dotted(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _public(dotted: str) -> bool:
    return not any(p.startswith("_") for p in dotted.split(".")[1:])


def test_every_module_is_private_but_the_declared_public_ones():
    modules = {_dotted(p) for p in PACKAGE.rglob("*.py") if "__pycache__" not in p.parts and p.name != "__main__.py"}
    public = {m for m in modules if _public(m)}
    assert public == {"driver", *(f"driver.{m}" for m in driver.PUBLIC_MODULES)}, sorted(public)
    assert len(modules) > 3 * len(public)   # the point: most of the code is behind the public names


def test_the_public_names_resolve_and_nothing_else_is_offered():
    for name in driver.__all__:
        assert getattr(driver, name) is not None, name
    for name in driver.PUBLIC_MODULES:
        assert importlib.import_module(f"driver.{name}") is getattr(driver, name)
    assert dir(driver) == sorted({*driver.__all__, *driver.PUBLIC_MODULES, "__version__"})
    for private in ("deck", "runner", "cli", "kernels", "study"):
        with pytest.raises(AttributeError):
            getattr(driver, private)


@pytest.mark.parametrize("name", driver.PUBLIC_MODULES)
def test_each_public_package_exports_only_public_names_that_resolve(name):
    module = importlib.import_module(f"driver.{name}")
    exported = getattr(module, "__all__", None)
    assert exported, f"driver.{name} declares no __all__"
    for attr in exported:
        assert not attr.startswith("_"), (name, attr)
        assert hasattr(module, attr), (name, attr)


def test_deck_error_is_the_public_one_in_tracebacks_and_pickles():
    err = driver.DeckError("a.dat", 3, "crank", "must be positive (got -5.0)")
    assert type(err).__module__ == "driver"
    back = pickle.loads(pickle.dumps(err))
    assert (back.path, back.line, back.key, back.message) == ("a.dat", 3, "crank", "must be positive (got -5.0)")
    assert str(back) == str(err)
    with pytest.raises(driver.DeckError, match="crank"):
        driver.fourbar.run(fixed_link=12, crank=-5, coupler=15, rocker=9, step_deg=20)


def _private_references(text: str) -> list[str]:
    return re.findall(r"\bdriver(?:\.[a-z][a-z_]*)*\._(?!kernels\b)[a-z][a-z_]*", text)


def test_examples_and_readme_use_the_public_api_only():
    """What a user copies (examples/, README) names no private module; docs/ may, to explain
    the inside, but not in their Python code blocks."""
    for path in [*sorted((ROOT / "examples").glob("*.py")), ROOT / "README.md"]:
        text = path.read_text()
        if path.suffix == ".py":
            tree = ast.parse(text)
            names = [n.module or "" for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)]
            names += [a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names]
            text = "\n".join(names)
        assert not _private_references(text), (path.name, _private_references(text))
    for path in sorted((ROOT / "docs").glob("*.md")):
        blocks = re.findall(r"```python\n(.*?)```", path.read_text(), re.S)
        found = [r for b in blocks for r in _private_references(b)]
        assert not found, (path.name, found)


def test_shared_docstring_sections_are_filled_in_where_used():
    """driver._docs.fill_doc (SciPy's doccer in small): a field is replaced by its section, an
    unknown field stays visible (and fails the numpydoc check), no docstring is no error."""
    from driver._docs import fill_doc
    from driver._study import HOOK_SECTIONS

    @fill_doc(rod="rod : float\n        Rod length, m.")
    def f(rod: float) -> None:
        """Do it.

        Parameters
        ----------
        %(rod)s
        %(other)s
        """

    assert "rod : float\n        Rod length, m." in (f.__doc__ or "") and "%(other)s" in (f.__doc__ or "")
    g = fill_doc(rod="x")(lambda: None)
    assert g.__doc__ is None
    for study in study_names():
        doc = importlib.import_module(f"driver.{study}").estimate.__doc__
        assert "%(" not in doc and HOOK_SECTIONS["estimate"] in doc, study


#: files whose import lines in strings are made up on purpose (the self-checks of the import walks)
FAKE_IMPORTS = {"test_private_names.py": "its walk's self-check imports names that do not exist",
                "test_import_graph.py": "its docstring and self-check name a fake package"}


def test_every_import_of_the_driver_resolves_also_in_code_held_in_strings():
    """Code run through ``python -c`` (tests, bench/) is text to the import checks: every
    ``from driver... import name`` written anywhere in the repository's Python must resolve (a
    module renamed private would otherwise fail only when that script runs).  A study's generated
    stubs (``_keywords.pyi``, ``_kernels.pyi``) are modules to type checkers only: an import of one
    resolves when the stub defines the names."""
    pattern = re.compile(r"from (driver(?:\.[A-Za-z_]+)*) import ([A-Za-z_][A-Za-z_0-9, ]*)")
    missing = []
    for path in sorted([*ROOT.glob("driver/**/*.py"), *ROOT.glob("tests/**/*.py"), *ROOT.glob("bench/*.py"),
                        *ROOT.glob("tools/*.py"), *ROOT.glob("examples/*.py")]):
        if path.name in FAKE_IMPORTS:
            continue
        for m in pattern.finditer(path.read_text()):
            names = [n.strip().split(" as ")[0] for n in m.group(2).split(",") if n.strip()]
            stub = ROOT.joinpath(*m.group(1).split(".")).with_suffix(".pyi")
            if stub.is_file() and not stub.with_suffix(".py").exists():   # a stub-only module
                defined = {t.id for n in ast.walk(ast.parse(stub.read_text())) for t in
                           ([n.target] if isinstance(n, ast.AnnAssign) else []) if isinstance(t, ast.Name)}
                defined |= {n.name for n in ast.walk(ast.parse(stub.read_text())) if isinstance(n, ast.FunctionDef)}
                missing += [f"{path.relative_to(ROOT)}: from {m.group(1)} import {n}" for n in names if n not in defined]
                continue
            if all(ROOT.joinpath(*m.group(1).split("."), f"{n}.pyi").is_file() for n in names):
                continue   # stub-only modules of a package (from driver.fourbar import _kernels)
            try:
                module = importlib.import_module(m.group(1))
            except ModuleNotFoundError:
                missing.append(f"{path.relative_to(ROOT)}: from {m.group(1)} import ...")
                continue
            for name in (n.strip().split(" as ")[0] for n in m.group(2).split(",")):
                if name and not hasattr(module, name) and not (
                        hasattr(module, "__path__") and importlib.util.find_spec(f"{m.group(1)}.{name}")):
                    missing.append(f"{path.relative_to(ROOT)}: from {m.group(1)} import {name}")
    assert not missing, missing
