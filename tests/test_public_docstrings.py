"""Every public name has a numpydoc docstring, and each study's ``run`` states every key's unit.

The public namespace is derived, never listed: ``driver.__all__``, the ``__all__`` of every
registered study (``driver.studies()``), of every engine package (``driver._dispatch.ENGINES``:
sweep, optimize, synthesis) and of :mod:`driver._outcome` (the outcome types the API returns),
recursing into the modules those ``__all__`` export (``driver.fourbar._forces``, the kernel
wrappers).  Each function and class found there, and each public method and property a public
class defines, is validated with :func:`numpydoc.validate.validate`.  A new public name without
a docstring (GL08) fails here.  Public data (``SPEC``, ``STUDY``, tables of constants) has no
docstring of its own and is described by the ``#:`` comment above it; it is not validated.

Checks enforced (:data:`CHECKS`):

* GL02, GL03, GL05-GL10: the docstring exists (GL08) and is well formed (closing quotes,
  blank lines, indentation, known sections in numpydoc order);
* SS01-SS06: a one-line summary, capitalised, ending in a period, imperative ("Return", not
  "Returns"), not naming the function;
* PR01-PR10: every parameter documented, none unknown, in signature order, each with a type
  and a capitalised description ending in a period.  For a class the constructor's
  parameters may be documented under Parameters or Attributes (a dataclass's fields are
  both: SciPy's ``OptimizeResult`` lists them under Attributes); an enum has no constructor
  to document;
* RT01-RT05, YD01: what a function returns or yields is documented, with a description.

Left out, and why: GL01 (the house style opens the text on the quotes' line; PEP 257 allows
both), ES01 (a one-line docstring is complete for a property or a small function), SA01-SA04
(See Also is optional) and EX01 (examples where they help, not everywhere).  The examples
that exist are run as doctests here, so they cannot rot.

Units: the truth is each study's SPEC (the key table the deck reader validates against,
printed in docs/<study>.md).  The Parameters entry of every key of ``driver.<study>.run``
must carry that unit, in brackets (``[rad/s]``, ``[dimensionless]``).
"""
from __future__ import annotations

import doctest
import enum
import importlib
import inspect
import types
from pathlib import Path

import numpydoc.docscrape as docscrape
import numpydoc.validate as numpydoc_validate
import pytest

ROOT = Path(__file__).resolve().parents[1]

#: the numpydoc checks enforced (see the module docstring for those left out and why)
CHECKS = frozenset({"GL02", "GL03", "GL05", "GL06", "GL07", "GL08", "GL09", "GL10",
                    "SS01", "SS02", "SS03", "SS04", "SS05", "SS06",
                    "PR01", "PR02", "PR03", "PR04", "PR05", "PR06", "PR07", "PR08", "PR09", "PR10",
                    "RT01", "RT02", "RT03", "RT04", "RT05", "YD01"})


def _roots() -> list[str]:
    """The public modules whose ``__all__`` make the public namespace (derived, not listed)."""
    import driver
    from driver._dispatch import ENGINES
    return ["driver", "driver._outcome", *(f"driver.{s}" for s in driver.studies()),
            *(f"driver.{e}" for e in ENGINES)]


def _is_documentable(obj: object) -> bool:
    return inspect.isclass(obj) or inspect.isroutine(obj) or (callable(obj) and hasattr(obj, "__wrapped__"))


def public_names() -> dict[str, object]:
    """Dotted name -> object of every public function, class, method and property (first path wins)."""
    names: dict[str, object] = {}
    seen: set[int] = set()
    todo = [(m, importlib.import_module(m)) for m in _roots()]
    done: set[str] = set()
    while todo:
        path, module = todo.pop(0)
        if module.__name__ in done:
            continue
        done.add(module.__name__)
        for name in module.__all__:
            obj = getattr(module, name)
            if isinstance(obj, types.ModuleType):
                if obj.__name__.startswith("driver.") and hasattr(obj, "__all__"):
                    todo.append((f"{path}.{name}", obj))
                continue
            if not _is_documentable(obj) or id(obj) in seen:
                continue
            seen.add(id(obj))
            names[f"{path}.{name}"] = obj
            if inspect.isclass(obj) and not issubclass(obj, enum.Enum):
                for attr, value in vars(obj).items():
                    if attr.startswith("_") or id(value) in seen:
                        continue
                    if isinstance(value, (property, staticmethod, classmethod)) or inspect.isfunction(value):
                        seen.add(id(value))
                        names[f"{path}.{name}.{attr}"] = value
    return names


PUBLIC = public_names()


