"""Any planar linkage [issue 38]: the ``&linkage`` group.

A mechanism is a driver (a crank turning about a ground pivot, or a block moving along a
ground guide) followed by class-II Assur groups (dyads RRR, RRP, PRR, RPR, PRP), each attached
to points already placed, with points on any link (tracers, attachments, load points).
The kernel (fortran/linkage.f90) solves positions, velocities and accelerations of every joint
and point, every link's angle and rates and every slide; assembly failures, toggles and dead
centres per group; joint forces, the driving torque (or force), shaking force and moment,
group by group in closed form; flywheel energy; and batched summaries for sweeps and
&optimize.  Deck grammar, sign conventions and equations: docs/linkage.md.

The package's private modules, in the layers of every study (docs/layout.md): ``_kernel`` (the
Fortran wrappers, columns and status named by enums) with ``_kernel_program`` (the kernel's
program of one mechanism: plain data); ``_spec`` (deck keys, checks, labels, budget) with
``_spec_model`` (the deck's mechanism resolved, checked and compiled); ``_analysis`` (a deck
through the kernel, events, tidy table) with ``_analysis_flywheel`` (a turning-moment table)
and ``_analysis_frames`` (poses as drawing data; the report page's animation); ``_batch`` (many
designs in one kernel call; the summary); ``_figures``; ``_report`` (the run); ``_published``
(the textbook closed forms).
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from driver._study import BatchSummary, Study
from driver.linkage import _kernel as kernel
from driver.linkage import _published as published
from driver.linkage._analysis import solve
from driver.linkage._analysis_flywheel import table_flywheel
from driver.linkage._analysis_frames import animation_frames
from driver.linkage._batch import (
    BATCH_ELEMENTS,
    BATCH_IGNORED,
    BATCH_INDEPENDENT,
    BATCH_KEYS,
    BATCH_PASSES,
    PASS_NAMES,
    refusal,
    summarise,
    summarise_batch,
)
from driver.linkage._spec import LABELS, SPEC, SUMMARY_SETTINGS, SWEEP_BEST, SWEEP_PLOT, estimate
from driver.linkage._spec_model import compile_deck

if TYPE_CHECKING:   # run's keys as typed keywords: generated from SPEC (tools/gen_keyword_signatures.py)
    from driver.linkage._keywords import run
else:
    from driver.linkage._report import run

__all__ = ["SPEC", "STUDY", "run", "estimate", "summarise", "summarise_batch", "compile_deck", "solve",
           "table_flywheel", "animation_frames", "BATCH_KEYS", "BATCH_PASSES", "LABELS", "kernel"]

STUDY = Study(name="linkage", package=__name__, spec=SPEC, run=run, estimate=estimate, summarise=summarise,
              batch=BatchSummary(summarise_batch, keys=BATCH_KEYS, ignored=BATCH_IGNORED,
                                 independent=BATCH_INDEPENDENT, elements=BATCH_ELEMENTS, refusal=refusal,
                                 passes=BATCH_PASSES, pass_names=tuple(PASS_NAMES)),
              labels=LABELS, sweep_plot=SWEEP_PLOT, sweep_best=SWEEP_BEST, summary_settings=SUMMARY_SETTINGS,
              published=published.compare, animation=animation_frames, figures=f"{__name__}._figures", kernel=kernel)
