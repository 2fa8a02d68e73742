"""The four-bar force analysis (issue 26), public as ``driver.fourbar.forces``: a face, no code.

Joint forces, input torque, shaking force and moment per crank position (kernel
``fortran/fourbar_forces.f90``), their summary, Berkof-Lowen shaking-force balancing
(``balance = 'force'``), the batch summary for sweeps and ``&optimize``, and the figures.  The
code lives in the study's layers (docs/layout.md): the keys and their checks in ``_spec``, the
analysis through the kernel in ``_analysis_forces``, the batch summary in ``_batch``, the .out
text in ``_report_forces`` and the figures in ``_figures`` (which imports matplotlib: the plot
functions are imported from it on first use).  Units: SI (lengths in metres when masses are
given); sign conventions and the equations: docs/fourbar.md, section "Force analysis".
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

from driver.fourbar._analysis_forces import COLUMNS, ForceAnalysis, analyse, props, tidy_columns
from driver.fourbar._batch import FORCE_BATCH_KEYS as BATCH_KEYS
from driver.fourbar._batch import force_summary as summary
from driver.fourbar._batch import summarise_force_batch
from driver.fourbar._report_forces import figures, summary_lines, table_lines
from driver.fourbar._spec import FORCE_KEYS as KEYS
from driver.fourbar._spec import force_check as check
from driver.fourbar._spec import forces_active as active

if TYPE_CHECKING:   # for type checkers and IDEs; at run time from __getattr__ below
    from driver.fourbar._figures import plot_pin_polars, plot_shaking, plot_torque

__all__ = ["KEYS", "check", "active", "props", "ForceAnalysis", "analyse", "COLUMNS", "tidy_columns", "table_lines",
           "summary_lines", "summary", "summarise_force_batch", "BATCH_KEYS", "figures", "plot_torque", "plot_pin_polars",
           "plot_shaking"]

#: the figure functions (they draw into axes the caller gives), from the study's figure module
_PLOTS = ("plot_torque", "plot_pin_polars", "plot_shaking")


def __getattr__(name: str) -> Any:
    """PEP 562: the plot functions on first use (matplotlib is the optional [plot] extra)."""
    if name in _PLOTS:
        from driver.fourbar import _figures
        return getattr(_figures, name)
    raise AttributeError(f"module 'driver.fourbar.forces' has no attribute {name!r}")
