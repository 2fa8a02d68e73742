"""Deck fuzz campaign: thousands of malformed decks through the command line, in one process.

    .venv/bin/python tests/fuzz_decks.py --count 10000 --seed 0 [--memory 4G] [--json]

Decks are mutations of the shipped decks (every study group and sweeps; the optimisation and
synthesis decks only through the reader) and generated ones: garbage and extreme values,
wrong types and lengths, duplicated keys and groups, unicode, CRLF, BOM, binary junk, repeat
counts, '/' and subscripts, truncation; and a share (GRAMMAR_SHARE) from a grammar-aware generator
(:func:`grammar_deck`): number spellings near and off the Fortran syntax, repeat counts, keep and
plot_y expressions over the typed summary columns, titles with '$', braces and control characters,
where a number Fortran does not read must be refused naming its key (oracle :func:`fortran_values`).
Every deck must end in exit 0, 1 or 2 with its messages naming the deck, never a traceback or an
unexpected exception ("run failed"), no
NaN/inf/**** in a written table, and nothing written when the exit is 2 (the slowest deck is
reported, not judged: no timing is a pass/fail rule).  Runs use a small work budget (``--max-work``) so that a mutated deck of a
long study is refused by its estimate instead of running for seconds: the campaign exercises
reading, validation, estimates and every fast run path.  Prints a summary (``--json``: one
JSON object); exit status 1 when any deck broke a rule.
"""
from __future__ import annotations

import argparse
import contextlib
import io
import json
import os
import random
import re
import shutil
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: share of the campaign's decks built by the grammar-aware generator (:func:`grammar_deck`)
GRAMMAR_SHARE = float(os.environ.get("FUZZ_GRAMMAR_SHARE", "0.15"))
INPUTS = ROOT / "inputs"
#: decks whose runs are too long for a campaign even when valid (many cases / evaluations):
#: mutations of these, and of every &optimize and &synthesis deck (their runs have no estimate
#: yet and take seconds), go through the deck reader only
SKIP_RUN = {"fourbar_design_search.dat", "slidercrank_matrix_sweep.dat"}
READ_ONLY_GROUPS = re.compile(r"^\s*&(optimize|synthesis)\b", re.IGNORECASE | re.MULTILINE)

VALUES = ["0", "-1", "1", "2", "1e300", "-1e300", "1e-300", "4.9e-324", "1e400", "-1e400", "1e15", "1e16",
          "999999999", "1e9", "1e5", "-0.0", "nan", "NaN", "inf", "-inf", "+inf", "'x'", "''", "abc", "",
          ".true.", ".false.", "T", ".t.", "1, 2", "1, 2, 3, 4, 5", "3*1", "10001*1", "99999999999*1", "2*",
          "360", "360/7", "0.5", "1d3", "1.0D-2", "'listing'", "'exact'", "'all'", "(1, 2)", "1 2",
          "\u22125.0", "5\u00a0", "'\u00e9'", "\x00", "'a\"b'", "'unterminated", "&", "$", "%", "=", "1e",
          ".5", "5.", "+", "-", "1_2", "0x10", "1e-4", "1e-6", "1e8", "100000*11.52", "12345678901234567890"]
JUNK = ["\x00", "\x01\x02", "\xff", "\u22124", "\ufeff", "\r", "\t", "/", "&", "!", "'", '"', "=", ",", "*",
        "(1)", "%x", "&end", "$end", "\u00a0", "\U0001F600", "\\", "\u2028"]


