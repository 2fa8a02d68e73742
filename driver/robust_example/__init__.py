"""&robust_example: Taylor's (1996) robust-design example, section 2.3 of [Ma'arif 2006].

Three estimates of the target t_x that minimises the spread of Y = b0 + b1 X + b2 X^2 when X
varies about t_x with standard deviation sigma_x:

* eq. (2.2), the exact tolerance analysis of the known quadratic (2.1);
* dual response (2.3.1): mean and sample std per target (Table 2.2), a quadratic through the
  means (2.7) and through ln(std) (2.8), t_min = -b1/(2 b2) (2.9);
* Taguchi inner/outer array (2.3.2): row means of Table 2.3 arranged by target and noise offset
  (Table 2.4), their mean and sample std per target (Table 2.5), quadratics (2.11)/(2.12),
  t_min (2.13);
* tolerance analysis of the fitted mean (2.3.3): (2.14), t_min (2.15).

``mode = 'report'`` fits (2.8) to the std rounded to 7 dp and (2.11) to the means rounded to 4 dp,
as printed (this reproduces the printed coefficients); ``mode = 'exact'`` uses unrounded values.
The printed results that do not reproduce, eq. (2.12) and the last digit of two Table 2.5 std
values, are compared with the deck's ``printed_*`` values and flagged, not forced.

This is statistics, not mechanism physics: it is plain numpy (no Fortran kernel).

The package's private modules, by job: ``_spec`` (deck keys, the cross-check, the budget estimate), ``_analysis``
(the fits and estimates), ``_report`` (the run: .out, tidy table, summary), ``_figures`` and
``_published`` (the printed results and what does not reproduce).
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from driver._study import Study
from driver.robust_example import _published as published
from driver.robust_example._analysis import analyse, quadratic_fit
from driver.robust_example._published import NOT_REPRODUCIBLE
from driver.robust_example._spec import MODE_REASONS, SPEC, estimate

if TYPE_CHECKING:   # run's keys as typed keywords: generated from SPEC (tools/gen_keyword_signatures.py)
    from driver.robust_example._keywords import run
else:
    from driver.robust_example._report import run

__all__ = ["SPEC", "STUDY", "run", "estimate", "quadratic_fit", "analyse", "MODE_REASONS", "NOT_REPRODUCIBLE"]

STUDY = Study(name="robust_example", package=__name__, spec=SPEC, run=run, estimate=estimate,
              published=published.compare, figures=f"{__name__}._figures")
