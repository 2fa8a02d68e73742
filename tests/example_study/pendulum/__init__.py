"""&pendulum: a uniform rigid rod swinging about one end, at any amplitude (the example study).

A complete study in the house layers (docs/layout.md), to show what adding a study takes: this
folder and one line in ``driver._study.REGISTRY`` (tests/test_new_study.py copies it into a
scratch repository as ``driver/pendulum`` and adds the line; tests/test_study_contract.py
registers it in place).  A real study adds its Fortran kernel (``fortran/<study>.f90`` and its
line in ``fortran/meson.build``); this example's "kernel" is numpy/scipy (:mod:`._kernel`), which
the house rules allow for the example only.  ``_keywords.pyi`` is generated from the SPEC
(tools/gen_keyword_signatures.py).

The rod (length L, uniform) pivots without friction at one end under gravity g; released at
rest from amplitude theta0 it swings with the period of the equivalent simple pendulum of length
2L/3: T = 4 sqrt(2L / 3g) K(sin(theta0 / 2)), K the complete elliptic integral of the first kind.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from driver._study import BatchSummary, Study

from . import _kernel as kernel
from . import _published as published
from ._batch import BATCH_IGNORED, BATCH_INDEPENDENT, BATCH_KEYS, BATCH_PASSES, summarise, summarise_batch
from ._spec import LABELS, SPEC, SWEEP_BEST, SWEEP_PLOT, estimate

if TYPE_CHECKING:   # run's keys as typed keywords: generated from SPEC (tools/gen_keyword_signatures.py)
    from ._keywords import run
else:
    from ._report import run

__all__ = ["SPEC", "STUDY", "run", "estimate", "summarise", "summarise_batch"]

STUDY = Study(name="pendulum", package=__name__, spec=SPEC, run=run, estimate=estimate, summarise=summarise,
              batch=BatchSummary(summarise_batch, keys=BATCH_KEYS, ignored=BATCH_IGNORED,
                                 independent=BATCH_INDEPENDENT, passes=BATCH_PASSES, pass_names=("elliptic",)),
              labels=LABELS, sweep_plot=SWEEP_PLOT, sweep_best=SWEEP_BEST, published=published.compare,
              figures=f"{__name__}._figures", kernel=kernel)
