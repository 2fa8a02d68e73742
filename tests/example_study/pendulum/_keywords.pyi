"""Static signature of ``pendulum.run`` for type checkers and IDEs: the keys of its SPEC as typed
keyword arguments.  GENERATED from the SPEC by tools/gen_keyword_signatures.py
(driver._signatures.render_stub): do not edit; tests/test_keyword_signatures.py fails while it is stale."""
from typing import overload

from driver._deck import Params
from driver._result import Result

__all__ = ["run"]

@overload
def run(params: Params, /, progress: bool = False) -> Result: ...
@overload
def run(
    *,
    progress: bool = False,
    length: float,
    gravity: float = 9.80665,
    amplitude_deg: float,
    points: int = 13,
    title: str = "",
) -> Result: ...
