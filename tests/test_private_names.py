"""No module of the driver imports another module's underscored name (issue 25).

Inside a study package a name a sibling imports is part of the package's internal interface and
has a public name in its module (the modules themselves become private, SciPy style).  Checked by
an ast walk over driver/, bench/ and tools/ (tests may exercise a module's private helpers):
``from driver.x import _y`` and ``x._y`` on an imported driver module are both refused, unless
``_y`` is itself a private module of the package (``driver._kernels``, ``driver._keywords``, ...:
importing a private module is how the package is put together).  A self-check shows the walk
finds each form.
"""
from __future__ import annotations

import ast

from conftest import ROOT

SCANNED = ("driver", "bench", "tools")
#: underscored names another module may take, each with its reason
ALLOWED = {"driver._fortran._kernels": "the private extension module driver._kernels, taken from its loader so that a "
                                      "missing build raises the loader's readable ImportError (tests/test_install.py)"}


def _is_module(dotted: str) -> bool:
    """True when ``dotted`` (e.g. 'driver._kernels') is a module or package of this tree."""
    path = ROOT.joinpath(*dotted.split("."))
    return (path.with_suffix(".py").is_file() or path.with_suffix(".pyi").is_file()
            or (path / "__init__.py").is_file() or any(path.parent.glob(path.name + ".*.so")))


def private_imports(source: str, package: str = "driver") -> list[tuple[int, str]]:
    """(line, 'module.name') for every underscored name ``source`` takes from another module of
    ``package``: imported by name, or read as an attribute of an imported module."""
    tree = ast.parse(source)
    modules: dict[str, str] = {}   # local name -> dotted name of an imported package module
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.split(".")[0] == package:
            for alias in node.names:
                dotted = f"{node.module}.{alias.name}"
                if _is_module(dotted):
                    modules[alias.asname or alias.name] = dotted
                elif alias.name.startswith("_") and not alias.name.startswith("__"):
                    found.append((node.lineno, dotted))
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.split(".")[0] == package and alias.asname:
                    modules[alias.asname] = alias.name
    for node in ast.walk(tree):
        if (isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id in modules
                and node.attr.startswith("_") and not node.attr.startswith("__")
                and not _is_module(f"{modules[node.value.id]}.{node.attr}")):
            found.append((node.lineno, f"{modules[node.value.id]}.{node.attr}"))
    return sorted(found)


def test_the_walk_finds_each_form():
    source = ("from driver.sweep._spec import Grid, _hidden\n"
              "from driver import _kernels, plotting\n"            # a private module: fine
              "from driver.sweep import _spec as sp\n"
              "import driver.plotting as plt\n"
              "sp._secret(1); plt._wrap(2); plotting.wrap(3); _kernels.fourbar\n"
              "from driver._deck import __version__\n")             # dunder: not private
    assert private_imports(source) == [(1, "driver.sweep._spec._hidden"), (5, "driver.plotting._wrap"),
                                       (5, "driver.sweep._spec._secret")]


def test_no_module_imports_another_modules_private_name():
    found = []
    for folder in SCANNED:
        for path in sorted((ROOT / folder).rglob("*.py")):
            found += [f"{path.relative_to(ROOT)}:{line}: {name}" for line, name in private_imports(path.read_text())
                      if name not in ALLOWED]
    assert found == [], "give these names a public name in their module (or move them):\n" + "\n".join(found)
    assert all(reason for reason in ALLOWED.values())
