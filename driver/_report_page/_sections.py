"""The sections of a report page, from an engine's outcome: one builder per kind of outcome
(a study run, a sweep, an optimisation, a synthesis), sharing the blocks of a run's result
(animation, figures, headline figures, tables).

Everything comes from the outcome: the run's result, the sweep's summary and best case, the
optimiser's history, evaluations and optimum, the synthesised linkage and its run.  Nothing is
run again and no file the engine wrote is read back; the deck is echoed as its file says it.
"""
from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import f90nml

from driver._mechanism import Mark, MechanismFrames
from driver._names import shown
from driver._outcome import OptimizeOutcome, Outcome, RunOutcome, StreamedSummary, SweepOutcome, SynthesisOutcome
from driver._report_page._blocks import (
    Block,
    Details,
    FigureBlock,
    Page,
    Pre,
    Section,
    Text,
    frame_table,
    warnings_section,
)
from driver._report_page._figures import figure_blocks, figure_svg, plain
from driver._report_page._fragment import labels_of, result_sections, run_blocks
from driver._report_page._numbers import Printed
from driver._report_page._render import run_metadata

if TYPE_CHECKING:
    from driver._deck import Deck, Params

__all__ = ["page_of", "result_sections", "deck_text", "outcome_frames"]

def deck_text(deck: Deck | None, params: Params | None = None) -> str:
    """The deck as its file says it; a deck given in Python (no file) as the namelists of its
    groups, or of the keys ``params`` was given."""
    if deck is not None:
        path = Path(deck.path)
        try:
            if path.is_file() and path.stat().st_size < 2_000_000:
                return path.read_text(errors="replace")
        except OSError:
            pass
        return str(f90nml.Namelist({g.name: dict(g.values) for g in deck.groups.values()}))
    if params is not None:
        return str(f90nml.Namelist({params.group: {k: params[k] for k in params.given}}))
    return ""


def _subtitle(study: str, params: Params | None) -> str:
    from driver._study import load_study
    module = load_study(study) if study else None
    doc = module.spec.doc if module is not None else ""
    title = params.get("title", "") if params is not None and hasattr(params, "get") else ""
    return " \u2014 ".join(x for x in (doc, shown(title)) if x)


def _run_page(oc: RunOutcome, deck: Deck | None, compare: bool = True) -> Page:
    result, params = oc.result, oc.result.params
    comparison, note = None, ""
    if compare and params is not None:
        from driver._compare import compare_result
        try:
            comparison = compare_result(deck.path if deck is not None else Path(result.name), params, result)
        except Exception as exc:   # a comparison that fails is reported on the page, not fatal
            note = f"the comparison could not be made: {exc.__class__.__name__}: {exc}"
    sections, failed = result_sections(result, params, comparison, note)
    warnings = list(result.warnings) + failed
    if result.failure and result.failure not in warnings:
        warnings.insert(0, f"the run failed: {result.failure}")
    elif result.failure:
        warnings[warnings.index(result.failure)] = f"the run failed: {result.failure}"
    sections.insert(0, warnings_section(warnings))
    sections.append(Section("deck", "deck", [Pre(deck_text(deck, params))]))
    return Page(f"{shown(result.name)}: {result.study}", _subtitle(result.study, params), sections, run_metadata())


def _messages(oc: Outcome) -> list[str]:
    return [str(m) for m in oc.messages]


def _close(sections: list[Section], oc: Outcome, deck: Deck | None, notes: list[str], published: str) -> None:
    """The sections every engine's page shares: warnings first; the published note and the deck last."""
    sections.insert(0, warnings_section(_messages(oc) + notes))
    sections.append(Section("published", "comparison with the published tables", [Text(published, "note")]))
    sections.append(Section("deck", "deck", [Pre(deck_text(deck))]))


def _swept_value(params: Any, key: str, element: int | None) -> Any:
    """A swept key's value in a case's parameters: the key's, or its element (from 1)."""
    value = params[key]
    return value if element is None else value[element - 1]


def _sweep_page(oc: SweepOutcome, deck: Deck | None) -> Page:
    from driver._study import load_study
    from driver.sweep._report import best_words, summary_figures
    summary = oc.summary.to_pandas() if isinstance(oc.summary, StreamedSummary) else oc.summary
    module = load_study(oc.study)
    keys = [c for c in summary.columns if c.partition(".")[0] == oc.study] if summary is not None else []
    notes: list[str] = []
    maps: list[Block] = []
    if summary is not None and module is not None and oc.sweep is not None and len(summary):
        try:
            for k, fig in enumerate(summary_figures(summary, oc.sweep, keys, module, oc.name)):
                caption = f"{shown(oc.name)}_summary{'' if k == 0 else f'_{k + 1}'}: the summary over the swept keys"
                maps.append(FigureBlock(figure_svg(fig, caption), caption))
        except Exception as exc:
            notes.append(f"the design-space maps could not be drawn: {exc.__class__.__name__}: {exc}")
    sections = [Section("design-space", "design space", maps or [Text("No summary to map.", "note")])]
    if oc.best is not None:
        from driver.sweep._spec import split_key
        best = {k: _swept_value(oc.best.params, *split_key(k)) for k in keys}   # 'key' or 'key(i)'
        values = ", ".join(f"{k} = {v:.6g}" for k, v in best.items() if isinstance(v, (int, float)))
        blocks, failed = run_blocks(oc.best, oc.best.params, "The marked design.")
        notes += failed
        why = plain(best_words(module, oc.best_metric))
        sections.append(Section("best", "the marked design",
                                [Text(f"Case {oc.best_case}, {why}" + (f": {values}." if values else "."))] + blocks))
    sections.append(Section("tables", "sweep summary (.out)",
                            [Pre(oc.text)] if oc.text else [Text(f"See {shown(oc.name)}.out.", "note")]))
    if summary is not None:
        sections.append(Section("summary-table", "summary table",
                                [frame_table(summary, labels=labels_of(oc.study, summary.columns),
                                             printed=Printed(oc.text or ""))]))
    _close(sections, oc, deck, notes, "A sweep runs a study over many cases; the published tables belong to "
                                      "single-case decks.")
    rows = len(summary) if summary is not None else oc.n_cases
    sub = (f"sweep of &{oc.study} over {', '.join(keys)}: {rows} rows in the summary, {oc.n_kept} kept "
           f"of {oc.n_cases} cases")
    return Page(f"{shown(oc.name)}: sweep", sub, sections, run_metadata())