def _mutate(text: str, rng: random.Random, groups: list[str]) -> str:
    lines = text.split("\n")
    kind = rng.randrange(16)
    k = rng.randrange(len(lines)) if lines else 0
    if kind <= 4:    # a value replaced (most common: values are where misreads live)
        cands = [(i, m) for i, l in enumerate(lines) for m in re.finditer(r"(\w+)\s*=\s*", l)]
        if cands:
            i, m = rng.choice(cands)
            rest = lines[i][m.end():]
            tail = re.match(r"[^,!]*(.*)", rest).group(1)
            lines[i] = lines[i][:m.end()] + rng.choice(VALUES) + tail
    elif kind == 5:  # a line duplicated (duplicate keys) or a group duplicated
        if rng.random() < 0.5:
            lines.insert(k, lines[k])
        else:
            lines += text.split("\n")
    elif kind == 6:
        del lines[k]
    elif kind == 7:
        j = rng.randrange(len(lines))
        lines[k], lines[j] = lines[j], lines[k]
    elif kind == 8:  # truncation
        return text[: rng.randrange(len(text) + 1)]
    elif kind == 9:  # junk inserted
        pos = rng.randrange(len(text) + 1)
        return text[:pos] + rng.choice(JUNK) + text[pos:]
    elif kind == 10:  # line ends, BOM
        return rng.choice(["\ufeff" + text, text.replace("\n", "\r\n"), "\ufeff" + text.replace("\n", "\r\n"),
                           text.replace("\n", "\r")])
    elif kind == 11:  # a subscript or a component on a key
        cands = [(i, m) for i, l in enumerate(lines) for m in re.finditer(r"(\w+)(\s*=)", l)]
        if cands:
            i, m = rng.choice(cands)
            lines[i] = lines[i][:m.end(1)] + rng.choice(["(2)", "(1:3)", "%a", "(0)"]) + lines[i][m.end(1):]
    elif kind == 12:  # an unknown or misspelt key / group
        lines.insert(max(1, k), rng.choice(["  bogus = 1", "  omega = 1, omega = 2", "&" + rng.choice(groups),
                                            "/", "  title = 'x' /", "&fourbar /", "&sweep key1 = 'x' /"]))
    elif kind == 13:  # random bytes
        return text + "".join(chr(rng.randrange(0, 0x300)) for _ in range(rng.randrange(1, 30)))
    elif kind == 14:  # a key repeated with a long list
        cands = [(i, m) for i, l in enumerate(lines) for m in re.finditer(r"(\w+)\s*=\s*", l)]
        if cands:
            i, m = rng.choice(cands)
            lines[i] = lines[i][:m.end()] + ", ".join([rng.choice(VALUES[:20])] * rng.randrange(1, 50))
    else:            # two mutations
        return _mutate(_mutate(text, rng, groups), rng, groups)
    return "\n".join(lines)


def _generated(rng: random.Random, specs: dict) -> str:
    """A deck built from a group's key list with random values (often valid, often not)."""
    group = rng.choice(sorted(specs))
    keys = list(specs[group].keys)
    body = []
    for key in rng.sample(keys, min(len(keys), rng.randrange(1, 12))):
        body.append(f"  {key} = {rng.choice(VALUES)}")
    text = f"&{group}\n" + "\n".join(body) + "\n/\n"
    if rng.random() < 0.2 and group != "sweep":
        key = rng.choice(keys)
        text += f"&sweep key1 = '{group}.{key}', values1 = {rng.choice(VALUES)}, {rng.choice(VALUES)} /\n"
    return text


def fortran_number(tok: str) -> float | None:
    """Oracle: the value Fortran list-directed input reads from ``tok`` (no repeat count), or
    None.  A hand scanner: [sign] digits [. digits] [(e|d) [sign] digits], ASCII digits, at least
    one digit in the mantissa and in a given exponent, at most 40 digits."""
    i, n = 0, len(tok)
    if i < n and tok[i] in "+-":
        i += 1
    mant = 0
    while i < n and tok[i] in "0123456789":
        i, mant = i + 1, mant + 1
    if i < n and tok[i] == ".":
        i += 1
        while i < n and tok[i] in "0123456789":
            i, mant = i + 1, mant + 1
    if mant == 0:
        return None
    exp = 0
    if i < n and tok[i] in "eEdD":
        i += 1
        if i < n and tok[i] in "+-":
            i += 1
        while i < n and tok[i] in "0123456789":
            i, exp = i + 1, exp + 1
        if exp == 0:
            return None
    if i != n or mant + exp > 40:
        return None
    return float(tok.replace("d", "e").replace("D", "e"))


def fortran_values(tok: str) -> list[float] | None:
    """The values ``tok`` stands for: one number, or r copies after one repeat count r >= 1."""
    head, star, rest = tok.partition("*")
    if star:
        if not head or any(c not in "0123456789" for c in head) or int(head) == 0 or "*" in rest:
            return None
        v = fortran_number(rest)
        return None if v is None else [v] * int(head)
    v = fortran_number(tok)
    return None if v is None else [v]



# ----------------------------------------------------------------------------- grammar-aware decks

_ODD_DIGITS = ["\uff13", "\u0663", "\u00b2", "\u0967"]
_TAILS = [""] * 8 + ["_8", "_", "+1", "-7", "*2", "x", "/7"]
_SPECIAL = ["0xff", "inf", "nan", "1" * 45, "(1,2)", "1_000", "4+1", "360-7", "5.0_8", "2*1*4.0", "3e", "1d+"]


def number_token(rng: random.Random) -> str:
    """A token near the Fortran number syntax (the grammar of tests/test_grammar_fuzz.py)."""
    if rng.random() < 0.06:
        return rng.choice(_SPECIAL)
    digits = lambda: "".join(rng.choice("0123456789") for _ in range(rng.randrange(0, 4)))
    whole = digits() + (rng.choice(_ODD_DIGITS) if rng.random() < 0.05 else "")
    dot = rng.choice(["", ".", "."])
    body = rng.choice(["", "", "+", "-"]) + whole + dot + (digits() if dot else "")
    if rng.random() < 0.4:
        body += rng.choice("eEdDq") + rng.choice(["", "+", "-"]) + digits()
    body += rng.choice(_TAILS)
    return rng.choice(["", "", "", "2*", "3*", "0*", "2*2*"]) + body


