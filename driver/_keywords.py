"""Static signatures of the studies' ``run`` (type checkers and IDEs).  GENERATED from each
study's SPEC by tools/gen_keyword_signatures.py (driver._signatures.render_module): do not
edit; tests/test_keyword_signatures.py fails while it is stale."""
from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Literal, overload

from numpy.typing import NDArray

from driver._deck import Params
from driver._result import Result

__all__ = ["fourbar", "linkage", "manipulator", "robust_example", "slidercrank", "ujoint"]


@overload
def fourbar(params: Params, /, progress: bool = False) -> Result: ...


@overload
def fourbar(
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
    counterweight_radius: float | Sequence[float] | NDArray[Any] = ...,
) -> Result: ...


def fourbar(params: Params | None = None, /, progress: bool = False, **keys: Any) -> Result:
    """The signature of ``driver.fourbar.run`` (its docstring has the keys)."""
    raise NotImplementedError("a signature only: call driver.fourbar.run")


@overload
def linkage(params: Params, /, progress: bool = False) -> Result: ...


@overload
def linkage(
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


def linkage(params: Params | None = None, /, progress: bool = False, **keys: Any) -> Result:
    """The signature of ``driver.linkage.run`` (its docstring has the keys)."""
    raise NotImplementedError("a signature only: call driver.linkage.run")


@overload
def manipulator(params: Params, /, progress: bool = False) -> Result: ...


@overload
def manipulator(
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


def manipulator(params: Params | None = None, /, progress: bool = False, **keys: Any) -> Result:
    """The signature of ``driver.manipulator.run`` (its docstring has the keys)."""
    raise NotImplementedError("a signature only: call driver.manipulator.run")


@overload
def robust_example(params: Params, /, progress: bool = False) -> Result: ...


@overload
def robust_example(
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


def robust_example(params: Params | None = None, /, progress: bool = False, **keys: Any) -> Result:
    """The signature of ``driver.robust_example.run`` (its docstring has the keys)."""
    raise NotImplementedError("a signature only: call driver.robust_example.run")


@overload
def slidercrank(params: Params, /, progress: bool = False) -> Result: ...


@overload
def slidercrank(
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


def slidercrank(params: Params | None = None, /, progress: bool = False, **keys: Any) -> Result:
    """The signature of ``driver.slidercrank.run`` (its docstring has the keys)."""
    raise NotImplementedError("a signature only: call driver.slidercrank.run")


@overload
def ujoint(params: Params, /, progress: bool = False) -> Result: ...


@overload
def ujoint(
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
    maxiter: int = 200,
    ftol: float = 1e-12,
    paper_beta: float | Sequence[float] | NDArray[Any] = ...,
    paper_phi: float | Sequence[float] | NDArray[Any] = ...,
    paper_u: float = ...,
    paper_nit: int = ...,
    paper_nfev: int = ...,
    paper_band: float | Sequence[float] | NDArray[Any] = ...,
) -> Result: ...


def ujoint(params: Params | None = None, /, progress: bool = False, **keys: Any) -> Result:
    """The signature of ``driver.ujoint.run`` (its docstring has the keys)."""
    raise NotImplementedError("a signature only: call driver.ujoint.run")