def _optimize_page(oc: OptimizeOutcome, deck: Deck | None) -> Page:
    p = oc.problem
    notes: list[str] = []
    figs, failed = figure_blocks(oc.figures, oc.name)
    notes += failed
    sections = [Section("convergence", "convergence and design space", list(figs))]
    opt = oc.optimum
    if opt is not None:
        word = "The optimum." if opt.converged else "The best design found (the method did not converge)."
        blocks, failed = run_blocks(opt.result, opt.params, word)
        notes += failed
        blocks.append(Details(f"{shown(oc.name)}.optimum.dat", [Pre(opt.deck)]))
        sections.append(Section("optimum", "the optimum" if opt.converged else "the best design", blocks))
    sections.append(Section("tables", "report (.out)", [Pre(oc.text)]))
    if oc.history_table is not None:
        sections.append(Section("history", "history", [frame_table(oc.history_table, printed=Printed(oc.text))]))
    _close(sections, oc, deck, notes, "An optimisation has no published table of its own; compare the optimum "
                                      "deck it writes (--compare).")
    sense = "minimize" if p.sense > 0 else "maximize"
    sub = f"{sense} {p.objective_text} over {', '.join(p.names)}; {oc.nfev} designs evaluated"
    return Page(f"{shown(oc.name)}: optimisation", sub, sections, run_metadata())


def _targets(oc: SynthesisOutcome) -> tuple[Mark, ...]:
    """A path synthesis's target points, in its linkage's frame, for the animation."""
    syn = oc.value
    if syn is None or getattr(syn.params, "task", "") != "path" or syn.design is None:
        return ()
    from driver.synthesis import path_targets
    return (Mark(path_targets(syn), "target points"),)


def _synthesis_page(oc: SynthesisOutcome, deck: Deck | None) -> Page:
    notes: list[str] = []
    blocks: list[Block] = []
    figs, failed = figure_blocks(oc.figures, oc.name)
    notes += failed
    if oc.result is not None:
        blocks, failed = run_blocks(oc.result, oc.params, "The synthesised linkage.", _targets(oc))
        notes += failed
        if oc.linkage_deck:
            blocks.append(Details(f"{shown(oc.name)}.linkage.dat", [Pre(oc.linkage_deck)]))
    sections = [Section("linkage", "the synthesised linkage", list(figs) + blocks
                        or [Text("No linkage was found.", "note")])]
    sections.append(Section("tables", "report (.out)", [Pre(oc.text)]))
    if len(oc.table):
        sections.append(Section("task-table", f"{shown(oc.name)}{oc.table_name}.csv", [frame_table(oc.table)]))
    _close(sections, oc, deck, notes, "A synthesis has no published table of its own; compare the linkage "
                                      "deck it writes (--compare).")
    linkage = f" of a &{oc.result.study} linkage" if oc.result is not None else ""
    return Page(f"{shown(oc.name)}: synthesis", f"synthesis ({oc.task}){linkage}", sections, run_metadata())


def outcome_frames(outcome: Outcome) -> tuple[MechanismFrames | None, str]:
    """The mechanism the page of ``outcome`` animates, as frames, and whose it is: a run's, a
    sweep's best case's, an optimisation's optimum's, the synthesised linkage's (its targets
    added); (None, '') when there is none (no such run, or a study without an animation)."""
    from driver._report_page._animation import study_frames
    if isinstance(outcome, RunOutcome):
        r = outcome.result
        return study_frames(r.params, r), shown(r.name)
    if isinstance(outcome, SweepOutcome) and outcome.best is not None:
        return study_frames(outcome.best.params, outcome.best), f"{shown(outcome.name)}, case {outcome.best_case}"
    if isinstance(outcome, OptimizeOutcome) and outcome.optimum is not None:
        return study_frames(outcome.optimum.params, outcome.optimum.result), f"{shown(outcome.name)}, the optimum"
    if isinstance(outcome, SynthesisOutcome) and outcome.result is not None:
        return study_frames(outcome.params, outcome.result, _targets(outcome)), f"{shown(outcome.name)}, the linkage"
    return None, ""


def page_of(outcome: Outcome, deck: Deck | None = None) -> Page:
    """The page of an engine's outcome (``deck``: the deck it ran, echoed on the page)."""
    if isinstance(outcome, RunOutcome):
        return _run_page(outcome, deck)
    if isinstance(outcome, SweepOutcome):
        return _sweep_page(outcome, deck)
    if isinstance(outcome, OptimizeOutcome):
        return _optimize_page(outcome, deck)
    if isinstance(outcome, SynthesisOutcome):
        return _synthesis_page(outcome, deck)
    raise TypeError(f"no report page for {type(outcome).__name__}")
