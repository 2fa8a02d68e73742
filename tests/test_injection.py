"""A deck is data, never code: every injection attempt is refused with exit 2 and runs nothing.

Each payload, if it were ever evaluated, would create a canary file; the test asserts the exit
status, a one-line deck error that names the key, and that the canary never exists.
"""
from __future__ import annotations

import pytest

from driver._cli import main

BASE = """&fourbar
  fixed_link = 12.0, crank = 2.0, coupler = 15.0, rocker = 9.0
  omega = 5.0, step_deg = 60
/
"""
SWEEP = "&sweep\n  key1 = 'fourbar.crank', values1 = 2, 3\n  {line}\n/\n"

# expressions of the sweep's keep filter and plot columns: {c} is the canary path
EXPRESSIONS = [
    '@os.system("touch {c}") == 1',
    '@time.sleep(30) is None',
    '__import__("os").system("touch {c}")',
    'os.system("touch {c}")',
    'open("{c}", "w")',
    'exec("open(\\"{c}\\", \\"w\\")")',
    'eval("1")',
    'compile("1", "x", "eval")',
    'getattr(os, "system")("touch {c}")',
    'globals()',
    'locals()["x"]',
    'vars()',
    'breakpoint()',
    '().__class__.__bases__[0].__subclasses__()',
    '"".__class__.__mro__[1].__subclasses__()',
    'rocker_swing_deg.__class__',
    'abs.__self__.open("{c}", "w")',
    'abs.__globals__',
    '[c for c in ().__class__.__base__.__subclasses__()]',
    '(lambda: open("{c}", "w"))()',
    'lambda x: x',
    '{{x for x in range(10)}}',
    '(x := 1)',
    'f"{{open(\'{c}\', \'w\')}}"',
    'rocker_swing_deg[0]',
    'rocker_swing_deg[::-1] > 0',
    'abs(rocker_swing_deg, key=open)',
    'abs(*[1])',
    'max(**{{"a": 1}})',
    '`__import__("os").system("touch {c}")`',
    '`rocker_swing_deg` @ 2',
    '__builtins__',
    '__builtins__.open("{c}", "w")',
    'rocker_swing_deg if open("{c}", "w") else 0',
    '\\u006fpen("{c}", "w")',
    'ｏｐｅｎ("{c}", "w")',
    'pd.read_csv("{c}")',
    'np.save("{c}", 1)',
    'import os',
    'rocker_swing_deg; open("{c}", "w")',
    'rocker_swing_deg > 60 or __import__("os")',
    'sqrt(rocker_swing_deg).real',
    'rocker_swing_deg > 60 and (yield)',
    'await rocker_swing_deg',
    '[1, 2]',
    '(1, 2)',
    '{{"a": 1}}',
    'rocker_swing_deg is None',
    'rocker_swing_deg in (1, 2)',
    '~meets_transmission_band',
    'rocker_swing_deg << 2',
    'no_such_column > 1',
    '1' * 2001,
    '(' * 300 + '1' + ')' * 300,
]

# other ways a deck might try to run code, connect somewhere or write elsewhere
DECKS = [
    BASE + "&sweep key1 = 'fourbar.crank', values1 = 2, scheduler = 'tcp://203.0.113.5:8786' /\n",
    BASE + "&sweep key1 = 'fourbar.crank', values1 = 2, SCHEDULER = 'tls://evil:1' /\n",
    BASE + "&sweep key1 = 'fourbar.crank', values1 = 2, scheduler = 'inproc://x' /\n",
    BASE + "&sweep key1 = 'fourbar.__class__', values1 = 2 /\n",
    BASE + "&sweep key1 = '__import__(\"os\").system', values1 = 'touch {c}' /\n",
    BASE + "&sweep key1 = 'fourbar.method', values1 = '$(touch {c})' /\n",
    BASE.replace("step_deg = 60", "step_deg = 60, method = '`touch {c}`'"),
    BASE.replace("step_deg = 60", "step_deg = 60, method = 'listing; touch {c}'"),
    BASE.replace("&fourbar", "&os"),
    BASE.replace("&fourbar", "&cli"),
    BASE.replace("&fourbar", "&runner"),
    BASE.replace("&fourbar", "&__init__"),
    BASE.replace("&fourbar", "&_kernels"),
    BASE.replace("&fourbar", "&sweep"),
    BASE.replace("omega = 5.0", "omega = __import__('os').system('touch {c}')"),
    BASE.replace("omega = 5.0", "omega = 5.0 / ; touch {c}"),
    BASE.replace("omega = 5.0", "omega%system = 'touch {c}'"),
    BASE.replace("omega = 5.0", "omega(1) = 5.0"),
]


