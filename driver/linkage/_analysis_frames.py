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
from driver._mechanism import Guide, Link, MechanismFrames
from driver._result import Result
from driver.linkage._analysis import Motion, solve
from driver.linkage._kernel import LinkageStatus, LinkCol, PointCol
from driver.linkage._kernel_program import Mechanism

__all__ = ["cycle_inputs", "guide_lines", "frames", "animation_frames", "BLOCK_HALF"]


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
    placed = np.all((m.a.status == LinkageStatus.ok) | (m.a.status == LinkageStatus.toggle), axis=1)
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


def _placed_links(m: Motion) -> np.ndarray:
    """(n, links) True where a link is placed: the ground and the driver always, a group's two
    links where the group is assembled (a toggle is placed)."""
    mech, st = m.mech, m.a.status
    out = np.zeros((len(m.x), len(mech.links)), dtype=bool)
    out[:, 0] = True
    out[:, mech.driver_link - 1] = True
    for d, dy in enumerate(mech.dyads):
        ok = (st[:, d] == LinkageStatus.ok) | (st[:, d] == LinkageStatus.toggle)
        out[:, dy.k1 - 1] = ok
        out[:, dy.k2 - 1] = ok
    return out


def _outline(xy: np.ndarray) -> tuple[list[int], bool]:
    """The drawing order of a rigid link's points from their positions at one pose (k, 2): a
    polygon around their centroid (body True), or, when they lie on one line, the polyline along
    it (body False)."""
    c = xy.mean(axis=0)
    rel = xy - c
    size = float(np.max(np.hypot(rel[:, 0], rel[:, 1]))) or 1.0
    if len(xy) >= 3:
        _, sv, vt = np.linalg.svd(rel)
        if sv[1] > 1e-6 * size:
            return [int(i) for i in np.argsort(np.arctan2(rel[:, 1], rel[:, 0]))], True
        along = rel @ vt[0]
    else:
        along = np.arange(len(xy), dtype=float)
    return [int(i) for i in np.argsort(along, kind="stable")], False


#: a slider block's half length and half height, as fractions of the mechanism's size
BLOCK_HALF = (0.06, 0.035)


