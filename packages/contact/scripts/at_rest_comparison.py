# SPDX-License-Identifier: Apache-2.0
"""Compare at-rest treatments on the standing-G1 check (dev script; needs mujoco and mjlab's G1 MJCF).

Usage: ``uv run python packages/contact/scripts/at_rest_comparison.py``. Prints one row per option; the
numbers are quoted in packages/contact/README.md.
"""

from __future__ import annotations

import importlib.util
import sys
import time
from pathlib import Path

import warp as wp

from gmloco.contact import ContactRFT3DCfg

ROOT = Path(__file__).resolve().parents[3]


def _load_harness():  # noqa: ANN202
    """Import the standing-G1 harness from the train test file by path."""
    path = ROOT / "packages" / "train" / "tests" / "test_standing_on_sand.py"
    spec = importlib.util.spec_from_file_location("standing_harness", path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


OPTIONS: dict[str, ContactRFT3DCfg] = {
    "none (published 3D-RFT)": ContactRFT3DCfg(at_rest="none"),
    "ema (Choi S16, c_r 0.5)": ContactRFT3DCfg(at_rest="ema"),
    "unloading r=1 damping 1 ms (default)": ContactRFT3DCfg(at_rest="unloading"),
    "unloading r=1 no damping": ContactRFT3DCfg(at_rest="unloading", unloading_damping=0.0),
    "unloading r=2": ContactRFT3DCfg(at_rest="unloading", unloading_ratio=2.0, unloading_damping=0.0),
    "unloading r=5": ContactRFT3DCfg(at_rest="unloading", unloading_ratio=5.0, unloading_damping=0.0),
    "unloading r=20": ContactRFT3DCfg(at_rest="unloading", unloading_ratio=20.0, unloading_damping=0.0),
    "unloading r=5 damping 5 ms": ContactRFT3DCfg(at_rest="unloading", unloading_ratio=5.0, unloading_damping=0.005),
}


def main() -> None:
    """Run every option on each material and print force/sinkage statistics."""
    wp.config.quiet = True
    harness = _load_harness()
    materials = sys.argv[1:] or ["dry_sand"]
    for material in materials:
        for name, cfg in OPTIONS.items():
            t0 = time.perf_counter()
            r = harness.simulate_standing(cfg, material=material)
            print(
                f"{material:10s} {name:38s} W {r.weight:6.1f} N  Fz {r.fz_mean:6.1f} +- {r.fz_std:6.1f} N "
                f"({100 * r.fz_std / r.weight:5.1f} %)  Fxy std {r.fxy_std:5.1f} N  sinkage {1e3 * r.sinkage:6.2f} mm "
                f"(static {1e3 * r.sinkage_static:5.2f} mm, {r.sinkage / r.sinkage_static:4.2f}x)  "
                f"[{time.perf_counter() - t0:4.1f} s]"
            )


if __name__ == "__main__":
    main()
