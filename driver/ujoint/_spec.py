"""Hooke-joint study: the &ujoint deck keys, their checks, conventions and labels (no physics).

Angles in the deck are degrees.  What the paper prints that cannot be reproduced, and why, is
:data:`NOT_REPRODUCIBLE` (docs/ujoint.md).
"""
from __future__ import annotations

import math

import numpy as np

from driver._deck import GroupSpec, Key, Params, non_empty, positive
from driver._limits import Estimate
from driver._study import contract_doc
from driver.ujoint._kernel import UjointStatus, ujoint_geometry

DEG = math.pi / 180.0
OPTIONS = {0: "analyse only", 1: "phases free, joint angles fixed",
           2: "joint angles free, phases fixed", 3: "joint angles and phases free"}


#: reading precision of the paper's plotted bands [rpm] (it quotes whole rpm)
BAND_TOL = 1.0


#: how the θ, ρ and output angles are measured (printed in --keys and every .out)
CONVENTIONS = (
    "theta (the input angle) and every shaft angle turn right-handed about their shaft's "
    "direction (input towards output; the 'axes' vectors); theta = 0 where angle_origin says: "
    "'normal' (default, the paper's) when joint 1's input yoke lies along the normal to the plane "
    "of joint 1, 'plane' (textbooks') when it lies in that plane, 90 deg on. rho_k > 0 when the "
    "plane of joint k+1 is turned right-handed about shaft k from the plane of joint k. th_out is "
    "the last joint's output yoke angle from the normal to (with 'plane': from) the plane of the "
    "last joint, in the sense of theta; it includes the phases (in phase: th_out = theta + 90 "
    "(n-1) deg + the joints' error)")

#: the input angle's origin, by angle_origin: (what theta = 0 means, short words for tables and
#: figures, the kernel's angle at theta = 0 [deg]: the kernel measures from the normal)
ORIGINS = {"normal": ("joint 1's input yoke along the normal to the plane of its shafts (the paper's eq. 5/8; "
                      "a single joint's slowest output, omega_out = omega_in cos beta)",
                      "theta from the normal to joint 1's plane", 0.0),
           "plane": ("joint 1's input yoke in the plane of its shafts (textbooks'; a single joint's fastest "
                     "output, omega_out = omega_in / cos beta)", "theta from joint 1's plane", 90.0)}

#: why the paper's printed results are not reproducible (published quantity -> why)
NOT_REPRODUCIBLE = {
    "x": "the printed optima are not reproducible: no tested definition of U (phase convention, exact or "
         "approximate kinematics, grid, units, aggregation) makes them stationary points; computed: the tool's optimum",
    "U": "the printed objective values are not reproducible under any tested definition of U; computed: the "
         "printed design evaluated under this deck's objective [rpm^2]",
    "iterations": "MATLAB fmincon's count; the tool runs scipy SLSQP from several starts (its counts are in the .out)",
    "evaluations": "MATLAB fmincon's count; the tool runs scipy SLSQP from several starts (its counts are in the .out)",
    "phi_3": "phi_3 does not exist: three joints on four shafts have two intermediate shafts, so two phases",
    "option1_band": "the paper reads 24-26 rpm loosely off its Figure 6; every model gives about 23-27 rpm for the "
                    "trial point (reported, not forced)",
}


def _open_angles(v) -> str | None:
    bad = [x for x in v if not -90.0 < x < 90.0]
    return (f"a joint angle must lie strictly between -90 and 90 deg (got {bad[0]})"
            if bad else None)


def _finite(v) -> str | None:
    return None if math.isfinite(v) else "must be finite"


def _non_negative_finite(v) -> str | None:
    return None if math.isfinite(v) and v >= 0.0 else f"must be a finite value of at least 0 (got {v})"


