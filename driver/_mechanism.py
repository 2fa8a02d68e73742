"""The frames of a mechanism's motion: what a study hands the report page to animate.

A study's ``Study.animation`` hook returns a :class:`MechanismFrames`: per frame the positions
of the mechanism's named points, and once the parts drawn between them (:class:`Link`: a bar
between two points, a polyline through several, a rigid body as the polygon of its points), the
fixed pivots (ground marks), fixed lines (:class:`Guide`: a slider's guide, a limit position),
the points whose paths are traced, and the words (caption, length unit, the label of each
frame).  The page draws every mechanism with the same code from this data alone; it names no
mechanism kind.  Plain data: numpy only.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["Link", "Guide", "Mark", "MechanismFrames", "LINK_COLOURS", "PATH_COLOURS", "MARK_COLOUR", "MASS_COLOUR"]

#: colours of the links, in drawing order (cycled): the page's animation, its GIF export and the
#: studies' linkage drawings use the same, so a crank is the same colour in every view
LINK_COLOURS = ("#2c3e50", "#2980b9", "#e67e22", "#16a085", "#8e44ad", "#c0392b", "#7f8c8d")
#: colours of the traced paths, in order (cycled)
PATH_COLOURS = ("#999999", "#c0392b", "#8e44ad", "#27ae60", "#d35400")
#: colour of fixed marks (a synthesis's target points) and of counterweights
MARK_COLOUR = "#000000"
MASS_COLOUR = "#4d4d4d"


@dataclass(frozen=True)
class Link:
    """A part of the mechanism drawn between named points of every frame.

    Parameters
    ----------
    name : str
        What it is, in words (``'crank'``, ``'coupler'``); its tooltip on the page.
    points : tuple of int
        Indices into :attr:`MechanismFrames.names`: two for a bar, more for a polyline through
        them (a deflected rod's nodes), in order.
    body : bool, default False
        A rigid body: the polygon of its points, filled.
    colour : int, optional
        Index into the page's palette: links with the same index share a colour (a shaft and
        its yoke); default the link's place in :attr:`MechanismFrames.links`.
    """

    name: str
    points: tuple[int, ...]
    body: bool = False
    colour: int | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "points", tuple(int(i) for i in self.points))
        if len(self.points) < 2:
            raise ValueError(f"link {self.name!r}: a link joins at least two points")
        if self.body and len(self.points) < 3:
            raise ValueError(f"link {self.name!r}: a rigid body drawn as a polygon needs three points or more")


@dataclass(frozen=True)
class Guide:
    """A fixed line drawn under the moving parts (the ground link, a slider's guide, a limit
    position of the mechanism).

    Parameters
    ----------
    xy : array_like
        (k, 2) vertices, k >= 2, in the frames' length unit.
    name : str
        What it is, in words (its tooltip).
    dashed : bool, default False
        Drawn dashed (a position the mechanism passes, not a part).
    closed : bool, default False
        The last vertex joins the first (a circle drawn as a polygon).
    """

    xy: np.ndarray
    name: str
    dashed: bool = False
    closed: bool = False

    def __post_init__(self) -> None:
        xy = np.array(self.xy, dtype=np.float64)
        if xy.ndim != 2 or xy.shape[1] != 2 or len(xy) < 2 or not np.isfinite(xy).all():
            raise ValueError(f"guide {self.name!r}: needs (k, 2) finite vertices, k >= 2 (got shape {xy.shape})")
        xy.flags.writeable = False
        object.__setattr__(self, "xy", xy)


@dataclass(frozen=True)
class Mark:
    """Fixed points drawn on top of the moving parts as open squares (the target points a path
    synthesis passes through).

    Parameters
    ----------
    xy : array_like
        (k, 2) positions, k >= 1, in the frames' length unit.
    name : str
        What they are, in words (their tooltip and legend entry).
    """

    xy: np.ndarray
    name: str

    def __post_init__(self) -> None:
        xy = np.array(self.xy, dtype=np.float64).reshape(-1, 2) if np.size(self.xy) else np.zeros((0, 2))
        if len(xy) < 1 or not np.isfinite(xy).all():
            raise ValueError(f"mark {self.name!r}: needs (k, 2) finite positions, k >= 1")
        xy.flags.writeable = False
        object.__setattr__(self, "xy", xy)


@dataclass(frozen=True)
class MechanismFrames:
    """The motion of a mechanism as frames of named points.

    Parameters
    ----------
    names : tuple of str
        The points' names (``'A'``, ``'B'``), one per column of :attr:`points`.
    points : array_like
        (n_frames, n_points, 2) positions in the length unit :attr:`units`; NaN where a point
        does not exist at that frame (a linkage that cannot be assembled there): the links
        through it are hidden and the page says :attr:`invalid_note`.
    links : tuple of Link
        The parts drawn, in drawing order (later ones on top).
    labels : tuple of str
        One label per frame, shown beside the frame slider (``'120°'``, ``'Dexterity at P2'``).
    ground : tuple of int, optional
        Points that are fixed pivots (drawn with a ground mark).
    joints : tuple of int, optional
        Points drawn as pins (open circles).
    markers : tuple of int, optional
        Points drawn as dots (a coupler point).
    masses : tuple of int, optional
        Points drawn as masses (filled discs larger than a pin: the counterweights a force
        balance adds).
    guides : tuple of Guide, optional
        Fixed lines drawn under the parts.
    marks : tuple of Mark, optional
        Fixed points drawn on top of the parts (target points).
    paths : tuple of int, optional
        Points whose paths over the frames are drawn (dashed), split where a frame is invalid
        and between :attr:`segments`.
    segments : tuple of (int, int), optional
        Frame ranges ``[start, stop)`` that are separate motions (a crank that rocks: each
        assembly interval); default one motion over every frame.
    periodic : bool, default True
        The frames cover one cycle: a path valid at every frame of a single motion is closed.
    frame_name : str, default 'frame'
        What the frames step through, in words (``'crank angle'``), shown beside the page's range control.
    units : str, default ''
        The length unit of the positions (``'m'``; ``''`` when the deck's unit is free).
    caption : str, default ''
        A sentence under the drawing (what is drawn, what is magnified).
    invalid_note : str
        What the page says at a frame where a point does not exist.
    """

    names: tuple[str, ...]
    points: np.ndarray
    links: tuple[Link, ...]
    labels: tuple[str, ...]
    ground: tuple[int, ...] = ()
    joints: tuple[int, ...] = ()
    markers: tuple[int, ...] = ()
    masses: tuple[int, ...] = ()
    guides: tuple[Guide, ...] = ()
    marks: tuple[Mark, ...] = ()
    paths: tuple[int, ...] = ()
    segments: tuple[tuple[int, int], ...] = ()
    periodic: bool = True
    frame_name: str = "frame"
    units: str = ""
    caption: str = ""
    invalid_note: str = "the mechanism cannot be assembled at this position"

    def __post_init__(self) -> None:
        pts = np.array(self.points, dtype=np.float64)
        if pts.ndim != 3 or pts.shape[2] != 2 or pts.shape[0] < 1:
            raise ValueError(f"points must be (n_frames, n_points, 2) (got shape {pts.shape})")
        n_frames, n_points = pts.shape[:2]
        names = tuple(str(n) for n in self.names)
        if len(names) != n_points or len(set(names)) != n_points:
            raise ValueError(f"names: {n_points} distinct names needed, one per point (got {names})")
        if np.isinf(pts).any():
            raise ValueError("points: an infinite position (use NaN where a point does not exist)")
        labels = tuple(str(s) for s in self.labels)
        if len(labels) != n_frames:
            raise ValueError(f"labels: one per frame ({n_frames}), got {len(labels)}")
        for attr in ("ground", "joints", "markers", "masses", "paths"):
            idx = tuple(int(i) for i in getattr(self, attr))
            if any(not 0 <= i < n_points for i in idx):
                raise ValueError(f"{attr}: a point index outside 0..{n_points - 1}")
            object.__setattr__(self, attr, idx)
        for link in self.links:
            if any(not 0 <= i < n_points for i in link.points):
                raise ValueError(f"link {link.name!r}: a point index outside 0..{n_points - 1}")
        if any(np.isnan(pts[:, i]).any() for i in self.ground):
            raise ValueError("ground: a fixed pivot must exist at every frame")
        segs = tuple((int(a), int(b)) for a, b in self.segments)
        if segs and (segs[0][0] != 0 or segs[-1][1] != n_frames or any(a >= b for a, b in segs)
                     or any(s[1] != t[0] for s, t in zip(segs, segs[1:]))):
            raise ValueError(f"segments must cover the frames 0..{n_frames} in order, each non-empty")
        pts.flags.writeable = False
        object.__setattr__(self, "points", pts)
        object.__setattr__(self, "names", names)
        object.__setattr__(self, "labels", labels)
        object.__setattr__(self, "links", tuple(self.links))
        object.__setattr__(self, "guides", tuple(self.guides))
        object.__setattr__(self, "marks", tuple(self.marks))
        object.__setattr__(self, "segments", segs)

    @property
    def n_frames(self) -> int:
        """Number of frames."""
        return int(self.points.shape[0])

    @property
    def valid(self) -> np.ndarray:
        """(n_frames,) True where every point exists."""
        return ~np.isnan(self.points).any(axis=(1, 2))

    def index(self, name: str) -> int:
        """The column of the point called ``name``."""
        return self.names.index(name)

    def runs(self) -> list[tuple[int, int]]:
        """The frame ranges ``[start, stop)`` over which paths are drawn: each motion
        (:attr:`segments`) split where a frame is invalid; runs of one frame dropped."""
        out = []
        for a, b in self.segments or ((0, self.n_frames),):
            ok = self.valid[a:b]
            edges = np.flatnonzero(np.diff(np.concatenate([[0], ok.astype(np.int8), [0]])))
            out += [(a + int(s), a + int(e)) for s, e in zip(edges[::2], edges[1::2]) if e - s > 1]
        return out

    def closed_paths(self) -> bool:
        """The traced paths close on themselves: one periodic motion valid at every frame."""
        return self.periodic and not self.segments and bool(self.valid.all())

    def extent(self) -> tuple[float, float, float, float]:
        """(x0, y0, width, height) of every finite point, guide and mark, in the frames' unit."""
        xy = self.points.reshape(-1, 2)
        xy = np.vstack([xy[np.isfinite(xy).all(axis=1)], *(g.xy for g in self.guides), *(m.xy for m in self.marks)])
        lo, hi = xy.min(axis=0), xy.max(axis=0)
        return float(lo[0]), float(lo[1]), float(hi[0] - lo[0]), float(hi[1] - lo[1])

    def decimals(self) -> int:
        """Decimals that keep seven significant digits of the drawing's size (for the page's data)."""
        _, _, w, h = self.extent()
        size = max(w, h)
        return int(min(12, max(0, 7 - math.ceil(math.log10(size))))) if size > 0 else 6
