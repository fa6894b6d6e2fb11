# SPDX-License-Identifier: Apache-2.0
"""Does the box study's model ranking depend on the MPM numerics? Score the models against every conv level.

Usage: ``uv run python benchmarks/box_intrusion/gpu/scores_vs_numerics.py`` (CPU, ~1 min). Copies each conv
directory (5 forward trials, seed 0; MPM from the GPU) to a temporary directory, adds the reduced-order models
there with ``workflows/box_study.py --max-minutes 0`` (no MPM is run, the committed GPU outputs are left
untouched), and writes the forward scores per level to ``gpu/scores_vs_numerics.json``.

Two material mappings: ``mapping_v1`` levels (``conv_v*``, ``mapping_v1/conv_v0.03_i4000``) ran with
``mpm:friction = mu_int`` (before commit 89a2ef5); ``dp`` levels (``conv_dp_v*``) with the Drucker-Prager
friction of commit 89a2ef5. The dp levels also score ``rft3d_fitted``, the 3D-RFT set fitted from the dp plate
sweep (``results/rft_fit/rft_fit_v0.02_i1000``).
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

RESULTS_HOME = Path(__file__).resolve().parents[3] / "results/box_intrusion/gpu"
"""The results folder this script reads and writes (its data lives under ``results/``, the code here)."""

GPU = RESULTS_HOME
REPO = GPU.parents[2]
FITTED = "results/rft_fit/rft_fit_v0.02_i1000/rft3d_fitted.json"
"""3D-RFT set fitted from the dp-mapping plate sweep (scored on the dp levels only)."""
LEVELS = [
    ("mapping_v1", "conv_v0.05_i250", 0.05, 250),
    ("mapping_v1", "conv_v0.03_i50", 0.03, 50),
    ("mapping_v1", "conv_v0.03_i250", 0.03, 250),
    ("mapping_v1", "conv_v0.03_i1000", 0.03, 1000),
    ("mapping_v1", "mapping_v1/conv_v0.03_i4000", 0.03, 4000),
    ("mapping_v1", "conv_v0.02_i250", 0.02, 250),
    ("dp", "conv_dp_v0.05_i1000", 0.05, 1000),
    ("dp", "conv_dp_v0.03_i1000", 0.03, 1000),
    ("dp", "conv_dp_v0.03_i4000", 0.03, 4000),
    ("dp", "conv_dp_v0.02_i1000", 0.02, 1000),
]
"""(mapping, directory under gpu/, voxel size [m], rheology iterations) of the conv levels."""
MODELS = ["mpm", "rigid", "heuristic_rft", "cone_single", "cone_multi", "rft3d"]


def score_level(mapping: str, name: str, voxel: float, iterations: int, tmp: Path) -> dict:
    """Add the reduced-order models to a copy of one conv level and return its forward summary."""
    work = tmp / name.replace("/", "_")
    shutil.copytree(GPU / name, work)
    fitted = ["--fitted-coeffs", FITTED] if mapping == "dp" else []
    cmd = [sys.executable, "workflows/box_study.py", "--models", *MODELS, "--variants", "forward",
           "--num-trials", "5", "--voxel-size", str(voxel), "--max-iterations", str(iterations),
           "--duration", "0.6", "--max-minutes", "0", "--no-figure", "--out-dir", str(work), *fitted]  # fmt: skip
    subprocess.run(cmd, cwd=REPO, check=True, capture_output=True)
    fwd = json.loads((work / "summary.json").read_text())["variants"]["forward"]
    keys = ("travel_rel_err_median", "sinkage_rel_err_median", "grf_profile_err_median")
    return {
        "mapping": mapping, "dir": f"results/box_intrusion/gpu/{name}", "voxel_size": voxel,
        "max_iterations": iterations, "mpm_trials": fwd["mpm_trials_done"],
        "mpm_travel_median": fwd["mpm_travel_median"], "mpm_sinkage_median": fwd["mpm_sinkage_median"],
        "best": fwd["best"], "scores": {m: {k: s[k] for k in keys} for m, s in fwd["scores"].items()},
    }  # fmt: skip


def main() -> None:
    """Score every level and write ``scores_vs_numerics.json``."""
    with tempfile.TemporaryDirectory() as t:
        levels = [score_level(*lv, Path(t)) for lv in LEVELS]
    out = {
        "note": "forward variant, seed 0; medians over the level's MPM trials (v1 2 cm / 250: trial 0 only; "
        "dp 2 cm / 1000: trials 0, 1, 3, 4)",
        "levels": levels,
    }
    (GPU / "scores_vs_numerics.json").write_text(json.dumps(out, indent=1))
    for lv in levels:
        print(lv["mapping"], lv["voxel_size"], lv["max_iterations"], lv["mpm_trials"], lv["best"])


if __name__ == "__main__":
    main()
