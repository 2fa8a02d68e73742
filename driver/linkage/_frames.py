"""The mechanism's poses over one cycle as generic drawing data: points, links (polylines
through their joints), sliding blocks on their guides, guide lines, ground marks and tracer
paths -- for the figures and the report page's animation (one frame per input).

Plain geometry from the kernel's positions: a guide on a moving link is carried by that link's
frame (its origin point and angle)."""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from driver._deck import Params
from driver._result import Result
from driver.linkage._analysis import Motion, solve
from driver.linkage._kernel import LinkCol, PointCol, Status
from driver.linkage._model import Mechanism

__all__ = ["cycle_inputs", "guide_lines", "frames", "animation_frames"]


def cycle_inputs(p: Params, mech: Mechanism, n: int) -> np.ndarray:
    """``n`` inputs over one cycle in the deck's units: a crank's turn from ``start``, or a
    slider's range start..stop."""
    if mech.driver == "crank":
        return p.start + np.linspace(0.0, 360.0, n, endpoint=False)
    return np.linspace(p.start, p.stop, n)


def _origins(mech: Mechanism) -> dict[int, str]:
    """Each moving link's origin, as a point name (the kernel's frames, fortran/linkage.f90)."""
    out: dict[int, str] = {}
    if mech.driver == "crank":
        out[mech.driver_link] = mech.point_names[mech.driver_anchor - 1]
    else:
        out[mech.driver_link] = mech.driver_pin
    for d in mech.dyads:
        a, b, c = d.joints
        if d.kind == "rrr":
            out[d.k1], out[d.k2] = a, b
        elif d.kind == "rrp":
            out[d.k1], out[d.k2] = a, c
        elif d.kind == "prr":   # kernel order: rod (k1) from the point b, block (k2) at c
            out[d.k1], out[d.k2] = b, c
        elif d.kind == "rpr":
            out[d.k1], out[d.k2] = a, b
        else:
            out[d.k1], out[d.k2] = c, c
    return out


def guide_lines(m: Motion) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Every guide's point (n, 2) and unit direction (n, 2) at each input."""
    mech, a = m.mech, m.a
    origins = _origins(mech)
    out = {}
    n = len(m.x)
    for name, link, gx, gy, ga in mech.guides:
        if link == 1:
            out[name] = (np.tile([gx, gy], (n, 1)), np.tile([math.cos(ga), math.sin(ga)], (n, 1)))
            continue
        j = mech.point_index(origins[link]) - 1
        th = a.links[:, LinkCol.ANGLE, link - 1]
        c, s = np.cos(th), np.sin(th)
        ox, oy = a.points[:, PointCol.X, j], a.points[:, PointCol.Y, j]
        pt = np.column_stack([ox + gx * c - gy * s, oy + gx * s + gy * c])
        out[name] = (pt, np.column_stack([np.cos(th + ga), np.sin(th + ga)]))
    return out


def frames(p: Params, n: int = 180) -> tuple[Motion, dict[str, Any]]:
    """The mechanism at ``n`` inputs over one cycle as generic drawing data (module docstring):
    ``input`` (deck units), ``ok``, ``points`` {name: (n, 2)}, ``links`` [(name, [joint names])],
    ``blocks`` [(link, pin point, guide name)], ``guides`` {name: (points (n, 2), directions
    (n, 2))}, ``ground`` [pivot names], ``paths`` [tracer names]."""
    m0 = solve(p, np.array([p.start]))
    mech = m0.mech
    m = solve(p, cycle_inputs(p, mech, n), mech)
    placed = np.all((m.a.status == Status.OK) | (m.a.status == Status.TOGGLE), axis=1)
    pts = {name: np.column_stack([m.a.points[:, PointCol.X, j], m.a.points[:, PointCol.Y, j]])
           for j, name in enumerate(mech.point_names)}
    pins = {}
    for lname in mech.blocks:
        joints = mech.link_joints.get(lname, [])
        pins[lname] = joints[0] if joints else ""
    data = {"input": m.x, "ok": placed, "points": pts,
            "links": [(name, mech.link_joints.get(name, [])) for name in mech.links[1:] if name not in mech.blocks],
            "blocks": [(name, pins[name], guide) for name, guide in mech.blocks.items()],
            "guides": guide_lines(m), "ground": [n_ for n_, link, _, _ in mech.points if link == 1],
            "paths": [t for t in mech.tracers] + [d.joints[2] for d in mech.dyads if d.kind != "rpr"]}
    return m, data


def animation_frames(params: Params, result: Result | None = None, n: int = 180) -> dict[str, Any] | None:
    """Make the report page's animation data: the mechanism's frames over one cycle.

    Parameters
    ----------
    params : Params
        A validated ``&linkage`` deck.
    result : Result, optional
        The deck's run (not needed: the frames come from the kernel).
    n : int, default 180
        Frames over one cycle.

    Returns
    -------
    dict
        JSON-ready (rounded to 6 digits): ``kind`` 'mechanism', ``input`` (deck units), ``ok``,
        ``points`` {name: [[x, y], ...]}, ``links`` [[name, [joint names]]], ``blocks`` [[link,
        pin, guide]], ``guides`` {name: {point, direction}}, ``ground`` (pivot names),
        ``paths`` (tracer names) and ``box_points`` bounding the drawing [length].
    """
    _, f = frames(params, n)
    r = lambda a: np.round(np.asarray(a, dtype=float), 6).tolist()
    ok = f["ok"]
    allp = np.vstack([v[ok] for v in f["points"].values()]) if ok.any() else np.zeros((1, 2))
    return {"kind": "mechanism", "input": r(f["input"]), "ok": ok.astype(int).tolist(),
            "points": {k: r(np.where(ok[:, None], v, 0.0)) for k, v in f["points"].items()},
            "links": [[name, joints] for name, joints in f["links"]],
            "blocks": [[name, pin, guide] for name, pin, guide in f["blocks"]],
            "guides": {k: {"point": r(pt), "direction": r(u)} for k, (pt, u) in f["guides"].items()},
            "ground": f["ground"], "paths": f["paths"], "box_points": allp}
