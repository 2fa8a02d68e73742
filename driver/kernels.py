"""The one thin wrapper around the private Fortran extension ``driver._kernels``.

Nothing else imports ``_kernels``.  Wrappers convert inputs once to
Fortran-ordered float64 (f2py would otherwise copy C-ordered 2-D arrays
silently), loop nothing in Python, and return numpy arrays.  One section per
study; each kernel's physics and units are documented in ``fortran/<study>.f90``.
"""
from __future__ import annotations

import sys
import threading
from pathlib import Path

import numpy as np

try:
    from driver import _kernels
except ImportError as _exc:
    _root = Path(__file__).resolve().parents[1]
    if (_root / "meson.build").is_file() and (_root / "fortran").is_dir():
        raise ImportError(
            f"the Fortran kernels (driver._kernels) are not built in the source checkout {_root}, and "
            f"Python imports 'driver' from there because it is the current folder (or on sys.path). "
            f"Run from another folder to use an installed copy, or build this checkout in place: "
            f"bash .ci/setup (see docs/install.md)") from _exc
    raise ImportError(f"the Fortran kernels (driver._kernels) cannot be loaded: {_exc}; reinstall "
                      f"mechanism-driver (see docs/install.md)") from _exc

__all__ = ["farray", "release_spares", "fourbar_listing", "fourbar_exact", "fourbar_coupler_point", "fourbar_summaries",
           "fourbar_joint_forces", "fourbar_berkof_lowen", "fourbar_force_summaries", "FOURBAR_FORCE_SUMMARY_COLUMNS",
           "FOURBAR_SUMMARY_COLUMNS", "FOURBAR_GRASHOF", "FOURBAR_STATUS",
           "MANIPULATOR_STATUS", "manipulator_arm_states", "manipulator_torques", "manipulator_ik",
           "manipulator_design_indices", "manipulator_position_errors", "manipulator_design_summaries",
           "MANIPULATOR_SUMMARY_PARAMS", "MANIPULATOR_SUMMARY_COLUMNS",
           "UJOINT_MODELS", "UJOINT_OBJECTIVES", "ujoint_speed", "ujoint_objective",
           "ujoint_equivalent", "ujoint_geometry", "ujoint_summaries", "UJOINT_SUMMARY_COLUMNS",
           "SLIDERCRANK_STATUS", "SLIDERCRANK_PROFILE", "slidercrank_simulate", "slidercrank_matrices", "slidercrank_rigid",
           "slidercrank_axial_force", "slidercrank_frequencies",
           "SLIDERCRANK_NL_STATUS", "slidercrank_nl_simulate", "slidercrank_column_static",
           "slidercrank_corot_element"]


def farray(x, ndim: int | None = None) -> np.ndarray:
    """``x`` as a Fortran-contiguous float64 array (no copy when it already is one)."""
    if type(x) is np.ndarray and x.dtype == np.float64 and x.flags.f_contiguous \
            and (ndim is None or x.ndim == ndim):
        return x          # fast path: the optimisers call kernels with such arrays (~1 us saved)
    a = np.asfortranarray(x, dtype=np.float64)
    if ndim is not None and a.ndim != ndim:
        raise ValueError(f"expected a {ndim}-D array, got shape {a.shape}")
    return a


# ----------------------------------------------------------------------------- output buffers

#: outputs at least this large [bytes] are kept for the next call of the same shape (smaller
#: ones come from numpy's own cache and cost no page faults)
SPARE_MIN_BYTES = 1 << 20
_spares: dict[str, np.ndarray] = {}
_spares_lock = threading.Lock()


def _spare(name: str, shape: tuple[int, ...], dtype: type) -> np.ndarray:
    """A fresh-to-the-caller output array of ``shape`` (Fortran order) for kernel output ``name``.

    A large output array (``SPARE_MIN_BYTES`` or more) is remembered; the next call of the
    same output and shape gets the same memory back when nobody holds it any more -- no
    reference to it or to a view of it (numpy views and pandas columns built without a copy
    hold their base) -- instead of new memory whose first touch costs a page fault per 4 KiB
    (at 10^6 four-bar positions, 88 MB: most of the call).  An array still held anywhere is
    never handed out again: the caller then gets new memory, which becomes the spare."""
    dtype = np.dtype(dtype)
    if int(np.prod(shape)) * dtype.itemsize < SPARE_MIN_BYTES:
        return np.empty(shape, dtype=dtype, order="F")
    with _spares_lock:
        a = _spares.get(name)
        # held only by the dict, the local name and getrefcount's argument: nobody else has it
        if a is not None and a.shape == shape and a.dtype == dtype and sys.getrefcount(a) == 3:
            return a
        a = np.empty(shape, dtype=dtype, order="F")
        _spares[name] = a
        return a


def release_spares() -> None:
    """Forget the remembered output arrays (their memory is freed once nobody holds them)."""
    with _spares_lock:
        _spares.clear()


# ----------------------------------------------------------------------------- four-bar

