"""SHA-256 of the raw float64 results of every kernel on fixed inputs (a test helper).

``python tests/kernel_fingerprint.py`` prints them as JSON for whichever installed
``driver`` it imports; test_install compares the portable wheel's fingerprint with
the native editable build's: the kernels must agree to the last bit.
"""
from __future__ import annotations

import hashlib
import json

import numpy as np

from driver.fourbar import _kernel as fourbar_kernel
from driver.linkage import _kernel as linkage_kernel
from driver.manipulator import _kernel as manipulator_kernel
from driver.slidercrank import _kernel as slidercrank_kernel
from driver.ujoint import _kernel as ujoint_kernel


def _h(*arrays) -> str:
    d = hashlib.sha256()
    for a in arrays:
        d.update(np.ascontiguousarray(np.asarray(a, dtype=np.float64)).tobytes())
    return d.hexdigest()


def fingerprint() -> dict[str, str]:
    """One hash per kernel wrapper of driver._fortran (every one: test_packaging checks it), inputs chosen
    to exercise every code path (vector loops included)."""
    rng = np.random.default_rng(20261125)
    theta = np.concatenate([np.linspace(0, 2 * np.pi, 2001), rng.uniform(-50, 50, 4003)])
    out = {}
    table, st = fourbar_kernel.fourbar_listing(12.0, 5.0, 15.0, 9.0, 5.0, 0, 20, 19)
    out["fourbar_listing"] = _h(table, st)
    for branch in (1, -1):
        s, st = fourbar_kernel.fourbar_exact(theta, 12.0, 5.0, 15.0, 9.0, 5.0, 0.7, branch)
        out[f"fourbar_exact{branch:+d}"] = _h(s, st, fourbar_kernel.fourbar_coupler_point(theta, s, st, 5.0, 5.0, 0.7, 7.5, 2.0))
    n = 3001
    l1, l2 = rng.uniform(0.2, 1.0, n), rng.uniform(0.2, 1.0, n)
    th1, th2 = rng.uniform(-np.pi, np.pi, n), rng.uniform(-np.pi, np.pi, n)
    jac, w, kappa, tau = manipulator_kernel.manipulator_arm_states(l1, l2, th1, th2, (1.3, -0.4), (0.2, 2.0))
    out["manipulator_arm_states"] = _h(jac, w, kappa, tau, manipulator_kernel.manipulator_torques(l1, l2, th1, th2))
    x, y = rng.uniform(-1.5, 1.5, n), rng.uniform(-1.5, 1.5, n)
    out["manipulator_ik"] = _h(*manipulator_kernel.manipulator_ik(l1, l2, x, y, 1),
                               *manipulator_kernel.manipulator_ik(l1, l2, x, y, -1))
    px, py = rng.uniform(0.1, 0.6, 9), rng.uniform(0.1, 0.6, 9)
    out["manipulator_design_indices"] = _h(*manipulator_kernel.manipulator_design_indices(px, py, l1[:500] + 0.6, l2[:500] + 0.6))
    out["manipulator_position_errors"] = _h(manipulator_kernel.manipulator_position_errors(th1[:9], th2[:9],
                                                                            rng.normal(0, 1e-3, (2000, 2))))
    beta, phi, rho = np.radians([12.0, 25.0, 9.0]), np.radians([80.0, 100.0]), np.radians([20.0, -35.0])
    for name, code in ujoint_kernel.UJOINT_MODELS.items():
        r = ujoint_kernel.ujoint_speed(code, beta, phi, rho, theta)
        f, g = ujoint_kernel.ujoint_objective(code, ujoint_kernel.UJOINT_OBJECTIVES["mean_square"], beta, phi, rho, 720)
        out[f"ujoint_{name}"] = _h(*r, f, g)
    # the Simeon (1996) steel rod: A = 64 mm^2, I = 3.41e-10 m^4, rho = 7870, E = 200 GPa, 150 rad/s
    sc = slidercrank_kernel.slidercrank_simulate(16, 0.15, 0.3, 7870 * 64e-6, 2e11 * 64e-6, 2e11 * 3.413333333e-10, 0.004,
                                0.075552, 150.0, 2.5e-5, 800, 400, 400, alpha=1.0, beta=1e-6)
    assert sc["status"] == slidercrank_kernel.SLIDERCRANK_STATUS["ok"], sc["status"]
    out["slidercrank_simulate"] = _h(*(sc[n] for n in ("eps_ax", "eps_of", "n_avg", "mid", "slider", "elong")),
                                     sc["status"])
    pr = slidercrank_kernel.slidercrank_simulate(16, 0.15, 0.3, 7870 * 64e-6, 2e11 * 64e-6, 2e11 * 3.413333333e-10, 0.004,
                                0.075552, 150.0, 2.5e-5, 800, 400, 400, alpha=1.0, beta=1e-6, fields=False, lag=100)
    out["slidercrank_simulate_profile"] = _h(*(pr[n] for n in slidercrank_kernel.SLIDERCRANK_PROFILE), pr["status"])
    out.update(_batch_and_auxiliary_kernels(rng, theta))
    return out