#: summary columns of &fourbar by kind, for expressions (the typed columns of a sweep's keep)
_COLUMNS = {"number": ["mu_min_deg", "mu_max_deg", "rocker_swing_deg", "fourbar.crank", "case"],
            "bool": ["meets_band_40_120", "assemblable"], "text": ["grashof_class"]}


def expression(rng: random.Random, depth: int = 0) -> str:
    """An expression over the typed columns: often well typed, often not (text arithmetic, min of
    one column, '#', fullwidth letters, non-finite constants, bad number spellings)."""
    if depth >= 3 or rng.random() < 0.3:
        kind = rng.choice(["number", "number", "bool", "text", "const"])
        if kind == "const":
            return rng.choice(["2", "0.5", "1e3", "'crank-rocker'", "True", "1_0", "0x1f", "1e400", "9**9**9",
                               "log(0.0)", "'x'*1000000000", "\uff4du_min_deg", "mu_min_deg # + 1"])
        return rng.choice(_COLUMNS[kind])
    form = rng.choice(["arith", "compare", "bool", "not", "call", "minmax"])
    x = expression(rng, depth + 1)
    if form == "not":
        return f"not ({x})"
    if form == "call":
        return f"{rng.choice(['abs', 'sqrt', 'floor', 'cos', 'exp'])}({x})"
    y = expression(rng, depth + 1)
    if form == "minmax":
        return f"{rng.choice(['min', 'max'])}({x}" + (f", {y})" if rng.random() < 0.8 else ")")
    op = {"arith": ["+", "-", "*", "/", "**"], "compare": ["<", ">=", "==", "!="], "bool": ["and", "or"]}[form]
    return f"({x}) {rng.choice(op)} ({y})"


_TITLE = list("ab $\\{}^_%#&") + ["\x1b", "\x00", "\x07", "\t", "\u00e9", "\U0001F600", "\\frac", "$$", "{" * 20]


def title(rng: random.Random) -> str:
    return "".join(rng.choice(_TITLE) for _ in range(rng.randrange(1, 10))).replace("'", "")


def grammar_deck(rng: random.Random) -> tuple[str, set[str], bool]:
    """(deck text, the keys one of which a refusal must name (empty: no refusal is required),
    whether to draw figures).

    A four-bar deck whose number values, sweep values (repeat counts), keep/plot_y expressions
    and title come from the grammars above; when a number token is not one Fortran reads, the
    deck must be refused naming that key (the oracle :func:`fortran_values`)."""
    keys = {"fixed_link": "12.0", "crank": "2.0", "coupler": "15.0", "rocker": "9.0", "omega": "5.0",
            "step_deg": "60"}
    must: set[str] = set()
    k = rng.choice(list(keys))
    if rng.random() < 0.5:
        tok = number_token(rng)
        keys[k] = tok
        vals = fortran_values(tok)
        # an empty value is Fortran's null value, which a deck may not give (a deck states every
        # value): refused naming its key too
        if not tok.strip() or vals is None or len(vals) != 1:
            must.add(k)
    text = "&fourbar\n" + "\n".join(f"  {key} = {v}" for key, v in keys.items())
    if rng.random() < 0.3:
        text += f"\n  title = '{title(rng)}'"
    text += "\n/\n"
    if rng.random() < 0.7:
        toks = [rng.choice(["2", "3", "4.5", "2*3.0"]) if rng.random() < 0.6 else number_token(rng)
                for _ in range(rng.randrange(1, 4))]
        lines = ["  key1 = 'fourbar.crank'", f"  values1 = {', '.join(toks)}"]
        # an empty token is Fortran's null value: refused as such (", ,"), or no value at all (a
        # trailing separator); either way only a bad number requires a refusal
        if any(t.strip() and fortran_values(t) is None for t in toks):
            must.add("values1")
        if any(not t.strip() for t in toks[:-1]):   # ", ," within the list: a null value, refused
            must.add("values1")
        if not any(t.strip() for t in toks):   # no value at all: a swept key without values, refused
            must.add("values1")
        if rng.random() < 0.6:
            lines.append(f"  keep = \"{expression(rng)}\"")
        if rng.random() < 0.3:
            lines.append(f"  plot_y = \"{expression(rng)}\"")
        text += "&sweep\n" + "\n".join(lines) + "\n/\n"
    return text, must, rng.random() < 0.05


_BAD = re.compile(r"(?<![A-Za-z_])(nan|[+-]?inf)(?![A-Za-z_])|\*\*\*\*", re.IGNORECASE)


