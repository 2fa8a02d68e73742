"""Figures on the page: matplotlib figures as inline SVG, and figure labels as text.

The SVG is matplotlib's own (text kept as text: small, searchable, sharp in print); it is edited
as XML (:mod:`xml.etree.ElementTree`), never as a string: its size attributes are dropped so that
it scales to the page, and it is given its class, role and accessible name.
"""
from __future__ import annotations

import io
import re
import xml.etree.ElementTree as ET
from collections.abc import Iterable
from typing import Any

from markupsafe import Markup

from driver._names import shown
from driver._report_page._blocks import FigureBlock

__all__ = ["plain", "figure_svg", "figure_blocks"]

_SVG = "http://www.w3.org/2000/svg"
_XLINK = "http://www.w3.org/1999/xlink"
ET.register_namespace("", _SVG)
ET.register_namespace("xlink", _XLINK)

_GREEK = {"alpha": "α", "beta": "β", "gamma": "γ", "delta": "δ", "theta": "θ", "mu": "μ", "rho": "ρ",
          "sigma": "σ", "tau": "τ", "varphi": "φ", "phi": "φ", "omega": "ω", "psi": "ψ"}
_SUB = str.maketrans("0123456789", "₀₁₂₃₄₅₆₇₈₉")


#: a figure on the page is drawn at most this many pixels per inch of its width (fonts the same
#: in every figure), and at least this many: 7 pt tick labels stay 9 px tall (legible); a
#: narrower window scrolls the figure sideways rather than shrinking it
MAX_PX_PER_INCH = 110
MIN_PX_PER_INCH = 94


def plain(label: str) -> str:
    """A figure label as plain text: its mathtext symbols as Unicode (``$\\omega_2$`` -> ω₂) and
    an escaped ``\\$`` (deck text) as the dollar sign it stands for."""
    def math(m: re.Match) -> str:
        t = m.group(1)
        t = re.sub(r"\\overline\{([^{}]*)\}", r"mean(\1)", t)   # \overline{d^2}: the mean of d^2
        t = re.sub(r"\\sqrt\{([^{}]*)\}", "\u221a\\1", t)
        t = re.sub(r"\^\{?2\}?", "\u00b2", t)
        t = re.sub(r"\\([A-Za-z]+)", lambda g: _GREEK.get(g.group(1), g.group(1)), t)
        t = re.sub(r"_\{([0-9]+)\}|_([0-9])", lambda g: (g.group(1) or g.group(2)).translate(_SUB), t)
        return t.replace("{", "").replace("}", "")
    out = re.sub(r"(?<!\\)\$(.+?)(?<!\\)\$", math, label)
    return out.replace("\\$", "$")


def figure_svg(fig: Any, label: str = "") -> Markup:
    """A matplotlib figure as inline SVG: no XML prolog or metadata, no fixed size (it scales to
    the page, at most its own width at :data:`MAX_PX_PER_INCH`, so fonts read the same whatever
    its size, and at least at :data:`MIN_PX_PER_INCH`, so they stay legible), class ``fig``,
    role ``img`` and ``label`` as its accessible name."""
    from driver.plotting import SVG_SALT, style
    buf = io.BytesIO()
    with style(**{"svg.hashsalt": SVG_SALT, "svg.fonttype": "none"}):
        fig.savefig(buf, format="svg", metadata={"Date": None, "Creator": None})
    root = ET.fromstring(buf.getvalue())
    for meta in root.findall(f"{{{_SVG}}}metadata"):
        root.remove(meta)
    for attr in ("width", "height"):
        root.attrib.pop(attr, None)
    root.set("class", "fig")
    width = fig.get_figwidth()
    root.set("style", f"max-width:{round(width * MAX_PX_PER_INCH)}px;min-width:{round(width * MIN_PX_PER_INCH)}px")
    root.set("role", "img")
    root.set("aria-label", label)
    return Markup(ET.tostring(root, encoding="unicode"))


def figure_blocks(figures: Iterable[Any], prefix: str) -> tuple[list[FigureBlock], list[str]]:
    """Every figure (a :class:`driver._result.Figure`: ``name`` and ``draw()``) drawn as a block
    captioned ``<prefix>_<name>: <name in words>``; and a line for each that could not be drawn
    (a figure that fails must not lose the page)."""
    blocks, failed = [], []
    for f in figures:
        try:
            fig = f.draw()
        except Exception as exc:
            failed.append(f"figure '{f.name}' could not be drawn: {exc.__class__.__name__}: {exc}")
            continue
        caption = plain(f"{shown(prefix)}_{f.name}: {f.name.replace('_', ' ')}")
        blocks.append(FigureBlock(figure_svg(fig, caption), caption))
    return blocks, failed
