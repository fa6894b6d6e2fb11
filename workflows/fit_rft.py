# SPDX-License-Identifier: Apache-2.0
"""3D-RFT coefficients from MPM plate intrusions (issue 5): thin CLI around ``gmloco.eval.rft_fit.run``.

Resumable and time-boxed; runs with plain python::

    PYTHONPATH=packages/contact/src:packages/eval/src python workflows/fit_rft.py \
        --voxel-size 0.02 --max-minutes 9 --out-dir results/rft_fit
"""

from __future__ import annotations

import argparse
import json
from dataclasses import replace

__all__ = ["main"]


def main() -> None:
    """Parse the command line, run sweep + fit, print the fit summary."""
    from gmloco.eval.mpm.box_scene import MpmSolverCfg
    from gmloco.eval.rft_fit import RftFitCfg, rft_fit_smoke_cfg, run

    p = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    p.add_argument("--out-dir", default="results/rft_fit")
    p.add_argument("--material", default="dry_sand", help="gmloco.contact.MATERIAL_PRESETS name")
    p.add_argument("--voxel-size", type=float, default=0.02)
    p.add_argument("--plate-size", type=float, default=0.1)
    p.add_argument("--ridge", type=float, default=1e-3)
    p.add_argument("--max-minutes", type=float, default=60.0)
    p.add_argument("--device", default=None)
    p.add_argument("--smoke", action="store_true", help="CPU smoke: 2 plate runs, tiny bed")
    a = p.parse_args()
    if a.smoke:
        cfg = rft_fit_smoke_cfg(a.out_dir)
    else:
        base = RftFitCfg()
        plate = replace(base.plate, plate_size=a.plate_size, solver=MpmSolverCfg(voxel_size=a.voxel_size),
                        device=a.device)  # fmt: skip
        cfg = replace(base, out_dir=a.out_dir, material=a.material, plate=plate, ridge=a.ridge,
                      max_minutes=a.max_minutes)  # fmt: skip
    print(json.dumps(run(cfg), indent=1))


if __name__ == "__main__":
    main()
