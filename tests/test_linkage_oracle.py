"""The linkage kernel against an independent implementation (tests/linkage_oracle.py: Newton on
the loop equations of all links at once, the constraint Jacobian for velocities and
accelerations, one Newton-Euler system for every joint force) on hypothesis-drawn mechanisms of
every group type (RRR, RRP, PRR, RPR, PRP), both six-bars and an input slider: 1e-9 of each
quantity's scale.  Velocities and accelerations also against central differences of the
kernel's own positions; input power against the rate of kinetic and potential energy and the
loads' power."""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from driver.linkage._analysis import solve
from driver.linkage._kernel import DriverCol, JointCol, LinkageStatus, LinkCol, PointCol, ShakeCol, SlideCol
from linkage_oracle import Oracle, kernel_frames, params_of

TOL = 1e-9
coord = st.floats(-1.0, 1.0)
size = st.floats(0.3, 1.0)
SETTINGS = dict(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])


def _cross(a: np.ndarray, b: np.ndarray) -> float:
    return float(a[0] * b[1] - a[1] * b[0])


def _fmt(v: float) -> str:
    return repr(float(v))


def _crank(theta0: float, r: float) -> tuple[str, np.ndarray]:
    return (f"driver_joints='O2','A', driver_length={_fmt(r)}, omega=3.0, alpha=1.5, start={_fmt(theta0)}, "
            f"stop={_fmt(theta0 + 6)}, step=2", np.array([r * math.cos(math.radians(theta0)),
                                                          r * math.sin(math.radians(theta0))]))


def _mass_lines(links: list[str], rng: np.random.Generator) -> str:
    m = rng.uniform(0.2, 2.0, len(links))
    com = rng.uniform(-0.3, 0.3, (len(links), 2))
    inertia = rng.uniform(1e-3, 5e-2, len(links))
    return (f"bodies={', '.join(repr(l) for l in links)}, mass={', '.join(map(_fmt, m))}, "
            f"com_uv={', '.join(map(_fmt, com.ravel()))}, inertia={', '.join(map(_fmt, inertia))}, gravity=0.3,-9.81")


