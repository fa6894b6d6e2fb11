# SPDX-License-Identifier: Apache-2.0
"""Does the box study's model ranking depend on the MPM numerics? Score the five models against every conv level.

Usage: ``uv run python results/box_intrusion/gpu/scores_vs_numerics.py`` (CPU, ~30 s). Copies each
``gpu/conv_v*_i*`` directory (5 forward trials, seed 0; MPM from the GPU) to a temporary directory, adds the
reduced-order models there with ``workflows/box_study.py --max-minutes 0`` (no MPM is run, the committed GPU
outputs are left untouched), and writes the forward scores per level to ``gpu/scores_vs_numerics.json``.
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

GPU = Path(__file__).resolve().parent
REPO = GPU.parents[2]
LEVELS = [(0.05, 250), (0.03, 50), (0.03, 250), (0.03, 1000), (0.02, 250)]
"""(voxel size [m], rheology iterations) of the conv directories, coarse to fine."""
MODELS = ["mpm", "rigid", "heuristic_rft", "cone_single", "cone_multi", "rft3d"]


def score_level(voxel: float, iterations: int, tmp: Path) -> dict:
    """Add the reduced-order models to a copy of one conv level and return its forward summary."""
    name = f"conv_v{voxel}_i{iterations}"
    shutil.copytree(GPU / name, tmp / name)
    cmd = [sys.executable, "workflows/box_study.py", "--models", *MODELS, "--variants", "forward",
           "--num-trials", "5", "--voxel-size", str(voxel), "--max-iterations", str(iterations),
           "--duration", "0.6", "--max-minutes", "0", "--no-figure", "--out-dir", str(tmp / name)]  # fmt: skip
    subprocess.run(cmd, cwd=REPO, check=True, capture_output=True)
    fwd = json.loads((tmp / name / "summary.json").read_text())["variants"]["forward"]
    keys = ("travel_rel_err_median", "sinkage_rel_err_median", "grf_profile_err_median")
    return {
        "dir": f"results/box_intrusion/gpu/{name}", "voxel_size": voxel, "max_iterations": iterations,
        "mpm_trials": fwd["mpm_trials_done"], "mpm_travel_median": fwd["mpm_travel_median"],
        "mpm_sinkage_median": fwd["mpm_sinkage_median"], "best": fwd["best"],
        "scores": {m: {k: s[k] for k in keys} for m, s in fwd["scores"].items()},
    }  # fmt: skip


def main() -> None:
    """Score every level and write ``scores_vs_numerics.json``."""
    with tempfile.TemporaryDirectory() as t:
        levels = [score_level(v, i, Path(t)) for v, i in LEVELS]
    out = {
        "note": "forward variant, seed 0; medians over the level's MPM trials (2 cm: trial 0 only)",
        "levels": levels,
    }
    (GPU / "scores_vs_numerics.json").write_text(json.dumps(out, indent=1))
    for lv in levels:
        print(lv["voxel_size"], lv["max_iterations"], lv["mpm_trials"], lv["best"])


if __name__ == "__main__":
    main()
