"""A flywheel from a turning-moment diagram given in the deck (``turning_moment_deg``,
``turning_moment``): the kernel integrates the piecewise-linear torque exactly
(fortran/linkage.f90 table_energy)."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from driver._deck import Params
from driver.linkage import _kernel as kernel
from driver.linkage._kernel import EnergyCol

__all__ = ["TableFlywheel", "table_flywheel"]


@dataclass(frozen=True)
class TableFlywheel:
    """The energy of a turning-moment diagram: mean torque [N m], energy fluctuation [J],
    flywheel inertia [kg m^2] for the deck's speed fluctuation at its mean speed ``omega``
    (None when omega is 0), the crank angles [deg] of the energy's maximum and minimum, the
    cycle's work [J] and the extreme torques [N m]."""

    mean: float
    fluctuation: float
    inertia: float | None
    at_max_deg: float
    at_min_deg: float
    work: float
    torque_max: float
    torque_min: float


def table_flywheel(p: Params) -> TableFlywheel:
    """Size the flywheel of the deck's turning-moment diagram.

    Parameters
    ----------
    p : Params
        A validated ``&linkage`` deck with ``turning_moment_deg`` and ``turning_moment``
        (``omega`` the mean speed [rad/s], ``speed_fluctuation`` the coefficient C_s).

    Returns
    -------
    TableFlywheel
        Mean torque [N m], energy fluctuation [J], flywheel inertia [kg m^2] and the rest.
    """
    r = kernel.table_energy(np.radians(np.asarray(p.turning_moment_deg, float)), np.asarray(p.turning_moment, float),
                            p.speed_fluctuation, p.omega)
    return TableFlywheel(float(r[EnergyCol.MEAN_TORQUE]), float(r[EnergyCol.ENERGY_FLUCTUATION]),
                         float(r[EnergyCol.FLYWHEEL_INERTIA]) if p.omega != 0 else None,
                         math.degrees(r[EnergyCol.AT_MAX]), math.degrees(r[EnergyCol.AT_MIN]), float(r[EnergyCol.WORK]),
                         float(r[EnergyCol.TORQUE_MAX]), float(r[EnergyCol.TORQUE_MIN]))
