"""Manipulator figures: the design space with its iso-RI2 ellipses and optima, and the motor
torques along C_rob (drawn in the house style of :mod:`driver.plotting`)."""
from __future__ import annotations

import math

import numpy as np

from driver.deck import Params
from driver.manipulator import kernel
from driver.manipulator.analysis import Conv, Workspace, optima

__all__ = ["design_space_figure", "torque_figure"]


def design_space_figure(p: Params, ws: Workspace, conv: Conv, used: dict):
    """The (l1, l2) design space: reach conditions, iso-RI2 ellipses, C_rob, the optima and the designs."""
    from driver.plotting import manipulator_design_space
    field_l = np.linspace(0.05, ws.R + 1.0, 161)
    L1, L2 = np.meshgrid(field_l, field_l)
    ri = kernel.manipulator_design_indices(ws.x, ws.y, L1.ravel(), L2.ravel())[0][:, 1].reshape(L1.shape)
    levels = p.ri2_levels or [math.sqrt(ws.n)]
    return manipulator_design_space(ws.r, ws.R, math.sqrt(conv.c_pairs), L1, L2, ri, float(ws.d2.sum()), ws.n,
                                    levels, optima(conv.c_pairs), used["names"], used["l1"], used["l2"],
                                    title=p.title or p.path.stem)


def torque_figure(sweep: dict, conv: Conv, title: str = ""):
    """Motor torques along C_rob (Table 4.8), where the target is out of reach left blank."""
    from driver.plotting import manipulator_torque_crob
    return manipulator_torque_crob(sweep["l1"], np.where(sweep["ok"], sweep["tau"][:, 0], np.nan),
                                   np.where(sweep["ok"], sweep["tau"][:, 1], np.nan), conv.c_sweep,
                                   violates=sweep["ok"] & ~sweep["reach_all"], title=title)
