"""ruff and mypy in CI: zero findings.

ruff checks the whole repository (``ruff check .`` from the root: the package, tools, tests,
bench, examples, docs/gen_keys.py, the build backend), mypy its configured files (``driver``
and ``tools``).  Both are configured in pyproject.toml and pinned in its ``lint`` extra, so a
new release cannot change the verdict unannounced (docs/typing.md).  A failure lists the
findings themselves, one ``file:line: code message`` per line.  Each tool is first shown a
known mistake, so that a gate that checks nothing (a broken configuration, an excluded tree)
cannot pass.
"""
from __future__ import annotations

import importlib.metadata
import json
import re
import subprocess
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _run(args: list[str], timeout: float, **kw) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", *args], cwd=ROOT, capture_output=True, text=True,
                          timeout=timeout, **kw)


def test_the_installed_tools_are_the_pinned_ones():
    lint = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]["lint"]
    pins = dict(req.split("==") for req in lint)
    assert len(pins) == len(lint) >= 5, lint   # every tool and stub package pinned exactly
    installed = {name: importlib.metadata.version(name) for name in pins}
    assert installed == pins, "the lint tools installed are not the pinned ones: run bash .ci/setup"


def test_ruff_sees_a_known_mistake():
    proc = _run(["ruff", "check", "--no-cache", "--output-format", "json", "--stdin-filename", "tests/canary.py", "-"],
                60, input="import os\n")
    assert proc.returncode == 1, proc.stderr
    assert [d["code"] for d in json.loads(proc.stdout)] == ["F401"]


def test_ruff_finds_nothing_in_the_repository():
    proc = _run(["ruff", "check", "--no-cache", "--output-format", "json", "."], 600)
    assert proc.returncode in (0, 1) and not proc.stderr.strip(), proc.stderr   # 2: ruff itself failed
    findings = [f"{Path(d['filename']).resolve().relative_to(ROOT).as_posix()}:{d['location']['row']}: "
                f"{d['code']} {d['message']}" for d in json.loads(proc.stdout)]
    assert not findings, f"ruff: {len(findings)} finding(s):\n" + "\n".join(findings)
    assert proc.returncode == 0, proc.stdout


def test_mypy_sees_a_known_mistake(tmp_path):
    canary = tmp_path / "canary.py"
    canary.write_text("x: int = 'one'\n")
    proc = _run(["mypy", "--cache-dir", str(tmp_path / "cache"), str(canary)], 300)
    assert proc.returncode == 1 and "[assignment]" in proc.stdout, proc.stdout + proc.stderr


def test_mypy_finds_nothing_in_its_files(tmp_path):
    proc = _run(["mypy", "--cache-dir", str(tmp_path / "cache")], 900)
    errors = [line for line in proc.stdout.splitlines() if re.match(r"^\S+\.pyi?:\d+: error: ", line)]
    assert not errors, f"mypy: {len(errors)} error(s):\n" + "\n".join(errors)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    checked = re.search(r"^Success: no issues found in (\d+) source files$", proc.stdout, re.M)
    assert checked and int(checked.group(1)) > 50, proc.stdout   # driver/ and tools/: ~90 files
