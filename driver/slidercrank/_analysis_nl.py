"""Slider-crank with a geometrically nonlinear rod (``model = 'nonlinear'``): one case through the
kernel (fortran/slidercrank_nl.f90), the growth criterion, and the dynamic-buckling onset search.

SI units; strains dimensionless here (the report prints microstrain), deflections in m.

Growth criterion (docs/slidercrank.md, "Does the rod buckle?"): with d_k the peak |lateral
deflection from the chord A-C| in revolution k of N, compare the median of the last h
revolutions with the median of the h before them, h = 2 max(1, N // 6) (2 for 4 to 11
revolutions, 4 for 12 to 17): the mean growth per revolution (ratio)^(1/h) - 1 above
``growth_tolerance`` means the response *grows*, and so does a run stopped because the
deflection passed L/2.  Medians of even-length windows, not the last two values: a buckled
rod's response can be irregular from one revolution to the next (period 2, or no period at
all), and one large revolution is no trend.  The response is *irregular* when max/min - 1 of
the d_k over those 2h revolutions exceeds 5 %.  The rod counts as *buckled* when its peak lateral deflection in
the last revolution exceeds ``large_deflection`` x L.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from driver._deck import Params
from driver.slidercrank import _kernel as kernel
from driver.slidercrank._analysis import no_record
from driver.slidercrank._spec import Model


@dataclass
class NLCase:
    """One nonlinear run: crank speed, element count, last-revolution records (empty unless
    the run is ``ok``; the per-revolution peaks ``rev_lat``/``rev_eps`` always) and statistics."""

    omega: float
    n_elements: int
    status: str
    dt: float
    steps_per_rev: int
    angle_deg: np.ndarray = field(default_factory=no_record)
    eps_ax: np.ndarray = field(default_factory=no_record)
    eps_of: np.ndarray = field(default_factory=no_record)
    lat_max: np.ndarray = field(default_factory=no_record)
    mid: np.ndarray = field(default_factory=no_record)
    energy: np.ndarray = field(default_factory=no_record)
    rev_lat: np.ndarray = field(default_factory=no_record)
    rev_eps: np.ndarray = field(default_factory=no_record)
    shapes: np.ndarray = field(default_factory=no_record)
    frames: np.ndarray = field(default_factory=no_record)
    frame_deg: np.ndarray = field(default_factory=no_record)
    shape_deg: tuple[float, ...] = (0.0, 0.0)
    solves: int = 0
    max_solves: int = 0
    cuts: int = 0
    deepest_cut: int = 0
    steps_done: int = 0
    fail_step: int = -1
    fail_iter: int = 0
    growth: float = 0.0
    scatter: float = 0.0

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    @property
    def collapsed(self) -> bool:
        """The run stopped because the lateral deflection passed L/2 (or turned NaN)."""
        return self.status == "limit"

    @property
    def fail_angle_deg(self) -> float:
        return math.degrees(self.omega * max(self.fail_step, 0) * self.dt) % 360.0

    @property
    def fail_rev(self) -> int:
        return max(self.fail_step - 1, 0) // self.steps_per_rev + 1

    def peak(self, sign: int) -> tuple[float, float, int]:
        """Peak tensile (+1) or compressive (-1) axial strain [-], crank angle [deg], element (1 = crank end)."""
        flat = np.argmax(sign * self.eps_ax)
        e, j = np.unravel_index(flat, self.eps_ax.shape)
        return float(self.eps_ax[e, j]), float(self.angle_deg[j] % 360.0), int(e) + 1

    @property
    def peak_lateral(self) -> float:
        """Peak |lateral deflection from the chord| over the last revolution [m]."""
        return float(self.lat_max.max())

    def grows(self, tol: float) -> bool:
        return self.collapsed or self.growth > tol

    def buckled(self, tol: float, limit: float) -> bool:
        """Grows, or its peak lateral deflection exceeds ``limit`` [m]."""
        return self.grows(tol) or (self.ok and self.peak_lateral > limit)


IRREGULAR = 0.05
#: about this many of the rod's lateral deflection profiles are kept per recorded revolution
#: (``NLCase.frames``: the report page's animation of the deflected rod)
FRAMES_PER_REV = 180


def _half(n: int) -> int:
    return 2 * max(1, n // 6)


def _window(rev_lat: np.ndarray) -> np.ndarray:
    d = np.asarray(rev_lat, dtype=float)
    return d[-2 * _half(len(d)):]


def growth_ratio(rev_lat: np.ndarray) -> float:
    """Mean growth per revolution of the per-revolution peaks d (at least 4 values):
    (median of the last h / median of the h before)^(1/h) - 1, h = 2 max(1, len(d) // 6)."""
    d = np.asarray(rev_lat, dtype=float)
    h = _half(len(d))
    before, last = float(np.median(d[-2 * h:-h])), float(np.median(d[-h:]))
    return (last / before) ** (1.0 / h) - 1.0 if before > 0 else 0.0


def scatter(rev_lat: np.ndarray) -> float:
    """max/min - 1 of the per-revolution peaks over the growth window (0: periodic)."""
    d = _window(rev_lat)
    return float(d.max() / d.min() - 1.0) if d.min() > 0 else 0.0


def run_nl_case(model: Model, params: Params, omega: float, n_el: int, alpha: float, beta: float,
                energy: bool = False, revolutions: int | None = None) -> NLCase:
    """Integrate ``revolutions`` (default: the deck's) revolutions at crank speed omega [rad/s] and
    keep the last one; alpha [1/s], beta [s] Rayleigh damping."""
    spr = params.steps_per_rev
    revs = revolutions or params.revolutions
    dt = 2 * math.pi / (omega * spr)
    n_steps = revs * spr
    rec_start = (revs - 1) * spr
    res = kernel.slidercrank_nl_simulate(
        n_el, model.r2, model.length, model.rho_a, model.ea, model.ei, model.depth / 2, model.m_s, omega, dt,
        n_steps, spr, rec_start, spr + 1, alpha, beta, hht=params.hht_alpha, start=params.start, tol=params.newton_tolerance,
        max_iterations=params.newton_max_iterations, max_cuts=params.max_step_cuts, energy=energy,
        frame_every=max(1, spr // FRAMES_PER_REV))
    status = res["status"].name   # the kernel's status table (NonlinearStatus): 'ok', 'limit', ...
    st = res["stats"]
    case = NLCase(omega, n_el, status, dt, spr, solves=int(st[0]), max_solves=int(st[1]), cuts=int(st[2]),
                  deepest_cut=int(st[3]), steps_done=int(st[4]), fail_step=res["fail_step"],
                  fail_iter=res["fail_iter"], rev_lat=res["rev_lat"], rev_eps=res["rev_eps"])
    if status != "ok":
        return case
    steps = rec_start + np.arange(spr + 1)
    case.angle_deg = np.degrees(omega * dt * steps) - 360.0 * (revs - 1)
    case.eps_ax, case.eps_of = res["eps_ax"], res["eps_of"]
    case.lat_max, case.mid, case.energy = res["lat_max"], res["mid"], res["energy"]
    case.shapes = res["shapes"]
    case.frames = res["frames"]
    every = max(1, spr // FRAMES_PER_REV)
    case.frame_deg = 360.0 * every * np.arange(case.frames.shape[1]) / spr
    case.shape_deg = tuple(float(math.degrees(omega * dt * k) % 360.0) for k in res["shape_step"])
    case.growth = growth_ratio(case.rev_lat)
    case.scatter = scatter(case.rev_lat)
    return case


def onset_search(model: Model, params: Params, alpha: float, beta: float,
                 step: float = 0.05) -> dict[str, tuple[float, float] | None]:
    """Lowest crank speeds [rad/s] at which the nonlinear rod (``onset_elements`` elements) grows
    and at which it buckles (grows or deflects more than ``large_deflection`` x L), bracketed on the
    ``onset_speeds`` grid and bisected to ``step``: {'grows': (lo, hi) or None, 'buckled': ...},
    (lo, hi) the last speed without and the first with the verdict."""
    n = params.onset_elements
    tol, limit = params.growth_tolerance, params.large_deflection * model.length
    cache: dict[float, NLCase] = {}

    def case(w: float) -> NLCase:
        if w not in cache:
            cache[w] = run_nl_case(model, params, w, n, alpha, beta)
        return cache[w]

    def verdict(w: float, what: str) -> bool:
        c = case(w)
        if c.status not in ("ok", "limit"):
            raise ArithmeticError(f"onset search at {w:g} rad/s, {n} elements: Newton did not converge at step "
                                  f"{c.fail_step} after {c.fail_iter} solves and {c.cuts} step cuts")
        return c.grows(tol) if what == "grows" else c.buckled(tol, limit)

    grid = sorted(set(params.onset_speeds))
    out: dict[str, tuple[float, float] | None] = {}
    for what in ("buckled", "grows"):
        first = next((i for i, w in enumerate(grid) if verdict(w, what)), None)
        if first is None:
            out[what] = None
            continue
        if first == 0:
            out[what] = (0.0, grid[0])
            continue
        lo, hi = grid[first - 1], grid[first]
        while hi - lo > step:
            mid = round(0.5 * (lo + hi), 6)
            lo, hi = (lo, mid) if verdict(mid, what) else (mid, hi)
        out[what] = (lo, hi)
    return out
