"""Write each study's ``_keywords.pyi``: the static keyword signature of its ``run``, in its own package.

The signature is generated from the study's SPEC (the deck keys, their kinds, defaults and
allowed values) by :func:`driver._signatures.render_stub` into ``driver/<study>/_keywords.pyi``;
a type checker then refuses a misspelt or mistyped key in ``driver.<study>.run(...)``.  Only
type checkers read the stub (the study's ``__init__`` imports it under ``TYPE_CHECKING``), so a
new study imports, runs and is registered before its stub exists: write it once the SPEC is
there, and again after a SPEC changes (tests/test_keyword_signatures.py fails while a committed
stub is stale)::

    .venv/bin/python tools/gen_keyword_signatures.py            # every registered study
    .venv/bin/python tools/gen_keyword_signatures.py linkage    # one study
"""
from __future__ import annotations

import sys
from pathlib import Path

STUB = "_keywords.pyi"


def stubs(groups: list[str] | None = None) -> dict[Path, str]:
    """{path of the study's ``_keywords.pyi``: its text} for the registered studies ``groups``
    (default every one); the stub lies beside the study package's ``__init__.py``."""
    from driver._signatures import render_stub
    from driver._study import load_study, study_names
    out = {}
    for group in groups or study_names():
        study = load_study(group)
        if study is None:
            raise SystemExit(f"gen_keyword_signatures: &{group} is not a registered study (driver._study.REGISTRY)")
        out[Path(str(study.module.__file__)).parent / STUB] = render_stub(study.spec)
    return out


def main(argv: list[str] | None = None) -> int:
    for path, text in stubs(list(sys.argv[1:] if argv is None else argv)).items():
        path.write_text(text)
        print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
