"""Four-bar linkage from keyword arguments: its table, extremes and a figure.

    python examples/fourbar_plot.py [OUTDIR]

The paper's crank-5 linkage (lengths in one consistent unit, crank speed in rad/s) solved on
the closed loop every 5 degrees; prints the transmission-angle extremes [deg] and the peak
rocker speed [rad/s], and saves the linkage drawing as OUTDIR/fourbar_linkage.png.
"""
from __future__ import annotations

import sys
from pathlib import Path

import driver
from driver.plotting import save_figure


def main(outdir: Path) -> driver.Result:
    r = driver.fourbar.run(fixed_link=12.0, crank=5.0, coupler=15.0, rocker=9.0, omega=5.0, step_deg=5.0)
    s = r.summary
    print(f"{s['grashof_class']}: transmission angle {s['mu_min_deg']:.2f} .. {s['mu_max_deg']:.2f} deg, "
          f"peak rocker speed {s['rocker_omega_peak_rad_s']:.4f} rad/s")
    print(r.tidy[["theta_deg", "rocker_deg", "rocker_omega_rad_s", "transmission_deg"]].head(4).to_string(index=False))
    fig = r.figure("linkage")             # a matplotlib Figure; shows inline in Jupyter
    fig.axes[0].set_title("crank 5: linkage positions (from Python)")
    path = save_figure(fig, Path(outdir) / "fourbar_linkage.png")
    print(f"wrote {path}")
    return r


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("example_outputs"))