KEYS = dict(
    beta=Key("floats", check=lambda v: non_empty(v) or _open_angles(v), units="deg",
             doc="operating angle of each joint (any count >= 1); the trial/start design. "
             "Omit when 'axes' gives the geometry."),
    phi=Key("floats", units="deg",
            doc="the paper's phases, one per intermediate shaft (n-1 values); "
            "90 = yokes in phase. Default: in phase"),
    delta=Key("floats", units="deg",
              doc="yoke phases instead of phi (0 = in phase; delta = phi - 90)"),
    rho=Key("floats", units="deg",
            doc="angle between the planes of joints k and k+1 about their shared shaft k, "
            "positive right-handed about the shaft's direction (input towards output) "
            "(n-1 values; exact model only; default coplanar)"),
    axes=Key("floats", units="-",
             doc="3-D chain: shaft direction vectors x,y,z of shafts 0..n (input first); "
             "gives beta and rho (exact model only)"),
    rpm=Key("float", default=25.0, check=positive, units="rpm",
            doc="input shaft speed (the paper: 25 rpm)"),
    model=Key("str", default="exact", choices=("paper", "exact"),
              doc="'paper': every joint driven by the input angle plus a phase; "
              "'exact': each joint's output drives the next"),
    phasing=Key("str", default="cumulative", choices=("cumulative", "eq13"),
                doc="paper model only: joint k at theta+phi_1+..+phi_(k-1) (the text) "
                "or theta+phi_(k-1) (eq. 13 as printed; the yoke phase of shaft k is then "
                "phi_k - phi_(k-1) - 90, and every derived figure uses it)"),
    option=Key("int", default=0, choices=(0, 1, 2, 3),
               doc="0 analyse, 1 phases free, 2 angles free (phases fixed), 3 both free"),
    objective=Key("str", default="mean_square", choices=("mean_square", "rms", "peak_to_peak"),
                  doc="mean (R-1)^2 over a revolution (the paper's U per omega_in^2), "
                  "its root, or max R - min R; R = omega_out/omega_in"),
    beta_lower=Key("floats", default=[0.0], units="deg", doc="lower bound(s) on joint angles"),
    beta_upper=Key("floats", default=[40.0], units="deg",
                   doc="upper bound(s) on joint angles (the paper: 40)"),
    phi_lower=Key("floats", default=[0.0], units="deg", doc="lower bound(s) on phases phi"),
    phi_upper=Key("floats", default=[180.0], units="deg",
                  doc="upper bound(s) on phases phi; bounds spanning 180 deg or more make the "
                  "phase periodic (searched without bounds, reported in [phi_lower, phi_lower+180))"),
    n_starts=Key("int", default=16,
                 check=lambda v: positive(v) or ("at most 100000 starts" if v > 100_000 else None),
                 doc="multi-start: the trial point plus n_starts-1 seeded random starts"),
    seed=Key("int", default=0, doc="random seed of the multi-start (deterministic)"),
    n_grid=Key("int", default=360, check=lambda v: None if v >= 8 else "must be at least 8",
               doc="input angles per revolution for objective and band, and the brackets of the root "
               "finding of the peaks and of the angles where the speed ratio is one"),
    table_step=Key("float", default=10.0, check=positive, units="deg",
                   doc="input-angle step of the .out's speed table"),
    tidy_grid=Key("str", default="n_grid", choices=("n_grid", "table_step"),
                  doc="the input angles of the tidy table (CSV, Parquet): the n_grid angles of the "
                  "objective and summary (360 / n_grid deg apart), or the speed table's (table_step)"),
    angle_origin=Key("str", default="normal", choices=("normal", "plane"),
                     doc="where the input angle theta is 0: 'normal', the paper's (kept as the default so "
                     "its figures reproduce): joint 1's input yoke along the normal to the plane of its "
                     "shafts, a single joint's slowest output; 'plane', textbooks': the yoke in that "
                     "plane, its fastest output (theta_plane = theta_normal - 90 deg). Every table, "
                     "figure and angle column says which"),
    load_inertia=Key("float", units="kg m^2", check=_non_negative_finite,
                     doc="moment of inertia of the driven (output) shaft and what it carries; with it "
                     "(and load_torque) the input torque over a turn at constant input speed, "
                     "T_in = (J alpha_out + T_load) omega_out/omega_in (default 0)"),
    load_torque=Key("float", units="N m", check=_finite,
                    doc="constant torque of the load on the output shaft, resisting its rotation "
                    "(default 0); see load_inertia"),
    maxiter=Key("int", default=200, check=positive, doc="SLSQP iteration limit per start"),
    ftol=Key("float", default=1e-12, check=positive,
             doc="SLSQP tolerance on the objective divided by its scale, the larger of the "
             "trial's value and a single joint's at the largest joint angle; objectives below "
             "ftol times the scale are reported as below the resolution"),
    paper_beta=Key("floats", units="deg", doc="the paper's printed optimum: joint angles"),
    paper_phi=Key("floats", units="deg", doc="the paper's printed optimum: phases phi"),
    paper_u=Key("float", doc="the paper's printed objective value (for display only)"),
    paper_nit=Key("int", doc="the paper's printed iteration count"),
    paper_nfev=Key("int", doc="the paper's printed function evaluations"),
    paper_band=Key("floats", units="rpm", doc="the paper's trial band read off its plot: min, max"),
)


def loads(params) -> tuple[float, float] | None:
    """The output shaft's load: (moment of inertia [kg m^2], load torque [N m]), or None when the
    deck gives neither ``load_inertia`` nor ``load_torque`` (no input-torque analysis)."""
    j, t = params.get("load_inertia"), params.get("load_torque")
    if j is None and t is None:
        return None
    return (0.0 if j is None else float(j), 0.0 if t is None else float(t))


def origin_deg(params) -> float:
    """The kernel's input angle [deg, from the normal to joint 1's plane] at the deck's theta = 0."""
    return ORIGINS[params.get("angle_origin") or "normal"][2]