def _batch_and_auxiliary_kernels(rng: np.random.Generator, theta: np.ndarray) -> dict[str, str]:
    """The batch-summary, force, geometry and closed-form kernels (every other wrapper of driver._fortran)."""
    out = {}
    nd = 2000
    links = rng.uniform(2.0, 15.0, (nd, 4))
    ends = np.column_stack([np.zeros(nd), np.where(rng.random(nd) < 0.5, 360.0, rng.uniform(30, 300, nd))])
    params = np.column_stack([links, rng.uniform(1, 10, nd), ends, np.where(rng.random(nd) < 0.5, 1.0, -1.0)])
    out["fourbar_summaries"] = _h(fourbar_kernel.fourbar_summaries(params))
    # forces in SI: the crank-5 linkage in metres, masses and inertias of steel bars, a load
    p, q, r, s = 0.12, 0.05, 0.15, 0.09
    props = np.array([0.4, 1.1, 0.7, 2e-4, 2.1e-3, 5e-4, 0.025, 0.075, 0.045, 0.0, 0.1, -0.05,
                      9.81, 1.5, 3.0, -2.0, 0.07, 0.02])
    states, st = fourbar_kernel.fourbar_exact(theta, p, q, r, s, 5.0, 0.7, 1)
    out["fourbar_joint_forces"] = _h(fourbar_kernel.fourbar_joint_forces(states, st, p, q, r, s, 5.0, 0.7, props))
    forces = fourbar_kernel.fourbar_joint_forces(states, st, p, q, r, s, 5.0, 0.7, props)
    out["fourbar_link_stresses"] = _h(fourbar_kernel.fourbar_link_stresses(
        states, st, p, q, r, s, 0.7, props, forces, np.array([2e-5, 3e-5, 2.5e-5, 5e-8, 8e-8, 6e-8])))
    balanced, cw = fourbar_kernel.fourbar_berkof_lowen(q, r, s, props, (0.03, 0.04))
    out["fourbar_berkof_lowen"] = _h(balanced, cw)
    nf = 200
    scale = rng.uniform(0.8, 1.2, (nf, 4)) * np.array([p, q, r, s])
    fparams = np.column_stack([scale, rng.uniform(2, 20, nf), rng.uniform(-1, 1, nf), np.zeros(nf),
                               np.full(nf, 360.0), np.where(rng.random(nf) < 0.5, 1.0, -1.0),
                               np.tile(props, (nf, 1)), np.full(nf, 0.05), (rng.random(nf) < 0.5) * 1.0,
                               np.full((nf, 2), 0.03)])
    out["fourbar_force_summaries"] = _h(fourbar_kernel.fourbar_force_summaries(fparams))
    wx, wy = rng.uniform(0.2, 0.5, 6), rng.uniform(0.2, 0.5, 6)
    mparams = np.column_stack([rng.uniform(0.3, 0.8, (nd, 2)), rng.uniform(0.2, 0.6, (nd, 2)),
                               np.full(nd, 3.0), np.full(nd, 9.81), np.full(nd, 1e-3)])
    unit = rng.uniform(-1, 1, (500, 2))
    out["manipulator_design_summaries"] = _h(
        manipulator_kernel.manipulator_design_summaries(wx, wy, mparams, 1, (1.0, 0.5, 0.2, 0.1), "global", unit),
        manipulator_kernel.manipulator_design_summaries(wx, wy, mparams, -1, (1.0, 0.5, 0.2, 0.1), "per_point", unit))
    beta = rng.uniform(0.05, 0.5, (nd, 3))
    phi, rho = rng.uniform(-np.pi, np.pi, (nd, 2)), rng.uniform(-np.pi, np.pi, (nd, 2))
    kinds = ujoint_kernel.UJOINT_OBJECTIVES
    out["ujoint_summaries"] = _h(*(ujoint_kernel.ujoint_summaries(code, kinds[obj], beta, phi, rho, 360)
                                   for code in ujoint_kernel.UJOINT_MODELS.values() for obj in kinds))
    eq = [ujoint_kernel.ujoint_equivalent(code, beta[i], phi[i], rho[i])
          for code in ujoint_kernel.UJOINT_MODELS.values() for i in range(50)]
    eq += [ujoint_kernel.ujoint_equivalent(ujoint_kernel.UJOINT_MODELS["exact"], beta[0], [np.pi / 2, 0.0], [0.0, 0.0])]
    out["ujoint_equivalent"] = _h([be for be, _ in eq], [np.nan if br is None else br for _, br in eq])
    exact = ujoint_kernel.UJOINT_MODELS["exact"]
    out["ujoint_jet"] = _h(*ujoint_kernel.ujoint_jet(exact, beta[0], phi[0], rho[0], theta))
    out["ujoint_roots"] = _h(*(ujoint_kernel.ujoint_roots(exact, what, beta[i], phi[i], rho[i], 360, (0.4, 1.5))
                               for what in ujoint_kernel.UJOINT_ROOTS for i in range(5)))
    out["ujoint_input_torque"] = _h(*ujoint_kernel.ujoint_input_torque(exact, beta[0], phi[0], rho[0], theta,
                                                                       60.0, 0.4, 1.5))
    axes = rng.normal(0, 1, (5, 3)) * 0.2 + np.array([1.0, 0.0, 0.0])
    g_beta, g_rho, g_status = ujoint_kernel.ujoint_geometry(np.cumsum(axes, axis=0))
    out["ujoint_geometry"] = _h(g_beta, g_rho, g_status)
    sc = (0.15, 0.3, 7870 * 64e-6, 2e11 * 64e-6, 2e11 * 3.413333333e-10)
    mb, kb = slidercrank_kernel.slidercrank_matrices(16, *sc, 0.075552, 1.3, 150.0, True)
    out["slidercrank_matrices"] = _h(mb, kb)
    out["slidercrank_rigid"] = _h(slidercrank_kernel.slidercrank_rigid(theta, 150.0, 0.15, 0.3))
    out["slidercrank_axial_force"] = _h(slidercrank_kernel.slidercrank_axial_force(theta[:500], np.linspace(0, 0.3, 17), 150.0,
                                                                  0.15, 0.3, 7870 * 64e-6, 0.075552))
    out["slidercrank_frequencies"] = _h(slidercrank_kernel.slidercrank_frequencies(7870 * 64e-6, 2e11 * 64e-6,
                                                                  2e11 * 3.413333333e-10, 0.3, 0.075552))
    nl = slidercrank_kernel.slidercrank_nl_simulate(6, 0.15, 0.3, 7870 * 64e-6, 2e11 * 64e-6, 2e11 * 3.413333333e-10, 0.004, 1.3,
                                   150.0, 2 * np.pi / 150.0 / 360, 400, 360, 0, 400, 0.0, 1e-4, -0.05)
    out["slidercrank_nl_simulate"] = _h(*(nl[key] for key in ("eps_ax", "eps_of", "lat_max", "mid", "elong",
                                                               "slider", "rev_lat", "rev_eps", "stats")),
                                        [nl["status"]])
    out["slidercrank_column_static"] = _h(slidercrank_kernel.slidercrank_column_static(
        8, 1.0, 2e11 * 64e-6, 2e11 * 3.413333333e-10, 1.06 * np.pi ** 2 * 2e11 * 3.413333333e-10, 1e-3))
    pe = rng.normal(0, 1e-3, 6)
    out["slidercrank_corot_element"] = _h(*slidercrank_kernel.slidercrank_corot_element(0.05, 2e11 * 64e-6,
                                                                                        2e11 * 3.413333333e-10, pe))
    # the linkage kernel: every group type (RRR, RRP, PRR, RPR, PRP), forces, a guide-force table
    import pathlib

    from driver._deck import read_deck, validate
    from driver.linkage import SPEC as LINKAGE_SPEC
    from driver.linkage import compile_deck
    from driver.linkage._batch import design_numbers
    root = pathlib.Path(__file__).resolve().parents[1] / "inputs"
    decks = [validate(read_deck(root / f"{d}.dat").groups["linkage"], LINKAGE_SPEC, d)
             for d in ("linkage_engine", "linkage_whitworth", "linkage_watt2", "linkage_inverted_slider_crank")]
    prp = read_deck("prp.dat", "&linkage\npivots='O2', pivot_xy=0,0, guides='slot','ways', guide_on='crank','ground', "
                    "guide_xy=0,0, 0.3,0.1, guide_deg=60,10\ndriver_joints='O2','A', driver_length=1, step=1\n"
                    "dyads='PRP','PRR', dyad_joints='slot','ways','P', 'ways','P','Q', dyad_links='b1','b2','b3','rod', "
                    "dyad_dims=0.1,-0.05, 0.2,0.8\nbodies='crank','b1','b2','rod', mass=1,0.5,0.5,0.7, "
                    "inertia=0.1,0.01,0.01,0.05, com_uv=0.2,0,0,0,0,0,0.3,0.05\n/\n")
    decks.append(validate(prp.groups["linkage"], LINKAGE_SPEC, "prp.dat"))
    xs = np.linspace(0.0, 2 * np.pi, 1500)
    for i, p in enumerate(decks):
        mech = compile_deck(p)
        a = linkage_kernel.analyse(mech, xs)
        out[f"linkage_analyse{i}"] = _h(*[np.asarray(v, float) for v in a])
        b = linkage_kernel.analyse(mech, xs, out=linkage_kernel.buffers(mech, len(xs)))   # into made buffers
        out[f"linkage_analyse_out{i}"] = _h(*[np.asarray(v, float) for v in b])
        out[f"linkage_reusable_call{i}"] = _h(*linkage_kernel.reusable_call(mech, xs, continuity=False)())
        rows = np.asfortranarray(np.tile(design_numbers(p, mech, {}, 1), (3, 1)))
        out[f"linkage_summaries{i}"] = _h(linkage_kernel.summaries(mech, rows, 90, mech.driver == "crank"),
                                          [linkage_kernel.summary_width(mech)])
    out["linkage_table_energy"] = _h(linkage_kernel.table_energy(np.radians([0.0, 90, 135, 180, 360]),
                                                                 np.array([0.0, 0, 1000, 0, 0]), 0.02, 50.0))
    return out


if __name__ == "__main__":
    print(json.dumps(fingerprint(), indent=1, sort_keys=True))
