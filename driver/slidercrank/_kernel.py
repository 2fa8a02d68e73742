"""The slidercrank study's kernel wrappers: slidercrank.f90 (the linear KED model: Newmark time loop, element matrices,
rigid kinematics, frequencies) and slidercrank_nl.f90 (the nonlinear co-rotational rod).

Thin wrappers over the study's modules of the compiled extension (loaded once by
:mod:`driver._fortran`): inputs are converted once to Fortran-ordered float64 (f2py would
otherwise copy C-ordered 2-D arrays silently), nothing is looped in Python, numpy arrays come
back.  Each kernel's physics and units are documented in its Fortran source.
"""
from __future__ import annotations

from enum import IntEnum
from typing import TYPE_CHECKING, Any

import numpy as np

from driver._docs import fill_doc
from driver._fortran import KernelStatus, farray, kernel_status

if TYPE_CHECKING:   # the study's modules of the extension, typed (generated: tools/gen_kernel_stub.py)
    from driver.slidercrank import _kernels
else:
    from driver._fortran import _kernels

__all__ = ['SimulateStatus', 'NonlinearStatus', 'Shape', 'SLIDERCRANK_STATUS', 'SLIDERCRANK_PROFILE', 'slidercrank_simulate',
           'slidercrank_matrices', 'slidercrank_rigid', 'slidercrank_axial_force', 'slidercrank_frequencies',
           'SLIDERCRANK_NL_STATUS', 'slidercrank_nl_simulate', 'slidercrank_column_static',
           'slidercrank_corot_element']


class SimulateStatus(KernelStatus):
    """Status word of the linear rod's time loop (fortran/slidercrank.f90 ``st_*``).

    Each with the words a report prints for it; ``bad_args`` (the kernel refused its call) raises.
    """

    ok = int(_kernels.slidercrank.st_ok), "ok"
    buckled = int(_kernels.slidercrank.st_buckled), "STATIC INSTABILITY", "K + K_G lost definiteness (the rod buckles)"
    diverged = (int(_kernels.slidercrank.st_diverged), "LIMIT L/20",
                "elastic deflection exceeded L/20 (or a rotation 0.25 rad): the linear model is no longer valid")
    not_spd = int(_kernels.slidercrank.st_not_spd), "NOT SPD", "the iteration matrix is not positive definite"
    bad_args = int(_kernels.slidercrank.st_bad_args), "BAD ARGUMENTS", "the kernel refused its arguments", True


#: the linear rod's status codes by name (``SLIDERCRANK_STATUS["ok"]``): :class:`SimulateStatus`
SLIDERCRANK_STATUS: type[SimulateStatus] = SimulateStatus
_SC_START = {"rest": 0, "quasistatic": 1, "given": 2}


#: rows of slidercrank_simulate's per-step profile (fortran/slidercrank.f90 prof_*)
SLIDERCRANK_PROFILE = ("eps_1", "eps_2", "eps_max", "eps_max_el", "eps_min", "eps_min_el", "outer_max",
                       "n_avg_1", "lag_change")


_doc = fill_doc(
    rod="""n_elements : int
        Rod elements.
    crank_radius : float
        Crank radius, m.
    rod_length : float
        Rod length, m.
    rho_a : float
        Rod mass per unit length, kg/m.
    ea : float
        Axial stiffness E A, N.
    ei : float
        Bending stiffness E I, N m^2.""",
    motion="""half_depth : float
        Half the in-plane section depth (the outer fibre), m.
    slider_mass : float
        Mass on the guide, kg.
    omega : float
        Crank speed, rad/s (theta2 = omega t from 0).
    dt : float
        Time step, s.
    n_steps : int
        Time steps.""",
)