def per_joint(params: Params, key: str, count: int, what: str) -> np.ndarray:
    """A bound key: one value for all, or exactly ``count`` values."""
    v = params[key]
    if len(v) == 1:
        return np.full(count, float(v[0]))
    if len(v) != count:
        raise params.error(key, f"give one value for all {what} or exactly {count} (got {len(v)})")
    return np.asarray(v, float)


def joint_geometry(params: Params) -> tuple[np.ndarray, np.ndarray | None]:
    """Joint angles [deg] and plane angles [deg or None] from beta/rho or axes."""
    if params.axes is not None:
        if params.beta is not None:
            raise params.error("axes", "give either 'beta' (with optional 'rho') or 'axes', not both")
        if params.rho is not None:
            raise params.error("rho", "'axes' already fixes the plane angles; remove 'rho'")
        a = np.asarray(params.axes, float)
        if a.size % 3 or a.size < 6:
            raise params.error("axes", "needs x,y,z of at least two shafts (a multiple of 3 values, "
                                       f"at least 6; got {a.size})")
        a = a.reshape(-1, 3)
        for k, v in enumerate(a):
            if not np.linalg.norm(v) > 0.0:
                raise params.error("axes", f"shaft {k} direction ({', '.join(map(str, v))}) has zero "
                                           "length; every shaft needs a nonzero direction")
        beta_rad, rho_rad, status = ujoint_geometry(a)
        if status != UjointStatus.ok:
            k = int(np.argmax(beta_rad >= 0.5 * math.pi))
            raise params.error("axes", f"joint {k + 1} bends by {beta_rad[k] / DEG:.4f} deg; a joint angle "
                                       "must lie strictly between -90 and 90 deg")
        return beta_rad / DEG, rho_rad / DEG
    if params.beta is None:
        raise params.error(None, "give the joint angles 'beta' (deg) or the shaft directions 'axes'")
    beta = np.asarray(params.beta, float)
    rho = None
    if params.rho is not None:
        rho = np.asarray(params.rho, float)
        if rho.size != beta.size - 1:
            raise params.error("rho", f"a chain of {beta.size} joint(s) has {beta.size - 1} plane "
                                      f"angle(s) between successive joints; got {rho.size}")
    return beta, rho


def phases_deg(params: Params, n: int, key: str | None = None) -> np.ndarray:
    """The paper's phases phi [deg] (n-1,) from phi or delta (default: in phase)."""
    keys = [key] if key else ["phi", "delta"]
    given = [k for k in keys if params[k] is not None]
    if len(given) > 1:
        raise params.error("delta", "give the phases either as 'phi' (90 = in phase) or as "
                                    "'delta' (0 = in phase), not both")
    if not given:
        return np.full(n - 1, 90.0)
    k = given[0]
    v = np.asarray(params[k], float)
    if v.size != n - 1:
        extra = (" (the paper's phi_3 does not exist: three joints on four shafts leave two "
                 "intermediate shafts)" if n == 3 and v.size > n - 1 else "")
        raise params.error(k, f"a chain of {n} joint(s) has {n - 1} intermediate shaft(s), so "
                              f"{n - 1} phase(s); got {v.size}{extra}")
    return v + 90.0 if k == "delta" else v


def cross_check(params: Params) -> None:
    """Check the ``&ujoint`` keys against each other (the SPEC's cross-key check).

    Parameters
    ----------
    params : Params
        Validated ``&ujoint`` keys.

    Raises
    ------
    DeckError
        Keys that do not fit together (list lengths, a 3-D chain with a paper model, ...),
        naming the key.
    """
    beta, rho = joint_geometry(params)
    n = beta.size
    exact = params.model == "exact"
    if not exact:
        for k in ("rho", "axes"):
            if params[k] is not None:
                raise params.error(k, "plane angles need model = 'exact' (the paper's model is coplanar)")
    elif "phasing" in params.given:
        raise params.error("phasing", "applies only to model = 'paper' (the exact chain has no "
                                      "phasing choice)")
    phases_deg(params, n)
    blo = per_joint(params, "beta_lower", n, "joints")
    bhi = per_joint(params, "beta_upper", n, "joints")
    for key, v in (("beta_lower", blo), ("beta_upper", bhi)):
        msg = _open_angles(v)
        if msg:
            raise params.error(key, msg.replace("a joint angle", "a joint-angle bound"))
    if np.any(blo > bhi):
        j = int(np.argmax(blo > bhi))
        raise params.error("beta_lower", f"lower bound {blo[j]} deg exceeds upper bound {bhi[j]} deg "
                                         f"for joint {j + 1}; need beta_lower <= beta_upper")
    if n > 1:
        plo = per_joint(params, "phi_lower", n - 1, "phases")
        phi_hi = per_joint(params, "phi_upper", n - 1, "phases")
        if np.any(plo > phi_hi):
            j = int(np.argmax(plo > phi_hi))
            raise params.error("phi_lower", f"lower bound {plo[j]} deg exceeds upper bound {phi_hi[j]} "
                                            f"deg for phase {j + 1}; need phi_lower <= phi_upper")
    if params.option == 1 and n < 2:
        raise params.error("option", "option 1 optimises phases, but a single joint has none; "
                                     "use option 0 or 2")
    if params.option in (2, 3) and params.axes is not None:
        raise params.error("option", "with 'axes' the joint angles follow from the geometry; "
                                     "only options 0 and 1 apply (give 'beta' and 'rho' to free them)")
    if params.paper_beta is not None:
        if len(params.paper_beta) != n:
            raise params.error("paper_beta", f"needs {n} joint angle(s); got {len(params.paper_beta)}")
        msg = _open_angles(params.paper_beta)
        if msg:
            raise params.error("paper_beta", msg)
    if params.paper_phi is not None:
        phases_deg(params, n, "paper_phi")
    if params.paper_band is not None and len(params.paper_band) != 2:
        raise params.error("paper_band", f"needs two values (min, max rpm); got {len(params.paper_band)}")


