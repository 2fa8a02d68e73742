"""The page's text from its data: the Jinja2 templates shipped beside this module, autoescaped,
and the run's metadata."""
from __future__ import annotations

import datetime as _dt
import functools
import hashlib
import platform
from collections.abc import Sequence
from pathlib import Path

import jinja2
import numpy as np
from markupsafe import Markup

from driver._report_page._blocks import Page, Section

__all__ = ["TEMPLATES", "environment", "render_page", "render_fragment", "run_metadata"]

#: the templates' folder (shipped with the package)
TEMPLATES = Path(__file__).with_name("templates")
#: the longest line of text the page shows whole: a longer one (a deck's 75 kB title echoed in
#: the deck and the .out) is cut in the middle, saying how many characters were left out.  The
#: names the page prints (a run's, a design's, a deck's title) are bounded where they are
#: composed, to :data:`driver._names.NAME_CHARS`; this bound holds for every text a block
#: shows (the templates' ``bounded`` filter; not the drawing's coordinates).
LINE_CHARS = 2000


def bounded(value: object) -> object:
    """A template value as the page prints it: text (not Markup: the figures' SVG) with every
    line over :data:`LINE_CHARS` characters cut in the middle (:func:`driver._names.shown`)."""
    if isinstance(value, str) and not isinstance(value, Markup) and len(value) > LINE_CHARS:
        from driver._names import shown
        return "\n".join(line if len(line) <= LINE_CHARS else shown(line, LINE_CHARS) for line in value.split("\n"))
    return value


@functools.cache
def environment() -> jinja2.Environment:
    """The templates' environment: every value escaped unless it is Markup (the figures' SVG),
    an undefined name an error, not an empty string; the filter ``bounded`` (:func:`bounded`)."""
    env = jinja2.Environment(loader=jinja2.FileSystemLoader(TEMPLATES), autoescape=True,
                             undefined=jinja2.StrictUndefined, keep_trailing_newline=True)
    env.filters["bounded"] = bounded
    return env


def render_page(page: Page) -> str:
    """The whole page (``templates/page.html.j2``)."""
    return environment().get_template("page.html.j2").render(page=page)


def render_fragment(sections: Sequence[Section]) -> str:
    """Sections without the page around them (``templates/fragment.html.j2``), for a notebook."""
    return environment().get_template("fragment.html.j2").render(sections=sections)


def run_metadata() -> dict[str, str]:
    """Tool version, build (Python, numpy, the compiled kernels' file and checksum) and the date."""
    from driver import __version__
    meta = {"tool": f"mechanism-driver {__version__}"}
    try:
        import driver._kernels as k
        data = Path(k.__file__).read_bytes()
        meta["kernels"] = f"{Path(k.__file__).name} (sha256 {hashlib.sha256(data).hexdigest()[:12]})"
    except (ImportError, OSError):   # pragma: no cover - the driver cannot run without them
        meta["kernels"] = "not found"
    meta["build"] = (f"Python {platform.python_version()}, numpy {np.__version__}, "
                     f"{platform.system()} {platform.machine()}")
    meta["date"] = _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%d %H:%M:%S UTC")
    return meta
