"""The animation of a mechanism on the page, from a study's :class:`~driver._mechanism.MechanismFrames`.

Generic: the parts are drawn from the frames' links, pins, ground marks, guides and traced paths
alone (``templates/animation.html.j2``); a few lines of JavaScript (``templates/animation.js``)
move them to the frame the slider selects, from the frames' points shipped as JSON in the page.
No mechanism is named here: a four-bar, a slider-crank, a shaft chain and an arm are drawn by the
same code.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from driver._mechanism import LINK_COLOURS, MARK_COLOUR, MASS_COLOUR, PATH_COLOURS, Mark, MechanismFrames

__all__ = ["ANIMATION_FRAMES", "AnimationView", "LinkView", "animation_view"]

#: frames asked of a study's animation hook (a crank turn in 2 degree steps)
ANIMATION_FRAMES = 180


@dataclass
class LinkView:
    """A link as drawn: its SVG element (``line``, ``polyline`` or ``polygon``), the indices of
    its points (moved by the script) and its colour."""

    name: str
    element: str
    points: str
    colour: str


@dataclass
class AnimationView:
    """Everything the animation template draws, in the frames' length unit (y up)."""

    id: str
    viewbox: str
    flip: str
    line: float
    pin: float
    links: list[LinkView]
    joints: list[tuple[str, int]]
    markers: list[tuple[str, int]]
    masses: list[tuple[str, int]]
    marks: list[dict[str, Any]]
    mass_colour: str
    ground: list[str]
    guides: list[dict[str, Any]]
    paths: list[dict[str, Any]]
    data: dict[str, Any]
    note: dict[str, Any]
    invalid_note: str
    frame_name: str
    caption: str
    n_frames: int
    first_label: str


def _coords(xy: np.ndarray) -> str:
    """``x,y x,y ...`` of SVG points (five significant digits)."""
    return " ".join(f"{x:.5g},{y:.5g}" for x, y in xy)


def animation_view(frames: MechanismFrames, anim_id: str, caption: str = "") -> AnimationView:
    """The view of ``frames`` for the animation template; ``caption`` follows the study's own."""
    x0, y0, w, h = frames.extent()
    span = max(w, h, 1e-9)
    pad = 0.08 * span
    x0, y0, w, h = x0 - pad, y0 - pad, w + 2 * pad, h + 2 * pad
    s = max(w, h)
    line, pin = 0.012 * s, 0.014 * s
    pts = frames.points
    links = []
    for k, link in enumerate(frames.links):
        element = "polygon" if link.body else "line" if len(link.points) == 2 else "polyline"
        colour = LINK_COLOURS[(k if link.colour is None else link.colour) % len(LINK_COLOURS)]
        links.append(LinkView(link.name, element, " ".join(map(str, link.points)), colour))
    ground = [f"M{p[0] - 2 * pin:.5g},{p[1] - 2.2 * pin:.5g} L{p[0] + 2 * pin:.5g},{p[1] - 2.2 * pin:.5g} "
              f"L{p[0]:.5g},{p[1]:.5g} Z" for p in (pts[0, i] for i in frames.ground)]
    guides = [{"points": _coords(g.xy), "name": g.name, "dashed": g.dashed, "closed": g.closed} for g in frames.guides]
    paths = []
    closed = frames.closed_paths()
    for j, i in enumerate(frames.paths):
        for a, b in frames.runs():
            paths.append({"points": _coords(pts[a:b, i]), "name": f"path of {frames.names[i]}", "closed": closed,
                          "colour": PATH_COLOURS[j % len(PATH_COLOURS)]})
    marks = [{"name": m.name, "colour": MARK_COLOUR, "squares": [
        {"x": f"{x - 1.3 * pin:.5g}", "y": f"{y - 1.3 * pin:.5g}", "size": f"{2.6 * pin:.4g}"} for x, y in m.xy]}
        for m in frames.marks]
    d = frames.decimals()
    flat = np.round(pts.reshape(frames.n_frames, -1), d)
    data = {"labels": list(frames.labels),
            "points": [[None if np.isnan(v) else float(v) for v in row] for row in flat]}
    words = " ".join(t for t in (frames.caption, *(f"Squares: {m.name}." for m in frames.marks), caption) if t)
    if frames.units:
        words += f" Lengths in {frames.units}."
    return AnimationView(
        id=anim_id, viewbox=f"{x0:.6g} {y0:.6g} {w:.6g} {h:.6g}", flip=f"translate(0,{2 * y0 + h:.6g}) scale(1,-1)",
        line=line, pin=pin, links=links, joints=[(frames.names[i], i) for i in frames.joints],
        markers=[(frames.names[i], i) for i in frames.markers], masses=[(frames.names[i], i) for i in frames.masses],
        marks=marks, mass_colour=MASS_COLOUR, ground=ground, guides=guides, paths=paths,
        data=data, note={"x": x0 + 0.02 * w, "y": y0 + 0.06 * h, "size": 0.04 * s},
        invalid_note=frames.invalid_note, frame_name=frames.frame_name, caption=words,
        n_frames=frames.n_frames, first_label=frames.labels[0])


def study_frames(params: Any, result: Any, marks: tuple[Mark, ...] = (), n: int = ANIMATION_FRAMES) -> MechanismFrames | None:
    """The frames of a run's mechanism from its study's hook (``Study.animation``), with ``marks``
    added (what an engine adds to the drawing: a synthesis's target points); None for a study
    without one."""
    import dataclasses

    from driver._study import load_study
    study = load_study(params.group) if params is not None else None
    if study is None or study.animation is None:
        return None
    frames = study.animation(params, result, n)
    return dataclasses.replace(frames, marks=frames.marks + tuple(marks)) if marks else frames


def study_animation(params: Any, result: Any, anim_id: str, caption: str = "",
                    marks: tuple[Mark, ...] = ()) -> AnimationView | None:
    """The animation of a run's mechanism, from its study's hook (``Study.animation``), ``marks``
    added; None for a study without one."""
    frames = study_frames(params, result, marks)
    return None if frames is None else animation_view(frames, anim_id, caption)