@st.composite
def mechanisms(draw) -> tuple[str, str]:
    """A deck body whose mechanism assembles at its first input: (kind, text)."""
    kind = draw(st.sampled_from(["rrr", "rrp", "prr", "rpr", "prp", "watt2", "stephenson3", "slider_rrr"]))
    seed = draw(st.integers(0, 2**31 - 1))
    rng = np.random.default_rng(seed)
    theta0 = draw(st.floats(0.0, 360.0))
    r = draw(size)
    drv, A = _crank(theta0, r)
    ox, oy = draw(coord) * 2, draw(coord) * 2
    jx, jy = draw(coord) * 2, draw(coord) * 2
    loads = ""
    if kind in ("rrr", "watt2", "stephenson3"):
        O4 = np.array([ox + 1.5, oy])
        B = np.array([jx, jy + 1.0])
        l1, l2 = np.linalg.norm(B - A), np.linalg.norm(B - O4)
        mode = 1 if _cross(O4 - A, B - A) > 0 else -1
        text = (f"pivots='O2','O4', pivot_xy=0,0, {_fmt(O4[0])},{_fmt(O4[1])}\n{drv}\n"
                f"dyads='RRR', dyad_joints='A','O4','B', dyad_links='coupler','rocker', "
                f"dyad_dims={_fmt(l1)},{_fmt(l2)}, dyad_modes={mode}")
        links = ["crank", "coupler", "rocker"]
        if kind != "rrr":
            # the second group: from a point C on the rocker (Watt II) or P on the coupler (Stephenson III)
            on, base, ang = (("rocker", O4, math.atan2(*(B - O4)[::-1])) if kind == "watt2" else
                             ("coupler", A, math.atan2(*(B - A)[::-1])))
            u, v = draw(coord), draw(coord)
            C = base + np.array([[math.cos(ang), -math.sin(ang)], [math.sin(ang), math.cos(ang)]]) @ [u, v]
            O6 = np.array([draw(coord) * 2, draw(coord) * 2 - 1.0])
            D = np.array([draw(coord) * 2, draw(coord) * 2 + 0.5])
            l5, l6 = np.linalg.norm(D - C), np.linalg.norm(D - O6)
            assume(l5 > 0.2 and l6 > 0.2)
            m2 = 1 if _cross(O6 - C, D - C) > 0 else -1
            text = (f"pivots='O2','O4','O6', pivot_xy=0,0, {_fmt(O4[0])},{_fmt(O4[1])}, {_fmt(O6[0])},{_fmt(O6[1])}\n"
                    f"{drv}\ndyads='RRR','RRR', dyad_joints='A','O4','B', 'C','O6','D', "
                    f"dyad_links='coupler','rocker','link5','link6', dyad_dims={_fmt(l1)},{_fmt(l2)}, "
                    f"{_fmt(l5)},{_fmt(l6)}, dyad_modes={mode},{m2}\npoints='C', point_on={on!r}, "
                    f"point_uv={_fmt(u)},{_fmt(v)}")
            links += ["link5", "link6"]
            loads = "loads='D', load_xy=3.0,-2.0, torque_links='link6', torques=0.7"
        assume(l1 > 0.2 and l2 > 0.2)
    elif kind in ("rrp", "prr"):
        gang = draw(st.floats(-180, 180))
        g = np.array([ox, oy])
        u = np.array([math.cos(math.radians(gang)), math.sin(math.radians(gang))])
        n = np.array([-u[1], u[0]])
        e, s = draw(coord) * 0.3, draw(coord) * 2
        B = g + e * n + s * u
        l = np.linalg.norm(B - A)
        assume(l > 0.2)
        mode = 1 if s >= (A - g) @ u else -1
        joints, dl, dims = (("'A','bore','B'", "'rod','slider'", f"{_fmt(l)},{_fmt(e)}") if kind == "rrp" else
                            ("'bore','A','B'", "'slider','rod'", f"{_fmt(e)},{_fmt(l)}"))
        text = (f"pivots='O2', pivot_xy=0,0, guides='bore', guide_xy={_fmt(g[0])},{_fmt(g[1])}, guide_deg={_fmt(gang)}\n"
                f"{drv}\ndyads={kind!r}, dyad_joints={joints}, dyad_links={dl}, dyad_dims={dims}, dyad_modes={mode}\n"
                "guide_force_on='slider', guide_force_over='slide', guide_force_x=-10,10, guide_force=-40,60")
        links = ["crank", "rod", "slider"]
    elif kind == "rpr":
        O4 = np.array([ox + 1.5, oy])
        b = A - O4
        e = draw(coord) * 0.9 * np.linalg.norm(b)
        mode = draw(st.sampled_from([1, -1]))
        text = (f"pivots='O2','O4', pivot_xy=0,0, {_fmt(O4[0])},{_fmt(O4[1])}\n{drv}\n"
                f"dyads='RPR', dyad_joints='O4','A','slot', dyad_links='lever','block', dyad_dims={_fmt(e)},0, "
                f"dyad_modes={mode}\npoints='E', point_on='lever', point_uv=0.7,0.1")
        links = ["crank", "lever", "block"]
        loads = "loads='E', load_xy=-1.0,2.5"
    elif kind == "prp":
        # a slot in the crank (guide 'slot' on the crank) and a ground guide; blocks pinned at P
        sg = draw(st.floats(20, 160))
        gang = draw(st.floats(-180, 180))
        text = (f"pivots='O2', pivot_xy=0,0, guides='slot','ways', guide_on='crank','ground', "
                f"guide_xy=0,0, {_fmt(ox)},{_fmt(oy)}, guide_deg={_fmt(sg)},{_fmt(gang)}\n{drv}\n"
                f"dyads='PRP', dyad_joints='slot','ways','P', dyad_links='block1','block2', "
                f"dyad_dims={_fmt(jx * 0.2)},{_fmt(jy * 0.2)}")
        links = ["crank", "block1", "block2"]
    else:   # an input slider driving an RRR group
        gang = draw(st.floats(-180, 180))
        s0 = draw(coord)
        u = np.array([math.cos(math.radians(gang)), math.sin(math.radians(gang))])
        A = s0 * u
        O4 = np.array([ox + 1.5, oy])
        B = np.array([jx, jy + 1.0])
        l1, l2 = np.linalg.norm(B - A), np.linalg.norm(B - O4)
        assume(l1 > 0.2 and l2 > 0.2)
        mode = 1 if _cross(O4 - A, B - A) > 0 else -1
        text = (f"pivots='O4', pivot_xy={_fmt(O4[0])},{_fmt(O4[1])}, guides='ways', guide_xy=0,0, "
                f"guide_deg={_fmt(gang)}\ndriver='slider', driver_joints='ways','A', omega=0.8, alpha=-0.4, "
                f"start={_fmt(s0)}, stop={_fmt(s0 + 0.03)}, step=0.01\n"
                f"dyads='RRR', dyad_joints='A','O4','B', dyad_links='coupler','rocker', "
                f"dyad_dims={_fmt(l1)},{_fmt(l2)}, dyad_modes={mode}")
        links = ["slider", "coupler", "rocker"]
    text += "\n" + _mass_lines(links, rng) + ("\n" + loads if loads else "")
    return kind, text


