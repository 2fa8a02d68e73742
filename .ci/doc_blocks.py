"""The install command blocks of the docs that .ci/clean-clone runs word for word.

A block is the fenced ``bash`` block right after a line ``<!-- clean-clone: NAME -->`` in
README.md or docs/*.md.
    python3 .ci/doc_blocks.py            # one line per block: NAME FILE
    python3 .ci/doc_blocks.py NAME       # the block's text, as written
"""
from __future__ import annotations

import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MARK = re.compile(r"^<!-- clean-clone: ([\w-]+) -->\s*\n```bash\n(.*?)^```", re.M | re.S)


def blocks() -> dict[str, tuple[str, str]]:
    """NAME -> (file relative to the repository, block text) for every marked block."""
    found: dict[str, tuple[str, str]] = {}
    for path in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]:
        for m in MARK.finditer(path.read_text()):
            if m.group(1) in found:
                raise SystemExit(f"doc_blocks: block {m.group(1)!r} is marked twice")
            found[m.group(1)] = (str(path.relative_to(ROOT)), m.group(2))
    return found


if __name__ == "__main__":
    every = blocks()
    if len(sys.argv) == 1:
        print("\n".join(f"{name} {file}" for name, (file, _) in every.items()))
    elif sys.argv[1] in every:
        sys.stdout.write(every[sys.argv[1]][1])
    else:
        raise SystemExit(f"doc_blocks: no block {sys.argv[1]!r}; marked: {', '.join(every)}")
