# SPDX-License-Identifier: Apache-2.0
"""Creep of a standing G1 (sole-only collider) with and without static friction in the crater (dev script).

Usage: ``uv run python packages/contact/scripts/creep_comparison.py [--duration 8]``. Runs ``simulate_creep`` of
tests/contact/test_standing_creep.py (plain MuJoCo C G1 on a vertical slide, PD at HOME, lowered over 1 s,
200 Hz) on the presets and on corners of the paper's DR box, and prints one row per (material, law): the largest
horizontal foot speed per 1 s window [mm/s], the force std / weight over the 3rd second and the late sinkage.
The numbers are quoted in packages/contact/README.md ("Static friction in the crater").
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
import warp as wp

from gmloco.contact import MATERIAL_PRESETS, MaterialCfg

ROOT = Path(__file__).resolve().parents[3]
DR_CORNERS = {
    "stiff, mu_s 1.0 (3000, 0.9, 1.0)": MaterialCfg(3000.0, 1.0, 0.9, 1.0),
    "dry sand, mu_s 1.0 (1500, 0.6, 1.0)": MaterialCfg(1500.0, 1.0, 0.6, 1.0),
    "basalt, mu_s 0.1 (2700, 0.839, 0.1)": MaterialCfg(2700.0, 1.0, 0.839, 0.1),
    "soft (900, 0.4, 0.6)": MaterialCfg(900.0, 1.0, 0.4, 0.6),
}


def _creep_module():  # noqa: ANN202
    """Import tests/contact/test_standing_creep.py (the repository root goes on sys.path for ``tests.contact``)."""
    sys.path.insert(0, str(ROOT))
    import tests.contact.test_standing_creep as creep

    return creep


def main() -> None:
    """Print the comparison rows."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--duration", type=float, default=8.0, help="simulated seconds per run")
    args = parser.parse_args()
    wp.config.quiet = True
    creep = _creep_module()
    media = {name: MATERIAL_PRESETS[name] for name in ("dry_sand", "basalt", "poppy_seed")} | DR_CORNERS
    for label, material in media.items():
        for static in (False, True):
            t0 = time.perf_counter()
            r = creep.simulate_creep(creep.sole_cfg(static), material, duration=args.duration)
            speeds = " ".join(f"{1e3 * v:6.1f}" for v in r.foot_speed)
            collapsed = "collapsed" if not np.all(r.fz_std < 1.0) else ""
            print(
                f"{label:38s} {'static' if static else 'viscous':7s} foot speed per s [mm/s]: {speeds} | "
                f"std/W 3rd s {100 * r.fz_std[2]:5.1f} % | late sink {1e3 * r.late_sinkage:6.2f} mm "
                f"{collapsed} [{time.perf_counter() - t0:4.1f} s]",
                flush=True,
            )


if __name__ == "__main__":
    main()
