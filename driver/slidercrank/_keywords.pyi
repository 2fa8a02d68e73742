"""Static signature of ``slidercrank.run`` for type checkers and IDEs: the keys of its SPEC as typed
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
    material: Literal["custom", "aluminium", "medium_carbon_steel", "low_carbon_steel"] = "custom",
    crank_radius: float = 0.125,
    rod_length: float = 0.505,
    area: float = ...,
    second_moment: float = ...,
    density: float = ...,
    youngs_modulus: float = ...,
    section_depth: float = ...,
    section_width: float = ...,
    section_diameter: float = ...,
    yield_strength: float = ...,
    slider_mass: float = 0.9,
    bearing_mass_crank: float = 0.05,
    bearing_mass_slider: float = 0.05,
    speeds: float | Sequence[float] | NDArray[Any],
    n_elements: int = 700,
    element_counts: int | Sequence[int] | NDArray[Any] = ...,
    steps_per_rev: int = 1440,
    revolutions: int = 4,
    settle_tolerance: float = 0.001,
    damping_ratio: float = 0.02,
    start: Literal["quasistatic", "rest", "simeon1996"] = "quasistatic",
    analysis: Literal["dynamic", "quasistatic"] = "dynamic",
    geometric_stiffness: bool = False,
    end_time: float = 0.0,
    benchmark: Literal["none", "simeon1996"] = "none",
    model: Literal["linear", "nonlinear"] = "linear",
    newton_tolerance: float = 1e-08,
    hht_alpha: float = -0.05,
    newton_max_iterations: int = 25,
    max_step_cuts: int = 6,
    growth_tolerance: float = 0.01,
    large_deflection: float = 0.02,
    onset_speeds: float | Sequence[float] | NDArray[Any] = ...,
    onset_elements: int = 40,
) -> Result: ...