#: axis labels of summary columns and deck keys (driver._output.column_label): name -> (words, units);
#: {i} is the number of a joint in the chain
LABELS = {"rpm": ("input shaft speed", "rpm"), "objective": ("objective (optimum)", "-"),
          "objective_trial": ("objective (trial)", "-"), "pp_ratio": ("peak-to-peak speed ratio", "-"),
          "omega_out_min_rpm": ("minimum output speed", "rpm"), "omega_out_max_rpm": ("maximum output speed", "rpm"),
          "beta_e_deg": ("equivalent joint angle", "deg"), "beta_res_deg": ("resultant joint angle", "deg"),
          "peak_accel_rad_s2": ("peak output acceleration", "rad/s^2"),
          "peak_accel_at_deg": ("input angle of the peak output acceleration", "deg"),
          "ratio_one_at_deg": ("first input angle where the output speed equals the input's", "deg"),
          "input_torque_peak_Nm": ("peak input torque", "N m"),
          "input_torque_peak_at_deg": ("input angle of the peak input torque", "deg"),
          "input_torque_mean_Nm": ("mean input torque", "N m"),
          "load_inertia": ("output-shaft moment of inertia", "kg m^2"), "load_torque": ("load torque", "N m"),
          "iterations": ("iterations", "-"),
          "evaluations": ("objective evaluations", "-"),
          "phi_{i}_deg": ("phase angle $\\varphi_{{i}}$", "deg"), "beta_{i}_deg": ("joint angle $\\beta_{{i}}$", "deg"),
          "beta": ("joint angle $\\beta$", "deg"), "phi": ("phase angle $\\varphi$", "deg"),
          "delta": ("yoke phase $\\delta$", "deg"), "rho": ("angle between the joint planes $\\rho$", "deg")}
#: what a sweep summary plots when its deck names no plot_y
SWEEP_PLOT = ("omega_out_min_rpm", "omega_out_max_rpm", "pp_ratio", "beta_e_deg", "peak_accel_rad_s2", "objective")


SPEC = GroupSpec("ujoint", KEYS, check=cross_check,
                 doc="Hooke-joint shaft chain: speed fluctuation, exact 3-D kinematics, SSO options 0-3. "
                 "Conventions: " + CONVENTIONS)


@contract_doc
def estimate(params: Params) -> Estimate:
    """Estimate the memory and work of a run from the keys alone, before it allocates.

    Per input angle of the grid and joint about 200 bytes of kernel arrays and 20 ns per
    objective evaluation; SLSQP evaluates objective and gradient about (variables + 1) times per
    iteration for every start; each speed-table row costs about 1 KB and 20 us to format.

    %(estimate)s
    """
    p = params
    joints = max(len(p.beta or []), len(p.phi or []) + 1, 2)
    m = float(p.n_grid)
    try:
        rows = math.floor(360.0 / p.table_step + 1e-9) + 1.0
    except (OverflowError, ZeroDivisionError):
        rows = math.inf
    evals = 0.0 if p.option == 0 else float(p.n_starts) * p.maxiter * (2 * joints + 1)
    mem = Estimate(200.0 * m * joints + 5e6, 2e-8 * m * joints * (evals + 10), "n_grid",
                   "n_starts" if p.option else "n_grid", f"{m:.4g} grid angles x {joints} joints"
                   + (f", about {evals:.3g} objective evaluations" if evals else ""))
    table = Estimate(1000.0 * rows * joints, 2e-5 * rows * joints, "table_step", "table_step",
                     f"{rows:.4g} speed-table rows")
    return mem + table
