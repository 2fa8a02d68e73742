"""Packaging metadata, the single version source, shipped example decks, the portable kernel build."""
from __future__ import annotations

import importlib.metadata
import re
import shutil
import subprocess
import sys
import tomllib

import pytest

import driver
from conftest import INPUTS, ROOT
from driver import _example_decks as example_decks

PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())


def run(args, cwd):
    return subprocess.run([sys.executable, "-m", "driver", *args], cwd=cwd, capture_output=True, text=True)


def test_version_has_one_source():
    meson_version = re.search(r"project\([^)]*?[ (,]version:\s*'([^']+)'", (ROOT / "meson.build").read_text()).group(1)
    assert "version" not in PYPROJECT["project"] and "version" in PYPROJECT["project"]["dynamic"]
    assert driver.__version__ == meson_version == importlib.metadata.version("mechanism-driver")
    assert not re.search(r'__version__ = "\d', (ROOT / "driver" / "__init__.py").read_text())
    assert f"## {meson_version}" in (ROOT / "CHANGELOG.md").read_text()


def test_metadata_licence_authors_urls_classifiers():
    project = PYPROJECT["project"]
    assert project["name"] == "mechanism-driver"
    assert (ROOT / "LICENSE").read_text().startswith("MIT License")
    assert "License :: OSI Approved :: MIT License" in project["classifiers"]
    assert project["authors"] and {"Homepage", "Documentation", "Source", "Issues"} <= set(project["urls"])
    meta = importlib.metadata.metadata("mechanism-driver")
    assert meta["Name"] == "mechanism-driver" and meta.get_all("Project-URL")


def test_optional_features_are_extras_not_requirements():
    deps = " ".join(PYPROJECT["project"]["dependencies"])
    for module in ("matplotlib", "pyarrow", "dask"):
        assert module not in deps
    extras = PYPROJECT["project"]["optional-dependencies"]
    assert "matplotlib" in extras["plot"][0] and "pyarrow" in extras["parquet"][0] and "dask" in extras["dask"][0]
    assert extras["all"] == ["mechanism-driver[plot,parquet,dask]"]
    assert "mechanism-driver[all]" in extras["test"]
    assert '".[all,test]"' in (ROOT / ".ci" / "setup").read_text()


def test_kernels_do_not_call_libmvec():
    """glibc's vector sin/cos (libmvec) differ in the last bits between vector widths: a native build
    using them would not reproduce the portable build.  -nostdinc keeps every loop off them."""
    nm = shutil.which("nm")
    if nm is None:
        pytest.skip("binutils' nm not installed")
    from driver import _kernels
    symbols = subprocess.run([nm, "-D", "--undefined-only", _kernels.__file__], capture_output=True,
                             text=True, check=True).stdout
    assert "_ZGV" not in symbols and "libmvec" not in symbols
    assert "sin" in symbols or "cos" in symbols   # scalar libm calls are there: the check looks at the right table


def test_examples_are_the_repository_decks(tmp_path):
    assert example_decks.list_examples() == sorted(p.stem for p in INPUTS.glob("*.dat"))
    target = example_decks.copy_example("crank5", tmp_path)
    assert target.read_bytes() == (INPUTS / "crank5.dat").read_bytes()
    with pytest.raises(FileExistsError):
        example_decks.copy_example("crank5.dat", tmp_path)
    with pytest.raises(KeyError, match="crank5_exact"):
        example_decks.example_path("../meson")
    assert "crank 5" in example_decks.describe("crank5")


def test_example_command_line(tmp_path):
    listing = run(["--examples"], tmp_path)
    assert listing.returncode == 0 and "crank5_exact" in listing.stdout and "robust_example" in listing.stdout
    res = run(["--example", "crank5", "--example", "ujoint_option1"], tmp_path)
    assert res.returncode == 0, res.stderr
    assert (tmp_path / "crank5.dat").read_text() == (INPUTS / "crank5.dat").read_text()
    again = run(["--example", "crank5"], tmp_path)
    assert again.returncode == 1 and "not overwritten" in again.stderr
    bad = run(["--example", "crank55"], tmp_path)
    assert bad.returncode == 2 and "choose one of" in bad.stderr and "Traceback" not in bad.stderr
    ran = run(["crank5.dat", "-q"], tmp_path)
    assert ran.returncode == 0, ran.stderr
    assert (tmp_path / "outputs" / "crank5.out").read_text() == (ROOT / "outputs" / "crank5.out").read_text()


def test_study_names_without_import_match_the_studies():
    from driver._runner import available_studies
    from driver._study import study_names
    assert study_names() == sorted(available_studies())


def test_build_backend_finds_meson_and_ninja_of_its_own_environment_without_activation():
    """venv/bin/pip install --no-build-isolation -e . from a shell where the venv is not activated:
    the project's backend (backend/mesonpy_venv.py) must find this environment's meson and ninja,
    which a bare meson-python looks up on PATH only.  (.ci/clean-clone runs the real install.)"""
    import os
    import sysconfig
    scripts = sysconfig.get_path("scripts")
    if not (os.path.exists(os.path.join(scripts, "meson")) and os.path.exists(os.path.join(scripts, "ninja"))):
        pytest.skip("meson/ninja are not installed in this environment (bash .ci/setup installs them)")
    probe = ("import shutil, sys; sys.path.insert(0, 'backend'); before = shutil.which('meson'); "
             "import mesonpy_venv; print(before, shutil.which('meson'), shutil.which('ninja'))")
    env = {k: v for k, v in os.environ.items() if k not in ("VIRTUAL_ENV",)}
    env["PATH"] = "/usr/bin:/bin"
    out = subprocess.run([sys.executable, "-c", probe], cwd=ROOT, env=env, capture_output=True, text=True,
                         check=True).stdout.split()
    meson_before, meson_after, ninja_after = out
    assert meson_before == "None" or not meson_before.startswith(scripts)   # PATH alone would not find it
    assert meson_after == os.path.join(scripts, "meson") and ninja_after == os.path.join(scripts, "ninja")
    assert PYPROJECT["build-system"]["build-backend"] == "mesonpy_venv"
    assert PYPROJECT["build-system"]["backend-path"] == ["backend"]


def test_kernel_fingerprint_covers_every_kernel_wrapper():
    """tests/kernel_fingerprint.py (the native-vs-portable bit comparison of test_install) calls every
    public wrapper of every study's kernel module (``Study.kernel``): a new kernel cannot escape the
    CPU-independence check."""
    import inspect

    from driver._study import registered
    wrappers = [f"{name}_kernel.{n}(" for name, s in registered().items() if s.kernel is not None
                for n in s.kernel.__all__ if inspect.isfunction(getattr(s.kernel, n))]
    source = (ROOT / "tests" / "kernel_fingerprint.py").read_text()
    assert len(wrappers) >= 20
    assert [w for w in wrappers if w not in source] == []
