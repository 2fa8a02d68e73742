"""Many pendulums in one kernel call (sweeps and &optimize), and the summary of one deck (its row)."""
from __future__ import annotations

from collections.abc import Collection, Mapping
from typing import Any

import numpy as np
import pandas as pd

from driver._deck import Params
from driver._study import contract_doc

from ._analysis import periods

__all__ = ["BATCH_KEYS", "BATCH_IGNORED", "BATCH_INDEPENDENT", "BATCH_PASSES", "summarise_batch", "summarise"]

#: deck keys a batch may vary, those it ignores, and those whose checks involve no other key
BATCH_KEYS = ("length", "gravity", "amplitude_deg")
BATCH_IGNORED = ("title", "points")
BATCH_INDEPENDENT = ("length", "gravity", "amplitude_deg", "title", "points")
#: column -> kernel passes (the elliptic integral is the only one; the small-angle period is closed form)
BATCH_PASSES = {"period_s": ("elliptic",), "small_angle_period_s": (), "period_ratio": ("elliptic",)}


def summarise_batch(base: Mapping[str, Any], columns: Mapping[str, Any] | None = None,
                    wanted: Collection[str] | None = None) -> pd.DataFrame:
    """One summary row per design: ``columns`` {key: values} of BATCH_KEYS vary, the rest is ``base``."""
    cols = {k.partition(".")[2] if "." in k else k: np.asarray(v, float) for k, v in (columns or {}).items()}
    n = max([c.size for c in cols.values()] or [1])
    get = lambda k: np.broadcast_to(cols.get(k, float(base[k])), (n,))
    frame = pd.DataFrame(periods(get("length"), get("gravity"), get("amplitude_deg")))
    return frame if wanted is None else frame[[c for c in frame.columns if c in set(wanted)]]


@contract_doc
def summarise(params: Params) -> dict:
    """Summarise one deck: its row of the batch summary.

    %(summarise)s
    """
    return {k: float(v) for k, v in summarise_batch(params).iloc[0].items()}
