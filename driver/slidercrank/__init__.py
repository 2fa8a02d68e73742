"""Slider-crank with an elastic connecting rod [Andalas]: the &slidercrank study.

Rigid crank, elastic rod meshed with frame elements, slider on its guide; kineto-elastodynamic
(KED) finite-element model integrated with Newmark's average-acceleration rule.  The physics
(kinematics, rigid-body axial force, element matrices, banded Cholesky, the whole time loop)
lives in ``fortran/slidercrank.f90``; this module validates the deck, runs the cases, and
writes the paper's results: peak axial strain per crank speed, strain of the crank-end
element against crank angle (Figure 10), the element-convergence study (Figures 8-9), the
Euler-load ratio of every case and, with geometric stiffness, buckling.

Units in decks: SI (m, kg, Pa, rad/s, s).  Strains are reported in microstrain.

The package's private modules, by job: ``_spec`` (deck keys, materials, the model a deck describes, checks, the budget
estimate), ``_analysis`` (one case through the kernel, settling, static buckling onset), ``_report``
(the linear run: .out sections, tidy table, summary), ``_figures``, ``_published`` (Table 1 and the
Simeon 1996 reference), ``_kernel`` (the Fortran wrappers), and the nonlinear rod (``_analysis_nl``,
``_report_nl``: the run of a deck, either model). Cases are heavy (a time integration each), so the
study has no batch path: a sweep runs them one per task.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from driver._study import Study
from driver.slidercrank import _kernel as kernel
from driver.slidercrank import _published as published
from driver.slidercrank._analysis import Case, simeon_initial_state, static_onset
from driver.slidercrank._report import animation_frames
from driver.slidercrank._spec import (
    LABELS,
    MATERIALS,
    PAPER_SPEEDS,
    SIMEON1996,
    SPEC,
    STATUS_TEXT,
    SWEEP_PLOT,
    Model,
    estimate,
    min_steps_per_rev,
    rayleigh,
)

if TYPE_CHECKING:   # run's keys as typed keywords: generated from SPEC (tools/gen_keyword_signatures.py)
    from driver.slidercrank._keywords import run
else:
    from driver.slidercrank._report_nl import run

__all__ = ["SPEC", "STUDY", "run", "estimate", "MATERIALS", "PAPER_SPEEDS", "SIMEON1996", "simeon_initial_state",
           "min_steps_per_rev", "rayleigh", "static_onset", "STATUS_TEXT", "Model", "Case", "LABELS", "SWEEP_PLOT",
           "kernel"]

STUDY = Study(name="slidercrank", package=__name__, spec=SPEC, run=run, estimate=estimate, labels=LABELS,
              sweep_plot=SWEEP_PLOT, published=published.compare, animation=animation_frames, figures=f"{__name__}._figures",
              kernel=kernel)
