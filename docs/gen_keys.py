"""Generate the deck-key tables of docs/*.md from each group's SPEC (the one source of truth).

A page holds a table for group G between the lines ``<!-- keys:G begin -->`` and
``<!-- keys:G end -->``; this script rewrites what lies between them.

    python docs/gen_keys.py            # rewrite the tables
    python docs/gen_keys.py --check    # exit 1 (naming the pages) when a table is out of date

Run it after changing a SPEC (a key, its units, default, choices or doc string).
"""
from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
MARK = re.compile(r"(<!-- keys:(?P<group>[a-z_]+) begin -->\n)(?P<body>.*?)(<!-- keys:(?P=group) end -->)", re.S)


def spec_of(group: str):
    """The GroupSpec of a study or control group (sweep, optimize, synthesis)."""
    from driver._study import group_spec
    spec = group_spec(group)
    if spec is None:
        raise SystemExit(f"gen_keys: no namelist group &{group}")
    return spec


def _cell(text: str) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def _default(key) -> str:
    if key.required:
        return "**required**"
    if key.default is None:
        return "—"
    if isinstance(key.default, bool):
        return ".true." if key.default else ".false."
    if isinstance(key.default, str):
        return f"`'{key.default}'`"
    if isinstance(key.default, (list, tuple)):
        return "`" + ", ".join(map(str, key.default)) + "`" if key.default else "—"
    return f"`{key.default}`"


def table(group: str) -> str:
    """The markdown table of group ``group``'s keys."""
    spec = spec_of(group)
    lines = [f"`&{spec.name}`" + (f": {_cell(spec.doc)}" if spec.doc else "") + "", "",
             "| key | type | units | default | meaning |", "|---|---|---|---|---|"]
    for name, key in spec.keys.items():
        doc = key.doc
        if key.choices:
            doc = (doc + "; " if doc else "") + "one of " + ", ".join(f"`{c}`" for c in key.choices)
        lines.append(f"| `{name}` | {key.kind} | {_cell(key.units) or ''} | {_default(key)} | {_cell(doc)} |")
    return "\n".join(lines) + "\n"


def render(text: str) -> str:
    return MARK.sub(lambda m: m.group(1) + table(m.group("group")) + m.group(4), text)


def groups_documented() -> set[str]:
    return {m.group("group") for page in DOCS.glob("*.md") for m in MARK.finditer(page.read_text())}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true", help="only check; exit 1 when a table is out of date")
    args = ap.parse_args(argv)
    stale = []
    for page in sorted(DOCS.glob("*.md")):
        old = page.read_text()
        new = render(old)
        if new != old:
            stale.append(page.name)
            if not args.check:
                page.write_text(new)
    if args.check and stale:
        print(f"gen_keys: out of date: {', '.join(stale)} (run: python docs/gen_keys.py)", file=sys.stderr)
        return 1
    if not args.check and stale:
        print(f"gen_keys: rewrote {', '.join(stale)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
