"""No import circles between the modules of ``driver``.

The graph is read from the source with :mod:`ast` (nothing is imported): every ``import`` and
``from ... import`` statement of every ``driver/**/*.py`` file, at module level *and inside
functions* (a deferred import still ties two modules together: it only hides the circle from
the interpreter until the call), also under ``if TYPE_CHECKING:`` are they skipped (those are
read by type checkers only, never run).

How an import becomes an edge ``A -> B`` (B a module of ``driver``):

* ``import driver.x.y`` and ``from driver.x.y import name``: ``driver.x.y``;
* ``from driver.x import y`` where ``driver/x/y.py`` (or the package ``driver/x/y/``) exists:
  ``driver.x.y`` (a submodule is taken, not the package's face); any other name
  (``from driver.x import helper``) is an edge to ``driver.x`` itself, i.e. to its
  ``__init__.py``, which is what runs to hand the name on: a name re-exported by a package
  ``__init__`` ties the importer to that ``__init__`` and, through its own imports, to
  the module that defines it;
* relative imports are resolved against the importing module's package;
* executing a package's ``__init__`` as a side effect of importing one of its submodules is
  not an edge (otherwise every package whose ``__init__`` imports its parts would be a circle
  by construction); ``driver/__init__.py`` hands names on lazily (PEP 562) and has no edges.

The test can fail: :func:`test_the_finder_sees_a_circle` runs the same finder on a synthetic
package with a deferred circular import.

Inside every study package one dependency order holds (``driver._study.LAYERS``, docs/layout.md):
``_kernel`` -> ``_spec`` -> ``_analysis`` -> ``_tables`` -> ``_batch`` -> ``_figures`` -> ``_report``
-> ``_published``, a module importing only modules of an earlier layer or of its own (an extra
named after its layer, ``_report_nl``, belongs to it); the package's face (``__init__`` and any
module that only hands names on) stands above them and no layer imports it.  The example study
(tests/example_study/pendulum) is held to the same order, and a synthetic package shows that the
check sees a module importing a later layer and a layer importing the face.
"""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

from driver._study import LAYERS, REGISTRY, layer_of

ROOT = Path(__file__).resolve().parents[1]


def _module_name(path: Path, root: Path) -> str:
    parts = list(path.relative_to(root).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def _type_checking_only(node: ast.If) -> bool:
    test = node.test
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def _imports(tree: ast.AST) -> list[ast.Import | ast.ImportFrom]:
    """Every import statement of the tree (module level and deferred), except those that only
    type checkers see (``if TYPE_CHECKING:``)."""
    found: list[ast.Import | ast.ImportFrom] = []

    def visit(node: ast.AST) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.If) and _type_checking_only(child):
                for other in child.orelse:
                    visit_node(other)
                continue
            visit_node(child)

    def visit_node(node: ast.AST) -> None:
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            found.append(node)
        visit(node)

    visit(tree)
    return found


