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
"""
from __future__ import annotations

import ast
from pathlib import Path

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