def campaign(count: int, seed: int, max_work: str, workdir: Path) -> dict:
    from driver import sweep, synthesis
    from driver._cli import main
    from driver._runner import available_studies

    specs = {name: m.spec for name, m in available_studies().items()}
    specs["sweep"] = sweep.SPEC
    specs["synthesis"] = synthesis.SPEC
    bases = sorted(p for p in INPUTS.glob("*.dat"))
    texts = {p.name: p.read_text() for p in bases}
    rng = random.Random(seed)
    outcomes: Counter = Counter()
    problems: list[dict] = []
    slowest = (0.0, "")
    t_start = time.perf_counter()
    for n in range(count):
        must, plot = set(), False
        if rng.random() < GRAMMAR_SHARE:
            name = f"grammar{n}.dat"
            text, must, plot = grammar_deck(rng)
            original = text
        elif rng.random() < 0.15:
            name, text = f"gen{n}.dat", _generated(rng, specs)
            original = text
        else:
            base = rng.choice(bases).name
            name, text = base, _mutate(texts[base], rng, sorted(specs))
            original = texts[base]
        if name in SKIP_RUN or READ_ONLY_GROUPS.search(original):
            name = "read_only_" + name
        deck = workdir / f"d{n % 50}" / name
        deck.parent.mkdir(exist_ok=True)
        if isinstance(text, str):
            deck.write_bytes(text.encode("utf-8", "surrogatepass"))
        out = workdir / f"o{n % 50}"
        shutil.rmtree(out, ignore_errors=True)
        err = io.StringIO()
        t0 = time.perf_counter()
        args = [str(deck), "-o", str(out), "-q", "-j", "1", "--max-work", max_work] + (["--plot"] if plot else [])
        try:
            with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
                if name.startswith("read_only_"):
                    from driver._deck import DeckError, read_deck
                    try:
                        read_deck(deck)
                        rc = 0
                    except DeckError as exc:
                        print(f"error: {exc}", file=sys.stderr)
                        rc = 2
                else:
                    rc = main(args)
        except BaseException as exc:   # the campaign records what escaped
            rc = f"raised {exc.__class__.__name__}: {exc}"
        seconds = time.perf_counter() - t0
        slowest = max(slowest, (seconds, f"{deck} (deck {n})"))
        msg = err.getvalue()
        outcomes[rc if isinstance(rc, int) else "raised"] += 1
        why = []
        if rc not in (0, 1, 2):
            why.append(str(rc))
        if "Traceback" in msg or "run failed" in msg:
            why.append("traceback or unexpected exception")
        if rc in (1, 2) and str(deck) not in msg:
            why.append("message does not name the deck")
        if must and not (rc == 2 and any(f"key '{k}'" in msg for k in must)):
            why.append(f"a number Fortran does not read was not refused naming one of {sorted(must)}")
        if re.search(r"\w*Warning: |site-packages", msg):
            why.append("a library warning reached stderr")
        if rc == 2 and out.exists() and any(out.rglob("*")):
            why.append("files written for bad input")
        if out.exists():
            for f in out.rglob("*"):
                if f.suffix in (".out", ".csv", ".dat") and f.is_file() and _BAD.search(f.read_text(errors="replace")):
                    why.append(f"NaN/inf/**** in {f.name}")
                    break
        if why:
            keep = workdir / "failures" / f"{n}_{name}"
            keep.parent.mkdir(exist_ok=True)
            shutil.copy(deck, keep)
            problems.append({"deck": n, "base": name, "why": why, "stderr": msg[-400:], "saved": str(keep)})
    return {"decks": count, "seed": seed, "outcomes": {str(k): v for k, v in sorted(outcomes.items(), key=str)},
            "problems": len(problems), "first_problems": problems[:20],
            "slowest_s": round(slowest[0], 3), "slowest": slowest[1],
            "seconds": round(time.perf_counter() - t_start, 1)}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--count", type=int, default=10_000)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--max-work", default="0.2", help="work budget of each run (driver --max-work)")
    ap.add_argument("--memory", default=None, help="address-space limit of this process, e.g. 4G")
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args(argv)
    if args.memory:
        import resource

        from driver._limits import parse_size
        size = int(parse_size(args.memory))
        resource.setrlimit(resource.RLIMIT_AS, (size, size))
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    with tempfile.TemporaryDirectory(prefix="fuzz_decks_") as tmp:
        report = campaign(args.count, args.seed, args.max_work, Path(tmp))
        if report["problems"]:
            keep = Path(tempfile.mkdtemp(prefix="fuzz_failures_"))
            shutil.copytree(Path(tmp) / "failures", keep, dirs_exist_ok=True)
            report["failures_kept_in"] = str(keep)
    print(json.dumps(report, indent=None if args.json else 1))
    return 1 if report["problems"] else 0


if __name__ == "__main__":
    sys.exit(main())
