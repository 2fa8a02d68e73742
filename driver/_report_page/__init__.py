"""The report page of a deck (``--report``): one self-contained HTML file, ``<stem>.html``, built
from the engine's outcome.

Everything a reader needs is inside the one file, so it opens offline, mails as one attachment
and prints: the run's metadata (tool version, build, date), its warnings, the figures as inline
SVG, the fixed-format tables and the headline figures, the comparison with the published cells
where the deck reproduces a published table, the deck itself, and an animation of the mechanism
(the study's :class:`~driver._mechanism.MechanismFrames`, moved by a few lines of JavaScript).
Sweeps get the maps of their summary and their best case; optimisations their convergence, the
designs evaluated and the optimum; a synthesis its linkage.

The page is data (:mod:`~driver._report_page._blocks`: sections of blocks, made from the outcome
by :mod:`~driver._report_page._sections`) drawn by Jinja2 templates with autoescaping
(``templates/``): no markup is built from strings in Python.  No network, no external file: no
``<link>``, no ``src=`` to anything but inline data.  The page builder never prints; the command
line reports the path written.
"""
from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from driver._report_page._animation import ANIMATION_FRAMES, animation_view
from driver._report_page._figures import figure_svg, plain
from driver._report_page._fragment import fragment
from driver._report_page._render import render_fragment, render_page, run_metadata
from driver._report_page._sections import outcome_frames, page_of

if TYPE_CHECKING:
    from driver._deck import Deck
    from driver._outcome import Outcome

__all__ = ["MAX_PAGE_BYTES", "ANIMATION_FRAMES", "page", "fragment", "outcome_fragment", "write_report", "figure_svg", "plain",
           "run_metadata", "animation_view", "outcome_frames", "write_animation"]

#: the page size the browser test holds every shipped report to [bytes] (the SVG figures are most of it)
MAX_PAGE_BYTES = 6_000_000


def page(outcome: Outcome, deck: Deck | None = None) -> str:
    """The report page of an engine's outcome.

    Parameters
    ----------
    outcome : Outcome
        A :class:`~driver._outcome.RunOutcome`, :class:`~driver._outcome.SweepOutcome`,
        :class:`~driver._outcome.OptimizeOutcome` or :class:`~driver._outcome.SynthesisOutcome`.
    deck : Deck, optional
        The deck it ran (echoed on the page); without one, the run's keys are.

    Returns
    -------
    str
        The page's HTML.
    """
    return render_page(page_of(outcome, deck))


def outcome_fragment(outcome: Outcome) -> str:
    """An engine's outcome as an HTML fragment for a notebook: its page's sections (maps,
    convergence, the best case or the optimum with its animation, the tables) without the page
    around them and without the deck, made by the page's own templates."""
    sections = [s for s in page_of(outcome).sections if s.id not in ("deck", "published")]
    return render_fragment(sections)


def write_animation(stem: Path, outcome: Outcome, fmt: str) -> Path | None:
    """Write the animation the report page plays as ``<stem>_animation.<fmt>`` ('gif' or 'mp4':
    :func:`driver.plotting.save_animation`, from the same frames); None when the outcome has no
    mechanism to animate."""
    frames, whose = outcome_frames(outcome)
    if frames is None:
        return None
    from driver.plotting import save_animation
    return save_animation(frames, stem.with_name(f"{stem.name}_animation.{fmt}"), fmt, title=whose)


def write_report(path: Path, text: str) -> Path:
    """Write the page atomically as ``path`` (``<stem>.html``)."""
    from driver._atomic import write_text
    return write_text(Path(path), text)
