"""Static signature of ``ujoint.run`` for type checkers and IDEs: the keys of its SPEC as typed
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
    beta: float | Sequence[float] | NDArray[Any] = ...,
    phi: float | Sequence[float] | NDArray[Any] = ...,
    delta: float | Sequence[float] | NDArray[Any] = ...,
    rho: float | Sequence[float] | NDArray[Any] = ...,
    axes: float | Sequence[float] | NDArray[Any] = ...,
    rpm: float = 25.0,
    model: Literal["paper", "exact"] = "exact",
    phasing: Literal["cumulative", "eq13"] = "cumulative",
    option: Literal[0, 1, 2, 3] = 0,
    objective: Literal["mean_square", "rms", "peak_to_peak"] = "mean_square",
    beta_lower: float | Sequence[float] | NDArray[Any] = ...,
    beta_upper: float | Sequence[float] | NDArray[Any] = ...,
    phi_lower: float | Sequence[float] | NDArray[Any] = ...,
    phi_upper: float | Sequence[float] | NDArray[Any] = ...,
    n_starts: int = 16,
    seed: int = 0,
    n_grid: int = 360,
    table_step: float = 10.0,
    tidy_grid: Literal["n_grid", "table_step"] = "n_grid",
    angle_origin: Literal["normal", "plane"] = "normal",
    load_inertia: float = ...,
    load_torque: float = ...,
    maxiter: int = 200,
    ftol: float = 1e-12,
    paper_beta: float | Sequence[float] | NDArray[Any] = ...,
    paper_phi: float | Sequence[float] | NDArray[Any] = ...,
    paper_u: float = ...,
    paper_nit: int = ...,
    paper_nfev: int = ...,
    paper_band: float | Sequence[float] | NDArray[Any] = ...,
) -> Result: ...
