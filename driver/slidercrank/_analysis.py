"""Slider-crank study: one case integrated by the kernel (fortran/slidercrank.f90), its settling
check, the static buckling onset, and the Simeon (1996) benchmark's initial state.

SI units; strains are dimensionless here (the report prints microstrain).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.linalg import LinAlgError, cholesky_banded

from driver._deck import Params
from driver.slidercrank import _kernel as kernel
from driver.slidercrank._spec import SIMEON1996, Model


def simeon_initial_state(n_elements: int, length: float) -> tuple[np.ndarray, np.ndarray]:
    """Map Simeon's published initial modal values onto the finite-element nodes.

    Lateral v(x) = q1 sin(pi x/L) + q2 sin(2 pi x/L) with rotations v'(x); axial u(x) the
    quadratic through (0, 0), (L/2, q3), (L, q4); the slider's U_X = q4 (theta3 = 0 at t = 0).

    Parameters
    ----------
    n_elements : int
        Rod elements.
    length : float
        Rod length L, m.

    Returns
    -------
    q : numpy.ndarray
        Nodal displacements and rotations in the kernel's q ordering (3 n_elements), m and rad.
    qd : numpy.ndarray
        Their rates, m/s and rad/s.
    """
    x = np.linspace(0.0, 1.0, n_elements + 1)

    def nodal(q: tuple[float, ...]) -> np.ndarray:
        v = q[0] * np.sin(np.pi * x) + q[1] * np.sin(2 * np.pi * x)
        th = (q[0] * np.pi * np.cos(np.pi * x) + q[1] * 2 * np.pi * np.cos(2 * np.pi * x)) / length
        u = q[2] * 4 * x * (1 - x) + q[3] * x * (2 * x - 1)
        out = np.zeros(3 * n_elements)
        out[0] = th[0]
        inner = np.column_stack([u[1:-1], v[1:-1], th[1:-1]]).ravel()
        out[1:1 + inner.size] = inner
        out[-2], out[-1] = th[-1], u[-1]
        return out

    return nodal(SIMEON1996["q0"]), nodal(SIMEON1996["qd0"])


def static_onset(model: Model, n_elements: int, step_deg: float = 10.0) -> tuple[float, float] | None:
    """Find the lowest constant crank speed at which the rod buckles statically.

    The speed at which the static tangent K + K_G of the rigid-body axial force loses
    definiteness at some crank angle, and that angle to the ``step_deg`` scan.

    The rigid-body axial force, hence K_G, scales with omega^2 at constant crank speed, so at
    each crank angle the onset is the largest t = omega^2 keeping K + t K_G(omega = 1) positive
    definite (bisection on the kernel's banded matrices, LAPACK Cholesky as the test); a
    ``step_deg`` scan finds the critical angle and a 1-deg scan around it the speed.  Near the
    critical angle the speed varies by ~1e-4 only and the Cholesky test is that noisy on fine
    meshes, so the speed is good to about 0.01 rad/s and the angle only to the coarse scan.

    Parameters
    ----------
    model : Model
        The rod and mechanism (SI units).
    n_elements : int
        Rod elements.
    step_deg : float, default 10.0
        Crank-angle step of the coarse scan, deg.

    Returns
    -------
    tuple of float, or None
        (crank speed in rad/s, crank angle in deg); None if the rod never buckles below
        1e6 rad/s.
    """
    args = (n_elements, model.r2, model.length, model.rho_a, model.ea, model.ei, model.m_s)

    def omega_at(theta_deg: float) -> float:
        th = math.radians(theta_deg)
        k0 = kernel.slidercrank_matrices(*args, th, 0.0, False)[1]
        g = kernel.slidercrank_matrices(*args, th, 1.0, True)[1] - k0

        def definite(t: float) -> bool:
            try:
                cholesky_banded(k0 + t * g, lower=True, check_finite=False)
            except LinAlgError:
                return False
            return True

        lo, hi = 0.0, 1.0
        while definite(hi):
            lo, hi = hi, 4.0 * hi
            if hi > 1e12:
                return math.inf
        while hi - lo > 1e-8 * hi:
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if definite(mid) else (lo, mid)
        return math.sqrt(0.5 * (lo + hi))

    grid = np.arange(0.0, 360.0, step_deg)
    w = np.array([omega_at(t) for t in grid])
    k = int(np.argmin(w))
    if not math.isfinite(w[k]):
        return None
    fine = grid[k] + np.arange(-step_deg + 1.0, step_deg - 0.5, 1.0)
    return float(min(w[k], min(omega_at(t) for t in fine))), float(grid[k] % 360.0)


def no_record() -> np.ndarray:
    """The record of a run that failed (or was not asked for): empty."""
    return np.empty(0)


@dataclass
class Case:
    """One run: crank speed, element count and its last-revolution (or end-state) results.

    The records (arrays, one value per recorded time step) are empty unless the run is ``ok``.
    Strains are dimensionless (the report prints microstrain).

    Attributes
    ----------
    omega : float
        Crank speed, rad/s.
    n_elements : int
        Rod elements.
    status : str
        ``'ok'``, ``'buckled'``, ``'diverged'``, ``'not_spd'`` ...
    dt : float
        Time step, s.
    fail_angle_deg : float or None
        Crank angle where a failed run stopped, deg.
    fail_rev : int or None
        Revolution where a failed run stopped.
    angle_deg : numpy.ndarray
        Crank angle of each recorded step, deg.
    time : numpy.ndarray
        Time of each recorded step, s.
    eps_1, eps_2 : numpy.ndarray
        Axial strain of elements 1 and 2 (at the crank end).
    eps_max, eps_min : numpy.ndarray
        Largest and smallest axial strain over the rod.
    eps_max_el, eps_min_el : numpy.ndarray
        Their (0-based) elements.
    outer_max : numpy.ndarray
        Largest outer-fibre strain.
    n_avg_1 : numpy.ndarray
        Element 1's rigid-body axial force, N.
    mid : numpy.ndarray
        Midpoint deflection of the rod from its chord, m.
    slider : numpy.ndarray
        Slider position, m.
    elong : numpy.ndarray
        Rod elongation, m.
    euler_ratio : float
        Peak rigid-body rod compression over the Euler load, dimensionless.
    peak_compression : float
        Peak rigid-body rod compression, N.
    settle_strain, settle_mid : float or None
        Change of the strain field and of the midpoint deflection between the last two
        revolutions, relative to their peak, dimensionless; None when not measured.
    """

    omega: float
    n_elements: int
    status: str
    dt: float = 0.0
    fail_angle_deg: float | None = None
    fail_rev: int | None = None
    angle_deg: np.ndarray = field(default_factory=no_record)
    time: np.ndarray = field(default_factory=no_record)
    # the per-step profile of the strain fields (what the study prints; the kernel records no
    # field, see kernel.slidercrank_simulate): element 1 and 2 axial strain [-], the largest
    # and smallest axial strain and their (0-based) elements, the largest outer-fibre strain,
    # element 1's rigid-body axial force [N]
    eps_1: np.ndarray = field(default_factory=no_record)
    eps_2: np.ndarray = field(default_factory=no_record)
    eps_max: np.ndarray = field(default_factory=no_record)
    eps_max_el: np.ndarray = field(default_factory=no_record)
    eps_min: np.ndarray = field(default_factory=no_record)
    eps_min_el: np.ndarray = field(default_factory=no_record)
    outer_max: np.ndarray = field(default_factory=no_record)
    n_avg_1: np.ndarray = field(default_factory=no_record)
    mid: np.ndarray = field(default_factory=no_record)
    slider: np.ndarray = field(default_factory=no_record)
    elong: np.ndarray = field(default_factory=no_record)
    euler_ratio: float = 0.0
    peak_compression: float = 0.0
    settle_strain: float | None = None    # relative change between the last two revolutions
    settle_mid: float | None = None

    @property
    def ok(self) -> bool:
        """True when the run completed (``status == 'ok'``)."""
        return self.status == "ok"

    def crank_end_peak(self, sign: int) -> float:
        """Find the peak axial strain at the crank pin itself (s = 0).

        Recovered by linear extrapolation of the first two element strains (midpoints L/2n,
        3L/2n); exact for a strain field linear in s.  Element averages converge as 1/n where
        N(s) varies; this converges fast.

        Parameters
        ----------
        sign : int
            +1 the peak tension, -1 the peak compression.

        Returns
        -------
        float
            The peak strain, dimensionless (signed).
        """
        e = self.eps_1 if self.n_elements < 2 else 1.5 * self.eps_1 - 0.5 * self.eps_2
        return float(np.max(sign * e) * sign)

    def peak(self, sign: int) -> tuple[float, float, int]:
        """Find the peak axial strain over the rod and where it occurs.

        Where several elements and steps reach it: the lowest element, then its first step (the
        order of numpy's argmax over the (element, step) field).

        Parameters
        ----------
        sign : int
            +1 the peak tension, -1 the peak compression.

        Returns
        -------
        strain : float
            The peak strain, dimensionless (signed).
        angle_deg : float
            Crank angle where it occurs, deg in [0, 360).
        element : int
            The element (1-based, from the crank end).
        """
        vals, els = (self.eps_max, self.eps_max_el) if sign > 0 else (self.eps_min, self.eps_min_el)
        hit = np.flatnonzero(vals == (vals.max() if sign > 0 else vals.min()))
        j = int(hit[np.argmin(els[hit])])
        return float(vals[j]), float(self.angle_deg[j] % 360.0), int(els[j]) + 1

    def outer_peak(self) -> float:
        """Find the largest outer-fibre strain over the recorded steps.

        Returns
        -------
        float
            The strain, dimensionless.
        """
        return float(self.outer_max.max())


def run_case(model: Model, params: Params, omega: float, n_el: int, alpha: float, beta: float,
              p_euler: float) -> Case:
    spr = params.steps_per_rev
    dt = 2 * math.pi / (omega * spr)
    if params.end_time > 0:
        n_steps = max(1, round(params.end_time / dt))
        dt = params.end_time / n_steps
        rec_start, n_rec = n_steps, 1
    else:
        n_steps = params.revolutions * spr
        two = params.revolutions >= 2     # record the last two revolutions to judge settling
        rec_start, n_rec = (params.revolutions - (2 if two else 1)) * spr, (2 if two else 1) * spr + 1
    start, q0, qd0 = _start_state(params.start, n_el, model.length)
    settle = params.end_time <= 0 and params.revolutions >= 2
    res = kernel.slidercrank_simulate(
        n_el, model.r2, model.length, model.rho_a, model.ea, model.ei, model.depth / 2, model.m_s, omega,
        dt, n_steps, rec_start, n_rec, alpha, beta, start=start, dynamic=params.analysis == "dynamic",
        geometric_stiffness=params.geometric_stiffness, q_init=q0, qd_init=qd0, fields=False,
        lag=spr if settle else 0)
    if settle:
        res = _settle(res, spr)
        rec_start, n_rec = rec_start + spr, spr + 1
    steps = rec_start + np.arange(n_rec)
    theta = omega * dt * steps
    # peak rod compression from rigid-body statics over the reported revolution (N is quadratic in s)
    s = np.linspace(0.0, model.length, 41)
    n_rigid = kernel.slidercrank_axial_force(theta, s, omega, model.r2, model.length, model.rho_a, model.m_s)
    peak_c = max(0.0, float(-n_rigid.min()))
    status = res["status"].name   # the kernel's status table (SimulateStatus): 'ok', 'buckled', ...
    case = Case(omega, n_el, status, dt, euler_ratio=peak_c / p_euler, peak_compression=peak_c)
    if status != "ok":
        t_fail = max(res["fail_step"], 0) * dt
        case.fail_angle_deg = math.degrees(omega * t_fail) % 360.0
        case.fail_rev = int(omega * t_fail // (2 * math.pi)) + 1
        return case
    case.time = dt * steps
    case.angle_deg = np.degrees(theta) - 360.0 * (params.revolutions - 1) if params.end_time <= 0 \
        else np.degrees(theta)
    for name in (*PROFILE, "mid", "slider", "elong"):
        setattr(case, name, res[name])
    case.settle_strain, case.settle_mid = res.get("settle_strain"), res.get("settle_mid")
    return case


#: the kernel's per-step profile entries a Case keeps (kernel.SLIDERCRANK_PROFILE)
PROFILE = ("eps_1", "eps_2", "eps_max", "eps_max_el", "eps_min", "eps_min_el", "outer_max", "n_avg_1")


def _settle(res: dict, spr: int) -> dict:
    """Split a two-revolution record: keep the last revolution, and measure how far it is from
    periodic: the largest change of the strain field and of the midpoint deflection between
    the two revolutions, relative to their peak in the last one.  The strain field's change
    is the kernel's ``lag_change`` (a revolution apart, element by element), its peak the
    largest |strain| of the last revolution."""
    out = dict(res)
    for name in (*PROFILE, "mid", "slider", "elong"):
        out[name] = res[name][spr:]

    def change(a: np.ndarray, b: np.ndarray) -> float:
        peak = float(np.abs(b).max())
        return float(np.abs(b - a).max()) / peak if peak > 0 else 0.0
    peak = max(float(np.abs(out["eps_max"]).max()), float(np.abs(out["eps_min"]).max()))
    out["settle_strain"] = float(res["lag_change"][spr:].max()) / peak if peak > 0 else 0.0
    out["settle_mid"] = change(res["mid"][:spr + 1], out["mid"])
    return out


def history(model: Model, params: Params, omega: float, n_el: int, alpha: float,
            beta: float) -> dict[str, np.ndarray]:
    """The whole time history of a benchmark run (``end_time`` > 0), for its figure: the same
    kernel call as :func:`run_case` recording every step instead of the end state only.
    Returns time [s], midpoint deflection from the chord [m], rod elongation [m], slider
    position [m]; empty arrays when the run stops early."""
    dt = 2 * math.pi / (omega * params.steps_per_rev)
    n_steps = max(1, round(params.end_time / dt))
    dt = params.end_time / n_steps
    start, q0, qd0 = _start_state(params.start, n_el, model.length)
    res = kernel.slidercrank_simulate(
        n_el, model.r2, model.length, model.rho_a, model.ea, model.ei, model.depth / 2, model.m_s, omega,
        dt, n_steps, 0, n_steps + 1, alpha, beta, start=start, dynamic=params.analysis == "dynamic",
        geometric_stiffness=params.geometric_stiffness, q_init=q0, qd_init=qd0, fields=False)
    if res["status"] != kernel.SLIDERCRANK_STATUS["ok"]:
        return {k: np.empty(0) for k in ("time", "mid", "elong", "slider")}
    return {"time": dt * np.arange(n_steps + 1), "mid": np.asarray(res["mid"]), "elong": np.asarray(res["elong"]),
            "slider": np.asarray(res["slider"])}


def _start_state(start: str, n_el: int, length: float) -> tuple[str, np.ndarray | None, np.ndarray | None]:
    """(kernel start mode, q0, qd0) for the deck's ``start``: Simeon's benchmark gives its own
    initial state to the kernel as 'given'; every other mode starts from the kernel's own state."""
    if start == "simeon1996":
        q0, qd0 = simeon_initial_state(n_el, length)
        return "given", q0, qd0
    return start, None, None
