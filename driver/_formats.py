"""The file formats of figures (``--plot-format``) and of the mechanism's animation
(``--animation``): plain data, imported by the command line, the plotting module and
:mod:`driver._result` alike (it imports nothing of the driver)."""
from __future__ import annotations

__all__ = ["PLOT_FORMATS", "ANIMATION_FORMATS", "plot_format"]


#: file formats of ``--plot`` figures (``--plot-format``); the first is the default
PLOT_FORMATS = ("png", "svg", "pdf")
#: file formats of the mechanism's animation (``--animation``): GIF through Pillow, MP4 through ffmpeg
ANIMATION_FORMATS = ("gif", "mp4")


def plot_format(plot: bool | str | None) -> str | None:
    """The figure format a ``plot`` argument asks for: None (no figures), or one of
    :data:`PLOT_FORMATS` (``True`` means PNG).  Raises ValueError for any other format."""
    if not plot:
        return None
    fmt = PLOT_FORMATS[0] if plot is True else str(plot).lower().lstrip(".")
    if fmt not in PLOT_FORMATS:
        raise ValueError(f"figure format {plot!r} is not one of {', '.join(PLOT_FORMATS)}")
    return fmt
