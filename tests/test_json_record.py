"""``--json``: one record schema for every engine (docs/json.md, driver/record.schema.json).

Every shipped deck is run once with ``--json`` and its ``<stem>.json`` is validated against the
shipped JSON Schema by ``jsonschema`` (the test extra); so are the ``--compare --json`` lines.
Beyond the schema: strict JSON (no NaN or Infinity token), the same top-level keys in the same
order for every engine, the engine the deck's groups choose, ``ok`` iff exit code 0, every file
listed exists beside the record, and the command line's exit status is the worst record's.  The
schema itself is shown to refuse what it must (a missing key, a second section, a bad level).
"""
from __future__ import annotations

import copy
import json
import math
import os
import subprocess
import sys

import pytest

from conftest import INPUTS, ROOT

jsonschema = pytest.importorskip("jsonschema")
pytest.importorskip("pyarrow")

HEAD = ["engine", "study", "name", "deck", "ok", "exit_code", "messages", "summary", "files"]
DECKS = sorted(INPUTS.glob("*.dat"))


def _strict(text: str) -> dict:
    """The record parsed as strict JSON: NaN, Infinity and -Infinity are refused."""
    def refuse(token: str) -> None:
        raise ValueError(f"not strict JSON: {token}")
    return json.loads(text, parse_constant=refuse)


@pytest.fixture(scope="module")
def validator():
    from driver._record import SCHEMA
    assert SCHEMA.parent == ROOT / "driver"   # shipped inside the package
    schema = json.loads(SCHEMA.read_text())
    jsonschema.Draft202012Validator.check_schema(schema)
    return jsonschema.Draft202012Validator(schema)


@pytest.fixture(scope="module")
def records(tmp_path_factory):
    out = tmp_path_factory.mktemp("json")
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.run([sys.executable, "-m", "driver", *map(str, DECKS), "--json", "-q", "-o", str(out)],
                          capture_output=True, text=True, env=env, timeout=1800, cwd=ROOT)
    return out, proc


@pytest.mark.parametrize("deck", DECKS, ids=lambda p: p.stem)
def test_every_shipped_deck_writes_a_valid_record(records, validator, deck):
    from driver._deck import read_deck
    from driver._dispatch import engine_of
    out, _ = records
    path = out / f"{deck.stem}.json"
    rec = _strict(path.read_text())
    errors = sorted(validator.iter_errors(rec), key=lambda e: list(e.path))
    assert not errors, [f"{list(e.path)}: {e.message}" for e in errors[:5]]
    engine = {"study": "run"}.get(engine_of(read_deck(deck)), engine_of(read_deck(deck)))
    assert list(rec) == [*HEAD, engine] and rec["engine"] == engine
    assert rec["ok"] == (rec["exit_code"] == 0)
    assert rec["name"] == deck.stem and rec["deck"].endswith(deck.name)
    for f in rec["files"]:
        assert (out / f).is_file(), f
    assert f"{deck.stem}.json" not in rec["files"]
    for value in rec["summary"].values():
        assert not isinstance(value, float) or math.isfinite(value)


def test_the_exit_status_is_the_worst_record(records):
    out, proc = records
    codes = [_strict((out / f"{d.stem}.json").read_text())["exit_code"] for d in DECKS]
    assert proc.returncode == max(codes), proc.stderr[-2000:]


def test_records_hold_what_the_engines_computed(records):
    """A few values against their independent truth: the four-bar's transmission angle by the
    cosine rule, the sweep's swept values, the optimum's equality constraint recomputed."""
    out, _ = records
    rec = _strict((out / "crank5_exact.json").read_text())
    mu = lambda d2: math.degrees(math.acos((15.0**2 + 9.0**2 - d2) / (2 * 15.0 * 9.0)))
    assert rec["summary"]["mu_min_deg"] == pytest.approx(mu(49.0), abs=1e-9)
    assert rec["run"]["failure"] is None and "crank5_exact.out" in rec["files"]
    sw = _strict((out / "fourbar_paper_sweep.json").read_text())
    assert sw["sweep"]["swept_keys"] == ["fourbar.crank"] and sw["sweep"]["rows"] == 4
    assert sw["summary"]["cases"] == 4 and sw["summary"]["ok"] + sw["summary"]["failed"] == 4
    opt = _strict((out / "optimize_manipulator_torque.json").read_text())
    l1, l2 = opt["optimize"]["x"]
    eq = opt["optimize"]["constraints"][1]
    assert eq["kind"] == "equality" and eq["value"] == pytest.approx(l1 * l1 + l2 * l2, rel=1e-12)
    assert opt["summary"]["manipulator.designs_l1"] == l1 and opt["summary"]["objective"] == opt["optimize"]["fun"]


def test_compare_json_lines(validator, tmp_path):
    """--compare --json: one record per deck on stdout, a deck with bad input among them."""
    bad = tmp_path / "bad.dat"
    bad.write_text("&fourbar\n  crank = -5\n/\n")
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    decks = [INPUTS / "crank5.dat", INPUTS / "fourbar_paper_sweep.dat", bad]
    proc = subprocess.run([sys.executable, "-m", "driver", "--compare", "--json", *map(str, decks)],
                          capture_output=True, text=True, env=env, timeout=600, cwd=ROOT)
    lines = proc.stdout.splitlines()
    assert len(lines) == 3 and proc.returncode == 2
    recs = [_strict(line) for line in lines]
    for rec in recs:
        assert not list(validator.iter_errors(rec)), rec
        assert list(rec) == [*HEAD, "compare"] and rec["files"] == []
    crank5, sweep, broken = recs
    from driver._compare import compare
    frame = compare(INPUTS / "crank5.dat")
    assert crank5["summary"]["cells"] == len(frame) and crank5["ok"] and crank5["study"] == "fourbar"
    assert sweep["summary"] == {"cells": 0} and sweep["study"] is None
    assert broken["exit_code"] == 2 and broken["compare"] is None and broken["messages"][0]["level"] == "error"


def test_the_schema_refuses_what_it_must(validator):
    rec = {"engine": "run", "study": "fourbar", "name": "x", "deck": "x.dat", "ok": True, "exit_code": 0,
           "messages": [{"level": "warning", "text": "w"}], "summary": {"a_deg": 1.0, "b": None}, "files": ["x.out"],
           "run": {"failure": None, "warnings": ["w"], "figures": []}}
    assert validator.is_valid(rec)
    broken = []
    for change in (lambda r: r.pop("files"), lambda r: r.pop("run"), lambda r: r.update(sweep=r["run"]),
                   lambda r: r["messages"].append({"level": "note", "text": "?"}),
                   lambda r: r["summary"].update(nested={"no": 1}), lambda r: r.update(exit_code=3),
                   lambda r: r.update(engine="optimise")):
        r = copy.deepcopy(rec)
        change(r)
        broken.append(validator.is_valid(r))
    assert broken == [False] * 7