def _class_parameters_documented(name: str, cls: type) -> list[str]:
    """PR01/PR02 for a class: constructor parameters under Parameters or Attributes (its own or a base's)."""
    if issubclass(cls, enum.Enum):
        return []
    try:
        sig = inspect.signature(cls)
    except (TypeError, ValueError):
        return []
    wanted = [p for p, v in sig.parameters.items() if v.kind not in (v.VAR_POSITIONAL, v.VAR_KEYWORD)]
    doc = docscrape.ClassDoc(cls, config={"show_class_members": False})
    documented = set()
    for base in cls.__mro__[:-1]:   # a field a base class declares is documented there
        base_doc = doc if base is cls else docscrape.ClassDoc(base, config={"show_class_members": False})
        documented |= {n.strip().lstrip("*") for entry in base_doc["Parameters"] + base_doc["Attributes"]
                       for n in entry.name.split(",")}
    errors = [f"PR01 class parameter {p!r} not documented (Parameters or Attributes)"
              for p in wanted if p not in documented]
    errors += [f"PR02 unknown parameter {n.strip()!r}" for entry in doc["Parameters"] for n in entry.name.split(",")
               if n.strip().lstrip("*") not in sig.parameters]
    return errors


def problems(name: str) -> list[str]:
    """The enforced numpydoc findings of public ``name`` (empty: it passes)."""
    obj = PUBLIC[name]
    result = numpydoc_validate.validate(numpydoc_validate.get_doc_object(obj))
    codes = CHECKS - {"PR01", "PR02"} if inspect.isclass(obj) else CHECKS
    found = [f"{code} {message}" for code, message in result["errors"] if code in codes]
    if inspect.isclass(obj):
        found += _class_parameters_documented(name, obj)
    return found


def test_the_public_namespace_is_found():
    """The walk reaches what the API documents (a walk that finds nothing would pass anything)."""
    for name in ("driver.run", "driver.run_sweep", "driver.write", "driver.keys", "driver.Result",
                 "driver.Result.figure", "driver.DeckError", "driver.ExitCode", "driver.compare", "driver.read_deck",
                 "driver.fourbar.run", "driver.fourbar.assembly_intervals", "driver.optimize.optimize"):
        assert name in PUBLIC, name
    assert len(PUBLIC) > 100


@pytest.mark.parametrize("name", sorted(PUBLIC))
def test_public_docstring_is_valid_numpydoc(name):
    found = problems(name)
    assert not found, f"{name}:\n  " + "\n  ".join(found)


def test_a_bad_docstring_fails():
    """The check can fail: a function with a summary on two lines and an undocumented parameter."""
    def bad(crank: float) -> float:
        """returns the crank
        length."""
        return crank
    PUBLIC["bad"] = bad
    try:
        codes = {p.split()[0] for p in problems("bad")}
    finally:
        del PUBLIC["bad"]
    assert {"SS02", "SS06", "PR01", "RT01"} <= codes


def _study_keys():
    import driver
    from driver._study import load_study
    return [(group, name, key) for group in driver.studies()
            for name, key in load_study(group).spec.keys.items()]


@pytest.mark.parametrize("group,name,key", _study_keys(), ids=lambda v: v if isinstance(v, str) else "")
def test_study_run_states_each_key_unit(group, name, key):
    """Each key of ``driver.<study>.run`` is documented with the SPEC's unit (and only then with one)."""
    import driver
    from driver._signatures import unit_text
    entries = {p.name: " ".join(p.desc) for p in docscrape.FunctionDoc(getattr(driver, group).run)["Parameters"]}
    assert name in entries, f"{group}.run documents no key {name!r}"
    if key.units:
        assert unit_text(key.units) in entries[name], (group, name, key.units, entries[name])
    else:
        assert "[" not in entries[name].split("(")[0] or "default" in entries[name], (group, name, entries[name])


def test_unit_words():
    from driver._signatures import unit_text
    assert unit_text("rad/s") == "[rad/s]"
    assert unit_text("1") == unit_text("-") == "[dimensionless]"
    assert unit_text("") == ""


@pytest.mark.parametrize("name", sorted(n for n, o in PUBLIC.items() if ">>>" in (inspect.getdoc(o) or "")))
def test_docstring_examples_run(name, monkeypatch, tmp_path):
    """The Examples sections are doctests: they run and print what they say."""
    monkeypatch.chdir(ROOT)
    obj = PUBLIC[name]
    finder = doctest.DocTestFinder(recurse=False)
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    for test in finder.find(obj, name, globs={"tmp_path": tmp_path}):
        runner.run(test)
    assert runner.failures == 0, f"{name}: {runner.failures} example(s) failed"