def _well_conditioned(m, limit: float = 0.05) -> np.ndarray:
    """Rows away from every toggle (the quality angle's sine above ``limit``): both solvers'
    rounding is then of the size of the data."""
    good = m.ok.copy()
    for d, dy in enumerate(m.mech.dyads):
        qa = m.a.quality[:, d]
        good &= (np.abs(np.sin(qa)) > limit) if dy.kind == "rrr" else (np.abs(np.cos(qa)) > limit)
    return good


def _scale(*arrays: np.ndarray) -> float:
    return max(float(np.max(np.abs(a))) for a in arrays) + 1e-300


@settings(**SETTINGS)
@given(mechanisms())
def test_kernel_matches_the_independent_solver(case):
    kind, text = case
    p = params_of(text)
    m = solve(p)
    good = _well_conditioned(m)
    assume(good.any())
    o = Oracle(m.mech)
    qk = kernel_frames(m)
    mech = m.mech
    rng = np.random.default_rng(0)
    checked = 0
    for k in np.flatnonzero(good):
        q0 = qk[k] + 1e-4 * rng.standard_normal(qk.shape[1])
        q, qd, qdd = o.solve(m.xk[k], q0, mech.omega, mech.alpha)
        # the same assembly (the start was near the kernel's)
        ang_err = np.angle(np.exp(1j * (q[2::3] - qk[k, 2::3])))
        assert np.max(np.abs(ang_err)) < 1e-6, (kind, k)
        pos, vel, acc = [], [], []
        for j, pt in enumerate(mech.points):
            ps, vs, as_ = o.point_state(q, qd, qdd, (pt[1] - 1, pt[2], pt[3]))
            pos.append((m.a.points[k, [PointCol.X, PointCol.Y], j], ps))
            vel.append((m.a.points[k, [PointCol.VX, PointCol.VY], j], vs))
            acc.append((m.a.points[k, [PointCol.AX, PointCol.AY], j], as_))
        for pairs in (pos, vel, acc):
            scale = _scale(*[b for _, b in pairs]) + 1e-12
            for a, b in pairs:
                assert np.max(np.abs(a - b)) <= TOL * scale, (kind, k, a, b, scale)
        w, al = qd[2::3], qdd[2::3]
        sw, sa = _scale(w) + 1e-12, _scale(al) + 1e-12
        assert np.max(np.abs(m.a.links[k, LinkCol.OMEGA, 1:] - w)) <= TOL * sw
        assert np.max(np.abs(m.a.links[k, LinkCol.ALPHA, 1:] - al)) <= TOL * sa
        # forces: every joint, the drive, the shaking force and moment
        gf = None
        if mech.gf_block:
            s = m.a.slides[k, SlideCol.S, mech.gf_slide - 1]
            x, f = mech.gf_table[:, 0], mech.gf_table[:, 1]
            gf = (mech.gf_block - 1, mech.gf_guide_link - 1, mech.gf_scale * float(np.interp(s, x, f)))
        loads = [((mech.points[i - 1][1] - 1, mech.points[i - 1][2], mech.points[i - 1][3]), np.array(fxy))
                 for i, fxy in zip(mech.load_points, mech.load_xy)]
        torques = {l: float(mech.torque[l]) for l in range(1, len(mech.links)) if mech.torque[l]}
        reac, drive, shf, shm = o.forces(q, qd, qdd, mech.gravity, loads, torques, gf)
        fscale = _scale(np.array(reac), np.array([drive]), shf) + 1e-12
        kj = m.a.joints[k]
        for d, dy in enumerate(mech.dyads):
            ours = [kj[[JointCol.AX, JointCol.AY, JointCol.AQ], d], kj[[JointCol.BX, JointCol.BY, JointCol.BQ], d],
                    kj[[JointCol.CX, JointCol.CY, JointCol.CQ], d]]
            theirs = [np.array(reac[1 + 3 * d + i]) for i in range(3)]
            if dy.kind == "prr":   # the deck's order: guide, rod pivot, block on rod
                theirs = [theirs[1], theirs[0], -theirs[2]]
            for a, b in zip(ours, theirs):
                assert np.max(np.abs(a - b)) <= TOL * fscale * 10, (kind, k, d, a, b)
        assert abs(m.a.driver[k, DriverCol.DRIVE] - drive) <= TOL * fscale * 10
        assert np.max(np.abs(m.a.shaking[k, [ShakeCol.FX, ShakeCol.FY]] - shf)) <= TOL * fscale * 10
        assert abs(m.a.shaking[k, ShakeCol.M] - shm) <= TOL * fscale * 10 * (1 + _scale(qk[k, 0::3], qk[k, 1::3]))
        checked += 1
    assert checked > 0