def animation_frames(params: Params, result: Result | None = None, n: int = 180) -> MechanismFrames:
    """Make the report page's animation: the mechanism at ``n`` inputs over one cycle.

    Every point of the mechanism (ground pivots, the driver's pin, the groups' joints, the
    deck's points) from the kernel; each moving link drawn between its points (a bar, a rigid
    body's polygon, or a polyline when its points are in line); each slider block as a
    rectangle on its guide around its pin; a guide of the ground as a fixed line, a guide on a
    moving link (a slot) as a bar carried by that link; tracer paths.  A link that is not
    placed at an input (its group cannot be assembled there) is hidden at that frame.

    Parameters
    ----------
    params : Params
        A validated ``&linkage`` deck.
    result : Result, optional
        The deck's run (not needed: the frames come from the kernel).
    n : int, default 180
        Frames over one cycle (a crank's turn from ``start``; an input slider's ``start`` to
        ``stop``).

    Returns
    -------
    MechanismFrames
        Points in the deck's length unit (metres when the deck has bodies).
    """
    m, f = frames(params, n)
    mech = m.mech
    placed = _placed_links(m)
    nf = len(m.x)
    names: list[str] = []
    cols: list[np.ndarray] = []

    def add(name: str, xy: np.ndarray, link: int) -> int:
        xy = np.where(placed[:, link - 1, None], xy, np.nan)
        names.append(name)
        cols.append(xy)
        return len(names) - 1

    index = {name: add(name, f["points"][name], link) for name, link, _, _ in mech.points}
    every = np.vstack([f["points"][name][placed[:, link - 1]] for name, link, _, _ in mech.points])
    size = float(np.max(np.ptp(every, axis=0))) if len(every) else 1.0
    size = size if size > 0 else 1.0
    hw, hh = BLOCK_HALF[0] * size, BLOCK_HALF[1] * size
    links: list[Link] = []
    guides: list[Guide] = []
    # the moving links between their points
    for li, lname in enumerate(mech.links[1:], start=2):
        if lname in mech.blocks:
            continue
        pts = list(dict.fromkeys(mech.link_joints.get(lname, [])))
        if len(pts) < 2:
            continue
        ok = placed[:, li - 1]
        k = int(np.argmax(ok)) if ok.any() else 0
        order, body = _outline(np.array([f["points"][q][k] for q in pts]))
        links.append(Link(lname, tuple(index[pts[i]] for i in order), body=body))
    # guides: a ground guide is a fixed line, a guide on a moving link a bar it carries; each
    # reaches over every pin that slides on it (and the link's origin), a block's length beyond
    origins = _origins(mech)
    on_guide: dict[str, list[str]] = {}
    for block, guide in mech.blocks.items():
        on_guide.setdefault(guide, []).append(block)
    for gname, glink, _, _, _ in mech.guides:
        gp, gu = f["guides"][gname]
        ok = placed[:, glink - 1]
        ts = [np.full(nf, np.nan)]
        for block in on_guide.get(gname, []):
            pin = f["points"][mech.link_joints[block][0]]
            ts.append(np.where(ok, np.einsum("ij,ij->i", pin - gp, gu), np.nan))
        if glink != 1:
            ts.append(np.where(ok, np.einsum("ij,ij->i", f["points"][origins[glink]] - gp, gu), np.nan))
        t = np.concatenate(ts)
        t = t[np.isfinite(t)]
        lo, hi = (float(t.min()) - 1.5 * hw, float(t.max()) + 1.5 * hw) if len(t) else (-size / 2, size / 2)
        if glink == 1:
            guides.append(Guide(np.vstack([gp[0] + lo * gu[0], gp[0] + hi * gu[0]]), f"guide {gname}"))
            continue
        ends = (add(f"{gname}:start", gp + lo * gu, glink), add(f"{gname}:end", gp + hi * gu, glink))
        owner = mech.links[glink - 1]
        links.append(Link(f"guide {gname} on {owner}", ends))
        o = f["points"][origins[glink]]
        foot = gp + np.einsum("ij,ij->i", o - gp, gu)[:, None] * gu
        if np.nanmax(np.hypot(*(o - foot).T)) > 1e-9 * size:   # a slot beside the link's origin: its arm
            links.append(Link(f"{owner} to guide {gname}", (index[origins[glink]], add(f"{gname}:foot", foot, glink))))
    # slider blocks: a rectangle along the guide around the pin, reaching the guide's line
    for block, guide in mech.blocks.items():
        bl = mech.link_index(block)
        pin = f["points"][mech.link_joints[block][0]]
        gp, gu = f["guides"][guide]
        gn = np.column_stack([-gu[:, 1], gu[:, 0]])
        along = np.einsum("ij,ij->i", pin - gp, gu)
        off = np.einsum("ij,ij->i", pin - gp, gn)
        c0 = gp + along[:, None] * gu                          # the pin's foot on the guide's line
        lo = np.minimum(off, 0.0) - hh
        hi = np.maximum(off, 0.0) + hh
        corners = [(-hw, lo), (hw, lo), (hw, hi), (-hw, hi)]
        idx = tuple(add(f"{block}:{j + 1}", c0 + a * gu + b[:, None] * gn, bl)
                    for j, (a, b) in enumerate((a, np.broadcast_to(b, (nf,))) for a, b in corners))
        links.append(Link(block, idx, body=True))
    ground = tuple(index[name] for name, link, _, _ in mech.points if link == 1)
    used = {j for d in mech.dyads for j in d.joints[:2]} | {mech.driver_pin} | {d.joints[2] for d in mech.dyads}
    joints = tuple(index[q] for q in mech.point_names if q in used and index[q] not in ground)
    markers = tuple(index[q] for q in mech.tracers if q not in used)
    paths = tuple(index[q] for q in f["paths"] if q in index)
    crank = mech.driver == "crank"
    x = np.round(m.x, 6)
    labels = tuple(f"{v:g}\u00b0" for v in x) if crank else tuple(f"s = {v:g}" for v in x)
    title = params.title or params.path.stem
    return MechanismFrames(
        names=tuple(names), points=np.stack(cols, axis=1), links=tuple(links), labels=labels, ground=ground,
        joints=joints, markers=markers, guides=tuple(guides), paths=paths, periodic=crank,
        frame_name="crank angle" if crank else "input slide", units="m" if mech.forces else "",
        caption=f"{title}: over one {'crank turn' if crank else 'stroke of the input slider'}, every position "
                "from the kernel (blocks drawn to the mechanism's scale, guides over the blocks' travel).",
        invalid_note="a group of the linkage cannot be assembled at this input")
