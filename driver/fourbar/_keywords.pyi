"""Static signature of ``fourbar.run`` for type checkers and IDEs: the keys of its SPEC as typed
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
    fixed_link: float,
    crank: float,
    coupler: float,
    rocker: float,
    omega: float = 1.0,
    alpha: float = 0.0,
    step_deg: float,
    start_deg: float = 0.0,
    stop_deg: float = 360.0,
    method: Literal["exact", "listing"] = "exact",
    branch: Literal["open", "crossed"] = "open",
    transmission_band_deg: float | Sequence[float] | NDArray[Any] = ...,
    coupler_point: float | Sequence[float] | NDArray[Any] = ...,
    title: str = "",
    mass: float | Sequence[float] | NDArray[Any] = ...,
    inertia: float | Sequence[float] | NDArray[Any] = ...,
    com_distance: float | Sequence[float] | NDArray[Any] = ...,
    com_angle_deg: float | Sequence[float] | NDArray[Any] = ...,
    gravity: float = ...,
    load_torque: float = ...,
    load_force_x: float = ...,
    load_force_y: float = ...,
    speed_fluctuation: float = ...,
    balance: Literal["none", "force"] = ...,
    section_area: float | Sequence[float] | NDArray[Any] = ...,
    section_modulus: float | Sequence[float] | NDArray[Any] = ...,
    yield_strength: float | Sequence[float] | NDArray[Any] = ...,
    counterweight_radius: float | Sequence[float] | NDArray[Any] = ...,
) -> Result: ...
