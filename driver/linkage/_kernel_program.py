"""The kernel's program of one mechanism (fortran/linkage.f90): links, points, guides, driver,
groups and loads as the kernel's integer and real arrays, with the names tables and drawings use.

Plain data, no deck: :func:`driver.linkage._spec_model.compile_deck` makes a :class:`Mechanism`
from a deck's keys.  The kernel's numbers of one design are one flat vector
(:meth:`Mechanism.numbers`), so that a batch of designs differing only in numbers is one matrix
(driver/linkage/_batch.py)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["Dyad", "Mechanism", "KIND_CODE", "SLIDING"]

#: the kernel's group codes (fortran/linkage.f90 dy_*); PRR is RRP solved from its other end
KIND_CODE = {"rrr": 1, "rrp": 2, "prr": 2, "rpr": 3, "prp": 4}
#: groups with a sliding pair, and how many slides each has
SLIDING = {"rrr": 0, "rrp": 1, "prr": 1, "rpr": 1, "prp": 2}


@dataclass(frozen=True)
class Dyad:
    """One class-II group as the deck gives it and as the kernel solves it.

    ``kind`` the deck's type (lower case); ``joints`` its three names; ``links`` its two link
    names in the order of its letters; ``dims`` its two numbers; ``mode`` +1/-1.  The kernel
    row: ``code``, attachments ``a1``, ``a2`` (point or guide indices, 1-based), kernel links
    ``k1``, ``k2`` (1-based; for PRR the rod first), ``d1``, ``d2`` and the first slide index."""

    kind: str
    joints: tuple[str, str, str]
    links: tuple[str, str]
    dims: tuple[float, float]
    mode: int
    code: int
    a1: int
    a2: int
    k1: int
    k2: int
    d1: float
    d2: float
    slide: int

    @property
    def name(self) -> str:
        """How tables and messages name the group: its type and new joint, e.g. 'RRR B'."""
        return f"{self.kind.upper()} {self.joints[2]}"


@dataclass
class Mechanism:
    """A compiled ``&linkage`` mechanism: names and the kernel's program.

    Indices are the kernel's (1-based).  ``links[0]`` is the ground.  Points hold the ground
    pivots, the driver's pin, every group's new joint and the deck's points on links.
    """

    title: str
    driver: str                                  # 'crank' or 'slider'
    links: list[str] = field(default_factory=list)
    points: list[tuple[str, int, float, float]] = field(default_factory=list)   # name, link, u, v
    guides: list[tuple[str, int, float, float, float]] = field(default_factory=list)  # name, link, x, y, rad
    dyads: list[Dyad] = field(default_factory=list)
    slides: list[tuple[str, int, int]] = field(default_factory=list)   # block link name, its link, guide link
    driver_anchor: int = 0
    driver_link: int = 0
    driver_length: float = 0.0
    driver_slide: int = 0
    driver_pin: str = ""
    omega: float = 1.0
    alpha: float = 0.0
    tracers: list[str] = field(default_factory=list)
    #: for drawing: each moving link's joints (point names) and each block's guide
    link_joints: dict[str, list[str]] = field(default_factory=dict)
    blocks: dict[str, str] = field(default_factory=dict)     # block link name -> its guide's name
    output: tuple[int, int] = (1, 2)             # (1 link | 2 slide, index)
    output_name: str = ""
    # kinetostatics
    forces: bool = False
    body: np.ndarray = field(default_factory=lambda: np.zeros((1, 4)))   # (nl, 4) m, u, v, I
    gravity: tuple[float, float] = (0.0, -9.81)
    load_points: list[int] = field(default_factory=list)
    load_xy: list[tuple[float, float]] = field(default_factory=list)
    torque: np.ndarray = field(default_factory=lambda: np.zeros(1))
    gf_block: int = 0                            # link the table's force acts on (0: none)
    gf_guide_link: int = 0
    gf_over: int = 1                             # 1 input, 2 slide
    gf_slide: int = 0
    gf_table: np.ndarray = field(default_factory=lambda: np.zeros((2, 2)))
    gf_period: float = 0.0
    gf_scale: float = 1.0
    #: the kernel's arrays, made on first use (the mechanism is not changed once compiled)
    _arrays: dict[str, dict[str, np.ndarray]] = field(default_factory=dict, repr=False, compare=False)

    # ------------------------------------------------------------------ lookups
    def link_index(self, name: str) -> int:
        """1-based index of link ``name``."""
        return self.links.index(name) + 1

    def point_index(self, name: str) -> int:
        """1-based index of point ``name``."""
        return [p[0] for p in self.points].index(name) + 1

    @property
    def point_names(self) -> list[str]:
        """Every point's name, in kernel order."""
        return [p[0] for p in self.points]

    @property
    def slide_names(self) -> list[str]:
        """Every slide's name (its block's link name), in kernel order."""
        return [s[0] for s in self.slides]

    @property
    def moving_links(self) -> list[str]:
        """The moving links' names (all but the ground), in kernel order."""
        return self.links[1:]

    # ------------------------------------------------------------------ the kernel's program
    def integers(self) -> dict[str, np.ndarray]:
        """The kernel's integer arrays (shared by every design of a batch); empty lists padded
        with one inert entry (f2py and zero-size arrays).  Made once: read them, do not change
        them."""
        if "integers" not in self._arrays:
            self._arrays["integers"] = self._integers()
        return self._arrays["integers"]

    def _integers(self) -> dict[str, np.ndarray]:
        ipts = np.array([p[1] for p in self.points], dtype=np.int32)
        igd = np.array([g[1] for g in self.guides] or [1], dtype=np.int32)
        idy = np.array([[d.code, d.a1, d.a2, d.k1, d.k2, d.slide] for d in self.dyads],
                       dtype=np.int32, order="F")
        ild = np.array(self.load_points or [1], dtype=np.int32)
        idrv = np.array([1 if self.driver == "crank" else 2, self.driver_anchor, self.driver_link,
                         self.driver_slide], dtype=np.int32)
        ift = np.array([self.gf_block, self.gf_guide_link, self.gf_over, self.gf_slide], dtype=np.int32)
        return {"idrv": idrv, "ipts": ipts, "igd": igd, "idy": idy, "ild": ild, "ift": ift}

    def reals(self) -> dict[str, np.ndarray]:
        """The kernel's real arrays of this design (the ones :meth:`numbers` packs).  Made once:
        read them, do not change them."""
        if "reals" not in self._arrays:
            self._arrays["reals"] = self._reals()
        return self._arrays["reals"]

    def _reals(self) -> dict[str, np.ndarray]:
        rpts = np.array([[p[2], p[3]] for p in self.points], dtype=np.float64, order="F")
        rgd = np.array([[g[2], g[3], g[4]] for g in self.guides] or [[0.0, 0.0, 0.0]], dtype=np.float64, order="F")
        rdrv = np.array([self.driver_length, self.omega, self.alpha], dtype=np.float64)
        rdy = np.array([[d.d1, d.d2, d.mode] for d in self.dyads], dtype=np.float64, order="F")
        rl = np.asfortranarray(self.body, dtype=np.float64)
        grav = np.array(self.gravity, dtype=np.float64)
        rld = np.array(self.load_xy or [(0.0, 0.0)], dtype=np.float64, order="F")
        rtq = np.asarray(self.torque, dtype=np.float64)
        rft = np.array([self.gf_period, self.gf_scale, 0.0], dtype=np.float64)
        tab = np.asfortranarray(self.gf_table, dtype=np.float64)
        return {"rpts": rpts, "rgd": rgd, "rdrv": rdrv, "rdy": rdy, "rl": rl, "grav": grav, "rld": rld,
                "rtq": rtq, "rft": rft, "tab": tab}

    def program(self) -> tuple[np.ndarray, np.ndarray]:
        """The program packed as fortran/linkage.f90 analyse reads it: (integers: ng, nld, nt and
        the integer arrays in order; reals: :meth:`numbers`).  Made once: read it, do not change it."""
        if "program" not in self._arrays:
            i, r = self.integers(), self.reals()
            head = np.array([len(i["igd"]), len(i["ild"]), r["tab"].shape[0]], dtype=np.int32)
            iprog = np.concatenate([head] + [i[k].ravel(order="F") for k in ("idrv", "ipts", "igd", "idy", "ild",
                                                                              "ift")]).astype(np.int32)
            self._arrays["program"] = {"i": iprog, "r": self.numbers()}
        return self._arrays["program"]["i"], self._arrays["program"]["r"]

    def ground_points(self) -> tuple[tuple[int, float, float], ...]:
        """(index from 0, x, y) of each point on the ground (made once)."""
        if "ground" not in self._arrays:
            self._arrays["ground"] = tuple((j, u, v) for j, (_, link, u, v) in enumerate(self.points)
                                           if link == 1)   # type: ignore[assignment]
        return self._arrays["ground"]   # type: ignore[return-value]

    def numbers(self) -> np.ndarray:
        """This design's numbers as the batch kernel reads them (fortran/linkage.f90 summaries),
        without the scan's three (x0, span, C_s)."""
        r = self.reals()
        return np.concatenate([r[k].ravel(order="F") for k in
                               ("rpts", "rgd", "rdrv", "rdy", "rl", "grav", "rld", "rtq", "rft", "tab")])

    @property
    def nslides(self) -> int:
        """Slides the kernel reports (at least one: an inert column when there is none)."""
        return max(len(self.slides), 1)