@_doc
def slidercrank_simulate(n_elements: int, crank_radius: float, rod_length: float, rho_a: float,
                         ea: float, ei: float, half_depth: float, slider_mass: float, omega: float,
                         dt: float, n_steps: int, rec_start: int, n_rec: int, alpha: float = 0.0,
                         beta: float = 0.0, start: str = "quasistatic", dynamic: bool = True,
                         geometric_stiffness: bool = False, fast: bool = True,
                         q_init: np.ndarray | None = None, qd_init: np.ndarray | None = None,
                         fields: bool = True, lag: int = 0) -> dict:
    """Simulate the elastic connecting rod of a slider-crank: the whole time loop in Fortran.

    SI units throughout.  Records steps rec_start .. rec_start + n_rec - 1 (step 0 is the
    start).

    Parameters
    ----------
    %(rod)s
    %(motion)s
    rec_start, n_rec : int
        First recorded step and the number recorded.
    alpha : float, default 0.0
        Mass-proportional Rayleigh coefficient, 1/s (C = alpha M + beta K).
    beta : float, default 0.0
        Stiffness-proportional Rayleigh coefficient, s.
    start : {'quasistatic', 'rest', 'given'}, default 'quasistatic'
        Initial state; 'given' takes ``q_init`` and ``qd_init``.
    dynamic : bool, default True
        Newmark integration; False solves K u = Q quasi-statically at every step.
    geometric_stiffness : bool, default False
        Add K_G of the rigid-body axial force.
    fast : bool, default True
        Use the constant-leading-block Schur path when there is no geometric stiffness.
    q_init, qd_init : numpy.ndarray, optional
        Initial state in the kernel's q ordering, 3 n_elements values, m and rad (and per s).
    fields : bool, default True
        Record the whole strain and force fields (else only the per-step profile).
    lag : int, default 0
        With lag > 0 also ``lag_change`` (see Returns).

    Returns
    -------
    dict
        The records, as listed below.

    Notes
    -----
    The dict holds: eps_ax, eps_of (n_elements, n_rec) axial and outer-fibre strain [-];
    n_avg (n_elements, n_rec) element-averaged rigid-body axial force [N] -- these three only
    with ``fields`` (else None: a study that prints the profile below need not record 3 x 8
    bytes per element and step); mid midpoint deflection from the chord [m]; slider position
    [m]; elong rod elongation [m]; the per-step profile of the fields, always: eps_1, eps_2
    axial strain of elements 1 and 2, eps_max / eps_min the largest / smallest axial strain
    with eps_max_el / eps_min_el the (first, 0-based) element holding it, outer_max the
    largest outer-fibre strain, n_avg_1 element 1's rigid-body force [N], and with ``lag`` > 0
    lag_change: max over elements of |eps_ax[:, j] - eps_ax[:, j - lag]| (0 for j < lag);
    q_end, qd_end final state; status (a :class:`SimulateStatus`) and fail_step.
    """
    nq = 3 * int(n_elements)
    q0 = farray(np.zeros(nq) if q_init is None else q_init, 1)
    qd0 = farray(np.zeros(nq) if qd_init is None else qd_init, 1)
    out = _kernels.slidercrank.simulate(
        int(n_elements), int(n_rec), int(n_rec) if fields else 0, crank_radius, rod_length, rho_a, ea, ei,
        half_depth, slider_mass, omega, dt, int(n_steps), int(rec_start), alpha, beta, _SC_START[start],
        int(bool(dynamic)), int(bool(geometric_stiffness)), int(bool(fast)), int(lag), q0, qd0)
    names = ("eps_ax", "eps_of", "n_avg", "mid", "slider", "elong", "prof", "q_end", "qd_end", "status",
             "fail_step")
    res: dict[str, Any] = dict(zip(names, out))   # arrays and the integer status words
    res["status"] = kernel_status(SimulateStatus, res["status"], "slidercrank.simulate")
    res["fail_step"] = int(res["fail_step"])
    prof = res.pop("prof")
    for k, name in enumerate(SLIDERCRANK_PROFILE):
        res[name] = prof[k]
    res["eps_max_el"] = res["eps_max_el"].astype(np.int64) - 1
    res["eps_min_el"] = res["eps_min_el"].astype(np.int64) - 1
    if not lag:
        del res["lag_change"]
    if not fields:
        res["eps_ax"] = res["eps_of"] = res["n_avg"] = None
    return res


