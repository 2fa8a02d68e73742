"""The four-bar written as a crank and one RRR group gives the &fourbar study's numbers: coupler
and rocker angles, angular velocities and accelerations, transmission angle, joint forces,
input torque and shaking force and moment, to 1e-12 of each column's scale, on every shipped
&fourbar deck (their lengths, speeds, branches, masses and loads; the balanced deck with its
Berkof-Lowen counterweights); and the shipped deck inputs/linkage_fourbar_crank5.dat."""
from __future__ import annotations

import math

import numpy as np
import pytest

from conftest import INPUTS
from driver._deck import read_deck, validate
from driver.fourbar import SPEC as FOURBAR_SPEC
from driver.fourbar import _forces as fforces
from driver.fourbar import _kernel as fk
from driver.fourbar._analysis import crank_angles
from driver.fourbar._spec import force_value
from driver.linkage import compile_deck
from driver.linkage._analysis import solve
from driver.linkage._kernel import DriverCol, JointCol, LinkageStatus, LinkCol, ShakeCol
from linkage_oracle import params_of

DECKS = sorted(p.stem for p in INPUTS.glob("*.dat")
               if read_deck(p).groups.get("fourbar") is not None and "sweep" not in read_deck(p).groups
               and "optimize" not in read_deck(p).groups)
TOL = 1e-12
S, F = fk.State, fk.Force   # the four-bar kernels' columns, by name


def _fourbar(stem: str):
    path = INPUTS / f"{stem}.dat"
    return validate(read_deck(path).groups["fourbar"], FOURBAR_SPEC, path)


def _as_linkage(fp) -> str:
    """The &linkage body of a &fourbar deck."""
    branch = 1 if fp.branch == "open" else -1
    lines = [f"pivots='O2','O4', pivot_xy=0,0, {fp.fixed_link!r},0",
             f"driver_joints='O2','A', driver_length={fp.crank!r}, omega={fp.omega!r}, alpha={fp.alpha!r}, step=1",
             f"dyads='RRR', dyad_joints='A','O4','B', dyad_links='coupler','rocker', "
             f"dyad_dims={fp.coupler!r},{fp.rocker!r}, dyad_modes={branch}"]
    if fforces.active(fp):
        props = fforces.props(fp)
        if force_value(fp, "balance") == "force":
            props, _ = fk.fourbar_berkof_lowen(fp.crank, fp.coupler, fp.rocker, props,
                                               tuple(force_value(fp, "counterweight_radius") or
                                                     (fp.crank, fp.rocker)))
        m, inertia, d, phi = props[0:3], props[3:6], props[6:9], props[9:12]
        com = [(di * math.cos(ph), di * math.sin(ph)) for di, ph in zip(d, phi)]
        u, v = props[16], props[17]
        lines += [f"bodies='crank','coupler','rocker', mass={', '.join(map(repr, map(float, m)))}",
                  f"com_uv={', '.join(repr(float(c)) for xy in com for c in xy)}",
                  f"inertia={', '.join(map(repr, map(float, inertia)))}, gravity=0,{-float(props[12])!r}",
                  f"points='P', point_on='coupler', point_uv={float(u)!r},{float(v)!r}",
                  f"loads='P', load_xy={float(props[14])!r},{float(props[15])!r}",
                  f"torque_links='rocker', torques={float(props[13])!r}"]
    return "\n".join(lines)


def _close(a: np.ndarray, b: np.ndarray, what: str, scale: float | None = None) -> None:
    """|a - b| within 1e-12 of ``scale`` (default the column's own largest value)."""
    scale = max(float(np.max(np.abs(b))), 1e-300) if scale is None else scale
    err = float(np.max(np.abs(a - b)))
    assert err <= TOL * scale, f"{what}: {err:.3g} > 1e-12 of {scale:.3g}"


