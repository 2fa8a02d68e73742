"""Grammar-aware fuzzing of the input boundary (issue 23), with independent oracles.

Hypothesis builds number spellings, repeat counts, expressions over typed columns and
titles from small grammars that mix what Fortran list-directed input reads with what it does
not (kind suffixes, arithmetic, doubled repeat counts, non-ASCII digits, hex, bad exponents).
Each property compares the tool with an oracle written here, apart from ``driver._deck`` and
``driver._expr``: a character-by-character scanner of the Fortran number syntax, and a type
rule for the expression language.  Bounded: a few hundred examples, seconds in all.
"""
from __future__ import annotations

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from driver._deck import DeckError, RawGroup, read_deck, validate
from driver._expr import ExprError, parse
from fuzz_decks import fortran_values as _oracle_values

SETTINGS = dict(deadline=None, derandomize=True, suppress_health_check=list(HealthCheck))

# ----------------------------------------------------------------------------- numbers

DIGITS = st.text("0123456789", min_size=0, max_size=4)
ODD_DIGITS = st.sampled_from(["\uff13", "\u0663", "\u00b2", "\u0967", "\U0001d7d9"])   # fullwidth, Arabic-Indic, ...


@st.composite
def number_tokens(draw) -> str:
    """A token near the Fortran number syntax: often right, often subtly wrong."""
    sign = draw(st.sampled_from(["", "", "+", "-"]))
    whole = draw(DIGITS)
    if draw(st.integers(0, 15)) == 0:
        whole += draw(ODD_DIGITS)
    dot = draw(st.sampled_from(["", ".", "."]))
    frac = draw(DIGITS) if dot else ""
    exp = ""
    if draw(st.booleans()):
        exp = draw(st.sampled_from(["e", "E", "d", "D", "q"])) + draw(st.sampled_from(["", "+", "-"])) + draw(DIGITS)
    tail = draw(st.sampled_from([""] * 8 + ["_8", "_", "+1", "-7", "*2", "x", "0x", "/"]))
    body = sign + whole + dot + frac + exp + tail
    if body.endswith("/"):   # '/' ends the group: within a value it is always 360/7 (a bare '/' is a group end)
        body = body[:-1] + "/7"
    if draw(st.integers(0, 20)) == 0:
        body = draw(st.sampled_from(["0xff", "inf", "nan", "1" * 45, "(1,2)", "1_000", "4+1", "360-7"]))
    counts = draw(st.sampled_from(["", "", "", "2*", "3*", "0*", "2*2*", "10*"]))
    return counts + body


@settings(max_examples=400, **SETTINGS)
@given(tokens=st.lists(number_tokens(), min_size=1, max_size=3))
def test_sweep_values_read_as_fortran_reads_them(tokens):
    text = ("&fourbar\n  fixed_link = 12, crank = 2, coupler = 15, rocker = 9\n/\n"
            f"&sweep\n  key1 = 'fourbar.crank'\n  values1 = {', '.join(tokens)}\n/\n")
    expected: list[float] | None = []
    # a separator just before the group's end is not a null value (Fortran's trailing comma)
    for t in (tokens[:-1] if len(tokens) > 1 and tokens[-1] == "" else tokens):
        v = _oracle_values(t)
        expected = None if v is None or expected is None else expected + v
    from driver.sweep import SPEC
    try:
        deck = read_deck("g.dat", text=text)
        validate(deck.groups["sweep"], SPEC, "g.dat")
    except DeckError as exc:
        assert expected is None, f"{tokens} refused: {exc}"
        assert exc.line == 6 and exc.key == "values1", str(exc)
        return
    assert expected is not None, f"{tokens} read as {deck.groups['sweep'].values['values1']}"
    got = deck.groups["sweep"].values["values1"]
    got = got if isinstance(got, list) else [got]
    assert [float(g) for g in got] == expected, tokens


@settings(max_examples=300, **SETTINGS)
@given(tok=number_tokens())
def test_api_strings_are_numbers_only_as_fortran_spells_them(tok):
    from driver.fourbar import SPEC
    raw = RawGroup("fourbar", {"fixed_link": 12.0, "crank": tok, "coupler": 15.0, "rocker": 9.0, "step_deg": 20}, {}, 1)
    v = _oracle_values(tok)
    want = v[0] if v is not None and len(v) == 1 and "*" not in tok else None
    if want is not None and not (0 < want <= 1e15):
        want = None   # out of the key's range: refused for that reason
    try:
        p = validate(raw, SPEC, "api")
    except DeckError as exc:
        assert want is None, f"{tok!r} refused: {exc}"
        assert exc.key == "crank"
        return
    assert want is not None and p["crank"] == want, (tok, p["crank"])