def import_graph(root: Path, package: str = "driver") -> dict[str, set[str]]:
    """{module: modules of ``package`` it imports}, read from ``root/package/**/*.py``."""
    files = sorted((root / package).rglob("*.py"))
    modules = {_module_name(f, root): f for f in files}
    graph: dict[str, set[str]] = {m: set() for m in modules}
    for name, path in modules.items():
        is_pkg = path.name == "__init__.py"
        here = name if is_pkg else name.rpartition(".")[0]
        for node in _imports(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            else:
                if node.level:
                    base = here.split(".")
                    base = base[: len(base) - (node.level - 1)] if node.level > 1 else base
                    origin = ".".join(base + ([node.module] if node.module else []))
                else:
                    origin = node.module or ""
                targets = []
                for alias in node.names:
                    sub = f"{origin}.{alias.name}"
                    targets.append(sub if sub in modules else origin)
            for t in targets:
                # `import driver.x.y` names the deepest module of the tree it reaches
                while t and t not in modules and "." in t:
                    t = t.rpartition(".")[0]
                if t in modules and t != name:
                    graph[name].add(t)
    return graph


def circles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan), each sorted."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []
    counter = [0]

    def strong(v: str) -> None:
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                strong(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                found.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            strong(v)
    return found


def _ties(graph: dict[str, set[str]], circle: list[str]) -> list[str]:
    members = set(circle)
    return [f"{a} -> {b}" for a in circle for b in sorted(graph[a]) if b in members]


def test_the_finder_sees_a_circle(tmp_path: Path) -> None:
    """A synthetic package: a -> b at module level, b -> a deferred in a function, c re-exported
    by the package face and d importing the face; the finder must report {a, b} and the
    face-tied circle {pkg, d}; e imports a name only under TYPE_CHECKING (no edge)."""
    pkg = tmp_path / "pkg"
    (pkg / "sub").mkdir(parents=True)
    (pkg / "__init__.py").write_text("from pkg.d import helper\n")
    (pkg / "a.py").write_text("from pkg import b\n")
    (pkg / "b.py").write_text("def f():\n    from pkg.a import thing\n    return thing\n")
    (pkg / "c.py").write_text("X = 1\n")
    (pkg / "d.py").write_text("from pkg import X_REEXPORTED\nhelper = 1\n")
    (pkg / "e.py").write_text("from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from pkg.a import t\n")
    (pkg / "sub" / "__init__.py").write_text("")
    (pkg / "sub" / "s.py").write_text("from .. import c\nfrom . import t\n")
    (pkg / "sub" / "t.py").write_text("")
    graph = import_graph(tmp_path, "pkg")
    assert graph["pkg.a"] == {"pkg.b"}
    assert graph["pkg.b"] == {"pkg.a"}                 # the deferred import counts
    assert graph["pkg.d"] == {"pkg"}                   # a re-exported name ties to the face
    assert graph["pkg.e"] == set()                     # TYPE_CHECKING only: no edge
    assert graph["pkg.sub.s"] == {"pkg.c", "pkg.sub.t"}   # relative imports resolved
    assert circles(graph) == [["pkg", "pkg.d"], ["pkg.a", "pkg.b"]]
    assert circles({"x": {"y"}, "y": set()}) == []


def test_driver_has_no_import_circle() -> None:
    graph = import_graph(ROOT)
    assert len(graph) > 50 and sum(map(len, graph.values())) > 100   # the whole package was read
    found = circles(graph)
    assert not found, "import circles:\n" + "\n".join(
        f"  {len(c)} modules: " + "; ".join(_ties(graph, c)) for c in found)


# ----------------------------------------------------------------------------- the order inside a study

#: statements a face may hold: it hands names on and declares, it computes nothing
_FACE_STATEMENTS = (ast.Import, ast.ImportFrom, ast.Assign, ast.AnnAssign, ast.Expr)


def is_face(path: Path) -> bool:
    """A module that only hands names on: imports, assignments, its docstring, ``if TYPE_CHECKING:``
    imports and a PEP 562 ``__getattr__``/``__dir__`` (names handed on on first use)."""
    for node in ast.parse(path.read_text()).body:
        if isinstance(node, ast.If) and _type_checking_only(node):
            continue
        if isinstance(node, ast.FunctionDef) and node.name in ("__getattr__", "__dir__"):
            continue
        if not isinstance(node, _FACE_STATEMENTS) or (isinstance(node, ast.Expr) and not isinstance(node.value, ast.Constant)):
            return False
    return True


def order_breaches(root: Path, package: str) -> list[str]:
    """Imports inside study package ``package`` (dotted, under ``root``) that break the layer order:
    a layer importing a later layer or a face, or a module of no layer that is no face."""
    graph = import_graph(root, package.split(".")[0])
    folder = root.joinpath(*package.split("."))
    mine = {m: g for m, g in graph.items() if m == package or m.startswith(package + ".")}
    rank = {layer: i for i, layer in enumerate(LAYERS)}
    found = []
    for module in sorted(mine):
        path = folder / "__init__.py" if module == package else folder / (module.rpartition(".")[2] + ".py")
        layer = None if module == package else layer_of(module)
        if layer is None and not is_face(path):
            found.append(f"{module}: neither a layer of {LAYERS} (or an extra named after one) nor a face")
            continue
        for target in sorted(t for t in mine[module] if t in mine):
            other = None if target == package else layer_of(target)
            if layer is None:
                continue                           # a face may hand on any layer's names
            if other is None:
                found.append(f"{module} -> {target}: a layer imports the package's face")
            elif rank[other] > rank[layer]:
                found.append(f"{module} -> {target}: {layer} imports the later layer {other}")
    return found


def test_the_order_check_sees_a_breach(tmp_path: Path) -> None:
    pkg = tmp_path / "driver" / "toy"
    pkg.mkdir(parents=True)
    (tmp_path / "driver" / "__init__.py").write_text("")
    (pkg / "__init__.py").write_text("from driver.toy._report import run\nfrom driver.toy import _faced as faced\n")
    (pkg / "_faced.py").write_text('"""A face."""\nfrom driver.toy._spec import SPEC as KEYS\n\n'
                                   "def __getattr__(name):\n    from driver.toy import _figures\n    return 1\n")
    (pkg / "_spec.py").write_text("from driver.toy._analysis import thing\nSPEC = 1\n")       # a later layer
    (pkg / "_analysis.py").write_text("thing = 1\n")
    (pkg / "_analysis_more.py").write_text("from driver.toy._analysis import thing\n")        # its own layer
    (pkg / "_figures.py").write_text("from driver.toy import _faced\n")                      # the face
    (pkg / "_report.py").write_text("from driver.toy._analysis_more import thing\nrun = 1\n")
    (pkg / "_helpers.py").write_text("def f():\n    return 1\n")                             # no layer, no face
    assert order_breaches(tmp_path, "driver.toy") == [
        "driver.toy._figures -> driver.toy._faced: a layer imports the package's face",
        f"driver.toy._helpers: neither a layer of {LAYERS} (or an extra named after one) nor a face",
        "driver.toy._spec -> driver.toy._analysis: _spec imports the later layer _analysis"]


@pytest.mark.parametrize("package", sorted(p for g, p in REGISTRY.items() if p == f"driver.{g}"))
def test_every_study_package_keeps_the_one_dependency_order(package: str) -> None:
    assert not order_breaches(ROOT, package)


def test_the_example_study_keeps_the_one_dependency_order() -> None:
    assert (ROOT / "tests" / "example_study" / "pendulum" / "__init__.py").is_file()
    assert not order_breaches(ROOT / "tests", "example_study.pendulum")

