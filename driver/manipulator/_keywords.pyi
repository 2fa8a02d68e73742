"""Static signature of ``manipulator.run`` for type checkers and IDEs: the keys of its SPEC as typed
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
    points_x: float | Sequence[float] | NDArray[Any],
    points_y: float | Sequence[float] | NDArray[Any],
    designs_l1: float | Sequence[float] | NDArray[Any] = ...,
    designs_l2: float | Sequence[float] | NDArray[Any] = ...,
    design_names: str | Sequence[str] = ...,
    printed_angles_deg: float | Sequence[float] | NDArray[Any] = ...,
    target_x: float = ...,
    target_y: float = ...,
    elbow: Literal[1, -1] = 1,
    joint_rates: float | Sequence[float] | NDArray[Any] = ...,
    joint_accels: float | Sequence[float] | NDArray[Any] = ...,
    gravity: float = 9.8,
    text_optimum_decimals: int = ...,
    mass_per_length: float = 10.0,
    crob_l1: float | Sequence[float] | NDArray[Any] = ...,
    ri2_levels: float | Sequence[float] | NDArray[Any] = ...,
    sweep_l1_start: float = 0.0,
    sweep_l1_step: float = 0.25,
    sweep_count: int = 0,
    tolerance_bound: float = 0.01,
    error_measure: Literal["global", "per_point"] = "global",
    mc_samples: int = 100000,
    mc_seed: int = 2005,
) -> Result: ...