@settings(**SETTINGS)
@given(mechanisms())
def test_rates_are_central_differences_of_positions(case):
    """Velocity and acceleration of every point and slide against central differences of the
    kernel's own positions (five-point stencils at input steps h/2 and h, h = 1e-3 rad or length:
    truncation O(h^4)), away from toggles (the quality angle's sine above 0.5).  The allowance is
    the rounding floor plus the stencils' own truncation, estimated from their difference at h and
    h/2 (Richardson: the h/2 stencil's error is about 1/15 of that difference), so a steep but
    right curve passes and a wrong rate fails."""
    kind, text = case
    p = params_of(text)
    m = solve(p)
    good = _well_conditioned(m, 0.5)
    assume(good.any())
    k = int(np.argmax(good))
    h = 1e-3
    offsets = np.array([-2.0, -1.0, -0.5, 0.0, 0.5, 1.0, 2.0])   # stencils: h at 0,1,3,5,6; h/2 at 1,2,3,4,5
    x = m.x[k] + (np.degrees(h) if m.mech.driver == "crank" else h) * offsets
    mm = solve(p, x, m.mech)
    assume(mm.ok.all())
    w, al = m.mech.omega, m.mech.alpha
    size = _scale(mm.a.points[:, [PointCol.X, PointCol.Y], :])   # the mechanism's size

    def stencils(f: np.ndarray, step: float) -> tuple[np.ndarray, np.ndarray]:
        d1 = (-f[4] + 8 * f[3] - 8 * f[1] + f[0]) / (12 * step)
        d2 = (-f[4] + 16 * f[3] - 30 * f[2] + 16 * f[1] - f[0]) / (12 * step * step)
        return d1, d2

    def check(pos: np.ndarray, vel: np.ndarray, acc: np.ndarray, scale: float = size) -> None:
        d1h, d2h = stencils(pos[[0, 1, 3, 5, 6]], h)
        d1, d2 = stencils(pos[[1, 2, 3, 4, 5]], h / 2)
        tv = np.abs(w * (d1h - d1))                      # about 15x the h/2 stencil's truncation
        ta = np.abs(w * w * (d2h - d2) + al * (d1h - d1))
        ev = np.abs(vel - w * d1)
        ea = np.abs(acc - (w * w * d2 + al * d1))
        assert np.all(ev <= 1e-7 * scale * (1 + abs(w)) + tv), (kind, vel, w * d1, tv)
        assert np.all(ea <= 1e-5 * scale * (1 + w * w + abs(al)) + ta), (kind, acc, ta)

    check(mm.a.points[:, [PointCol.X, PointCol.Y], :], mm.a.points[3, [PointCol.VX, PointCol.VY], :],
          mm.a.points[3, [PointCol.AX, PointCol.AY], :])
    if m.mech.slides:
        check(mm.a.slides[:, SlideCol.S, :], mm.a.slides[3, SlideCol.V, :], mm.a.slides[3, SlideCol.A, :])
    ang = np.unwrap(mm.a.links[:, LinkCol.ANGLE, :], axis=0)
    # angles: the scale of their own derivatives (an angle per unit of a slider's input may be large)
    check(ang, mm.a.links[3, LinkCol.OMEGA, :], mm.a.links[3, LinkCol.ALPHA, :],
          1.0 + _scale(mm.a.links[3, LinkCol.OMEGA, :]) / max(abs(w), 1e-300)
          + _scale(mm.a.links[3, LinkCol.ALPHA, :]) / max(w * w, 1e-300))