#: status codes of the four-bar kernels (fortran/fourbar.f90)
FOURBAR_STATUS = {"ok": int(_kernels.fourbar.st_ok), "no_assembly": int(_kernels.fourbar.st_no_assembly),
                  "toggle": int(_kernels.fourbar.st_toggle),
                  "indeterminate": int(_kernels.fourbar.st_indeterminate)}


def fourbar_listing(p: float, q: float, r: float, s: float, omega: float,
                    start: int, step: int, n: int) -> tuple[np.ndarray, np.ndarray]:
    """The published listing's table (single precision, as printed): (n, 10) rows and status.

    Columns: crank angle i [deg], epsl, phi, beta [whole deg, truncated], xa, ya, xb, yb,
    omr, oms [rad/s].  Status: 0 ok, 1 not assemblable, 2 velocities divide by zero.
    """
    table, status = _kernels.fourbar.listing_table(p, q, r, s, omega, int(start), int(step), int(n))
    return table, status


def fourbar_exact(theta: np.ndarray, p: float, q: float, r: float, s: float, omega: float,
                  alpha: float = 0.0, branch: int = 1, out: np.ndarray | None = None,
                  status: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Closed-loop states at crank angles ``theta`` [rad]: (n, 11) array and status (n,).

    Columns: coupler angle, rocker angle, transmission angle [rad]; xa, ya, xb, yb [length];
    coupler and rocker angular velocity [rad/s]; coupler and rocker angular acceleration
    [rad/s^2].  ``branch`` +1 open, -1 crossed.  Status: 0 ok, 1 cannot be assembled,
    2 toggle (velocities unbounded, returned as 0), 3 indeterminate (A on O_B).
    ``out`` (Fortran-ordered float64, (n, 11)) and ``status`` (int32, (n,)) may be passed
    to reuse buffers across calls; they are overwritten.
    """
    theta = farray(np.atleast_1d(theta), 1)
    n = theta.shape[0]
    if out is None:
        out = _spare("fourbar_exact.out", (n, 11), np.float64)
    elif not (out.flags.f_contiguous and out.dtype == np.float64 and out.shape == (n, 11)):
        raise ValueError("out must be a Fortran-ordered float64 array of shape (n, 11); "
                         "f2py would otherwise work on a hidden copy")
    if status is None:
        status = _spare("fourbar_exact.status", (n,), np.int32)
    elif not (status.dtype == np.int32 and status.shape == (n,)):
        raise ValueError("status must be an int32 array of shape (n,)")
    return _kernels.fourbar.exact_states(theta, p, q, r, s, omega, alpha, int(branch), out, status)


#: columns of fourbar_summaries (fortran/fourbar_summary.f90)
FOURBAR_SUMMARY_COLUMNS = ("grashof", "assemblable", "assembled_fraction", "mu_min_deg", "mu_min_at_deg",
                           "mu_max_deg", "mu_max_at_deg", "rocker_min_deg", "rocker_min_at_deg",
                           "rocker_max_deg", "rocker_max_at_deg", "rocker_swing_deg", "rocker_turns",
                           "toggles_in_range", "omega3_peak_rad_s", "omega3_peak_at_deg",
                           "omega2_peak_rad_s", "omega2_peak_at_deg", "time_ratio")
#: Grashof class codes of fourbar_summaries
FOURBAR_GRASHOF = {int(getattr(_kernels.fourbar_summary, f"gr_{k}")): k for k in
                   ("double_crank", "crank_rocker", "rocker_crank", "double_rocker", "change_point",
                    "triple_rocker")}


#: pass bits of fourbar_summaries (fortran/fourbar_summary.f90 pass_*); 'dense_scan' with
#: 'peaks' is the previous peak search (every 1 deg grid point), the baseline of bench and tests
FOURBAR_PASSES = {k: int(getattr(_kernels.fourbar_summary, f"pass_{k}")) for k in
                  ("transmission", "rocker", "peaks", "dense_scan")}


def fourbar_summaries(params: np.ndarray, passes: int = 7) -> np.ndarray:
    """Headline figures of many four-bars in one kernel call: (n, 19) array.

    ``params`` (n, 8): fixed link p, crank q, coupler r, rocker s [length], crank speed
    [rad/s], first and last crank angle of the range [deg], branch (+1 open, -1 crossed).
    Columns: FOURBAR_SUMMARY_COLUMNS (angles in degrees, speeds in rad/s; flags 0/1;
    figures that do not exist are 0 -- mask them with 'assemblable' and 'toggles_in_range').
    ``passes``: sum of FOURBAR_PASSES bits; the columns of a pass not asked for are 0 (not
    computed), the others have the same bits whichever passes run (default: all three).
    """
    params = farray(params, 2)
    if params.shape[1] != 8:
        raise ValueError(f"params must have 8 columns, got {params.shape[1]}")
    return _kernels.fourbar_summary.summaries(params, int(passes))


def fourbar_coupler_point(theta: np.ndarray, states: np.ndarray, status: np.ndarray, q: float,
                          omega: float, alpha: float, u: float, v: float) -> np.ndarray:
    """A point fixed to the coupler, u along A->B and v to its left [length], from the
    ``fourbar_exact`` results at crank angles ``theta`` [rad]: (n, 6) position, velocity
    [length/s] and acceleration [length/s^2] (zero where the linkage is not placed)."""
    theta = farray(np.atleast_1d(theta), 1)
    return _kernels.fourbar.coupler_point(theta, q, omega, alpha, u, v, farray(states, 2),
                                          np.asarray(status, dtype=np.int32))


def fourbar_joint_forces(states: np.ndarray, status: np.ndarray, p: float, q: float, r: float, s: float,
                         omega: float, alpha: float, props: np.ndarray) -> np.ndarray:
    """Joint forces from ``fourbar_exact`` results (same omega [rad/s], alpha [rad/s^2]): (n, 12).

    ``props`` (18,): masses [kg], inertias about the centres of mass [kg m^2], com distances [m]
    and angles [rad] of crank, coupler, rocker; gravity [m/s^2] (along -y); load torque on the
    rocker [N m]; load force at the coupler point [N]; the point's u, v [m].  Columns: input
    torque [N m]; F_O2, F_A, F_B, F_O4 (x, y) [N]; shaking force (x, y) [N]; shaking moment
    about O2 [N m] (fortran/fourbar_forces.f90).  Zero where status is not ok.
    """
    props = np.ascontiguousarray(props, dtype=np.float64)
    if props.shape != (18,):
        raise ValueError(f"props must have 18 values, got shape {props.shape}")
    return _kernels.fourbar_forces.joint_forces(farray(states, 2), np.asarray(status, dtype=np.int32),
                                                p, q, r, s, omega, alpha, props)


def fourbar_berkof_lowen(q: float, r: float, s: float, props: np.ndarray,
                         radii: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
    """Berkof-Lowen counterweights on crank and rocker at ``radii`` [m]: (props of the balanced
    linkage (18,), cw (6,) = crank mass x radius [kg m] and angle [rad], rocker the same, the two
    counterweight masses [kg])."""
    return _kernels.fourbar_forces.berkof_lowen(q, r, s, np.asarray(props, dtype=np.float64),
                                                np.asarray(radii, dtype=np.float64))


#: columns of fourbar_force_summaries (fortran/fourbar_forces.f90 force_summaries)
FOURBAR_FORCE_SUMMARY_COLUMNS = ("defined_fraction", "torque_peak_Nm", "torque_peak_at_deg", "torque_mean_Nm",
                                 "torque_rms_Nm", "F_O2_peak_N", "F_A_peak_N", "F_B_peak_N", "F_O4_peak_N",
                                 "shaking_force_peak_N", "shaking_moment_peak_Nm", "energy_fluctuation_J",
                                 "flywheel_inertia_kgm2")


def fourbar_force_summaries(params: np.ndarray) -> np.ndarray:
    """Force summaries of many four-bars in one kernel call: (n, 13), FOURBAR_FORCE_SUMMARY_COLUMNS.

    ``params`` (n, 31): p, q, r, s [m], omega [rad/s], alpha [rad/s^2], first and last crank
    angle [deg], branch (+1/-1), the 18 props of ``fourbar_joint_forces``, speed fluctuation,
    balance flag (1 = Berkof-Lowen counterweights first), counterweight radii [m].
    """
    params = farray(params, 2)
    if params.shape[1] != 31:
        raise ValueError(f"params must have 31 columns, got {params.shape[1]}")
    return _kernels.fourbar_forces.force_summaries(params)


# ----------------------------------------------------------------------------- manipulator

#: status codes of the 2R manipulator kernels (fortran/manipulator.f90)
MANIPULATOR_STATUS = {"ok": int(_kernels.manipulator.st_ok),
                      "unreachable": int(_kernels.manipulator.st_unreachable),
                      "degenerate": int(_kernels.manipulator.st_degenerate)}


def _col(x, n: int) -> np.ndarray:
    """``x`` (scalar or length-n) broadcast to a contiguous float64 vector of length n."""
    return farray(np.broadcast_to(np.asarray(x, dtype=np.float64), (n,)), 1)


def _pair(x, n: int) -> np.ndarray:
    """``x`` (pair or (n, 2)) broadcast to a Fortran-ordered (n, 2) float64 array."""
    return farray(np.broadcast_to(np.asarray(x, dtype=np.float64), (n, 2)), 2)


def _arm_inputs(l1, l2, th1, th2, qd, qdd, m1, m2, mass_per_length: float) -> tuple:
    """Kernel arguments of the 2R routines: every input broadcast to n rows, masses defaulted
    to ``mass_per_length`` times the link length."""
    n = max(np.size(l1), np.size(l2), np.size(th1), np.size(th2))
    l1v, l2v = _col(l1, n), _col(l2, n)
    m1v = _col(mass_per_length * l1v if m1 is None else m1, n)
    m2v = _col(mass_per_length * l2v if m2 is None else m2, n)
    return l1v, l2v, _col(th1, n), _col(th2, n), _pair(qd, n), _pair(qdd, n), m1v, m2v


def manipulator_arm_states(l1, l2, th1, th2, qd=(1.0, 1.0), qdd=(1.0, 1.0), m1=None, m2=None,
                           g: float = 9.8, mass_per_length: float = 10.0,
                           out: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None = None):
    """Jacobian, manipulability, condition number and torques of 2R configurations.

    Inputs broadcast to n rows: lengths l1, l2 [m], joint angles th1, th2 [rad] (th2 relative),
    joint rates ``qd`` [rad/s] and accelerations ``qdd`` [rad/s^2] as pairs or (n, 2), link
    masses m1, m2 [kg] (default ``mass_per_length`` [kg/m] times the length), g [m/s^2] along -y.
    Returns (jac (n, 4) = J11, J12, J21, J22 [m] of eq. 4.18, w = |det J| [m^2],
    kappa = sigma_max/sigma_min (0 where J is singular), tau (n, 2) [N m]).
    ``out`` = (jac, w, kappa, tau) Fortran-ordered float64 arrays of those shapes may be
    passed to reuse buffers across calls (large fresh arrays cost page faults that can
    exceed the kernel's own time); they are overwritten and returned.
    """
    args = _arm_inputs(l1, l2, th1, th2, qd, qdd, m1, m2, mass_per_length)
    n = args[0].shape[0]
    shapes = ((n, 4), (n,), (n,), (n, 2))
    if out is None:
        out = tuple(np.empty(shp, dtype=np.float64, order="F") for shp in shapes)
    elif len(out) != 4 or not all(isinstance(a, np.ndarray) and a.flags.f_contiguous and a.dtype == np.float64
                                  and a.shape == shp for a, shp in zip(out, shapes)):
        raise ValueError(f"out must be four Fortran-ordered float64 arrays of shapes {shapes}; "
                         "f2py would otherwise work on hidden copies")
    return _kernels.manipulator.arm_states(*args, float(g), *out)


def manipulator_torques(l1, l2, th1, th2, qd=(1.0, 1.0), qdd=(1.0, 1.0), m1=None, m2=None,
                        g: float = 9.8, mass_per_length: float = 10.0) -> np.ndarray:
    """Joint torques (n, 2) [N m] of Craig's point-mass 2R arm (report eqs 2.52/2.53).

    Same inputs and units as :func:`manipulator_arm_states`.
    """
    return _kernels.manipulator.craig_torques(*_arm_inputs(l1, l2, th1, th2, qd, qdd, m1, m2, mass_per_length),
                                              float(g))


def manipulator_ik(l1, l2, x, y, branch: int = 1) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Inverse kinematics of targets (x, y) [m] for arms (l1, l2) [m] on elbow ``branch``.

    +1 gives th2 >= 0, -1 gives th2 <= 0.  Returns th1, th2 [rad] and status per row
    (0 ok, 1 out of reach, 2 degenerate: zero link or target at the base; angles 0 there).
    """
    n = max(np.size(l1), np.size(l2), np.size(x), np.size(y))
    return _kernels.manipulator.inverse_kin(_col(l1, n), _col(l2, n), _col(x, n), _col(y, n),
                                            int(branch))


def manipulator_design_indices(x, y, l1, l2) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Robustness indices of designs (l1, l2) [m] for workspace points (x, y) [m].

    Returns ri (nd, 3) = RI1 (sigma_max/sigma_min, 0 when sigma_min = 0), RI2 = sigma_max
    (eq. 2.25), RI3 = sigma_max + ||J_x||_F (dimensionless); sum of cos(th2_i); and reach
    (1 when the design reaches every point).
    """
    x, y = farray(np.atleast_1d(x), 1), farray(np.atleast_1d(y), 1)
    nd = max(np.size(l1), np.size(l2))
    return _kernels.manipulator.design_indices(x, y, _col(l1, nd), _col(l2, nd))


def manipulator_position_errors(th1, th2, dl) -> np.ndarray:
    """Positioning errors [m] of an arm held at joint angles (th1, th2) [rad] of the workspace
    points, for link-length errors ``dl`` (ns, 2) [m].

    Returns (ns, 2): column 0 the global norm over all points stacked (Caro), column 1 the
    largest error at a single point.
    """
    th1, th2 = farray(np.atleast_1d(th1), 1), farray(np.atleast_1d(th2), 1)
    return _kernels.manipulator.position_errors(th1, th2, farray(dl, 2))


#: columns of the parameter matrix of :func:`manipulator_design_summaries`
MANIPULATOR_SUMMARY_PARAMS = ("l1", "l2", "target_x", "target_y", "mass_per_length", "gravity", "tolerance_bound")
#: columns of its result (fortran/manipulator_summary.f90)
MANIPULATOR_SUMMARY_COLUMNS = ("ri1", "ri2", "ri3", "sum_c2", "reach", "target_status", "theta1_deg", "theta2_deg",
                               "tau1", "tau2", "reaches_points", "dl1", "dl2", "mc_max")


#: pass bits of manipulator_design_summaries (fortran/manipulator_summary.f90 ds_*)
MANIPULATOR_PASSES = {k: int(getattr(_kernels.manipulator_summary, f"ds_{k}")) for k in
                      ("indices", "target", "tolerance")}


def manipulator_design_summaries(x, y, params, branch: int = 1, rates=(1.0, 1.0, 1.0, 1.0),
                                 measure: str = "global", unit=None, passes: int = 7) -> np.ndarray:
    """Design summaries of nd 2R arms for workspace points (x, y) [m] in one call: (nd, 14).

    ``params`` (nd, 7): columns MANIPULATOR_SUMMARY_PARAMS -- l1, l2 [m] (positive), the
    target point x, y [m], mass per length [kg/m], g [m/s^2] along -y, tolerance bound [m].
    ``branch`` the IK elbow branch (+1/-1), ``rates`` = (th1', th2' [rad/s], th1'', th2''
    [rad/s^2]), ``measure`` 'global' or 'per_point', ``unit`` (ns, 2) Monte Carlo samples in
    [-1, 1]^2 (the box is unit * dl; default one sample at (1, 1)).
    Result columns MANIPULATOR_SUMMARY_COLUMNS: RI1 (0 where sigma_min = 0), RI2, RI3, sum c2,
    reach (1/0, conditions 4.4), IK status at the target (MANIPULATOR_STATUS), theta1, theta2
    there [deg], tau1, tau2 [N m] (0 unless the status is ok), reaches_points (1 when the IK
    reaches every workspace point), tolerance half-widths dl1, dl2 [m] and the Monte Carlo
    maximum error [m] (the last three 0 unless reaches_points).  ``passes``: sum of
    MANIPULATOR_PASSES bits (indices: columns 0-4, target: 5-9, tolerance: 10-13); the
    columns of a pass not asked for are 0 (not computed).
    """
    x, y = farray(np.atleast_1d(x), 1), farray(np.atleast_1d(y), 1)
    params = farray(params, 2)
    if params.shape[1] != len(MANIPULATOR_SUMMARY_PARAMS):
        raise ValueError(f"params must have {len(MANIPULATOR_SUMMARY_PARAMS)} columns, got {params.shape[1]}")
    unit = farray(np.ones((1, 2)) if unit is None else unit, 2)
    if unit.shape[1] != 2 or unit.shape[0] < 1:
        raise ValueError(f"unit must have shape (ns >= 1, 2), got {unit.shape}")
    return _kernels.manipulator_summary.design_summaries(
        x, y, params, int(branch), farray(np.asarray(rates, dtype=np.float64).ravel(), 1),
        {"global": 0, "per_point": 1}[measure], unit, int(passes))



# ----------------------------------------------------------------------------- ujoint

#: model codes of fortran/ujoint.f90: the paper's eq. 13 as printed, the paper's text
#: (cumulative phases), the exact chain
UJOINT_MODELS = {"eq13": int(_kernels.ujoint.model_eq13), "cumulative": int(_kernels.ujoint.model_cumulative),
                 "exact": int(_kernels.ujoint.model_exact)}
#: objective codes of fortran/ujoint.f90
UJOINT_OBJECTIVES = {"mean_square": int(_kernels.ujoint.obj_mean_square), "rms": int(_kernels.ujoint.obj_rms),
                     "peak_to_peak": int(_kernels.ujoint.obj_peak_to_peak)}


def _ujoint_chain(beta, phi, rho) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """beta (n,), phi and rho (n-1,) [rad; rho None = coplanar] as float64 arrays."""
    beta = _vector(beta)
    if beta.size == 1:   # f2py refuses a 0-length input for dimension(n-1); it takes a dummy of 1
        return beta, _ONE_ZERO, _ONE_ZERO
    ph = _vector(phi)
    rh = np.zeros(ph.size) if rho is None else _vector(rho)
    return beta, ph, rh


_ONE_ZERO = np.zeros(1)


def _vector(x) -> np.ndarray:
    """``x`` (scalar or sequence) as a 1-D float64 array; no copy for one already."""
    if type(x) is np.ndarray and x.ndim == 1:
        return farray(x, 1)
    return farray(np.atleast_1d(x), 1)


def ujoint_speed(model: int, beta, phi, rho, theta) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Chain speed ratio at input angles ``theta`` [rad]: (R, dR/dtheta, output angle).

    beta (n,) joint angles [rad]; phi (n-1,) the paper's phases [rad] (pi/2 = yokes in
    phase); rho (n-1,) plane angles between successive joints [rad] or None (coplanar).
    R = omega_out/omega_in [-]; dR/dtheta [1/rad] times omega_in**2 [rad/s]**2 is the
    output angular acceleration [rad/s**2] at constant input speed; the output shaft angle
    [rad] is given by the exact model only (zeros for the paper models).
    """
    b, ph, rh = _ujoint_chain(beta, phi, rho)
    return _kernels.ujoint.chain_speed(int(model), b, ph, rh, farray(np.atleast_1d(theta), 1))


def ujoint_objective(model: int, kind: int, beta, phi, rho, m: int,
                     grad: bool = True) -> tuple[float, np.ndarray]:
    """Objective over ``m`` uniform input angles per revolution and its gradient.

    Returns (f, g): f dimensionless (mean (R-1)**2, its root, or max R - min R);
    g (2n-1,) = df/d(beta_1..beta_n [rad], phi_1..phi_(n-1) [rad]); zeros when ``grad``
    is False.
    """
    b, ph, rh = _ujoint_chain(beta, phi, rho)
    return _kernels.ujoint.chain_objective(int(model), int(kind), b, ph, rh, int(m), int(bool(grad)))


def ujoint_equivalent(model: int, beta, phi, rho, tol: float = 1e-7) -> tuple[float, float | None]:
    """Closed-form equivalent angles [rad]: (beta_e, beta_res or None).

    beta_e from the first-order phasor sum of the model's phasing; beta_res of the exact
    chain when every phi_k - rho_k is a multiple of pi/2 within ``tol`` [rad], else None.
    """
    b, ph, rh = _ujoint_chain(beta, phi, rho)
    be, br, st = _kernels.ujoint.chain_equivalent(int(model), b, ph, rh, float(tol))
    return float(be), (float(br) if st == int(_kernels.ujoint.st_ok) else None)


#: columns of ujoint_summaries (fortran/ujoint.f90 chain_summaries)
UJOINT_SUMMARY_COLUMNS = ("objective", "ratio_min", "ratio_max", "dratio_abs_max", "beta_e", "beta_res",
                          "beta_res_status")


#: pass bits of ujoint_summaries (fortran/ujoint.f90 sum_*)
UJOINT_PASSES = {k: int(getattr(_kernels.ujoint, f"sum_{k}")) for k in ("objective", "speed", "equivalent")}


def ujoint_summaries(model: int, kind: int, beta, phi, rho, m: int, tol: float = 1e-7, passes: int = 7) -> np.ndarray:
    """Headline figures of many designs of one chain layout in one kernel call: (nd, 7) array.

    beta (nd, n) joint angles [rad]; phi (nd, n-1) the paper's phases [rad]; rho (nd, n-1)
    plane angles [rad] or None (coplanar).  Every design shares ``model``, the objective
    ``kind`` and the grid of ``m`` input angles per revolution.  Columns
    (UJOINT_SUMMARY_COLUMNS): the objective (as :func:`ujoint_objective` without gradient),
    min and max of R = omega_out/omega_in and max |dR/dtheta| [1/rad] on the grid
    theta_j = 2 pi j/m (as :func:`ujoint_speed` there), beta_e and beta_res [rad] and the
    status of beta_res (0: defined; as :func:`ujoint_equivalent` with ``tol`` [rad]).
    Each row has the same bits as those single-design calls.  ``passes``: sum of
    UJOINT_PASSES bits (objective: column 0, speed: 1-3, equivalent: 4-6); the columns of a
    pass not asked for are 0 (not computed).
    """
    beta = np.asarray(beta, dtype=np.float64)
    if beta.ndim != 2 or beta.shape[1] < 1:
        raise ValueError(f"beta must be (designs, joints), got shape {beta.shape}")
    nd, n = beta.shape
    if nd == 0:
        return np.empty((0, len(UJOINT_SUMMARY_COLUMNS)))
    x = np.empty((nd, 3 * n - 2), dtype=np.float64, order="F")
    x[:, :n] = beta
    x[:, n:2 * n - 1] = phi
    x[:, 2 * n - 1:] = 0.0 if rho is None else rho
    return _kernels.ujoint.chain_summaries(model=int(model), kind=int(kind), n=n, nd=nd, x=x, m=int(m),
                                           tol=float(tol), passes=int(passes))


def ujoint_geometry(axes) -> tuple[np.ndarray, np.ndarray, int]:
    """Joint angles beta (n,) and plane angles rho (n-1,) [rad] of shaft directions ``axes``.

    axes: (n+1, 3) direction vectors, input shaft first (any length unit, nonzero).
    Status 0 ok, 2 an axis of zero length, 3 a joint angle of 90 deg or more.
    """
    a = farray(np.asarray(axes, dtype=np.float64).T, 2)
    beta, rho, status = _kernels.ujoint.chain_geometry(a)
    return beta, rho, int(status)



# ----------------------------------------------------------------------------- slidercrank

#: status codes of the slider-crank kernel (fortran/slidercrank.f90)
SLIDERCRANK_STATUS = {"ok": int(_kernels.slidercrank.st_ok), "buckled": int(_kernels.slidercrank.st_buckled),
                      "diverged": int(_kernels.slidercrank.st_diverged),
                      "not_spd": int(_kernels.slidercrank.st_not_spd),
                      "bad_args": int(_kernels.slidercrank.st_bad_args)}
_SC_START = {"rest": 0, "quasistatic": 1, "given": 2}


#: rows of slidercrank_simulate's per-step profile (fortran/slidercrank.f90 prof_*)
SLIDERCRANK_PROFILE = ("eps_1", "eps_2", "eps_max", "eps_max_el", "eps_min", "eps_min_el", "outer_max",
                       "n_avg_1", "lag_change")


def slidercrank_simulate(n_elements: int, crank_radius: float, rod_length: float, rho_a: float,
                         ea: float, ei: float, half_depth: float, slider_mass: float, omega: float,
                         dt: float, n_steps: int, rec_start: int, n_rec: int, alpha: float = 0.0,
                         beta: float = 0.0, start: str = "quasistatic", dynamic: bool = True,
                         geometric_stiffness: bool = False, fast: bool = True,
                         q_init: np.ndarray | None = None, qd_init: np.ndarray | None = None,
                         fields: bool = True, lag: int = 0) -> dict:
    """Elastic connecting rod of a slider-crank, whole time loop in Fortran.

    SI units: lengths [m], rho_a mass per length [kg/m], ea [N], ei [N m^2], masses [kg],
    omega crank speed [rad/s] (theta2 = omega t from 0), dt [s].  alpha [1/s] and beta [s]
    are the Rayleigh coefficients (C = alpha M + beta K).  start: 'rest', 'quasistatic' or
    'given' (q_init, qd_init in the kernel's q ordering, 3*n_elements values [m, rad]).
    Records steps rec_start .. rec_start + n_rec - 1 (step 0 is the start).

    Returns a dict: eps_ax, eps_of (n_elements, n_rec) axial and outer-fibre strain [-];
    n_avg (n_elements, n_rec) element-averaged rigid-body axial force [N] -- these three only
    with ``fields`` (else None: a study that prints the profile below need not record 3 x 8
    bytes per element and step); mid midpoint deflection from the chord [m]; slider position
    [m]; elong rod elongation [m]; the per-step profile of the fields, always: eps_1, eps_2
    axial strain of elements 1 and 2, eps_max / eps_min the largest / smallest axial strain
    with eps_max_el / eps_min_el the (first, 0-based) element holding it, outer_max the
    largest outer-fibre strain, n_avg_1 element 1's rigid-body force [N], and with ``lag`` > 0
    lag_change: max over elements of |eps_ax[:, j] - eps_ax[:, j - lag]| (0 for j < lag);
    q_end, qd_end final state; status (a SLIDERCRANK_STATUS value) and fail_step.
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
    res = dict(zip(names, out))
    res["status"], res["fail_step"] = int(res["status"]), int(res["fail_step"])
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


def slidercrank_matrices(n_elements: int, crank_radius: float, rod_length: float, rho_a: float,
                         ea: float, ei: float, slider_mass: float, theta2: float, omega: float = 0.0,
                         geometric_stiffness: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Banded mass and stiffness (LAPACK lower storage, shape (6, 3 n)) at crank angle theta2 [rad].

    The mass includes the slider mass on U_X; with geometric_stiffness the stiffness includes
    K_G of the rigid-body axial force at crank speed omega [rad/s].
    """
    mb, kb = _kernels.slidercrank.assemble_matrices(
        int(n_elements), 3 * int(n_elements), crank_radius, rod_length, rho_a, ea, ei, slider_mass,
        theta2, omega, int(bool(geometric_stiffness)))
    return mb, kb


def slidercrank_rigid(theta2: np.ndarray, omega: float, crank_radius: float, rod_length: float) -> np.ndarray:
    """Rigid kinematics at crank angles theta2 [rad], constant crank speed omega [rad/s]: (n, 7).

    Columns: theta3 [rad], theta3' [rad/s], theta3'' [rad/s^2], slider position x4 [m],
    slider acceleration A_h [m/s^2], crank-pin acceleration along and across the rod [m/s^2].
    """
    theta2 = farray(np.atleast_1d(theta2), 1)
    return _kernels.slidercrank.rigid_states(theta2, omega, crank_radius, rod_length)


def slidercrank_axial_force(theta2: np.ndarray, s: np.ndarray, omega: float, crank_radius: float,
                            rod_length: float, rho_a: float, slider_mass: float) -> np.ndarray:
    """Rigid-body axial force N [N] (tension positive) at stations s [m]: shape (len(s), len(theta2))."""
    theta2 = farray(np.atleast_1d(theta2), 1)
    s = farray(np.atleast_1d(s), 1)
    return _kernels.slidercrank.axial_force_at(theta2, s, omega, crank_radius, rod_length, rho_a, slider_mass)


def slidercrank_frequencies(rho_a: float, ea: float, ei: float, rod_length: float,
                            slider_mass: float) -> tuple[float, float, float]:
    """Closed forms: first bending (pinned-pinned) and first axial (fixed / slider mass) natural
    frequencies [rad/s], and the pinned-pinned Euler load pi^2 EI / L^2 [N]."""
    wb, wa, pe = _kernels.slidercrank.analytic_frequencies(rho_a, ea, ei, rod_length, slider_mass)
    return float(wb), float(wa), float(pe)


# ----------------------------------------------------------------------------- slidercrank, nonlinear rod

#: status codes of the nonlinear slider-crank kernel (fortran/slidercrank_nl.f90)
SLIDERCRANK_NL_STATUS = {"ok": int(_kernels.slidercrank_nl.nl_ok), "limit": int(_kernels.slidercrank_nl.nl_limit),
                         "not_spd": int(_kernels.slidercrank_nl.nl_not_spd),
                         "bad_args": int(_kernels.slidercrank_nl.nl_bad_args),
                         "no_convergence": int(_kernels.slidercrank_nl.nl_no_convergence)}


def slidercrank_nl_simulate(n_elements: int, crank_radius: float, rod_length: float, rho_a: float,
                            ea: float, ei: float, half_depth: float, slider_mass: float, omega: float,
                            dt: float, n_steps: int, steps_per_rev: int, rec_start: int, n_rec: int,
                            alpha: float = 0.0, beta: float = 0.0, hht: float = 0.0, start: str = "quasistatic",
                            tol: float = 1e-8, max_iterations: int = 25, max_cuts: int = 6,
                            energy: bool = False) -> dict:
    """Geometrically nonlinear (co-rotational) connecting rod, whole time loop in Fortran.

    Arguments as :func:`slidercrank_simulate` (SI units); steps_per_rev groups the steps into
    revolutions for the per-revolution peaks; hht the HHT-alpha parameter in [-1/3, 0] (0: Newmark
    average acceleration, no numerical damping); tol is the Newton tolerance on the relative
    residual, max_iterations the Newton solves allowed per step, max_cuts the step halvings.

    Returns a dict: eps_ax, eps_of (n_elements, n_rec) axial and outer-fibre strain [-];
    lat_max largest |lateral deflection from the chord| [m], mid the midspan node's lateral
    deflection [m], elong rod elongation [m], slider position [m], energy (4, n_rec):
    kinetic, strain energy, work of the loads, damping dissipation since the start [J];
    rev_lat, rev_eps peak |lateral deflection| [m] and |axial strain| per revolution;
    shapes (n_elements + 1, 2) lateral deflection profiles [m] at the recorded steps
    shape_step (largest deflection, largest crank-end compression); stats (Newton solves,
    most solves in a step, step cuts, deepest cut level, steps completed); status (a
    SLIDERCRANK_NL_STATUS value), fail_step, fail_iter.
    """
    n_rev = max(1, -(-int(n_steps) // int(steps_per_rev)))
    out = _kernels.slidercrank_nl.simulate_nl(
        int(n_elements), 3 * int(n_elements), int(n_rec), n_rev, crank_radius, rod_length, rho_a, ea, ei,
        half_depth, slider_mass, omega, dt, int(n_steps), int(steps_per_rev), int(rec_start), alpha, beta, hht,
        {"rest": 0, "quasistatic": 1}[start], tol, int(max_iterations), int(max_cuts), int(bool(energy)))
    names = ("eps_ax", "eps_of", "lat_max", "mid", "elong", "slider", "energy", "rev_lat", "rev_eps", "shapes",
             "shape_step", "stats", "status", "fail_step", "fail_iter")
    res = dict(zip(names, out))
    for key in ("status", "fail_step", "fail_iter"):
        res[key] = int(res[key])
    return res


def slidercrank_column_static(n_elements: int, length: float, ea: float, ei: float, load: float,
                              imperfection: float, tol: float = 1e-10,
                              max_iterations: int = 500) -> tuple[float, float, int, int]:
    """Static pinned-pinned column of co-rotational elements under an end load [N] (compression
    positive), from a sine initial guess of amplitude ``imperfection`` [m].

    Returns (midspan lateral deflection [m], end shortening [m], Newton solves, status).
    """
    n = int(n_elements)
    _q, mid, short, iters, status = _kernels.slidercrank_nl.column_static(
        n, 3 * n, length, ea, ei, load, imperfection, tol, int(max_iterations))
    return float(mid), float(short), int(iters), int(status)


def slidercrank_corot_element(le: float, ea: float, ei: float, p: np.ndarray,
                              tangent: bool = True) -> tuple[np.ndarray, np.ndarray, float, float, float]:
    """One co-rotational element: force (6,), tangent (6, 6) lower triangle [N, N/m], axial strain,
    mean curvature [1/m] and strain energy [J] for displacements p = (u, v, th) of its two nodes."""
    f, kt, eps, kap, en = _kernels.slidercrank_nl.element_corot(le, ea, ei, farray(p, 1), bool(tangent))
    return f, kt, float(eps), float(kap), float(en)