# ----------------------------------------------------------------------------- expressions

KINDS = {"a": "number", "b": "number", "ok": "bool", "cls": "text"}


@st.composite
def expressions(draw, depth: int = 0) -> tuple[str, str | None]:
    """(text, kind) where kind is the oracle's: 'number', 'bool', 'text', or None for a type error."""
    if depth >= 3 or draw(st.integers(0, 3)) == 0:
        leaf = draw(st.sampled_from(["a", "b", "ok", "cls", "2", "0.5", "1e3", "'crank-rocker'", "True",
                                     "1_0", "0x1f", "\uff41", "1e400", "a # b"]))
        kind = {"a": "number", "b": "number", "ok": "bool", "cls": "text", "2": "number", "0.5": "number",
                "1e3": "number", "'crank-rocker'": "text", "True": "bool"}.get(leaf)
        return leaf, kind
    form = draw(st.sampled_from(["arith", "compare", "bool", "not", "call1", "minmax"]))
    x, kx = draw(expressions(depth + 1))
    if form == "not":
        return f"not ({x})", None if kx is None else "bool"
    if form == "call1":
        fn = draw(st.sampled_from(["abs", "sqrt", "floor", "cos"]))
        return f"{fn}({x})", "number" if kx in ("number", "bool") else None
    y, ky = draw(expressions(depth + 1))
    if form == "minmax":
        fn = draw(st.sampled_from(["min", "max"]))
        if draw(st.booleans()):
            return f"{fn}({x})", None   # a reduction over cases is not in the language
        return f"{fn}({x}, {y})", "number" if {kx, ky} <= {"number", "bool"} else None
    if kx is None or ky is None:
        kind = None
    elif form == "arith":
        op = draw(st.sampled_from(["+", "-", "*", "/", "**"]))
        return f"({x}) {op} ({y})", "number" if {kx, ky} <= {"number", "bool"} else None
    elif form == "compare":
        op = draw(st.sampled_from(["<", ">=", "==", "!="]))
        return f"({x}) {op} ({y})", "bool" if (kx == "text") == (ky == "text") else None
    else:
        op = draw(st.sampled_from(["and", "or"]))
        return f"({x}) {op} ({y})", "bool"
    return f"({x}) + ({y})", kind


@settings(max_examples=400, **SETTINGS)
@given(e=expressions())
def test_expressions_type_checked_against_typed_columns(e):
    text, kind = e
    frame = {"a": np.array([1.0, -2.0, 3.0]), "b": np.array([0.0, 5.0, 1e-3]), "ok": np.array([True, False, True]),
             "cls": np.array(["crank-rocker", "double-crank", "crank-rocker"], dtype=object)}
    try:
        checked = parse(text, KINDS)
        result = checked.check_kinds(KINDS)
    except ExprError as exc:
        assert exc.message
        assert kind in (None, "text", "number", "bool")   # a constant part may be refused as not finite
        if kind in ("number", "bool"):
            assert "finite" in exc.message, (text, exc.message)
        return
    assert kind in ("number", "bool"), f"{text!r} accepted, oracle says {kind}"
    assert result == kind or (result, kind) == ("number", "bool") or (result, kind) == ("bool", "number")
    out = checked.evaluate(frame)
    assert out.shape == (3,) and out.dtype.kind in "bf", (text, out)


# ----------------------------------------------------------------------------- titles

TITLE_CHARS = st.sampled_from(list("ab $\\{}^_%#'&") + ["\x1b", "\x00", "\x07", "\u2028", "\t", "\u00e9",
                                                         "\U0001F600", "\u4e2d", "\\frac", "$$", "{" * 20])


@settings(max_examples=60, **SETTINGS)
@given(parts=st.lists(TITLE_CHARS, min_size=1, max_size=12))
def test_titles_are_printable_text_drawn_literally(parts):
    from matplotlib.figure import Figure

    from driver.fourbar import SPEC
    from driver.plotting import plain_text, style
    title = "".join(parts)
    raw = RawGroup("fourbar", {"fixed_link": 12.0, "crank": 5.0, "coupler": 15.0, "rocker": 9.0, "step_deg": 20, "title": title},
                   {}, 1)
    try:
        p = validate(raw, SPEC, "api")
    except DeckError as exc:
        assert exc.key == "title" and any(not c.isprintable() for c in title), str(exc)
        return
    assert all(c.isprintable() for c in p["title"])
    with style():
        fig = Figure()
        fig.suptitle(plain_text(p["title"]))
        fig.canvas.draw()   # mathtext would raise on '$\frac$', nested braces recurse
    assert plain_text(title).count("\\$") == title.count("$")
