"""&pendulum: a uniform rigid rod swinging about one end, at any amplitude (the example study).

A minimal study in the house layout, to show what adding a study takes: this folder and one
line in ``driver._study.REGISTRY`` (the test registers it for its run).  A real study adds its
Fortran kernel (``fortran/<study>.f90`` and a line in ``fortran/meson.build``); this example's
"kernel" is numpy/scipy (:mod:`.kernel`), which the house rules allow for the example only.

The rod (length L, uniform) pivots without friction at one end under gravity g; released at
rest from amplitude theta0 it swings with the period of the equivalent simple pendulum of length
2L/3: T = 4 sqrt(2L / 3g) K(sin(theta0 / 2)), K the complete elliptic integral of the first kind.
"""
from __future__ import annotations

from driver._study import BatchSummary, Study

from . import _kernel as kernel
from ._batch import BATCH_KEYS, BATCH_PASSES, summarise_batch
from ._report import run, summarise
from ._spec import LABELS, SPEC, estimate

__all__ = ["SPEC", "STUDY", "run", "estimate", "summarise", "summarise_batch"]

STUDY = Study(name="pendulum", package=__name__, spec=SPEC, run=run, estimate=estimate, summarise=summarise,
              batch=BatchSummary(summarise_batch, keys=BATCH_KEYS, ignored=("title", "points"),
                                 independent=("length", "gravity", "amplitude_deg", "title", "points"),
                                 passes=BATCH_PASSES, pass_names=("elliptic",)),
              labels=LABELS, sweep_plot=("period_s", "period_ratio"), sweep_best={"period_ratio": "min"},
              figures=f"{__name__}._figures", kernel=kernel)
