"""A run's part of the report page (animation, figures, headline figures, tables), as sections
of blocks, and the same as an HTML fragment for a notebook (``Result._repr_html_``).

Below the rest of the page in the dependency order: it knows a run's result and its study (the
animation, the labels) and none of the engines, so :class:`driver._result.Result` can show
itself with it (tests/test_import_graph.py).
"""
from __future__ import annotations

import re
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

from driver._mechanism import Mark
from driver._names import shown
from driver._report_page._animation import study_animation
from driver._report_page._blocks import (
    Animation,
    Block,
    Details,
    Pre,
    Section,
    comparison_blocks,
    frame_table,
    key_values,
)
from driver._report_page._figures import figure_blocks, plain
from driver._report_page._numbers import Printed, summary_texts
from driver._report_page._render import render_fragment

if TYPE_CHECKING:
    from driver._deck import Params
    from driver._result import Result

__all__ = ["HINT", "result_sections", "fragment", "labels_of", "unit_in", "summary_block", "tidy_table", "anim_id",
           "run_blocks"]

#: what the animation's caption adds to the study's
HINT = "Drag the slider or press play."


def labels_of(study: str, names: Any, units: Mapping[str, str] | None = None) -> dict[str, str]:
    """Each column's name in words with its unit (the column name is its tooltip): the study's
    labels, else ``units`` (a tidy table's ``attrs['units']``) for a name that does not say its
    unit."""
    from driver._output import column_label
    from driver._study import load_study
    module = load_study(study) if study else None
    out = {}
    for n in names:
        words = plain(column_label(module, str(n)))
        unit = (units or {}).get(n)
        if "[" not in words and unit not in (None, "", "1"):
            words = f"{words} [{'length units' if unit == 'length' else unit}]"
        out[n] = words
    return out


def unit_in(label: str) -> str:
    """The unit in a label's brackets ('' when none)."""
    m = re.search(r"\[([^\[\]]*)\]\s*$", label)
    return m.group(1) if m else ""


def summary_block(result: Result) -> Block:
    """The headline figures: names in words with units (the column name as tooltip), numbers as
    the run's .out prints them, zeros as zeros."""
    labels = labels_of(result.study, result.summary)
    printed = Printed(result.text + "\n" + "\n".join(result.extra.values()))
    texts = summary_texts(result.summary, printed, {k: unit_in(v) for k, v in labels.items()})
    return key_values(result.summary, labels, texts)


def tidy_table(result: Result) -> Block:
    """The tidy table: names in words, numbers to the .out's decimals (or six significant
    digits of their column)."""
    tidy = result.tidy
    labels = labels_of(result.study, tidy.columns, tidy.attrs.get("units"))
    return frame_table(tidy, labels=labels, printed=Printed(result.text))


def anim_id(name: str) -> str:
    """The HTML id of a run's animation: the name's letters and digits, at most 40 of them and
    then a digest of the whole name (a long name is not repeated in every line of the script)."""
    word = re.sub(r"[^A-Za-z0-9]", "", name) or "x"
    if len(word) > 40:
        import hashlib
        word = word[:40] + hashlib.sha256(name.encode("utf-8", "surrogatepass")).hexdigest()[:8]
    return "anim-" + word


def run_blocks(result: Result, params: Params | None, what: str,
                marks: tuple[Mark, ...] = ()) -> tuple[list[Block], list[str]]:
    """A run's animation (``marks`` added: a synthesis's targets), figures and headline figures,
    as blocks (the parts of a design a sweep, an optimisation or a synthesis draws); and the
    figures that could not be drawn."""
    blocks: list[Block] = []
    view = study_animation(params, result, anim_id(result.name), f"{what} {HINT}", marks)
    if view is not None:
        blocks.append(Animation(view))
    figs, failed = figure_blocks(result.figures, result.name)
    blocks += figs
    if result.summary:
        blocks.append(summary_block(result))
    return blocks, failed


def result_sections(result: Result, params: Params | None, comparison: Any,
                    comparison_note: str = "") -> tuple[list[Section], list[str]]:
    """The sections of one run: animation, figures, headline figures, the comparison with the
    published cells, the tables (.out and extra files) and the tidy table."""
    sections = []
    view = study_animation(params, result, anim_id(result.name), HINT)
    if view is not None:
        sections.append(Section("animation", "animation", [Animation(view)]))
    figs, failed = figure_blocks(result.figures, result.name)
    if figs:
        sections.append(Section("figures", "figures", list(figs)))
    if result.summary:
        sections.append(Section("summary", "headline figures", [summary_block(result)]))
    sections.append(Section("published", "comparison with the published tables",
                            comparison_blocks(comparison, comparison_note)))
    tables: list[Block] = [Pre(result.text)]
    tables += [Details(shown(result.name) + suffix, [Pre(text)]) for suffix, text in result.extra.items()]
    sections.append(Section("tables", "tables (.out)", tables))
    if result.tidy is not None and len(result.tidy):
        sections.append(Section("tidy", "tidy table", [tidy_table(result)]))
    return sections, failed




def fragment(result: Result) -> str:
    """A run's animation, figures, headline figures and tables as an HTML fragment, without the
    page around them (a notebook's rich display), made by the page's own templates."""
    sections, _ = result_sections(result, result.params, None, "")
    return render_fragment([s for s in sections if s.id != "published"])
