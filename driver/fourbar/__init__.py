"""Four-bar linkage study [Soegihardjo 2003]: the ``&fourbar`` group.

``method = 'listing'`` runs the published Fortran 77 program (Lampiran 1), kept
cell-for-cell, and audits it against the closed loop; ``method = 'exact'``
(default) solves the loop on the requested branch in double precision and adds
accelerations, Grashof class, limit and toggle positions and a summary.

Lengths in any consistent unit; angles in degrees in decks and tables; crank
speed in rad/s, accelerations in rad/s^2.

The package's private modules, in their dependency order (docs/layout.md): ``_kernel`` (the
Fortran wrappers), ``_spec`` (deck keys and checks, the force keys included, labels, the budget
estimate), ``_analysis`` (Grashof class, states and the summary kernel, extremes) and
``_analysis_forces`` (joint forces, torque, shaking, balancing), ``_batch`` (many designs in one
kernel call; the summary and the force summary), ``_figures``, ``_report`` (the run: .out, tidy
table, summary) and ``_report_forces`` (its force section), ``_published`` (the published listing
tables and their defects); ``_forces`` is the face of the force analysis (``driver.fourbar.forces``).
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

from driver._study import BatchSummary, Study
from driver.fourbar import _kernel as kernel
from driver.fourbar import _published as published
from driver.fourbar._analysis import (
    PASS_BITS,
    ST,
    Extremes,
    Grashof,
    Motion,
    assembly_intervals,
    blame,
    coupler_point,
    crank_angles,
    exact_grid,
    extremes,
    grashof,
    limit_angles,
    listing_grid,
    rocking_motions,
    tidy_frame,
)
from driver.fourbar._batch import (
    BATCH_IGNORED,
    BATCH_INDEPENDENT,
    BATCH_KEYS,
    BATCH_PASSES,
    batch_applies,
    batch_refusal,
    summarise,
    summarise_batch,
)
from driver.fourbar._published import LISTING_DEFECT, LISTING_PRECISION, exact_as_listed
from driver.fourbar._report import animation_frames
from driver.fourbar._spec import LABELS, RENAMED, SPEC, SUMMARY_SETTINGS, SWEEP_BEST, SWEEP_PLOT, estimate

if TYPE_CHECKING:   # run's keys as typed keywords: generated from SPEC (tools/gen_keyword_signatures.py)
    from driver.fourbar._keywords import run
else:
    from driver.fourbar._report import run
if TYPE_CHECKING:   # imported on first use (__getattr__ below)
    from driver.fourbar import _forces as forces

__all__ = ["SPEC", "STUDY", "run", "estimate", "summarise", "summarise_batch", "BATCH_KEYS", "BATCH_PASSES", "grashof",
           "limit_angles", "assembly_intervals", "rocking_motions", "Motion", "crank_angles", "exact_grid", "coupler_point",
           "listing_grid", "extremes", "tidy_frame",
           "exact_as_listed", "Grashof", "Extremes", "ST", "LABELS", "SWEEP_BEST", "SWEEP_PLOT", "LISTING_DEFECT",
           "LISTING_PRECISION", "forces", "kernel"]

STUDY = Study(name="fourbar", package=__name__, spec=SPEC, run=run, estimate=estimate, summarise=summarise,
              batch=BatchSummary(summarise_batch, keys=BATCH_KEYS, ignored=BATCH_IGNORED,
                                 independent=BATCH_INDEPENDENT, passes=BATCH_PASSES,
                                 pass_names=(*PASS_BITS, "forces"), refusal=batch_refusal,
                                 applies=batch_applies),
              labels=LABELS, sweep_plot=SWEEP_PLOT, sweep_best=SWEEP_BEST, summary_settings=SUMMARY_SETTINGS,
              renamed=RENAMED,
              blame=blame, published=published.compare, animation=animation_frames, figures=f"{__name__}._figures",
              kernel=kernel)


def __getattr__(name: str) -> Any:
    """PEP 562: ``forces`` (the force analysis's face) on first use, so that a run without masses
    does not import its modules (docs/performance.md, *Start-up*)."""
    if name == "forces":
        from driver.fourbar import _forces
        globals()["forces"] = _forces
        return _forces
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
