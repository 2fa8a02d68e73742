"""&manipulator: robust dimensional synthesis of a planar 2R arm ([Ma'arif 2006], chapter 4).

From a workspace given as points P_i (base A at the origin) the study computes

* the reach conditions |l1 - l2| <= r, l1 + l2 >= R (r, R = min, max d(A, P_i)), the robust
  circle C_rob: l1^2 + l2^2 = mean d^2 (RI2 = sqrt(n) on it), RI1/RI2/RI3 of any design,
  the iso-RI2 ellipse variables (Tables 4.1/4.3) and (l1, l2) pairs on C_rob (Table 4.2);
* the dexterity optimum (l2 = l1 sqrt(2)/2) and manipulability optimum (l1 = l2) on C_rob
  (Table 4.4);
* joint angles and Craig point-mass motor torques at a target point for the chosen designs
  (Tables 4.5-4.7) and along C_rob (Table 4.8; rows where the target is out of reach blank,
  with a note);
* tolerance synthesis: the largest box l +- dl whose positioning error stays within a bound
  (Caro's formulation, closed form and the exact largest box over every corner constraint),
  checked by Monte Carlo.

``mode = 'report'`` applies the report's conventions (docs/manipulator.md sec. 0):
C_rob radius rounded to 3 dp, C = radius^2 for Table 4.2 and round(radius^2, 2) for Table 4.8,
Table 4.5 theta2 printed as the interior angle 180 - acos(c2), Table 4.7 fed with the printed
Table 4.5 angles, Table 4.8 base angle round(atan2(y, x), 2 dp) - theta2.  ``mode = 'exact'``
uses mean d^2 itself, the IK joint angles on the chosen elbow branch at full precision.  In
report mode the .out lists every cell where the two modes differ, and why.

Physics (IK, Jacobian, indices, torques, positioning errors) is in fortran/manipulator.f90.

The package's private modules split the study by job: :mod:`._spec` (deck keys, checks, the budget estimate), :mod:`._analysis`
(conventions, optima, joint angles, tolerance synthesis), :mod:`._tables` (the tables and the
report/exact differences), :mod:`._report` (the run: text, tidy table, summary) and
:mod:`._batch` (the design summary of many designs in one kernel call), :mod:`._figures`,
:mod:`._published` (the report's printed tables) and :mod:`._kernel` (the Fortran wrappers).
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from driver._study import BatchSummary, Study
from driver.manipulator import _kernel as kernel
from driver.manipulator import _published as published
from driver.manipulator._analysis import DESIGN_STATUS, Workspace, optima, round_half_up, tolerance_box
from driver.manipulator._batch import (
    BATCH_IGNORED,
    BATCH_INDEPENDENT,
    BATCH_KEYS,
    BATCH_PASS_SUFFIXES,
    BATCH_PASSES,
    batch_refusal,
    summarise,
    summarise_batch,
)
from driver.manipulator._report import TIDY_UNITS, animation_frames, table_frame
from driver.manipulator._spec import LABELS, RENAMED, SPEC, SWEEP_BEST, SWEEP_PLOT, estimate
from driver.manipulator._tables import NOT_REPRODUCIBLE, REASONS, TEXT_REASONS, TIDY_NAMES

if TYPE_CHECKING:   # run's keys as typed keywords: generated from SPEC (tools/gen_keyword_signatures.py)
    from driver.manipulator._keywords import run
else:
    from driver.manipulator._report import run

__all__ = ["SPEC", "run", "Workspace", "tolerance_box", "round_half_up", "REASONS", "NOT_REPRODUCIBLE", "TEXT_REASONS",
           "TIDY_NAMES", "TIDY_UNITS", "table_frame", "LABELS", "SWEEP_PLOT", "SWEEP_BEST", "estimate", "optima",
           "summarise", "summarise_batch", "BATCH_KEYS", "BATCH_PASSES", "BATCH_PASS_SUFFIXES", "BATCH_IGNORED",
           "BATCH_INDEPENDENT", "DESIGN_STATUS", "STUDY", "kernel"]

STUDY = Study(name="manipulator", package=__name__, spec=SPEC, run=run, estimate=estimate, summarise=summarise,
              batch=BatchSummary(summarise_batch, keys=BATCH_KEYS, ignored=BATCH_IGNORED,
                                 independent=BATCH_INDEPENDENT, passes=BATCH_PASSES,
                                 pass_names=("indices", "target", "tolerance", "walk"), refusal=batch_refusal),
              labels=LABELS, sweep_plot=SWEEP_PLOT, sweep_best=SWEEP_BEST, renamed=RENAMED,
              published=published.compare, animation=animation_frames, figures=f"{__name__}._figures",
              kernel=kernel)
