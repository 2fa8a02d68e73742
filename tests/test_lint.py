"""ruff and mypy in CI, as a ratchet: no file may gain a finding.

Both tools are configured in pyproject.toml ([tool.ruff], [tool.mypy]; docs/typing.md).  Most
of the package is clean; the findings left (modules the study-layout and outcome work had just
moved when the gate came in) are listed per file in tests/lint_baseline.json.  A file not
listed must stay clean; a listed file may not get worse.  When a file is fixed, lower (or drop)
its entry so that it cannot slip back.
"""
from __future__ import annotations

import json
import re
import subprocess
import sys
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BASELINE = json.loads((ROOT / "tests" / "lint_baseline.json").read_text())


def _check(tool: str, found: Counter) -> None:
    allowed = BASELINE[tool]
    worse = {f: (n, allowed.get(f, 0)) for f, n in found.items() if n > allowed.get(f, 0)}
    assert not worse, f"{tool}: new findings (file: found, allowed): {worse}"


def test_ruff_adds_no_finding():
    proc = subprocess.run([sys.executable, "-m", "ruff", "check", "--no-cache", "--output-format", "json",
                           "driver", "tools"], cwd=ROOT, capture_output=True, text=True, timeout=600)
    found = Counter(Path(d["filename"]).resolve().relative_to(ROOT).as_posix() for d in json.loads(proc.stdout))
    _check("ruff", found)


def test_mypy_adds_no_error(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "mypy", "--cache-dir", str(tmp_path / "cache")],
                          cwd=ROOT, capture_output=True, text=True, timeout=900)
    found = Counter(m.group(1) for m in re.finditer(r"^([^:\s]+\.pyi?):\d+: error:", proc.stdout, re.M))
    assert "error: " not in proc.stderr, proc.stderr
    _check("mypy", found)
