"""The ``--json`` record of a sweep deck: what ran and where its summary is (``<stem>.json``)."""
from __future__ import annotations

import json
from pathlib import Path

from driver._atomic import write_text
from driver._deck import Deck
from driver._export import json_safe
from driver._runner import output_stem

__all__ = ["write_sweep_json"]


def write_sweep_json(deck: Deck, outdir: Path, exit_status: int) -> Path:
    """Write ``<stem>.json``: the deck, exit status, cases summarised (by status, and kept by the
    filter), the swept keys and the summary table's columns and file; returns its path."""
    stem = output_stem(outdir, deck.path, (".json",))
    table = stem.with_name(stem.name + "_summary.parquet")
    rec: dict = {"kind": "sweep", "deck": str(deck.path), "ok": exit_status == 0, "exit_status": exit_status,
                 "summary_table": table.name if table.exists() else None}
    if table.exists():   # only the columns counted are read (a large search has many rows)
        import pyarrow.parquet as pq
        names = pq.read_schema(table).names
        frame = pq.read_table(table, columns=[c for c in ("status", "kept") if c in names]).to_pandas()
        rec["rows"] = int(pq.read_metadata(table).num_rows)
        if "status" in frame:
            rec["status_counts"] = {str(k): int(v) for k, v in frame["status"].value_counts().sort_index().items()}
        if "kept" in frame:
            rec["kept"] = int(frame["kept"].astype(bool).sum())
        rec["swept_keys"] = [c for c in names if "." in c]
        rec["columns"] = [str(c) for c in names]
    return write_text(stem.with_name(stem.name + ".json"), json.dumps(json_safe(rec), indent=1, allow_nan=False) + "\n")