@_doc
def slidercrank_matrices(n_elements: int, crank_radius: float, rod_length: float, rho_a: float,
                         ea: float, ei: float, slider_mass: float, theta2: float, omega: float = 0.0,
                         geometric_stiffness: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Assemble the banded mass and stiffness matrices at one crank angle.

    The mass includes the slider mass on U_X; with geometric_stiffness the stiffness includes
    K_G of the rigid-body axial force at crank speed omega.

    Parameters
    ----------
    %(rod)s
    slider_mass : float
        Mass on the guide, kg.
    theta2 : float
        Crank angle, rad.
    omega : float, default 0.0
        Crank speed, rad/s.
    geometric_stiffness : bool, default False
        Include K_G.

    Returns
    -------
    mass : numpy.ndarray
        (6, 3 n) banded mass, LAPACK lower band storage: kg, kg m or kg m^2 as an entry
        couples translations and rotations.
    stiffness : numpy.ndarray
        (6, 3 n) banded stiffness, the same storage: N/m, N or N m likewise.
    """
    mb, kb = _kernels.slidercrank.assemble_matrices(
        int(n_elements), 3 * int(n_elements), crank_radius, rod_length, rho_a, ea, ei, slider_mass,
        theta2, omega, int(bool(geometric_stiffness)))
    return mb, kb


def slidercrank_rigid(theta2: np.ndarray, omega: float, crank_radius: float, rod_length: float) -> np.ndarray:
    """Compute the rigid-body kinematics at constant crank speed.

    Parameters
    ----------
    theta2 : numpy.ndarray
        Crank angles, rad.
    omega : float
        Crank speed, rad/s.
    crank_radius : float
        Crank radius, m.
    rod_length : float
        Rod length, m.

    Returns
    -------
    numpy.ndarray
        (n, 7): theta3 [rad], theta3' [rad/s], theta3'' [rad/s^2], slider position x4 [m],
        slider acceleration A_h [m/s^2], crank-pin acceleration along and across the rod
        [m/s^2].
    """
    theta2 = farray(np.atleast_1d(theta2), 1)
    return _kernels.slidercrank.rigid_states(theta2, omega, crank_radius, rod_length)


def slidercrank_axial_force(theta2: np.ndarray, s: np.ndarray, omega: float, crank_radius: float,
                            rod_length: float, rho_a: float, slider_mass: float) -> np.ndarray:
    """Compute the rigid-body axial force along the rod.

    Parameters
    ----------
    theta2 : numpy.ndarray
        Crank angles, rad.
    s : numpy.ndarray
        Stations along the rod from the crank pin, m.
    omega : float
        Crank speed, rad/s.
    crank_radius : float
        Crank radius, m.
    rod_length : float
        Rod length, m.
    rho_a : float
        Rod mass per unit length, kg/m.
    slider_mass : float
        Mass on the guide, kg.

    Returns
    -------
    numpy.ndarray
        (len(s), len(theta2)) axial force N, newtons, tension positive.
    """
    theta2 = farray(np.atleast_1d(theta2), 1)
    s = farray(np.atleast_1d(s), 1)
    return _kernels.slidercrank.axial_force_at(theta2, s, omega, crank_radius, rod_length, rho_a, slider_mass)


def slidercrank_frequencies(rho_a: float, ea: float, ei: float, rod_length: float,
                            slider_mass: float) -> tuple[float, float, float]:
    """Compute the rod's first natural frequencies and Euler load in closed form.

    Parameters
    ----------
    rho_a : float
        Rod mass per unit length, kg/m.
    ea : float
        Axial stiffness E A, N.
    ei : float
        Bending stiffness E I, N m^2.
    rod_length : float
        Rod length, m.
    slider_mass : float
        Mass on the guide, kg.

    Returns
    -------
    w_bend : float
        First bending (pinned-pinned) natural frequency, rad/s.
    w_axial : float
        First axial (fixed / slider mass) natural frequency, rad/s.
    p_euler : float
        Pinned-pinned Euler load pi^2 EI / L^2, N.
    """
    wb, wa, pe = _kernels.slidercrank.analytic_frequencies(rho_a, ea, ei, rod_length, slider_mass)
    return float(wb), float(wa), float(pe)


# ----------------------------------------------------------------------------- slidercrank, nonlinear rod

class NonlinearStatus(KernelStatus):
    """Status word of the nonlinear rod's kernels (fortran/slidercrank_nl.f90 ``nl_*``).

    Each with the words a report prints for it; ``bad_args`` (the kernel refused its call) raises.
    """

    ok = int(_kernels.slidercrank_nl.nl_ok), "ok"
    limit = int(_kernels.slidercrank_nl.nl_limit), "COLLAPSE", "the lateral deflection passed L/2: the rod has folded up"
    not_spd = int(_kernels.slidercrank_nl.nl_not_spd), "NOT SPD", "the Newton matrix is not positive definite"
    bad_args = int(_kernels.slidercrank_nl.nl_bad_args), "BAD ARGUMENTS", "the kernel refused its arguments", True
    no_convergence = (int(_kernels.slidercrank_nl.nl_no_convergence), "NO CONVERGENCE",
                      "Newton did not converge even after the allowed step cuts; reduce the time step "
                      "(steps_per_rev) or raise max_step_cuts")


#: the nonlinear rod's status codes by name (``SLIDERCRANK_NL_STATUS["ok"]``): :class:`NonlinearStatus`
SLIDERCRANK_NL_STATUS: type[NonlinearStatus] = NonlinearStatus


class Shape(IntEnum):
    """Columns of :func:`slidercrank_nl_simulate`'s ``shapes`` (and of its ``shape_step``).

    The rod's lateral deflection [m] at the step of largest deflection and at the step of largest
    crank-end compression.
    """

    LARGEST_DEFLECTION = 0
    LARGEST_COMPRESSION = 1


@_doc
def slidercrank_nl_simulate(n_elements: int, crank_radius: float, rod_length: float, rho_a: float,
                            ea: float, ei: float, half_depth: float, slider_mass: float, omega: float,
                            dt: float, n_steps: int, steps_per_rev: int, rec_start: int, n_rec: int,
                            alpha: float = 0.0, beta: float = 0.0, hht: float = 0.0, start: str = "quasistatic",
                            tol: float = 1e-8, max_iterations: int = 25, max_cuts: int = 6,
                            energy: bool = False, frame_every: int = 1) -> dict:
    """Simulate the geometrically nonlinear (co-rotational) connecting rod: the whole time loop in Fortran.

    Parameters
    ----------
    %(rod)s
    %(motion)s
    steps_per_rev : int
        Steps per revolution (groups the steps for the per-revolution peaks).
    rec_start, n_rec : int
        First recorded step and the number recorded.
    alpha : float, default 0.0
        Mass-proportional Rayleigh coefficient, 1/s.
    beta : float, default 0.0
        Stiffness-proportional Rayleigh coefficient, s.
    hht : float, default 0.0
        HHT-alpha parameter in [-1/3, 0], dimensionless (0: Newmark average acceleration, no
        numerical damping).
    start : {'quasistatic', 'rest'}, default 'quasistatic'
        Initial state.
    tol : float, default 1e-8
        Newton tolerance on the relative residual, dimensionless.
    max_iterations : int, default 25
        Newton solves allowed per step.
    max_cuts : int, default 6
        Step halvings allowed.
    energy : bool, default False
        Record the energy balance.
    frame_every : int, default 1
        Keep the rod's lateral deflection profile at every ``frame_every``-th recorded step
        (``frames``), dimensionless.

    Returns
    -------
    dict
        The records, as listed below.

    Notes
    -----
    The dict holds: eps_ax, eps_of (n_elements, n_rec) axial and outer-fibre strain [-];
    lat_max largest |lateral deflection from the chord| [m], mid the midspan node's lateral
    deflection [m], elong rod elongation [m], slider position [m], energy (4, n_rec):
    kinetic, strain energy, work of the loads, damping dissipation since the start [J];
    rev_lat, rev_eps peak |lateral deflection| [m] and |axial strain| per revolution;
    frames (n_elements + 1, (n_rec - 1) // frame_every + 1) lateral deflection profiles [m] at
    recorded steps 0, frame_every, ... (the rod's nodes over the recorded steps);
    shapes (n_elements + 1, 2) lateral deflection profiles [m] at the recorded steps
    shape_step (largest deflection, largest crank-end compression); stats (Newton solves,
    most solves in a step, step cuts, deepest cut level, steps completed); status (a
    :class:`NonlinearStatus`), fail_step, fail_iter.
    """
    n_rev = max(1, -(-int(n_steps) // int(steps_per_rev)))
    every = max(1, int(frame_every))
    out = _kernels.slidercrank_nl.simulate_nl(
        int(n_elements), 3 * int(n_elements), int(n_rec), n_rev, crank_radius, rod_length, rho_a, ea, ei,
        half_depth, slider_mass, omega, dt, int(n_steps), int(steps_per_rev), int(rec_start), alpha, beta, hht,
        {"rest": 0, "quasistatic": 1}[start], tol, int(max_iterations), int(max_cuts), int(bool(energy)),
        every, (max(int(n_rec), 1) - 1) // every + 1)
    names = ("eps_ax", "eps_of", "lat_max", "mid", "elong", "slider", "energy", "rev_lat", "rev_eps", "shapes",
             "frames", "shape_step", "stats", "status", "fail_step", "fail_iter")
    res: dict[str, Any] = dict(zip(names, out))   # arrays and the integer status words
    res["status"] = kernel_status(NonlinearStatus, res["status"], "slidercrank_nl.simulate_nl")
    for key in ("fail_step", "fail_iter"):
        res[key] = int(res[key])
    return res


def slidercrank_column_static(n_elements: int, length: float, ea: float, ei: float, load: float,
                              imperfection: float, tol: float = 1e-10,
                              max_iterations: int = 500) -> tuple[float, float, int, NonlinearStatus]:
    """Solve a static pinned-pinned column of co-rotational elements under an end load.

    Parameters
    ----------
    n_elements : int
        Elements.
    length : float
        Column length, m.
    ea : float
        Axial stiffness E A, N.
    ei : float
        Bending stiffness E I, N m^2.
    load : float
        End load, N, compression positive.
    imperfection : float
        Amplitude of the sine initial guess, m.
    tol : float, default 1e-10
        Newton tolerance on the relative residual, dimensionless.
    max_iterations : int, default 500
        Newton solves allowed.

    Returns
    -------
    mid : float
        Midspan lateral deflection, m.
    shortening : float
        End shortening, m.
    iterations : int
        Newton solves used.
    status : NonlinearStatus
        ``ok``, or ``no_convergence`` (an int: it compares equal to the Fortran code).

    Raises
    ------
    driver._errors.KernelError
        The kernel refused its arguments (``n_elements`` odd or below 2, ``tol`` or
        ``max_iterations`` not positive).
    """
    n = int(n_elements)
    _q, mid, short, iters, status = _kernels.slidercrank_nl.column_static(
        n, 3 * n, length, ea, ei, load, imperfection, tol, int(max_iterations))
    return float(mid), float(short), int(iters), kernel_status(NonlinearStatus, status, "slidercrank_nl.column_static")


def slidercrank_corot_element(le: float, ea: float, ei: float, p: np.ndarray,
                              tangent: bool = True, rates: np.ndarray | None = None, damping: float = 0.0,
                              rate_weight: float = 0.0) -> tuple[np.ndarray, np.ndarray, float, float, float]:
    """Evaluate one co-rotational element: nodal forces, tangent, strain, curvature and energy.

    With ``damping`` bd the force includes the damping of the deformation rates for the nodal
    velocities ``rates`` and the tangent its derivative at fixed rates (not symmetric) plus
    ``rate_weight`` cd times the rate derivative bd B^T K_l B / bd.

    Parameters
    ----------
    le : float
        Element length, m.
    ea : float
        Axial stiffness E A, N.
    ei : float
        Bending stiffness E I, N m^2.
    p : numpy.ndarray
        (6,) displacements (u, v, th) of its two nodes, m and rad.
    tangent : bool, default True
        Also compute the tangent.
    rates : numpy.ndarray, optional
        (6,) nodal velocities, m/s and rad/s (with ``damping``).
    damping : float, default 0.0
        Stiffness-proportional damping coefficient bd, s.
    rate_weight : float, default 0.0
        Weight cd of the rate derivative in the tangent, dimensionless.

    Returns
    -------
    force : numpy.ndarray
        (6,) nodal forces and moments, N and N m.
    tangent : numpy.ndarray
        (6, 6) tangent stiffness: N/m, N or N m as an entry couples translations and rotations.
    strain : float
        Axial strain, dimensionless.
    curvature : float
        Mean curvature, 1/m.
    energy : float
        Strain energy, J.
    """
    if damping == 0.0 and rate_weight == 0.0:
        f, kt, eps, kap, en = _kernels.slidercrank_nl.element_corot(le, ea, ei, farray(p, 1), bool(tangent))
    else:
        pd = np.zeros(6) if rates is None else rates
        f, kt, eps, kap, en = _kernels.slidercrank_nl.element_corot_d(le, ea, ei, farray(p, 1), farray(pd, 1),
                                                                      damping, rate_weight, bool(tangent))
    return f, kt, float(eps), float(kap), float(en)
