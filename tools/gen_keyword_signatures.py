"""Write ``driver/_keywords.py``, the static keyword signatures of every study's ``run``.

The signatures are generated from each study's SPEC (the deck keys, their kinds, defaults
and allowed values) by :func:`driver._signatures.render_module`; a type checker then refuses a
misspelt or mistyped key in ``driver.<study>.run(...)``.  Run after adding a study or changing
a SPEC (tests/test_keyword_signatures.py fails while the committed file is stale)::

    .venv/bin/python tools/gen_keyword_signatures.py
"""
from __future__ import annotations

import sys
from pathlib import Path

TARGET = Path(__file__).resolve().parents[1] / "driver" / "_keywords.py"


def specs() -> list:
    """The SPEC of every study the runner knows, in name order (a study module's ``SPEC``, or
    the ``spec`` of its study contract)."""
    from driver._deck import GroupSpec
    from driver._runner import available_studies
    out = []
    for _, study in sorted(available_studies().items()):
        spec = getattr(study, "spec", None)   # a study package's 'spec' may be its spec module
        out.append(spec if isinstance(spec, GroupSpec) else getattr(study, "SPEC"))  # noqa: B009 - a study module
    return out


def main() -> int:
    from driver._signatures import render_module
    TARGET.write_text(render_module(specs()))
    print(f"wrote {TARGET}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
