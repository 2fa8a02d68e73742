"""Hooke-joint shaft chain: optimise the yoke phases and read the optimum from Python.

    python examples/ujoint_optimum.py [OUTDIR]

Three joints at fixed operating angles 15, 20 and 9 deg, input 25 rpm; the phases of the two
intermediate shafts are optimised (the SSO paper's option 1) to make the output speed as
uniform as possible.  Prints the optimum phases [deg] and output speed band [rpm], and writes
the .out, .result.dat and the summary as JSON to OUTDIR.
"""
from __future__ import annotations

import sys
from pathlib import Path

import driver


def main(outdir: Path) -> driver.Result:
    r = driver.ujoint.run(option=1, beta=[15.0, 20.0, 9.0], phi=[30.0, 40.0], rpm=25.0, n_starts=8, seed=1)
    if not r.ok:
        raise SystemExit(f"optimiser failed: {r.failure}")
    s = r.summary
    print(f"optimum phases {s['phi_1_deg']:.4f}, {s['phi_2_deg']:.4f} deg; output speed "
          f"{s['omega_out_min_rpm']:.4f} .. {s['omega_out_max_rpm']:.4f} rpm "
          f"(trial objective {s['objective_trial']:.3e} -> {s['objective']:.3e})")
    for path in driver.write(r, outdir, json=True, name="ujoint_option1_api"):
        print(f"wrote {path}")
    return r


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("example_outputs"))
