"""Hooke-joint study: one design evaluated, and the SLSQP multi-start of options 1-3.

Every figure comes from the kernel (fortran/ujoint.f90 through driver._fortran); the angles of a
:class:`Design` are degrees, the kernel and the optimiser work in radians.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from driver import _blas as blas
from driver._deck import Params
from driver.ujoint._kernel import (
    UJOINT_CV_TOL,
    UJOINT_MODELS,
    UJOINT_OBJECTIVES,
    UJOINT_PASSES,
    UJOINT_SUMMARY_COLUMNS,
    ujoint_equivalent,
    ujoint_input_torque,
    ujoint_jet,
    ujoint_objective,
    ujoint_roots,
    ujoint_speed,
    ujoint_summaries,
)
from driver.ujoint._spec import DEG, loads, origin_deg

#: phases within this of a symmetric assembly count as sitting on it [rad]
SYM_TOL = 1e-7
#: how far a start is moved off the symmetric saddle [deg]
SADDLE_NUDGE = 1.0


#: the phases repeat every half turn (each joint's ratio depends on sin^2 of its input angle)
PHASE_PERIOD = 180.0
#: optima within this relative difference of the best objective tie (the mirror optima of a
#: symmetric chain differ only by rounding); ties are broken by TIE RULE in :func:`pick_best`
TIE_RTOL = 1e-6
#: tied end points closer than this are one optimum [deg] (the tie rule then takes the most
#: converged of them, so the reported digits do not depend on which start stopped first)
CLUSTER_TOL = 0.05
#: a start that ends within this of a bound counts as ended on it [rad]
BOUND_TOL = 1e-7


@dataclass
class Chain:
    """Fixed description of a run: model code, objective code, plane angles, grid.

    Attributes
    ----------
    model : int
        Model code (``driver.ujoint._kernel.UJOINT_MODELS``: eq13, cumulative, exact).
    kind : int
        Objective code (``UJOINT_OBJECTIVES``: mean_square, rms, peak_to_peak).
    rho : numpy.ndarray
        (n-1,) angles between the planes of successive joints, rad.
    m : int
        Input angles per revolution of the grid.
    rpm : float
        Input shaft speed, rpm.
    origin : float, default 0.0
        The kernel's input angle at the deck's theta = 0, deg (0: angle_origin 'normal', the
        kernel's own; 90: 'plane').
    load : tuple of float or None, default None
        The output shaft's moment of inertia [kg m^2] and load torque [N m]; None: no load given.
    """

    model: int
    kind: int
    rho: np.ndarray          # (n-1,) rad
    m: int                   # grid points per revolution
    rpm: float
    origin: float = 0.0      # deg
    load: tuple[float, float] | None = None

    @property
    def omega(self) -> float:
        """Input speed [rad/s]."""
        return self.rpm * 2.0 * math.pi / 60.0

    def kernel_rad(self, theta_deg) -> np.ndarray:
        """Convert the deck's input angles to the kernel's.

        Parameters
        ----------
        theta_deg : array_like
            Input angles from the deck's ``angle_origin``, deg.

        Returns
        -------
        numpy.ndarray
            The same angles from the normal to joint 1's plane (the kernel's origin), rad.
        """
        return (np.asarray(theta_deg, float) + self.origin) * DEG

    def deck_deg(self, theta_rad, period: float = 360.0) -> np.ndarray:
        """Convert the kernel's input angles to the deck's.

        Parameters
        ----------
        theta_rad : array_like
            Input angles from the normal to joint 1's plane (the kernel's origin), rad.
        period : float, default 360.0
            The period to reduce them to, deg (180: the speed ratio's period).

        Returns
        -------
        numpy.ndarray
            The same angles from the deck's ``angle_origin``, deg in [0, period).
        """
        d = np.mod(np.asarray(theta_rad, float) / DEG - self.origin, period)
        return np.where(d >= period - 1e-9, 0.0, d)


@dataclass
class Design:
    """One design evaluated: its angles and performance figures.

    R = omega_out / omega_in is the speed ratio of the chain over one input revolution.

    Attributes
    ----------
    label : str
        ``'trial'``, ``'optimum'``, ``'paper'``, ``'design'`` ...
    beta : numpy.ndarray
        Joint operating angles, deg.
    phi : numpy.ndarray
        Phases, deg (the paper's convention: 90 deg = yokes in phase).
    objective : float
        The run's objective of R (mean square, RMS or peak-to-peak of R - 1), dimensionless.
    u_rpm2 : float
        The paper's U: mean (R - 1)^2 times the input speed squared, rpm^2.
    pp : float
        Peak-to-peak ratio max R - min R, dimensionless.
    w_min, w_max : float
        Output speed band at the input speed, rpm.
    beta_e : float
        Closed-form equivalent angle of the chain, deg.
    beta_res : float or None
        Resultant angle, deg; None where undefined.
    peak_acc : float
        Peak output angular acceleration at constant input speed, rad/s^2 (its magnitude,
        found to 1e-12 rad by the kernel's root finding on the closed form).
    mean_ratio : float
        Mean of R over the revolution (1 for a closed chain), dimensionless.
    peak_acc_at : float or None
        The input angle of ``peak_acc`` (the first where it peaks), deg from the deck's origin;
        None for a constant-velocity chain.
    ratio_one_at : float or None
        The first input angle in [0, 180) deg (R has period 180 deg) where R = 1, deg from the
        deck's origin; None when R - 1 keeps its sign (a constant-velocity chain).
    extra : dict
        Further figures of the design.
    """

    label: str
    beta: np.ndarray         # deg
    phi: np.ndarray          # deg (paper convention)
    objective: float = 0.0
    u_rpm2: float = 0.0
    pp: float = 0.0
    w_min: float = 0.0
    w_max: float = 0.0
    beta_e: float = 0.0
    beta_res: float | None = None
    peak_acc: float = 0.0
    mean_ratio: float = 1.0
    peak_acc_at: float | None = None
    ratio_one_at: float | None = None
    extra: dict = field(default_factory=dict)


def yoke_shifts(model: int, phi_deg) -> np.ndarray:
    """Convert a design's phases to the phase shifts between successive joints.

    In the cumulative/exact convention the shift is phi itself; under eq. 13 as printed it is
    phi_k - phi_(k-1) (there phi_k is the absolute phase of joint k+1).

    Parameters
    ----------
    model : int
        Model code (``driver.ujoint._kernel.UJOINT_MODELS``).
    phi_deg : array_like
        The design's phases, deg.

    Returns
    -------
    numpy.ndarray
        The shifts between joints k and k+1, deg.
    """
    phi = np.asarray(phi_deg, float)
    return np.diff(phi, prepend=0.0) if model == UJOINT_MODELS["eq13"] else phi


def phases_for(model: int, shifts_deg) -> np.ndarray:
    """Convert phase shifts back to a model's phases (the inverse of :func:`yoke_shifts`).

    Parameters
    ----------
    model : int
        Model code (``driver.ujoint._kernel.UJOINT_MODELS``).
    shifts_deg : array_like
        Phase shifts between joints k and k+1, deg.

    Returns
    -------
    numpy.ndarray
        The phases, deg: the same physical assembly in ``model``'s convention.
    """
    s = np.asarray(shifts_deg, float)
    return np.cumsum(s) if model == UJOINT_MODELS["eq13"] else s


def evaluate(chain: Chain, label: str, beta_deg, phi_deg, model: int | None = None) -> Design:
    """Evaluate one design: every headline figure under ``chain``.

    Parameters
    ----------
    chain : Chain
        The run's model, objective, plane angles, grid and input speed.
    label : str
        The design's name in the report (``'trial'``, ``'optimum'`` ...).
    beta_deg : array_like
        Joint operating angles, deg.
    phi_deg : array_like
        Phases (the paper's convention), deg.
    model : int, optional
        A model code overriding the chain's.

    Returns
    -------
    Design
        The figures: objective (dimensionless), speed band (rpm), equivalent angles (deg),
        peak output acceleration (rad/s^2).
    """
    model = chain.model if model is None else model
    b = np.asarray(beta_deg, float) * DEG
    ph = np.asarray(phi_deg, float) * DEG
    f, _ = ujoint_objective(model, chain.kind, b, ph, chain.rho, chain.m, grad=False)
    ms, _ = ujoint_objective(model, UJOINT_OBJECTIVES["mean_square"], b, ph, chain.rho, chain.m, grad=False)
    theta = np.arange(chain.m) * (2.0 * math.pi / chain.m)
    ratio, dratio, _ = ujoint_speed(model, b, ph, chain.rho, theta)
    be, br = ujoint_equivalent(model, b, ph, chain.rho)
    # the peak acceleration and the first angle of R = 1 by the summary kernel's root finding
    # (the same bits as a sweep's batch row)
    row = dict(zip(UJOINT_SUMMARY_COLUMNS, ujoint_summaries(
        model, chain.kind, b[None, :], ph[None, :], None if b.size < 2 else np.asarray(chain.rho)[None, :],
        chain.m, passes=UJOINT_PASSES["speed"], theta0=chain.origin * DEG)[0]))
    return Design(label, np.asarray(beta_deg, float), np.asarray(phi_deg, float), float(f),
                  float(ms * chain.rpm ** 2), float(ratio.max() - ratio.min()),
                  float(chain.rpm * ratio.min()), float(chain.rpm * ratio.max()), be / DEG,
                  None if br is None else br / DEG, float(chain.omega ** 2 * row["dratio_abs_max"]),
                  float(ratio.mean()),
                  None if row["dratio_abs_max_at"] < 0 else float(chain.deck_deg(row["dratio_abs_max_at"])),
                  None if row["ratio_one_at"] < 0 else float(chain.deck_deg(row["ratio_one_at"], 180.0)))


@dataclass
class StartRun:
    """Outcome of one SLSQP start.

    Attributes
    ----------
    x0, x : numpy.ndarray
        Start and end point of the free variables, rad.
    f : float
        The objective at ``x`` (not scaled), dimensionless.
    nit, nfev, njev : int
        SLSQP iterations, objective and gradient evaluations.
    success : bool
        SLSQP converged.
    message : str
        SLSQP's words.
    on_bound : numpy.ndarray
        Indices of the free variables that end on a bound.
    """

    x0: np.ndarray
    x: np.ndarray
    f: float
    nit: int
    nfev: int
    njev: int
    success: bool
    message: str
    on_bound: np.ndarray = field(default_factory=lambda: np.empty(0, int))  # free-variable indices


def _symmetric(chain: Chain, phi_rad: np.ndarray) -> bool:
    """True when every phase shift is a multiple of 90 deg: the theta -> -theta symmetric
    assembly where the phase gradient vanishes identically (a saddle or a maximum)."""
    shift = phi_rad - (chain.rho if chain.model == UJOINT_MODELS["exact"] else 0.0)
    q = shift / (0.5 * math.pi)
    return bool(np.all(np.abs(q - np.round(q)) * 0.5 * math.pi < SYM_TOL))


def optimise(chain: Chain, option: int, beta0: np.ndarray, phi0: np.ndarray,
             lb: np.ndarray, ub: np.ndarray, starts: np.ndarray, maxiter: int,
             ftol: float, scale: float, progress: bool = False) -> list[StartRun]:
    """Minimise the objective by SLSQP from every start, with the kernel's gradient.

    The objective is divided by ``scale`` (:func:`objective_scale`, never 0) so ``ftol`` is
    relative.  Phases whose bounds span a period are searched unbounded and wrapped into
    [lb, lb + 180 deg): a bound there is no stopping point.

    Parameters
    ----------
    chain : Chain
        The run's model, objective, plane angles, grid and input speed.
    option : int
        1 phases free, 2 angles free, 3 both.
    beta0, phi0 : numpy.ndarray
        Joint angles and phases holding the fixed variables, rad.
    lb, ub : numpy.ndarray
        Bounds of the free variables, rad.
    starts : numpy.ndarray
        (starts, free variables) start points, rad; row 0 the trial point.
    maxiter : int
        SLSQP iteration limit per start.
    ftol : float
        SLSQP tolerance on the scaled objective, dimensionless.
    scale : float
        The objective's scale (:func:`objective_scale`).
    progress : bool, default False
        Show a progress bar on the terminal.

    Returns
    -------
    list of StartRun
        One per start, in the order of ``starts``.
    """
    n = beta0.size
    free = free_index(option, n)

    def full(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        z = np.concatenate([beta0, phi0])
        z[free] = x
        return z[:n], z[n:]

    fref = scale

    def fun(x: np.ndarray) -> tuple[float, np.ndarray]:
        b, p = full(x)
        f, g = ujoint_objective(chain.model, chain.kind, b, p, chain.rho, chain.m)
        return f / fref, g[free] / fref

    periodic = _periodic(option, n, lb, ub)
    bounds = [(None, None) if per else (a, b) for per, a, b in zip(periodic, lb, ub)]
    runs = []
    # imported here, by the options that optimise (an option-0 run needs neither); then the BLAS
    # library scipy brought is limited to one thread too (driver._blas)
    from scipy.optimize import minimize
    from tqdm import tqdm
    with blas.one_thread():
        results = [minimize(fun, x0, jac=True, method="SLSQP", bounds=bounds, options={"maxiter": maxiter, "ftol": ftol})
                   for x0 in tqdm(starts, desc="multi-start", unit="start", disable=not progress)]
    for x0, res in zip(starts, results):
        x = np.where(periodic, lb + np.mod(res.x - lb, PHASE_PERIOD * DEG), np.clip(res.x, lb, ub))
        f = ujoint_objective(chain.model, chain.kind, *full(x), chain.rho, chain.m, grad=False)[0]
        on_bound = ~periodic & (lb < ub) & ((x - lb < BOUND_TOL) | (ub - x < BOUND_TOL))
        runs.append(StartRun(x0, x, float(f), int(res.nit), int(res.nfev), int(getattr(res, "njev", 0)),
                             bool(res.success), str(res.message), np.flatnonzero(on_bound)))
    return runs


def _periodic(option: int, n: int, lb: np.ndarray, ub: np.ndarray) -> np.ndarray:
    """Which free variables are phases whose bounds span a whole period (searched unbounded)."""
    is_phase = free_index(option, n) >= n
    return is_phase & (ub - lb >= PHASE_PERIOD * DEG * (1.0 - 1e-12))


def objective_scale(chain: Chain, f_trial: float, beta_max_deg: float) -> float:
    """Choose the objective's scale, which cannot vanish.

    Parameters
    ----------
    chain : Chain
        The run's model, objective, plane angles, grid and input speed.
    f_trial : float
        The objective at the trial point, dimensionless.
    beta_max_deg : float
        The largest joint angle the run can reach, deg.

    Returns
    -------
    float
        The larger of ``f_trial`` and a single joint's objective at ``beta_max_deg`` (1 if
        that is 0), dimensionless.
    """
    b = np.array([abs(beta_max_deg) * DEG])
    ref = ujoint_objective(chain.model, chain.kind, b, None, None, chain.m, grad=False)[0]
    scale = max(f_trial, ref)
    return scale if scale > 0.0 else 1.0


def pick_best(runs: list[StartRun], n_beta: int) -> int:
    """Pick the reported optimum among the starts by the (deterministic) tie rule.

    Converged starts within TIE_RTOL (relative) of the best objective tie (mirror optima
    agree to rounding; along a continuous family of optima the most converged start wins).
    Among them the trial start (index 0) wins if it is there (so feeding an optimum back as
    the trial reproduces it); otherwise the smallest phases, compared
    lexicographically at 1e-6 deg, then the smallest joint angles; the tied starts within
    CLUSTER_TOL of that end point are one optimum, and the one of them with the lowest
    objective is reported (then the start order).  With no converged start, the lowest
    objective (a last iterate, reported as such).

    Parameters
    ----------
    runs : list of StartRun
        The starts' outcomes (index 0 the trial start).
    n_beta : int
        Number of joint angles among the variables.

    Returns
    -------
    int
        Index into ``runs`` of the reported optimum.
    """
    ok = [k for k, r in enumerate(runs) if r.success]
    if not ok:
        return min(range(len(runs)), key=lambda k: runs[k].f)
    fbest = min(runs[k].f for k in ok)
    tied = [k for k in ok if runs[k].f <= fbest + TIE_RTOL * abs(fbest)]
    if 0 in tied:
        return 0

    def key(k: int) -> tuple:
        x = np.round(runs[k].x / DEG, 6)
        return (*x[n_beta:], *x[:n_beta], k)
    first = runs[min(tied, key=key)].x
    same = [k for k in tied if _distance_deg(runs[k].x, first, n_beta) < CLUSTER_TOL]
    return min(same, key=lambda k: (runs[k].f, k))


def _distance_deg(x: np.ndarray, y: np.ndarray, n_beta: int) -> float:
    """Largest difference between two points of the free variables [deg], phases modulo 180."""
    d = np.abs(x - y) / DEG
    d[n_beta:] = np.minimum(d[n_beta:] % PHASE_PERIOD, PHASE_PERIOD - d[n_beta:] % PHASE_PERIOD)
    return float(d.max(initial=0.0))


def free_index(option: int, n: int) -> np.ndarray:
    """Indices of the free variables in [beta_1..beta_n, phi_1..phi_(n-1)]."""
    return {1: np.arange(n, 2 * n - 1), 2: np.arange(n), 3: np.arange(2 * n - 1)}[option]


def chain_of(params: Params, rho_deg: np.ndarray | None, n: int, model: str | None = None) -> Chain:
    model = model or (params.model if params.model == "exact" else params.phasing)
    rho = np.zeros(n - 1) if rho_deg is None else np.asarray(rho_deg, float) * DEG
    return Chain(UJOINT_MODELS[model], UJOINT_OBJECTIVES[params.objective], rho, params.n_grid, params.rpm,
                 origin_deg(params), loads(params))


def start_points(params: Params, option: int, beta: np.ndarray, phi: np.ndarray, lb: np.ndarray,
            ub: np.ndarray, chain: Chain) -> tuple[np.ndarray, list[str]]:
    """Start points [rad] (trial first, clipped into the bounds) and notes on what was done."""
    n = beta.size
    free = free_index(option, n)
    x_trial = np.concatenate([beta, phi])[free] * DEG
    notes = []
    x0 = np.clip(x_trial, lb, ub)
    names = [f"beta_{k + 1}" for k in range(n)] + [f"phi_{k + 1}" for k in range(n - 1)]
    for j in np.flatnonzero(x0 != x_trial):
        notes.append(f"trial {names[free[j]]} = {x_trial[j] / DEG:g} deg lies outside its bounds "
                     f"[{lb[j] / DEG:g}, {ub[j] / DEG:g}]; the search starts from {x0[j] / DEG:g} "
                     "(fmincon would have started infeasible)")
    nph = int(np.sum(free >= n))
    if nph:
        ph_full = np.concatenate([beta, phi])[n:] * DEG
        ph_full[free[free >= n] - n] = x0[free >= n]
        if _symmetric(chain, ph_full):
            iph = np.flatnonzero(free >= n)
            step = SADDLE_NUDGE * DEG
            x0[iph] = np.where(x0[iph] + step <= ub[iph], x0[iph] + step, x0[iph] - step)
            notes.append(f"the trial phases sit on the symmetric assembly (all shifts multiples of "
                         f"90 deg) where the phase gradient vanishes identically (a saddle for "
                         f"free phases); start 1 is moved {SADDLE_NUDGE:g} deg off it")
    rng = np.random.default_rng(params.seed)
    rand = lb + (ub - lb) * rng.random((params.n_starts - 1, lb.size))
    return np.vstack([x0, rand]), notes


def output_speed(chain: Chain, d: Design, theta_deg: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(omega_out [rpm], alpha_out [rad/s^2], theta_out [deg]) of design d at the deck's input
    angles theta_deg (from its angle_origin; theta_out from the same origin)."""
    r, dr, to = ujoint_speed(chain.model, d.beta * DEG, d.phi * DEG, chain.rho, chain.kernel_rad(theta_deg))
    return chain.rpm * r, chain.omega ** 2 * dr, to / DEG - chain.origin


def input_torque(chain: Chain, d: Design, theta_deg: np.ndarray) -> np.ndarray:
    """Input torque [N m] of design d at the deck's input angles theta_deg [deg] that drives the
    output shaft's load (``chain.load``) at constant input speed (zeros without a load)."""
    if chain.load is None:
        return np.zeros(np.shape(theta_deg))
    t, _ = ujoint_input_torque(chain.model, d.beta * DEG, d.phi * DEG, chain.rho, chain.kernel_rad(theta_deg),
                               chain.omega, *chain.load)
    return t


@dataclass
class Textbook:
    """The figures a textbook asks of a Hooke-joint chain, each found by root finding on the
    kernel's closed form (1e-12 rad): angles in deg from the deck's origin, in [0, 360).

    Attributes
    ----------
    ratio_one : numpy.ndarray
        The input angles where omega_out = omega_in (R = 1), deg; none for a chain whose
        fluctuation is below :data:`PP_SHOWN` (``uniform``).
    accel_peak : float
        The peak magnitude of the output angular acceleration at constant input speed, rad/s^2.
    accel_peak_at : numpy.ndarray
        The input angles where it is reached (within 1e-9 of it), deg.
    accel_peak_signed : numpy.ndarray
        The signed output acceleration there, rad/s^2.
    torque_peak, torque_mean : float or None
        With a load: the peak magnitude and the mean of the input torque over a turn, N m.
    torque_peak_at : numpy.ndarray
        The input angles of the torque peak, deg.
    torque_peak_signed : numpy.ndarray
        The signed input torque there, N m.
    """

    ratio_one: np.ndarray
    accel_peak: float
    accel_peak_at: np.ndarray
    accel_peak_signed: np.ndarray
    torque_peak: float | None = None
    torque_mean: float | None = None
    torque_peak_at: np.ndarray = field(default_factory=lambda: np.empty(0))
    torque_peak_signed: np.ndarray = field(default_factory=lambda: np.empty(0))
    uniform: bool = False   #: constant velocity to the printed p-p ratio (below :data:`PP_SHOWN`)


#: a design whose speed-ratio fluctuation (max R - min R) is below this counts as a constant-velocity
#: chain for its textbook figures: the .out prints the p-p ratio to six decimals, and an optimum's
#: residual fluctuation below that (1e-10 after SLSQP) is round-off of its phases, so the angles where
#: R crosses one moved with the BLAS kernel; it is also the objective's resolution (3.8e-14 ~ pp^2/8)
PP_SHOWN = 5e-7
assert PP_SHOWN > UJOINT_CV_TOL

#: extremes within this relative difference of the largest count as the same peak (the mirror and
#: half-turn images of one peak, equal but for round-off)
PEAK_RTOL = 1e-9


def textbook(chain: Chain, d: Design) -> Textbook:
    """Where design d's speed ratio is one, where and how high its output acceleration peaks,
    and with a load the peak and mean input torque over a turn (:class:`Textbook`)."""
    b, ph = d.beta * DEG, d.phi * DEG
    uniform = d.pp < PP_SHOWN   # constant velocity to the printed p-p ratio: no crossing or peak resolved
    one = np.empty(0) if uniform else np.sort(chain.deck_deg(ujoint_roots(chain.model, "ratio_one", b, ph,
                                                                          chain.rho, chain.m)))
    ext = np.empty(0) if uniform else ujoint_roots(chain.model, "accel_extreme", b, ph, chain.rho, chain.m)
    _, r1, _ = ujoint_jet(chain.model, b, ph, chain.rho, ext)
    acc = chain.omega ** 2 * r1
    top = float(np.abs(acc).max()) if acc.size else 0.0
    at = np.abs(acc) >= top * (1.0 - PEAK_RTOL) if top > 0 else np.zeros(acc.size, bool)
    order = np.argsort(chain.deck_deg(ext[at]))
    tb = Textbook(one, top, chain.deck_deg(ext[at])[order], acc[at][order], uniform=uniform)
    if chain.load is not None:
        inertia, load = chain.load
        coef = (inertia * chain.omega ** 2, load)
        tx = ujoint_roots(chain.model, "torque_extreme", b, ph, chain.rho, chain.m, coef)
        grid = np.arange(chain.m) * (2.0 * math.pi / chain.m)
        t_ext, _ = ujoint_input_torque(chain.model, b, ph, chain.rho, tx, chain.omega, inertia, load)
        t_grid, _ = ujoint_input_torque(chain.model, b, ph, chain.rho, grid, chain.omega, inertia, load)
        tb.torque_mean = float(t_grid.mean())   # the trapezoid rule of a periodic function
        if t_ext.size and np.abs(t_ext).max() >= np.abs(t_grid).max():
            peak = float(np.abs(t_ext).max())
            hit = np.abs(t_ext) >= peak * (1.0 - PEAK_RTOL)
            angles, signed = chain.deck_deg(tx[hit]), t_ext[hit]
        else:   # a torque constant over the turn (no load inertia, no fluctuation): the grid's
            peak = float(np.abs(t_grid).max())
            hit = np.abs(t_grid) >= peak * (1.0 - PEAK_RTOL)
            angles, signed = chain.deck_deg(grid[hit]), t_grid[hit]
        order = np.argsort(angles)
        tb.torque_peak, tb.torque_peak_at, tb.torque_peak_signed = peak, angles[order], signed[order]
    return tb
