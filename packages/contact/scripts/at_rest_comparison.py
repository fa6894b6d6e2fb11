# SPDX-License-Identifier: Apache-2.0
"""Compare at-rest treatments: standing G1 and box rebound (dev script; needs mujoco, mjlab's G1 and gmloco-eval).

Usage: ``uv run python packages/contact/scripts/at_rest_comparison.py [--only TEXT]``. Prints one row per option; the numbers are
quoted in packages/contact/README.md ("At rest").

* Standing G1: ``simulate_standing`` of packages/train/tests/test_standing_on_sand.py (sole collider 5 x 5, lowered
  over 1 s, settled 1 s, measured 1 s): std of the total vertical foot force / weight, sinkage / static.
* Box rebound: the box study's 35 kg 0.3 x 0.3 x 0.2 m box (six faces, 6 x 6 cells per face) released 0.1 m above
  the surface at 1 m/s along x (``gmloco.eval.box.rom``, MuJoCo C free body, 200 Hz), 3 s. Rise = highest CoM after
  the first deepest point minus the CoM settled over the last 0.5 s; e = sqrt(2 g max(rise, 0)) / v_impact.
"""

from __future__ import annotations

import argparse
import importlib.util
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import warp as wp

from gmloco.contact import MATERIAL_PRESETS, ContactRFT3DCfg, g1_foot_box_cfg

ROOT = Path(__file__).resolve().parents[3]
STANDING_MEDIA = ("dry_sand", "basalt", "poppy_seed")
BOX_MEDIA = ("dry_sand", "poppy_seed", "basalt")


def _load_harness():  # noqa: ANN202
    """Import the standing-G1 harness from the train test file by path."""
    path = ROOT / "packages" / "train" / "tests" / "test_standing_on_sand.py"
    spec = importlib.util.spec_from_file_location("standing_harness", path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


OPTIONS: dict[str, dict] = {  # rows before the static friction measured with the viscous crater friction
    "none (published 3D-RFT)": {"at_rest": "none"},
    "ema (Choi S16, c_r 0.5)": {"at_rest": "ema"},
    "unloading r=1 damping 1 ms (first default)": {"unloading_speed": 0.0, "static_friction": False},
    "unloading r=5": {
        "unloading_ratio": 5.0,
        "unloading_damping": 0.0,
        "unloading_speed": 0.0,
        "static_friction": False,
    },
    "unloading r=20": {
        "unloading_ratio": 20.0,
        "unloading_damping": 0.0,
        "unloading_speed": 0.0,
        "static_friction": False,
    },
    "unloading r=5 damping 5 ms": {
        "unloading_ratio": 5.0,
        "unloading_damping": 0.005,
        "unloading_speed": 0.0,
        "static_friction": False,
    },
    "unloading r=1 + impact damping u0 0.3": {"unloading_speed": 0.3, "static_friction": False},
    "unloading r=1 + impact damping u0 0.2": {"unloading_speed": 0.2, "static_friction": False},
    "r=1 + impact damping u0 0.15, viscous crater friction (previous default)": {"static_friction": False},
    "r=1 + impact damping u0 0.15 + static friction s0 2 mm (default)": {},
}


def box_rebound(options: dict, media: tuple[str, ...] = BOX_MEDIA, duration: float = 3.0) -> dict[str, tuple]:
    """Return {medium: (rise [m], e, settled sinkage [m], max sinkage [m])} of the box drop."""
    import gmloco.eval.box.rom as rb
    from gmloco.eval.box import BoxCfg

    box = BoxCfg(duration=duration)
    cfg = rb.RomBoxCfg(box=box, at_rest=options.get("at_rest", "unloading"), log_dt=0.005)
    extra = {k: v for k, v in options.items() if k != "at_rest"}
    orig = rb.make_box_contact_cfg
    rb.make_box_contact_cfg = lambda model, c: replace(orig(model, c), **extra)
    try:
        mats = [MATERIAL_PRESETS[m] for m in media]
        res = rb.simulate_rom_box(
            "rft3d", cfg, *(np.array([getattr(m, k) for m in mats]) for k in ("rho_c", "mu_int", "mu_surf"))
        )
    finally:
        rb.make_box_contact_cfg = orig
    out = {}
    z0 = 0.5 * box.size[2]
    v_in = np.sqrt(2.0 * 9.81 * box.drop_height)
    for i, m in enumerate(media):
        z = res.body_pos[i, :, 2]
        j = int(np.argmax(z < z0))
        while j + 1 < len(z) and z[j + 1] <= z[j]:
            j += 1
        settled = z[-100:].mean()
        rise = z[j:].max() - settled
        out[m] = (rise, np.sqrt(2.0 * 9.81 * max(rise, 0.0)) / v_in, z0 - settled, z0 - z[j])
    return out


def main() -> None:
    """Run every option (or those whose name contains ``--only``) and print standing and box statistics."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--only", default="", help="run only the options whose name contains this text")
    args = parser.parse_args()
    wp.config.quiet = True
    harness = _load_harness()
    for name, options in OPTIONS.items():
        if args.only not in name:
            continue
        t0 = time.perf_counter()
        cols = []
        for material in STANDING_MEDIA:
            r = harness.simulate_standing(ContactRFT3DCfg(collider=g1_foot_box_cfg("sole", 5), **options), material)
            cols.append(f"{material} {100 * r.fz_std / r.weight:5.1f} % {r.sinkage / r.sinkage_static:4.2f}x")
        for material, (rise, e, sink, sink_max) in box_rebound(options).items():
            cols.append(
                f"box {material} rise {1e3 * rise:6.1f} mm e {e:4.2f} ({1e3 * sink:.1f}/{1e3 * sink_max:.1f} mm)"
            )
        print(f"{name:48s} " + " | ".join(cols) + f"  [{time.perf_counter() - t0:4.1f} s]", flush=True)


if __name__ == "__main__":
    main()
