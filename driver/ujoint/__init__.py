"""Hooke-joint (universal-joint) shaft chains: the paper's SSO package, corrected and extended.

[Fajar] (M. Fajar, "Optimasi kecepatan sudut keluaran kopeling universal pada poros seri"):
three Hooke joints on four shafts, optimised with MATLAB fmincon in three options
(1 phases free, 2 angles free, 3 both).  This study

* evaluates the paper's model (every joint driven by the input angle plus a phase; eq. 13
  as printed or with cumulative phases as the text says) and the exact chain (each joint's
  output angle drives the next, with plane angles for non-coplanar 3-D chains), all in the
  Fortran kernel ``fortran/ujoint.f90``;
* runs the options with scipy SLSQP (the counterpart of fmincon's SQP) from the trial point
  and from seeded random starts, with the kernel's analytic gradient;
* reports trial, optimum and the paper's printed designs under the same objective, the
  fluctuation band, peak-to-peak ratio, closed-form equivalent angles and the peak output
  acceleration, and a speed table over the input angle.

Angles in the deck are degrees; the kernel works in radians.  Phases: the paper's phi
(90 deg = yokes on the intermediate shaft in phase) or the yoke phase delta = phi - 90 deg.
See docs/ujoint.md for what reproduces and what does not.

The package's private modules, by job: ``_spec`` (deck keys, checks, conventions, labels, the budget estimate),
``_analysis`` (one design evaluated; the multi-start optimiser), ``_report`` (the run: .out, tidy
table, summary, result.dat), ``_figures``, ``_batch`` (many given designs in one kernel call:
sweeps and &optimize), ``_published`` (the paper's printed results) and ``_kernel`` (the Fortran
wrappers).
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from driver._study import BatchSummary, Study
from driver.ujoint import _kernel as kernel
from driver.ujoint import _published as published
from driver.ujoint._analysis import (
    BOUND_TOL,
    CLUSTER_TOL,
    PHASE_PERIOD,
    SADDLE_NUDGE,
    SYM_TOL,
    TIE_RTOL,
    Chain,
    Design,
    StartRun,
    evaluate,
    objective_scale,
    optimise,
    phases_for,
    pick_best,
    yoke_shifts,
)
from driver.ujoint._batch import (
    BATCH_ELEMENTS,
    BATCH_IGNORED,
    BATCH_INDEPENDENT,
    BATCH_KEYS,
    BATCH_PASSES,
    batch_applies,
    summarise_batch,
)
from driver.ujoint._report import animation_frames
from driver.ujoint._spec import (
    BAND_TOL,
    CONVENTIONS,
    DEG,
    LABELS,
    NOT_REPRODUCIBLE,
    OPTIONS,
    SPEC,
    SWEEP_PLOT,
    cross_check,
    estimate,
)

if TYPE_CHECKING:   # run's keys as typed keywords: generated from SPEC (tools/gen_keyword_signatures.py)
    from driver.ujoint._keywords import run
else:
    from driver.ujoint._report import run

__all__ = ["SPEC", "STUDY", "run", "estimate", "Chain", "Design", "StartRun", "evaluate", "optimise",
           "objective_scale", "pick_best", "yoke_shifts", "phases_for", "cross_check", "summarise_batch",
           "batch_applies", "BATCH_KEYS", "BATCH_PASSES", "BATCH_IGNORED", "BATCH_INDEPENDENT", "BATCH_ELEMENTS",
           "LABELS", "SWEEP_PLOT", "BAND_TOL", "NOT_REPRODUCIBLE", "CONVENTIONS", "OPTIONS", "DEG", "SYM_TOL",
           "SADDLE_NUDGE", "PHASE_PERIOD", "TIE_RTOL", "CLUSTER_TOL", "BOUND_TOL", "kernel"]

STUDY = Study(name="ujoint", package=__name__, spec=SPEC, run=run, estimate=estimate,
              batch=BatchSummary(summarise_batch, keys=BATCH_KEYS, ignored=BATCH_IGNORED,
                                 independent=BATCH_INDEPENDENT, passes=BATCH_PASSES,
                                 pass_names=("objective", "speed", "equivalent"), applies=batch_applies,
                                 elements=BATCH_ELEMENTS),
              labels=LABELS, sweep_plot=SWEEP_PLOT, published=published.compare, animation=animation_frames,
              figures=f"{__name__}._figures", kernel=kernel)
