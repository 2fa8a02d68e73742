"""PEP 517 build backend: meson-python, run with the meson and ninja of its own environment.

meson-python runs ``meson`` and ``ninja`` by name, so with ``--no-build-isolation`` it finds
them only when the environment's scripts folder is on ``PATH``: ``venv/bin/pip install
--no-build-isolation -e .`` from a shell where that venv is not activated fails with
``meson executable "meson" not found``.  When meson-python is imported from the interpreter's
own environment (``--no-build-isolation``: the build requirements were installed there), this
module puts that environment's scripts folder first on ``PATH``, then hands every hook to
meson-python unchanged.  Under build isolation meson-python comes from pip's temporary
environment, whose scripts folder pip has already put first: nothing is changed.  The editable
install records absolute paths of the tools it found, so later rebuilds on import need no
``PATH`` either.
"""
from __future__ import annotations

import os
import sysconfig
from pathlib import Path

import mesonpy
from mesonpy import (
    build_editable,
    build_sdist,
    build_wheel,
    get_requires_for_build_editable,
    get_requires_for_build_sdist,
    get_requires_for_build_wheel,
)

__all__ = ["build_editable", "build_sdist", "build_wheel", "get_requires_for_build_editable",
           "get_requires_for_build_sdist", "get_requires_for_build_wheel", "own_scripts_dir"]


def own_scripts_dir() -> str | None:
    """The interpreter environment's scripts folder when meson-python is installed in that
    environment (not in a build-isolation overlay); otherwise None."""
    here = Path(mesonpy.__file__).resolve()
    for key in ("purelib", "platlib"):
        site = Path(sysconfig.get_path(key)).resolve()
        if site in here.parents:
            return sysconfig.get_path("scripts")
    return None


_scripts = own_scripts_dir()
if _scripts is not None:
    os.environ["PATH"] = os.pathsep.join([_scripts, *(d for d in os.environ.get("PATH", "").split(os.pathsep) if d)])
