"""The fourbar study's kernel wrappers: fourbar.f90 (closed-loop and listing kinematics, coupler
point), fourbar_summary.f90 (the batch summary) and fourbar_forces.f90 (joint forces,
Berkof-Lowen balancing, the force summary).

Thin wrappers over the study's modules of the compiled extension (loaded once by
:mod:`driver.kernels`): inputs are converted once to Fortran-ordered float64 (f2py would
otherwise copy C-ordered 2-D arrays silently), nothing is looped in Python, numpy arrays come
back.  Each kernel's physics and units are documented in its Fortran source.
"""
from __future__ import annotations

import numpy as np

from driver.kernels import _kernels, _spare, farray

__all__ = ['FOURBAR_PASSES', 'fourbar_listing', 'fourbar_exact', 'fourbar_coupler_point', 'fourbar_summaries',
           'fourbar_joint_forces', 'fourbar_berkof_lowen', 'fourbar_force_summaries',
           'FOURBAR_FORCE_SUMMARY_COLUMNS', 'FOURBAR_SUMMARY_COLUMNS', 'FOURBAR_GRASHOF', 'FOURBAR_STATUS']


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
