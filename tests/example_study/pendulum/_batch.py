"""Many pendulums in one kernel call (sweeps and &optimize)."""
from __future__ import annotations

from collections.abc import Collection, Mapping
from typing import Any

import numpy as np
import pandas as pd

from . import _kernel as kernel

BATCH_KEYS = ("length", "gravity", "amplitude_deg")
#: column -> kernel passes (the elliptic integral is the only one; the small-angle period is closed form)
BATCH_PASSES = {"period_s": ("elliptic",), "small_angle_period_s": (), "period_ratio": ("elliptic",)}


def summarise_batch(base: Mapping[str, Any], columns: Mapping[str, Any] | None = None,
                    wanted: Collection[str] | None = None) -> pd.DataFrame:
    """One summary row per design: ``columns`` {key: values} of BATCH_KEYS vary, the rest is ``base``."""
    cols = {k.partition(".")[2] if "." in k else k: np.asarray(v, float) for k, v in (columns or {}).items()}
    n = max([c.size for c in cols.values()] or [1])
    get = lambda k: np.broadcast_to(cols.get(k, float(base[k])), (n,))
    t, t0 = kernel.periods(get("length"), get("gravity"), np.radians(get("amplitude_deg")))
    frame = pd.DataFrame({"period_s": t, "small_angle_period_s": t0, "period_ratio": t / t0})
    return frame if wanted is None else frame[[c for c in frame.columns if c in set(wanted)]]
