"""Write each study's ``_kernels.pyi``: the type stub of its Fortran modules of the compiled extension.

f2py writes no stub, so without one every kernel call is ``Any`` to mypy and IDEs.  A study's
stub, ``driver/<study>/_kernels.pyi``, types the modules of the extension ``driver._kernels``
that belong to it -- the Fortran modules named after the study (``fourbar``, ``fourbar_summary``,
``fourbar_forces`` belong to ``&fourbar``; ``kinds`` and ``vecmath`` are shared building blocks
of no study) -- and the study's ``_kernel.py`` imports it for type checkers only::

    if TYPE_CHECKING:   # the study's modules of the extension, typed (tools/gen_kernel_stub.py)
        from driver.fourbar import _kernels
    else:
        from driver._fortran import _kernels

so a new study imports and runs before its stub exists, and no shared file lists its modules.
The stub is generated from the signatures f2py itself documents on each wrapper (the
``Parameters``/``Returns`` sections of ``_kernels.<module>.<routine>.__doc__``), so it says
exactly what the built module accepts: ``input float`` -> ``float``, ``input int`` -> ``int``,
``rank-N array('d')`` -> ``NDArray[np.float64]`` (``'i'`` -> ``np.int32``), optional arguments
get a default, several results a tuple.  Fortran module parameters (``st_ok`` ...) are 0-d
arrays, as f2py exposes them.

Run after adding a study's kernel or changing a kernel's interface (tests/test_kernel_stub.py
fails while a committed stub is stale)::

    .venv/bin/python tools/gen_kernel_stub.py            # every registered study with a Fortran kernel
    .venv/bin/python tools/gen_kernel_stub.py linkage    # one study
"""
from __future__ import annotations

import re
import sys
from pathlib import Path
from types import ModuleType

STUB = "_kernels.pyi"

_DTYPES = {"d": "np.float64", "i": "np.int32", "f": "np.float32", "l": "np.int64"}
_ENTRY = re.compile(r"^(\w+) : (.+)$")
_ARRAY = re.compile(r"^(?:input |in/output )?rank-(\d+) array\('(\w)'\) with bounds \((.*)\)$")


def _type(desc: str) -> str:
    """Python type of one f2py parameter/result description (``input rank-1 array('d') ...``)."""
    m = _ARRAY.match(desc)
    if m:
        return f"NDArray[{_DTYPES[m.group(2)]}]"
    base = desc.removeprefix("input ").removesuffix(", optional").strip()
    if base in ("float", "int", "complex", "string"):
        return {"string": "str"}.get(base, base)
    raise ValueError(f"an f2py description this generator does not know: {desc!r}")


def _sections(doc: str) -> tuple[str, dict[str, list[tuple[str, str]]]]:
    """The signature line and the named sections (Parameters, Other Parameters, Returns)."""
    lines = doc.splitlines()
    sections: dict[str, list[tuple[str, str]]] = {}
    current = None
    for i, line in enumerate(lines):
        if i + 1 < len(lines) and set(lines[i + 1]) == {"-"} and line.strip():
            current = line.strip()
            sections[current] = []
            continue
        m = _ENTRY.match(line)
        if m and current is not None:
            sections[current].append((m.group(1), m.group(2)))
    return lines[0].strip(), sections


def _routine(name: str, doc: str) -> list[str]:
    """The stub lines of one wrapped routine (a static method of its module's class)."""
    signature, sec = _sections(doc)
    args = [f"{a}: {_type(d)}" for a, d in sec.get("Parameters", [])]
    args += [f"{a}: {_type(d)} = ..." for a, d in sec.get("Other Parameters", [])]
    results = [(r, _type(d)) for r, d in sec.get("Returns", [])]
    if not results:
        ret = "None"
    elif len(results) == 1:
        ret = results[0][1]
    else:
        ret = f"tuple[{', '.join(t for _, t in results)}]"
    shapes = [f"{r}({m.group(3)})" for r, d in sec.get("Returns", []) if (m := _ARRAY.match(d))]
    head = f"    def {name}({', '.join(args)}) -> {ret}:"
    out = ["    @staticmethod"]
    if len(head) <= 120:
        out.append(head)
    else:
        out += [f"    def {name}("] + [f"        {a}," for a in args] + [f"    ) -> {ret}:"]
    note = f"``{signature}``" + (f"; shapes {', '.join(shapes)}" if shapes else "")
    out += [f'        """{note}"""', "        ..."]
    return out


def fortran_modules(kernels: ModuleType) -> list[str]:
    """Every Fortran module of the extension, by name."""
    return sorted(n for n in dir(kernels) if type(getattr(kernels, n)).__name__ == "fortran")


def owner(module: str, studies: list[str]) -> str | None:
    """The study a Fortran module belongs to: the longest study name that is the module's name or
    its prefix before an underscore (``fourbar_forces`` -> ``fourbar``); None for a shared
    building block (``kinds``, ``vecmath``)."""
    mine = [s for s in studies if module == s or module.startswith(s + "_")]
    return max(mine, key=len) if mine else None


def render(kernels: ModuleType, modules: list[str], study: str) -> str:
    """The stub text of study ``study``: its Fortran ``modules`` of the imported extension ``kernels``."""
    out = [f'"""Type stub of the Fortran modules of ``&{study}`` in the f2py extension ``driver._kernels`` (one class',
           "per Fortran module, bound to the module's name).  GENERATED by tools/gen_kernel_stub.py from the built",
           'module\'s own f2py signatures: do not edit; regenerate after a kernel interface changes."""',
           "import numpy as np",
           "from numpy.typing import NDArray"]
    for mname in modules:
        mod = getattr(kernels, mname)
        out += ["", f"class _{mname}:", f'    """Fortran module ``{mname}`` (fortran/*.f90)."""']
        for attr in sorted(dir(mod)):
            if attr.startswith("_"):
                continue
            value = getattr(mod, attr)
            if type(value).__name__ == "fortran":
                out += _routine(attr, value.__doc__)
            elif hasattr(value, "dtype"):
                dt = {"int32": "np.int32", "float64": "np.float64"}[str(value.dtype)]
                out.append(f"    {attr}: NDArray[{dt}]")
            else:
                raise TypeError(f"_kernels.{mname}.{attr}: {type(value).__name__} has no stub rule")
        out.append("")
    out.append("")
    out += [f"{m}: _{m}" for m in modules]
    return "\n".join(out) + "\n"


def stubs(kernels: ModuleType, groups: list[str] | None = None) -> dict[Path, str]:
    """{path of the study's ``_kernels.pyi``: its text} for the registered studies ``groups``
    (default every one) that have Fortran modules in ``kernels``."""
    from driver._study import load_study, study_names
    names = study_names()
    out = {}
    for group in groups or names:
        study = load_study(group)
        if study is None:
            raise SystemExit(f"gen_kernel_stub: &{group} is not a registered study (driver._study.REGISTRY)")
        modules = [m for m in fortran_modules(kernels) if owner(m, names) == group]
        if modules:
            out[Path(str(study.module.__file__)).parent / STUB] = render(kernels, modules, group)
    return out


def main(argv: list[str] | None = None) -> int:
    from driver._fortran import _kernels
    for path, text in stubs(_kernels, list(sys.argv[1:] if argv is None else argv)).items():
        path.write_text(text)
        print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
