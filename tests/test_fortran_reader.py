"""The deck reader against gfortran's own namelist reader (issue 36, item 3).

A tiny Fortran program (tests/data/namelist_reader.f90) is compiled once with gfortran, the
project's compiler; it reads namelist group ``&g`` -- a real ``x``, a real array ``a(8)``, a
logical ``l``, a string ``s`` and a string array ``c(4)``, each preset to a sentinel -- from
blocks of text on its standard input, one internal-file read per block, and prints what it
read (the bits of every real) or its error.  Hypothesis draws spellings of value lists (repeat
counts with and without a blank after the ``*``, nulls, blanks, tabs, commas, line breaks,
comments, slashes inside strings, exponents with E/D/Q, signs, logicals, quoted strings with
doubled quotes) and the tool's reader (:func:`driver._deck.read_deck` + ``validate``) reads
the same text.  For every spelling:

* the tool accepts it  =>  gfortran accepts it and read the same values, bit for bit (the
  elements after a list keep the sentinel);
* gfortran refuses it  =>  the tool refuses it;
* the tool refuses what gfortran accepts only for a deliberate reason its message names
  (:data:`DELIBERATE`, each documented in docs/input.md): a null value or a separator
  compilers read differently, arithmetic-looking exponents, the Q exponent, infinity/NaN,
  magnitudes no study takes, logicals spelt other than the usual ways, semicolons, text
  without quotes.

All spellings of one hypothesis example go to one gfortran process (hundreds per call).
"""
from __future__ import annotations

import shutil
import struct
import subprocess
from pathlib import Path

import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from driver._deck import DeckError, GroupSpec, Key, read_deck, validate

ROOT = Path(__file__).resolve().parents[1]
NA, NC = 8, 4                   # sizes of a and c in the Fortran program
SENTINEL_BITS = struct.unpack(">q", struct.pack(">d", -1.25e300))[0] & (2**64 - 1)

pytestmark = pytest.mark.skipif(shutil.which("gfortran") is None, reason="needs gfortran (the project's compiler)")

SPEC = GroupSpec("g", {
    "x": Key("float"),
    "a": Key("floats", check=lambda v: f"at most {NA} values" if len(v) > NA else None),
    "l": Key("bool"),
    "s": Key("str"),
    "c": Key("strs", check=lambda v: f"at most {NC} values" if len(v) > NC else None),
})

#: why the tool may refuse a spelling gfortran reads (each phrase is in the tool's message)
DELIBERATE = (
    "null value",                 # r* / , , / a leading comma, and separators compilers read differently
    "arithmetic is not read",     # 1.5+3 (Fortran: 1.5e3)
    "Q exponent",                 # 1q3: a gfortran extension
    "infinity and NaN",           # inf, nan, infinity
    "not a finite number",        # 1e400 (gfortran: Infinity)
    "outside what any study",     # magnitudes beyond 1e15
    "digits",                     # more than 40 digits
    "write .true. or .false.",    # .t, .tomato, tx: Fortran reads a logical from its first letter
    "semicolon",                  # 1;2 (gfortran: two values)
    "text is written in quotes",  # s = 5, c = 2*ab (gfortran reads some text without quotes)
    "repeat count applied to a repeat count",   # c = 2*1*'ab' (gfortran: the text 1*'ab', twice)
)


