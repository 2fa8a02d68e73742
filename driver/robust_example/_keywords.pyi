"""Static signature of ``robust_example.run`` for type checkers and IDEs: the keys of its SPEC as typed
keyword arguments.  GENERATED from the SPEC by tools/gen_keyword_signatures.py
(driver._signatures.render_stub): do not edit; tests/test_keyword_signatures.py fails while it is stale."""
from collections.abc import Sequence
from typing import Any, Literal, overload

from numpy.typing import NDArray

from driver._deck import Params
from driver._result import Result

__all__ = ["run"]

@overload
def run(params: Params, /, progress: bool = False) -> Result: ...
@overload
def run(
    *,
    progress: bool = False,
    title: str = "",
    mode: Literal["exact", "report"] = "exact",
    true_coeffs: float | Sequence[float] | NDArray[Any] = ...,
    sigma_x: float = 0.5,
    dual_targets: float | Sequence[float] | NDArray[Any],
    dual_y: float | Sequence[float] | NDArray[Any],
    taguchi_targets: float | Sequence[float] | NDArray[Any],
    taguchi_offsets: float | Sequence[float] | NDArray[Any],
    taguchi_y: float | Sequence[float] | NDArray[Any],
    printed_eq28: float | Sequence[float] | NDArray[Any] = ...,
    printed_eq211: float | Sequence[float] | NDArray[Any] = ...,
    printed_eq212: float | Sequence[float] | NDArray[Any] = ...,
    printed_table25_std: float | Sequence[float] | NDArray[Any] = ...,
) -> Result: ...
