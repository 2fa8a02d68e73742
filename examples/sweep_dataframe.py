"""A sweep from Python: the four-bar paper's crank lengths and a finer grid, as DataFrames.

    python examples/sweep_dataframe.py [OUTDIR]

First the shipped sweep deck (crank 2, 3, 4, 5 with the published program), then a grid given
in Python (crank x rocker) with a keep filter on the summary columns; both come back as pandas
DataFrames, one row per case.  The grid's files are written to OUTDIR/fourbar*.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import driver

ROOT = Path(__file__).resolve().parents[1]


def main(outdir: Path):
    paper = driver.run_sweep(ROOT / "inputs" / "fourbar_paper_sweep.dat", jobs=1)
    print(paper.summary[["fourbar.crank", "grashof_class", "mu_min_deg", "mu_max_deg", "rocker_swing_deg"]]
          .to_string(index=False))
    base = {"fixed_link": 12.0, "crank": 5.0, "coupler": 15.0, "rocker": 9.0, "omega": 5.0, "step_deg": 10.0}
    grid = driver.run_sweep({"fourbar": base}, grid={"crank": np.linspace(2.0, 6.0, 5), "rocker": [8.0, 9.0, 10.0]},
                            keep="meets_transmission_band or mu_min_deg > 30", case_outputs="none",
                            jobs=1, outdir=outdir)
    table = grid.summary.pivot(index="fourbar.crank", columns="fourbar.rocker", values="mu_min_deg")
    print("minimum transmission angle [deg], crank (rows) x rocker (columns):")
    print(table.round(2).to_string())
    print(f"{len(grid.kept)} of {len(grid.summary)} linkages kept")
    return paper, grid


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("example_outputs"))