@pytest.fixture(scope="module")
def gfortran(tmp_path_factory):
    work = tmp_path_factory.mktemp("nlreader")
    exe = work / "namelist_reader"
    res = subprocess.run(["gfortran", "-O0", "-J", str(work), str(ROOT / "fortran" / "kinds.f90"),
                          str(ROOT / "tests" / "data" / "namelist_reader.f90"), "-o", str(exe)],
                         capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    return exe


def fortran_reads(exe: Path, texts: list[str]) -> list[dict | str]:
    """gfortran's reading of each group text: {'x': bits, 'a': [bits], 'l', 's', 'c'} or 'ERR ...'."""
    blocks = []
    for t in texts:
        recs = t.split("\n")
        blocks.append(f"{len(recs)}\n" + "\n".join(recs) + "\n")
    out = subprocess.run([str(exe)], input="".join(blocks), capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    got: list[dict | str] = []
    for block in out.stdout.split("END\n")[:-1]:
        lines = block.split("\n")
        if lines[0].startswith("ERR"):
            got.append(lines[0])
            continue
        assert lines[0] == "OK", block
        c = [ln[2:].split(" ", 1) for ln in lines[5:5 + NC]]
        got.append({"x": int(lines[1].split()[1], 16), "a": [int(h, 16) for h in lines[2].split()[1:]],
                    "l": lines[3].split()[1] == "T", "s": lines[4][2:].split(" ", 1)[1],
                    "c": [v[1] if len(v) > 1 else "" for v in c]})
    assert len(got) == len(texts)
    return got


def tool_reads(text: str) -> dict | str:
    """The tool's reading of a group text: the keys given, or 'ERR <message>'."""
    try:
        deck = read_deck("g.dat", text=text)
        p = validate(deck.groups["g"], SPEC, "g.dat")
    except DeckError as exc:
        return "ERR " + exc.message
    return {k: p[k] for k in p.given}


def _bits(v: float) -> int:
    return struct.unpack(">q", struct.pack(">d", v))[0] & (2**64 - 1)


def agree(text: str, tool: dict | str, fortran: dict | str) -> str | None:
    """None when the two readings agree under the rules of the module docstring, else why not."""
    if isinstance(tool, str):
        if isinstance(fortran, str):
            return None
        if any(p in tool for p in DELIBERATE):
            return None
        return f"tool refuses ({tool}), gfortran reads {fortran}"
    if isinstance(fortran, str):
        return f"tool reads {tool}, gfortran refuses ({fortran})"
    for key, v in tool.items():
        if key == "x" and _bits(v) != fortran["x"]:
            return f"x: tool {v!r}, gfortran {struct.unpack('>d', fortran['x'].to_bytes(8, 'big'))[0]!r}"
        if key == "a":
            want = [_bits(f) for f in v] + [SENTINEL_BITS] * (NA - len(v))
            if want != fortran["a"]:
                return f"a: tool {v}, gfortran bits {fortran['a']}"
        if key == "l" and v != fortran["l"]:
            return f"l: tool {v}, gfortran {fortran['l']}"
        if key == "s" and v.rstrip(" ") != fortran["s"]:
            return f"s: tool {v!r}, gfortran {fortran['s']!r}"
        if key == "c" and [x.rstrip(" ") for x in v] + ["~"] * (NC - len(v)) != fortran["c"]:
            return f"c: tool {v}, gfortran {fortran['c']}"
    return None


# ----------------------------------------------------------------------------- the spellings

DIG = st.text("0123456789", min_size=0, max_size=3)
DIG1 = st.text("0123456789", min_size=1, max_size=4)


@st.composite
def numbers(draw, clean: bool = False) -> str:
    """A number spelling: often right (any sign, '.', E/D exponent), often subtly wrong."""
    sign = draw(st.sampled_from(["", "", "+", "-"]))
    if clean:
        mant = draw(st.sampled_from(["{w}", "{w}.", "{w}.{f}", ".{f}"])).format(w=draw(DIG1), f=draw(DIG1))
    else:
        dot = draw(st.sampled_from(["", ".", "."]))
        whole, frac = draw(DIG), draw(DIG)
        mant = whole + dot + (frac if dot else "")
    exp = ""
    if draw(st.integers(0, 2)) == 0:
        letter = draw(st.sampled_from(["e", "E", "d", "D"] if clean else ["e", "E", "d", "D", "q", "Q", ""]))
        esign = draw(st.sampled_from(["", "+", "-"] if letter else ["+", "-"]))
        exp = letter + esign + draw(DIG1 if clean else st.text("0123456789", min_size=0, max_size=3))
    tok = sign + mant + exp
    if not clean and draw(st.integers(0, 12)) == 0:
        tok = draw(st.sampled_from(["inf", "nan", "Infinity", "-inf", ".", "+", "-", "e5", "1e400", "1e-400",
                                    "4.9e-324", "0", "-0.0", "-0", "1" * 20, "9" * 41, "2e15", "1;2"]))
    return tok


LOGICALS = [".true.", ".false.", ".t.", ".f.", "t", "f", "T", "F", "true", "false", ".TRUE.", ".False."]
ODD_LOGICALS = [".t", ".f", ".tomato", "tx", ".true", "fals"]


@st.composite
def strings(draw) -> str:
    q = draw(st.sampled_from(["'", '"']))
    body = draw(st.text(alphabet="ab ,/!*=&'\"1.", max_size=8))
    return q + body.replace(q, q + q) + q


def values_for(key: str, clean: bool) -> st.SearchStrategy[str]:
    logicals = st.sampled_from(LOGICALS if clean else LOGICALS + ODD_LOGICALS)
    right = {"x": numbers(clean), "a": numbers(clean), "l": logicals, "s": strings(), "c": strings()}[key]
    if clean:
        return right
    wrong = st.one_of(numbers(), logicals, strings(), st.sampled_from(["ab", "5", "x1"]))
    return st.one_of(right, right, right, right, wrong)


CLEAN_SEPARATORS = [",", ", ", " , ", " ", "  ", "\t", ",\n  ", "\n  ", " ! note\n  ", ",\n  ! a comment line\n  "]
SEPARATORS = st.sampled_from(CLEAN_SEPARATORS + [", ! note\n  ", ",! note\n  ", ",,", ", ,", "\n  ,", ";"])
REPEATS = st.sampled_from([""] * 10 + ["1*", "2*", "3*", "02*", "0*", "2* ", "1* ", "3*\t", "2*1*"])


@st.composite
def spellings(draw) -> str:
    """``&g key = values /``: half of them clean (what a careful deck writes), half hostile."""
    clean = draw(st.booleans())
    key = draw(st.sampled_from(["x", "a", "a", "l", "s", "c"]))
    n = draw(st.integers(1, {"x": 1, "l": 1, "s": 1, "a": 4, "c": 2}[key]) if clean else st.integers(0, 5))
    items = []
    for _ in range(n):
        if not clean and draw(st.integers(0, 9)) == 0:
            items.append(draw(st.sampled_from(["", "2*", "1*"])))      # a null value, or r null values
        else:
            rep = draw(st.sampled_from(["", "", "", "2*"] if clean and key in "ac" else [""])) if clean \
                else draw(REPEATS)
            items.append(rep + draw(values_for(key, clean)))
    text = ""
    for k, item in enumerate(items):
        if k:
            text += draw(st.sampled_from(CLEAN_SEPARATORS) if clean else SEPARATORS)
        text += item
    lead = draw(st.sampled_from([" ", "\n  ", "\n  ! a comment line\n  "] if clean else
                                [" "] * 6 + [", ", "\n  ", " ! note\n  "]))
    tail = draw(st.sampled_from([" ", ", ", ",", ",\n", " ! note\n", ", ! note\n"] if clean else
                                [" "] * 6 + [", ", ",", ",\n", " ! note\n", ", ! note\n"]))
    return f"&g {key} ={lead}{text}{tail}/"


#: the reproducers of issue 36 and what the study of gfortran's reader found (kept as examples)
FOUND = [
    "&g a = 2* 5 /", "&g x = 1* 5 /", "&g a = 2*, 5 /", "&g a = 2*\n 5 /", "&g a = 1, 2, ! note\n 3 /",
    "&g a = 1, 2\n , 3 /", "&g a = ! note\n 1, 2 /", "&g x = '5' /", "&g a = 1, '5' /", "&g c = 'a', ! n\n 'b' /",
    "&g l = .t /", "&g x = 2!c\n/", "&g a = 1 2*\n 3 /", "&g x = 1.5+3 /", "&g x = 1q3 /", "&g a = 1;2 /",
]


def _check(exe: Path, texts: list[str]) -> None:
    bad = []
    for text, fortran in zip(texts, fortran_reads(exe, texts)):
        why = agree(text, tool_reads(text), fortran)
        if why:
            bad.append(f"{text!r}: {why}")
    assert not bad, f"{len(bad)} of {len(texts)} spellings read differently:\n" + "\n".join(bad[:20])


def test_the_found_spellings_read_as_gfortran_reads_them(gfortran):
    _check(gfortran, FOUND)


@settings(max_examples=12, deadline=None, derandomize=True, suppress_health_check=list(HealthCheck))
@given(texts=st.lists(spellings(), min_size=150, max_size=150))
@example(texts=FOUND)
def test_drawn_spellings_read_as_gfortran_reads_them(gfortran, texts):
    _check(gfortran, texts)


def test_the_comparison_can_fail(gfortran):
    """The harness sees a difference: a value gfortran reads and a sentinel it leaves."""
    text = "&g a = 1.5, 2 /"
    fortran = fortran_reads(gfortran, [text])[0]
    assert isinstance(fortran, dict) and fortran["a"][:3] == [_bits(1.5), _bits(2.0), SENTINEL_BITS]
    assert agree(text, {"a": [1.5, 2.5]}, fortran) is not None
    assert agree(text, {"a": [1.5, 2.0, 3.0]}, fortran) is not None
    assert agree(text, "ERR not a number", fortran) is not None
    assert agree(text, {"a": [1.5, 2.0]}, fortran) is None
