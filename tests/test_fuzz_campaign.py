"""The deck fuzz campaign (tests/fuzz_decks.py) as a slow test: 10 000 malformed decks of every
group, under a 4 GiB address-space limit, each ending in exit 0/1/2 with a message naming the
deck, no traceback, no NaN/inf/**** in a table, nothing written for bad input."""
from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

from conftest import ROOT

COUNT = int(os.environ.get("FUZZ_DECKS", "10000"))


@pytest.mark.slow
def test_fuzz_campaign():
    p = subprocess.run([sys.executable, str(ROOT / "tests" / "fuzz_decks.py"), "--count", str(COUNT),
                        "--seed", "0", "--memory", "4G", "--json"],
                       capture_output=True, text=True, cwd=ROOT, timeout=3600,
                       env={**os.environ, "OPENBLAS_NUM_THREADS": "1"})
    report = json.loads(p.stdout.strip().splitlines()[-1])
    assert report["problems"] == 0, json.dumps(report["first_problems"], indent=1)
    assert p.returncode == 0, p.stderr[-2000:]
    assert report["decks"] == COUNT
    # both sides exercised: decks that run and decks refused as bad input
    assert report["outcomes"].get("0", 0) > COUNT // 20 and report["outcomes"].get("2", 0) > COUNT // 2