@settings(**SETTINGS)
@given(mechanisms())
def test_input_power_balances_energy_rate(case):
    """At every position: input power = d/dt (kinetic + potential energy) - the loads' power,
    within 1e-9 of the cycle's peak power (the kernel's own kinematics; an identity the
    group-by-group force solution must keep)."""
    kind, text = case
    p = params_of(text)
    m = solve(p)
    good = _well_conditioned(m)
    assume(good.any())
    mech, a = m.mech, m.a
    w_in = mech.omega
    power_in = a.driver[:, DriverCol.DRIVE] * w_in
    rate = np.zeros(len(m.x))
    loads = np.zeros(len(m.x))
    g = np.array(mech.gravity)
    from driver.linkage._analysis_frames import _origins
    origins = _origins(mech)
    for l in range(2, len(mech.links) + 1):
        mass, gu, gv, inertia = mech.body[l - 1]
        j = mech.point_index(origins[l]) - 1
        th, om, alp = a.links[:, LinkCol.ANGLE, l - 1], a.links[:, LinkCol.OMEGA, l - 1], a.links[:, LinkCol.ALPHA, l - 1]
        rx, ry = gu * np.cos(th) - gv * np.sin(th), gu * np.sin(th) + gv * np.cos(th)
        vx = a.points[:, PointCol.VX, j] - om * ry
        vy = a.points[:, PointCol.VY, j] + om * rx
        ax = a.points[:, PointCol.AX, j] - alp * ry - om * om * rx
        ay = a.points[:, PointCol.AY, j] + alp * rx - om * om * ry
        rate += mass * (vx * ax + vy * ay) + inertia * om * alp - mass * (g[0] * vx + g[1] * vy)
        loads += mech.torque[l - 1] * om
    for i, (fx, fy) in zip(mech.load_points, mech.load_xy):
        loads += fx * a.points[:, PointCol.VX, i - 1] + fy * a.points[:, PointCol.VY, i - 1]
    if mech.gf_block:
        s = a.slides[:, SlideCol.S, mech.gf_slide - 1]
        f = mech.gf_scale * np.interp(s, mech.gf_table[:, 0], mech.gf_table[:, 1])
        loads += f * a.slides[:, SlideCol.V, mech.gf_slide - 1]
    peak = np.max(np.abs(np.concatenate([power_in[good], rate[good], loads[good]]))) + 1e-300
    assert np.max(np.abs(power_in + loads - rate)[good]) <= 1e-9 * peak


@pytest.mark.parametrize("deck", ["linkage_watt2", "linkage_stephenson3", "linkage_whitworth", "linkage_engine",
                                  "linkage_inverted_slider_crank", "linkage_crank_shaper"])
def test_shipped_decks_match_the_independent_solver(deck):
    """Every shipped deck at every tenth input: positions and rates of every point, every link."""
    from pathlib import Path

    from driver._deck import read_deck, validate
    from driver.linkage import SPEC
    path = Path(__file__).resolve().parents[1] / "inputs" / f"{deck}.dat"
    d = read_deck(path)
    p = validate(d.groups["linkage"], SPEC, path)
    m = solve(p)
    o = Oracle(m.mech)
    qk = kernel_frames(m)
    for k in range(0, len(m.x), 4):
        if not m.ok[k]:
            continue
        q, qd, qdd = o.solve(m.xk[k], qk[k] * (1 + 1e-6), m.mech.omega, m.mech.alpha)
        for j, pt in enumerate(m.mech.points):
            ps, vs, as_ = o.point_state(q, qd, qdd, (pt[1] - 1, pt[2], pt[3]))
            for col, ref in ((PointCol.X, ps[0]), (PointCol.VX, vs[0]), (PointCol.AX, as_[0])):
                scale = np.max(np.abs(m.a.points[:, col, :])) + 1e-12
                assert abs(m.a.points[k, col, j] - ref) <= TOL * scale, (deck, k, pt[0], col)
        assert np.all(m.a.status[k] == LinkageStatus.ok)
