# SPDX-License-Identifier: Apache-2.0
"""3D-RFT coefficients from MPM plate intrusions (issue 5): thin CLI around ``gmloco.eval.rft_fit.run``.

Resumable and time-boxed (call it again with the same ``--out-dir`` to continue); runs with plain python::

    PYTHONPATH=packages/contact/src:packages/eval/src python workflows/fit_rft.py \
        --voxel-size 0.02 --max-minutes 8 --out-dir results/rft_fit/dry_sand_v2cm

Outputs in ``--out-dir``: plate_runs.jsonl (one line per plate run, with its force/depth series), plate_G.csv,
rft3d_fitted.json (load it with ``gmloco.contact.load_rft3d_coeffs`` or pass it as ``coeffs=`` to
``ContactRFT3DCfg``), fit_summary.json and fig_rft_fit.png.
"""

from __future__ import annotations

import argparse
import json
from dataclasses import replace

__all__ = ["main"]


def main() -> None:
    """Parse the command line, run sweep + fit, print the fit summary."""
    from gmloco.eval.mpm.bed import SandBedCfg
    from gmloco.eval.mpm.box_scene import MpmSolverCfg
    from gmloco.eval.rft_fit import RftFitCfg, rft_fit_smoke_cfg, run

    p = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    p.add_argument("--out-dir", default="results/rft_fit")
    p.add_argument("--material", default="dry_sand", help="gmloco.contact.MATERIAL_PRESETS name")
    p.add_argument("--voxel-size", type=float, default=0.02)
    p.add_argument("--max-iterations", type=int, default=250, help="rheology iterations (>= 25)")
    p.add_argument("--plate-size", type=float, default=0.1)
    p.add_argument("--speed", type=float, default=0.5, help="plate speed [m/s]")
    p.add_argument("--bed", type=float, nargs=3, default=[0.7, 0.7, 0.35], help="bed x, y, depth [m]")
    p.add_argument("--depth-range", type=float, nargs=2, default=[0.08, 0.2], help="sampled centroid depths [m]")
    p.add_argument("--lead-in", type=float, default=0.1, help="travel before sampling [m]")
    p.add_argument("--gammas", type=float, nargs="+", default=None, help="intrusion angles [deg]")
    p.add_argument("--betas", type=float, nargs="+", default=None, help="plate tilts [deg]")
    p.add_argument("--psis", type=float, nargs="+", default=None, help="tilt headings [deg]")
    p.add_argument("--ridge", type=float, default=0.03)
    p.add_argument("--batch", type=int, default=1, help="plate runs per MPM solve (GPU: ~9)")
    p.add_argument("--max-minutes", type=float, default=60.0)
    p.add_argument("--device", default=None)
    p.add_argument("--no-figure", action="store_true", help="skip fig_rft_fit.png (no matplotlib on the GPU image)")
    p.add_argument("--smoke", action="store_true", help="CPU smoke: 2 plate runs, tiny bed")
    a = p.parse_args()
    if a.smoke:
        cfg = replace(rft_fit_smoke_cfg(a.out_dir), max_minutes=a.max_minutes)
    else:
        base = RftFitCfg()
        bed = SandBedCfg(size_x=a.bed[0], size_y=a.bed[1], depth=a.bed[2], center_x=0.0)
        solver = MpmSolverCfg(voxel_size=a.voxel_size, max_iterations=a.max_iterations)
        plate = replace(base.plate, plate_size=a.plate_size, speed=a.speed, bed=bed, solver=solver, device=a.device,
                        depth_range=tuple(a.depth_range), travel_before_sampling=a.lead_in)  # fmt: skip
        cfg = replace(base, out_dir=a.out_dir, material=a.material, plate=plate, ridge=a.ridge,
                      max_minutes=a.max_minutes, batch=a.batch, make_figure=not a.no_figure)  # fmt: skip
        for name, value in (("gamma_deg", a.gammas), ("beta_deg", a.betas), ("psi_deg", a.psis)):
            if value:
                cfg = replace(cfg, **{name: tuple(value)})
    print(json.dumps(run(cfg), indent=1))


if __name__ == "__main__":
    main()
