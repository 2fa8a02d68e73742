"""Mutated decks never crash: every outcome is success, a deck error (exit 2) or a reported run
failure in words (exit 1, e.g. a buckled case) -- never a traceback, never NaN or **** in a table."""
from __future__ import annotations

import re

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from conftest import INPUTS
from driver._cli import main

DECKS = ["crank5.dat", "crank5_exact.dat", "nongrashof.dat", "crank5_terminal.dat",
         "manipulator_case1_exact.dat", "manipulator_case2_report.dat", "robust_example.dat",
         "ujoint_analyse.dat"]
VALUES = ["0", "-1", "1e300", "-1e300", "1e-300", "'x'", "abc", "", ".true.", "1, 2", "360", "99999", "-0.5"]


@pytest.mark.slow
@settings(max_examples=150, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(deck=st.sampled_from(DECKS), line=st.integers(0, 200), value=st.sampled_from(VALUES),
       delete=st.booleans(), data=st.data())
def test_mutated_deck_never_crashes(tmp_path, capsys, deck, line, value, delete, data):
    lines = (INPUTS / deck).read_text().splitlines()
    k = line % len(lines)
    keys = list(re.finditer(r"\w+\s*=\s*", lines[k]))
    if delete or not keys:
        del lines[k]
    else:
        m = data.draw(st.sampled_from(keys))
        rest = lines[k][m.end():]
        tail = re.match(r"[^,!]*(.*)", rest).group(1)
        lines[k] = lines[k][:m.end()] + value + tail
    path = tmp_path / deck
    path.write_text("\n".join(lines) + "\n")
    out = tmp_path / "out"
    rc = main([str(path), "-o", str(out), "-q"])
    err = capsys.readouterr().err
    assert rc in (0, 1, 2)
    assert "Traceback" not in err and "run failed" not in err, err
    for f in out.glob("**/*.out") if out.exists() else []:
        assert not re.search(r"(^|[^a-z])nan([^a-z]|$)|\*\*\*\*", f.read_text(), re.I), f.name
