"""The mechanism of a ``&linkage`` deck: names resolved, checked, and compiled into the kernel's
program (fortran/linkage.f90: links, points, guides, driver, dyads, loads).

:func:`compile_deck` is the one place a deck's description is understood; every refusal names
the deck, line and key (an unknown or not-yet-placed point, a link over- or under-constrained,
a Grübler count other than one, a group locked to one link, inconsistent list lengths).
The deck's turning-moment diagram is checked here too (:func:`check_turning_moment`)."""
from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from driver._deck import Params
from driver.linkage._kernel_program import KIND_CODE, Dyad, Mechanism

__all__ = ["compile_deck", "check_turning_moment"]

def _group(p: Params, key: str, values: list[Any], size: int, what: str) -> list[tuple[Any, ...]]:
    """``values`` cut into tuples of ``size``; a DeckError at ``key`` unless it divides."""
    if len(values) % size:
        raise p.error(key, f"give {size} values per {what} (got {len(values)})")
    return [tuple(values[i:i + size]) for i in range(0, len(values), size)]


def _same_length(p: Params, key: str, got: int, want: int, what: str) -> None:
    if got != want:
        raise p.error(key, f"gives {got} {what}, the list it goes with has {want}")


def compile_deck(p: Mapping[str, Any]) -> Mechanism:
    """Resolve and check a ``&linkage`` deck's mechanism; compile the kernel's program.

    Parameters
    ----------
    p : Params
        Validated ``&linkage`` keys (a plain mapping with ``error``/``line_of`` as Params has).

    Returns
    -------
    Mechanism
        Names and the kernel's arrays.

    Raises
    ------
    DeckError
        With the deck's file, line and key: an unknown or not yet placed point or guide, a name
        given twice, a link placed twice (over-constrained: the Grübler count is not one) or
        never placed (under-constrained), a group attached to one link only, list lengths that
        do not match.
    """
    assert isinstance(p, Params)
    mech = Mechanism(title=p.title, driver=p.driver, omega=float(p.omega), alpha=float(p.alpha))
    mech.links.append("ground")
    placed_links = {"ground": "the frame"}
    known_points: dict[str, str] = {}          # name -> where it was defined
    known_guides: dict[str, str] = {}
    pending_points: dict[str, tuple[str, float, float]] = {}   # user points waiting for their link

    def add_point(name: str, link: int, u: float, v: float, key: str, where: str) -> None:
        if name in known_points or name in known_guides:
            raise p.error(key, f"name {name!r} is given twice ({known_points.get(name) or known_guides.get(name)} "
                               f"and {where}); every point and guide has its own name")
        known_points[name] = where
        mech.points.append((name, link, float(u), float(v)))

    def add_guide(name: str, link: int, x: float, y: float, deg: float, key: str, where: str) -> None:
        if name in known_points or name in known_guides:
            raise p.error(key, f"name {name!r} is given twice ({known_points.get(name) or known_guides.get(name)} "
                               f"and {where}); every point and guide has its own name")
        known_guides[name] = where
        mech.guides.append((name, link, float(x), float(y), math.radians(deg)))

    def place_link(name: str, key: str, where: str) -> int:
        if name == "ground":
            raise p.error(key, f"{where} names the ground as one of its moving links")
        if name in placed_links:
            raise p.error(key, f"link {name!r} is placed twice ({placed_links[name]} and {where}): a link belongs "
                               "to one group, so the mechanism's Grübler count would be "
                               f"{1 - 3} instead of 1 (over-constrained); attach to it through a point of "
                               "it (points, point_on, point_uv)")
        placed_links[name] = where
        mech.links.append(name)
        idx = len(mech.links)
        # points and guides waiting for this link become known now
        for pname, (lname, u, v) in list(pending_points.items()):
            if lname == name:
                add_point(pname, idx, u, v, "points", f"point {pname!r} on {name!r}")
                del pending_points[pname]
        for gname, (lname, x, y, deg) in list(pending_guides.items()):
            if lname == name:
                add_guide(gname, idx, x, y, deg, "guides", f"guide {gname!r} on {name!r}")
                del pending_guides[gname]
        return idx

    def need_point(name: str, key: str, where: str) -> int:
        if name in known_points:
            return mech.point_index(name)
        if name in known_guides:
            raise p.error(key, f"{where}: {name!r} is a guide, a point is needed here")
        if name in pending_points:
            raise p.error(key, f"{where}: point {name!r} is on link {pending_points[name][0]!r}, which is not "
                               "placed yet (groups attach only to points already placed: reorder the groups)")
        raise p.error(key, f"{where}: unknown point {name!r} (known so far: {', '.join(known_points) or 'none'})")

    def need_guide(name: str, key: str, where: str) -> int:
        if name in known_guides:
            return [g[0] for g in mech.guides].index(name) + 1
        if name in known_points:
            raise p.error(key, f"{where}: {name!r} is a point, a guide is needed here (the group's P end)")
        if name in pending_guides:
            raise p.error(key, f"{where}: guide {name!r} is on link {pending_guides[name][0]!r}, which is not "
                               "placed yet")
        raise p.error(key, f"{where}: unknown guide {name!r} (known so far: {', '.join(known_guides) or 'none'})")

    # ---- the frame: pivots and guides
    _same_length(p, "pivot_xy", len(p.pivot_xy) // 2, len(p.pivots), "pivot positions")
    for name, (x, y) in zip(p.pivots, _group(p, "pivot_xy", p.pivot_xy, 2, "pivot")):
        add_point(name, 1, x, y, "pivots", f"ground pivot {name!r}")
    on = p.guide_on if p.guide_on is not None else ["ground"] * len(p.guides)
    _same_length(p, "guide_on", len(on), len(p.guides), "links")
    _same_length(p, "guide_xy", len(p.guide_xy) // 2, len(p.guides), "guide points")
    _same_length(p, "guide_deg", len(p.guide_deg), len(p.guides), "guide directions")
    pending_guides: dict[str, tuple[str, float, float, float]] = {}
    for name, lname, (x, y), deg in zip(p.guides, on, _group(p, "guide_xy", p.guide_xy, 2, "guide"), p.guide_deg):
        if lname == "ground":
            add_guide(name, 1, x, y, deg, "guides", f"guide {name!r}")
        else:
            if name in pending_guides or name in known_points:
                raise p.error("guides", f"name {name!r} is given twice")
            pending_guides[name] = (lname, x, y, deg)
    # ---- points on links (known once their link is placed)
    _same_length(p, "point_on", len(p.point_on), len(p.points), "links")
    _same_length(p, "point_uv", len(p.point_uv) // 2, len(p.points), "point positions")
    for name, lname, (u, v) in zip(p.points, p.point_on, _group(p, "point_uv", p.point_uv, 2, "point")):
        if lname == "ground":
            raise p.error("point_on", f"point {name!r} is on the ground: give it as a ground pivot (pivots, pivot_xy)")
        if name in pending_points or name in known_points:
            raise p.error("points", f"name {name!r} is given twice")
        pending_points[name] = (lname, u, v)
    mech.tracers = list(p.points)
    # ---- the driver
    if len(p.driver_joints) != 2:
        raise p.error("driver_joints", f"give two names: the {'pivot' if p.driver == 'crank' else 'guide'} and "
                                       f"the pin (got {len(p.driver_joints)})")
    anchor, pin = p.driver_joints
    lname = p.driver_link or p.driver
    if p.driver == "crank":
        mech.driver_anchor = need_point(anchor, "driver_joints", "the crank's pivot")
        if mech.points[mech.driver_anchor - 1][1] != 1:
            raise p.error("driver_joints", f"the crank turns about a ground pivot; {anchor!r} is on a moving link")
        if not p.driver_length > 0:
            raise p.error("driver_length", f"the crank's length must be positive (got {p.driver_length:g})")
        mech.driver_link = place_link(lname, "driver_link", "the driver")
        add_point(pin, mech.driver_link, p.driver_length, 0.0, "driver_joints", "the crank's pin")
        mech.link_joints[lname] = [anchor, pin]
    else:
        mech.driver_anchor = need_guide(anchor, "driver_joints", "the input slider's guide")
        if mech.guides[mech.driver_anchor - 1][1] != 1:
            raise p.error("driver_joints", f"the input slider runs on a ground guide; {anchor!r} is on a moving link")
        mech.driver_link = place_link(lname, "driver_link", "the driver")
        add_point(pin, mech.driver_link, 0.0, 0.0, "driver_joints", "the input slider's pin")
        mech.link_joints[lname] = [pin]
        mech.blocks[lname] = anchor
        mech.slides.append((lname, mech.driver_link, 1))
        mech.driver_slide = len(mech.slides)
    mech.driver_length = float(p.driver_length)
    mech.driver_pin = pin
    # ---- the groups
    nd = len(p.dyads)
    if nd == 0:
        raise p.error("dyads", "give at least one group: a driver alone is not a linkage")
    joints = _group(p, "dyad_joints", p.dyad_joints, 3, "group (first attachment, second attachment, new joint)")
    links = _group(p, "dyad_links", p.dyad_links, 2, "group (its two links)")
    dims = _group(p, "dyad_dims", p.dyad_dims, 2, "group")
    modes = p.dyad_modes if p.dyad_modes is not None else [1] * nd
    _same_length(p, "dyad_joints", len(joints), nd, "groups")
    _same_length(p, "dyad_links", len(links), nd, "groups")
    _same_length(p, "dyad_dims", len(dims), nd, "groups")
    _same_length(p, "dyad_modes", len(modes), nd, "groups")
    for i, (kind, js, ls, ds, mode) in enumerate(zip(p.dyads, joints, links, dims, modes), start=1):
        where = f"group {i} ({kind.upper()} {js[2]})"
        d1, d2 = float(ds[0]), float(ds[1])
        if kind in ("rrr", "rrp", "rpr"):
            a1 = need_point(js[0], "dyad_joints", where)
            at1 = mech.points[a1 - 1][1]
        else:
            a1 = need_guide(js[0], "dyad_joints", where)
            at1 = mech.guides[a1 - 1][1]
        if kind in ("rrr", "prr", "rpr"):
            a2 = need_point(js[1], "dyad_joints", where)
            at2 = mech.points[a2 - 1][1]
        else:
            a2 = need_guide(js[1], "dyad_joints", where)
            at2 = mech.guides[a2 - 1][1]
        if at1 == at2:
            raise p.error("dyad_joints", f"{where} attaches both ends to the {'link ' if at1 != 1 else ''}"
                                         f"{mech.links[at1 - 1]!r}: with it the group is rigid (it cannot move, the "
                                         "mechanism's mobility is not one: over-constrained); attach one end to a "
                                         "moving link" + (", or give its points as points of that link" if at1 != 1
                                                          else ""))
        if kind == "rrr" and not (d1 > 0 and d2 > 0):
            raise p.error("dyad_dims", f"{where}: the link lengths must be positive (got {d1:g}, {d2:g})")
        if kind == "rrp" and not d1 > 0:
            raise p.error("dyad_dims", f"{where}: the rod length must be positive (got {d1:g})")
        if kind == "prr" and not d2 > 0:
            raise p.error("dyad_dims", f"{where}: the rod length must be positive (got {d2:g})")
        if kind in ("rrp", "prr", "rpr") or kind == "rrr":
            if js[0] == js[1]:
                raise p.error("dyad_joints", f"{where}: both attachments are {js[0]!r}")
        k1 = place_link(ls[0], "dyad_links", where)
        k2 = place_link(ls[1], "dyad_links", where)
        slide = 0
        if kind == "rrr":
            code_k1, code_k2, kd1, kd2 = k1, k2, d1, d2
            add_point(js[2], k1, d1, 0.0, "dyad_joints", where)
        elif kind == "rrp":
            code_k1, code_k2, kd1, kd2 = k1, k2, d1, d2
            add_point(js[2], k2, 0.0, 0.0, "dyad_joints", where)
            mech.slides.append((ls[1], k2, at2))
            slide = len(mech.slides)
        elif kind == "prr":       # the kernel's RRP: rod (second link) from the point, block on the guide
            a1, a2 = a2, a1
            code_k1, code_k2, kd1, kd2 = k2, k1, d2, d1
            add_point(js[2], k1, 0.0, 0.0, "dyad_joints", where)
            mech.slides.append((ls[0], k1, at1))
            slide = len(mech.slides)
        elif kind == "rpr":
            code_k1, code_k2, kd1, kd2 = k1, k2, d1 + d2, 0.0
            add_guide(js[2], k1, 0.0, d1, 0.0, "dyad_joints", f"{where}'s slot")
            mech.slides.append((ls[1], k2, k1))
            slide = len(mech.slides)
        else:
            code_k1, code_k2, kd1, kd2 = k1, k2, d1, d2
            add_point(js[2], k1, 0.0, 0.0, "dyad_joints", where)
            mech.slides.append((ls[0], k1, at1))
            mech.slides.append((ls[1], k2, at2))
            slide = len(mech.slides) - 1
        if kind == "rrr":
            mech.link_joints[ls[0]], mech.link_joints[ls[1]] = [js[0], js[2]], [js[1], js[2]]
        elif kind == "rrp":
            mech.link_joints[ls[0]], mech.link_joints[ls[1]] = [js[0], js[2]], [js[2]]
            mech.blocks[ls[1]] = js[1]
        elif kind == "prr":
            mech.link_joints[ls[0]], mech.link_joints[ls[1]] = [js[2]], [js[1], js[2]]
            mech.blocks[ls[0]] = js[0]
        elif kind == "rpr":
            mech.link_joints[ls[0]], mech.link_joints[ls[1]] = [js[0]], [js[1]]
            mech.blocks[ls[1]] = js[2]
        else:
            mech.link_joints[ls[0]], mech.link_joints[ls[1]] = [js[2]], [js[2]]
            mech.blocks[ls[0]], mech.blocks[ls[1]] = js[0], js[1]
        mech.dyads.append(Dyad(kind, (js[0], js[1], js[2]), (ls[0], ls[1]), (d1, d2), int(mode), KIND_CODE[kind],
                               a1, a2, code_k1, code_k2, kd1, kd2, slide))
    for pname, lnk, _, _ in mech.points:
        if pname in p.points:
            mech.link_joints.setdefault(mech.links[lnk - 1], []).append(pname)
    # ---- nothing left unplaced (under-constrained)
    for pname, (lname, _, _) in pending_points.items():
        raise p.error("point_on", f"point {pname!r} is on link {lname!r}, which no group places (unknown link: "
                                  f"the links are {', '.join(mech.links)})")
    for gname, (lname, _, _, _) in pending_guides.items():
        raise p.error("guide_on", f"guide {gname!r} is on link {lname!r}, which no group places (the links are "
                                  f"{', '.join(mech.links)})")
    # Grübler (Kutzbach): every group adds two links and three lower pairs, the driver one and one
    n_links, n_pairs = len(mech.links), 1 + 3 * nd
    mobility = 3 * (n_links - 1) - 2 * n_pairs
    if mobility != 1:   # cannot happen once the checks above pass; kept as the stated invariant
        raise p.error("dyads", f"the Grübler count is {mobility}, not 1")
    _output(p, mech)
    _forces(p, mech)
    return mech


def _output(p: Params, mech: Mechanism) -> None:
    """The summary's output element: the deck's ``output`` or the last group's slide or link."""
    name = p.output
    if name:
        if name in mech.slide_names and name != (mech.slide_names[mech.driver_slide - 1] if mech.driver_slide else None):
            mech.output = (2, mech.slide_names.index(name) + 1)
        elif name in mech.links[1:]:
            mech.output = (1, mech.link_index(name))
        else:
            raise p.error("output", f"{name!r} is neither a slider block nor a moving link (links: "
                                    f"{', '.join(mech.links[1:])})")
        mech.output_name = name
        return
    if mech.dyads:
        last = mech.dyads[-1]
        if last.slide:
            mech.output = (2, last.slide + (1 if last.kind == "prp" else 0))
            mech.output_name = mech.slides[mech.output[1] - 1][0]
        else:
            mech.output = (1, mech.link_index(last.links[1]))
            mech.output_name = last.links[1]
    else:
        mech.output = (1, mech.driver_link)
        mech.output_name = mech.links[mech.driver_link - 1]


def _forces(p: Params, mech: Mechanism) -> None:
    """The kinetostatic keys: bodies, loads, torques, the guide-force table."""
    nl = len(mech.links)
    mech.body = np.zeros((nl, 4))
    mech.torque = np.zeros(nl)
    mech.forces = p.bodies is not None
    dependent = ("mass", "com_uv", "inertia", "gravity", "loads", "load_xy", "torque_links", "torques",
                 "guide_force_on", "guide_force_x", "guide_force")
    if not mech.forces:
        for key in sorted((k for k in dependent if k in p.given), key=p.line_of):
            raise p.error(key, "belongs to the force analysis, which runs when 'bodies' is given (bodies = "
                               "the links with mass, mass = their masses in kg)")
        return
    nb = len(p.bodies)
    if p.mass is None:
        raise p.error("bodies", "give 'mass' too (one value per body, kg)")
    _same_length(p, "mass", len(p.mass), nb, "masses")
    com = _group(p, "com_uv", p.com_uv, 2, "body") if p.com_uv is not None else [(0.0, 0.0)] * nb
    _same_length(p, "com_uv", len(com), nb, "centres of mass")
    inertia = p.inertia if p.inertia is not None else [0.0] * nb
    _same_length(p, "inertia", len(inertia), nb, "inertias")
    for name, m, (u, v), i in zip(p.bodies, p.mass, com, inertia):
        if name not in mech.links[1:]:
            raise p.error("bodies", f"{name!r} is not a moving link (links: {', '.join(mech.links[1:])})")
        mech.body[mech.link_index(name) - 1] = (m, u, v, i)
    if p.gravity is not None:
        mech.gravity = (float(p.gravity[0]), float(p.gravity[1]))
    if (p.loads is None) != (p.load_xy is None):
        raise p.error("loads" if p.loads is not None else "load_xy", "give loads and load_xy together")
    if p.loads is not None:
        forces = _group(p, "load_xy", p.load_xy, 2, "load")
        _same_length(p, "load_xy", len(forces), len(p.loads), "forces")
        for name, fxy in zip(p.loads, forces):
            if name not in mech.point_names:
                raise p.error("loads", f"unknown point {name!r}")
            idx = mech.point_index(name)
            if mech.points[idx - 1][1] == 1:
                raise p.error("loads", f"{name!r} is a ground pivot: a load there moves nothing")
            mech.load_points.append(idx)
            mech.load_xy.append((float(fxy[0]), float(fxy[1])))
    if (p.torque_links is None) != (p.torques is None):
        raise p.error("torques" if p.torques is not None else "torque_links", "give torque_links and torques together")
    if p.torque_links is not None:
        _same_length(p, "torques", len(p.torques), len(p.torque_links), "torques")
        for name, t in zip(p.torque_links, p.torques):
            if name not in mech.links[1:]:
                raise p.error("torque_links", f"{name!r} is not a moving link")
            mech.torque[mech.link_index(name) - 1] += t
    if p.guide_force_on:
        if p.guide_force_on not in mech.slide_names:
            raise p.error("guide_force_on", f"{p.guide_force_on!r} is not a slider block (blocks: "
                                            f"{', '.join(mech.slide_names) or 'none'})")
        if p.guide_force_x is None or p.guide_force is None:
            raise p.error("guide_force_on", "give the table too: guide_force_x and guide_force")
        x: np.ndarray = np.asarray(p.guide_force_x, float)
        f: np.ndarray = np.asarray(p.guide_force, float)
        _same_length(p, "guide_force", len(f), len(x), "forces")
        if len(x) < 2 or np.any(np.diff(x) <= 0):
            raise p.error("guide_force_x", "give at least two abscissae, strictly ascending")
        j = mech.slide_names.index(p.guide_force_on)
        mech.gf_block = mech.slides[j][1]
        mech.gf_guide_link = mech.slides[j][2]
        mech.gf_slide = j + 1
        mech.gf_over = 1 if p.guide_force_over == "input" else 2
        mech.gf_scale = float(p.guide_force_scale)
        if mech.gf_over == 1 and mech.driver == "crank":
            if x[-1] - x[0] > p.cycle_deg + 1e-9:
                raise p.error("guide_force_x", f"the table spans {x[-1] - x[0]:g} deg, more than one cycle "
                                               f"(cycle_deg = {p.cycle_deg:g})")
            x = np.radians(x)
            mech.gf_period = math.radians(p.cycle_deg)
        mech.gf_table = np.column_stack([x, f])
    elif p.guide_force_x is not None or p.guide_force is not None:
        raise p.error("guide_force_x" if p.guide_force_x is not None else "guide_force",
                      "a force table needs guide_force_on: the slider block it acts on")


def check_turning_moment(p: Params) -> None:
    """The diagram's keys: given together, equal lengths, at least two angles, ascending."""
    a, t = p.turning_moment_deg, p.turning_moment
    if (a is None) != (t is None):
        raise p.error("turning_moment" if a is None else "turning_moment_deg",
                      "give turning_moment_deg and turning_moment together")
    if a is None:
        return
    if len(a) != len(t):
        raise p.error("turning_moment", f"gives {len(t)} torques for {len(a)} angles")
    if len(a) < 2 or np.any(np.diff(a) <= 0):
        raise p.error("turning_moment_deg", "give at least two crank angles, strictly ascending")