@pytest.mark.parametrize("stem", DECKS)
def test_four_bar_as_a_group_is_the_fourbar_study(stem):
    fp = _fourbar(stem)
    theta = crank_angles(fp)
    lp = params_of(_as_linkage(fp))
    mech = compile_deck(lp)
    m = solve(lp, theta, mech)
    out, status = fk.fourbar_exact(np.radians(theta), fp.fixed_link, fp.crank, fp.coupler, fp.rocker, fp.omega,
                                   fp.alpha, 1 if fp.branch == "open" else -1)
    ok = status == fk.FOURBAR_STATUS["ok"]
    assert np.array_equal(m.a.status[:, 0] == LinkageStatus.ok, ok)
    assert np.array_equal(m.a.status[:, 0] == LinkageStatus.no_assembly, status == fk.FOURBAR_STATUS["no_assembly"])
    if not ok.any():
        return
    a = m.a
    _close(a.links[ok, LinkCol.ANGLE, 2], out[ok, S.COUPLER_ANGLE], "coupler angle")
    _close(a.links[ok, LinkCol.ANGLE, 3], out[ok, S.ROCKER_ANGLE], "rocker angle")
    _close(a.quality[ok, 0], out[ok, S.TRANSMISSION_ANGLE], "transmission angle")
    _close(a.links[ok, LinkCol.OMEGA, 2], out[ok, S.COUPLER_OMEGA], "coupler omega")
    _close(a.links[ok, LinkCol.OMEGA, 3], out[ok, S.ROCKER_OMEGA], "rocker omega")
    _close(a.links[ok, LinkCol.ALPHA, 2], out[ok, S.COUPLER_ALPHA], "coupler alpha")
    _close(a.links[ok, LinkCol.ALPHA, 3], out[ok, S.ROCKER_ALPHA], "rocker alpha")
    if not mech.forces:
        return
    props = fforces.props(fp)
    if force_value(fp, "balance") == "force":
        props, _ = fk.fourbar_berkof_lowen(fp.crank, fp.coupler, fp.rocker, props,
                                           tuple(force_value(fp, "counterweight_radius") or (fp.crank, fp.rocker)))
    f = fk.fourbar_joint_forces(out, status, fp.fixed_link, fp.crank, fp.coupler, fp.rocker, fp.omega, fp.alpha,
                                props)
    _close(a.driver[ok, DriverCol.DRIVE], f[ok, F.INPUT_TORQUE], "input torque")
    _close(a.driver[ok][:, [DriverCol.FX, DriverCol.FY]], f[ok][:, [F.F_O2_X, F.F_O2_Y]], "F_O2")
    _close(a.joints[ok][:, [JointCol.AX, JointCol.AY], 0], f[ok][:, [F.F_A_X, F.F_A_Y]], "F_A")
    _close(a.joints[ok][:, [JointCol.CX, JointCol.CY], 0], f[ok][:, [F.F_B_X, F.F_B_Y]], "F_B")
    _close(a.joints[ok][:, [JointCol.BX, JointCol.BY], 0], f[ok][:, [F.F_O4_X, F.F_O4_Y]], "F_O4")
    # a balanced linkage's shaking force is rounding: measured on the linkage's own force scale
    fscale = float(np.max(np.abs(f[ok, F.F_O2_X:F.F_O4_Y + 1])))
    _close(a.shaking[ok][:, [ShakeCol.FX, ShakeCol.FY]], f[ok][:, [F.SHAKING_X, F.SHAKING_Y]], "shaking force", fscale)
    _close(a.shaking[ok, ShakeCol.M], f[ok, F.SHAKING_MOMENT], "shaking moment", fscale * fp.fixed_link)


def test_shipped_deck_is_crank5():
    """inputs/linkage_fourbar_crank5.dat: the crank5 linkage (crank5_exact.dat) and its coupler
    point P (crank5_coupler_point.dat) at the same crank angles."""
    path = INPUTS / "linkage_fourbar_crank5.dat"
    from driver.linkage import SPEC
    lp = validate(read_deck(path).groups["linkage"], SPEC, path)
    fp = _fourbar("crank5_coupler_point")
    theta = crank_angles(fp)
    m = solve(lp, theta)
    out, status = fk.fourbar_exact(np.radians(theta), 12, 5, 15, 9, 5.0, 0.0, 1)
    cp = fk.fourbar_coupler_point(np.radians(theta), out, status, 5, 5.0, 0.0, 7.5, 3.0)
    _close(m.a.links[:, LinkCol.OMEGA, 3], out[:, S.ROCKER_OMEGA], "rocker omega")
    j = m.mech.point_index("P") - 1
    _close(m.a.points[:, :, j], cp, "coupler point")
