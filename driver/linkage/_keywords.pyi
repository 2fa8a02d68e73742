"""Static signature of ``linkage.run`` for type checkers and IDEs: the keys of its SPEC as typed
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
    pivots: str | Sequence[str] = ...,
    pivot_xy: float | Sequence[float] | NDArray[Any] = ...,
    guides: str | Sequence[str] = ...,
    guide_on: str | Sequence[str] = ...,
    guide_xy: float | Sequence[float] | NDArray[Any] = ...,
    guide_deg: float | Sequence[float] | NDArray[Any] = ...,
    driver: Literal["crank", "slider"] = "crank",
    driver_joints: str | Sequence[str],
    driver_link: str = "",
    driver_length: float = 0.0,
    omega: float = 1.0,
    alpha: float = 0.0,
    start: float = 0.0,
    stop: float = 360.0,
    step: float,
    dyads: Literal["rrr", "rrp", "prr", "rpr", "prp"] | Sequence[Literal["rrr", "rrp", "prr", "rpr", "prp"]] = ...,
    dyad_joints: str | Sequence[str] = ...,
    dyad_links: str | Sequence[str] = ...,
    dyad_dims: float | Sequence[float] | NDArray[Any] = ...,
    dyad_modes: int | Sequence[int] | NDArray[Any] = ...,
    points: str | Sequence[str] = ...,
    point_on: str | Sequence[str] = ...,
    point_uv: float | Sequence[float] | NDArray[Any] = ...,
    output: str = "",
    scan_points: int = 720,
    bodies: str | Sequence[str] = ...,
    mass: float | Sequence[float] | NDArray[Any] = ...,
    com_uv: float | Sequence[float] | NDArray[Any] = ...,
    inertia: float | Sequence[float] | NDArray[Any] = ...,
    gravity: float | Sequence[float] | NDArray[Any] = ...,
    loads: str | Sequence[str] = ...,
    load_xy: float | Sequence[float] | NDArray[Any] = ...,
    torque_links: str | Sequence[str] = ...,
    torques: float | Sequence[float] | NDArray[Any] = ...,
    guide_force_on: str = "",
    guide_force_over: Literal["input", "slide"] = "input",
    guide_force_x: float | Sequence[float] | NDArray[Any] = ...,
    guide_force: float | Sequence[float] | NDArray[Any] = ...,
    guide_force_scale: float = 1.0,
    cycle_deg: float = 360.0,
    speed_fluctuation: float = 0.02,
    turning_moment_deg: float | Sequence[float] | NDArray[Any] = ...,
    turning_moment: float | Sequence[float] | NDArray[Any] = ...,
) -> Result: ...