def _run(tmp_path, text: str, name: str = "deck.dat") -> tuple[int, list[str], object]:
    canary = tmp_path / "canary"
    deck = tmp_path / name
    deck.write_text(text.replace("{c}", str(canary)).replace("{{", "{").replace("}}", "}"))
    out = tmp_path / "out"
    rc = main([str(deck), "-o", str(out), "-q", "-j", "1", "--plot"])
    return rc, out, canary


@pytest.mark.parametrize("payload", EXPRESSIONS)
@pytest.mark.parametrize("key", ["keep", "plot_y"])
def test_expression_injection_is_refused(payload, key, tmp_path, capsys):
    quoted = payload.replace("{c}", str(tmp_path / "canary"))
    # the payload is a Fortran string: double every quote character of its delimiter
    value = "'" + quoted.replace("'", "''") + "'"
    text = BASE + SWEEP.format(line=f"{key} = {value}")
    deck = tmp_path / "deck.dat"
    deck.write_text(text)
    out = tmp_path / "out"
    rc = main([str(deck), "-o", str(out), "-q", "-j", "1", "--plot"])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2, err
    assert len(err) == 1 and err[0].startswith(f"error: {deck}:"), err
    assert f"key '{key}'" in err[0] or "column" in err[0], err[0]
    assert not (tmp_path / "canary").exists()
    assert not out.exists()


@pytest.mark.parametrize("text", DECKS)
def test_deck_injection_is_refused(text, tmp_path, capsys):
    rc, out, canary = _run(tmp_path, text)
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2, err
    assert len(err) == 1 and err[0].startswith("error: "), err
    assert "Traceback" not in err[0]
    assert not canary.exists()
    assert not out.exists()


@pytest.mark.parametrize("name", ["..dat", "...dat", "....dat"])
def test_outputs_never_leave_outdir(name, tmp_path, capsys):
    parent = tmp_path / "parent"
    parent.mkdir()
    deck = parent / name
    deck.write_text(BASE)
    out = parent / "out"
    before = set(tmp_path.rglob("*"))
    rc = main([str(deck), "-o", str(out), "-q"])
    err = capsys.readouterr().err
    assert rc == 2 and "outside the output folder" in err and "rename the deck" in err
    assert set(tmp_path.rglob("*")) == before


def test_hidden_deck_name_writes_inside_outdir(tmp_path):
    deck = tmp_path / ".dat"
    deck.write_text(BASE)
    out = tmp_path / "out"
    assert main([str(deck), "-o", str(out), "-q"]) == 0
    assert [p.name for p in out.iterdir()] == [".dat.out"]


def test_scheduler_key_message_says_why_and_what_to_do(tmp_path, capsys):
    rc, out, _ = _run(tmp_path, DECKS[0])
    err = capsys.readouterr().err
    assert rc == 2
    assert "key 'scheduler'" in err and "deserialises" in err and "--scheduler" in err
    assert "DASK_SCHEDULER_ADDRESS" in err


def test_enough_attempts():
    assert 2 * len(EXPRESSIONS) + len(DECKS) + 4 >= 50
