# SPDX-License-Identifier: Apache-2.0
"""How the coupled sand force on a walking G1's soles changes from one MPM frame to the next, per coupling scheme.

The rigid robot receives the sand wrench of the previous MPM frame (the coupling is lagged). Each scheme
(``MpmSolverCfg.velocity_handover``: ``predict``, ``actual``, ``rewind``; and ``predict`` with the robots
receiving the mean of the last two frames' wrench, ``G1MpmSceneCfg.wrench_frames=2``) walks the same G1 (``artifacts/ppo_rft3d``,
1.0 m/s forward) for 240 frames of 5 ms (1.2 s; 4 frames per 50 Hz policy step, the tables' frame) on dry sand at
4 cm voxels, CPU; every frame's vertical sand force on both soles is recorded after the frame. Per scheme over the
last 200 frames: the mean force over m g, its mean by frame phase within the policy step (the phase the 50 Hz log
read before the scene logged the step mean is phase 3), the median change from one frame to the next and across two
frames, the pelvis height and the sinkage (with the two-frame mean, also the raw frames' alternation). Writes ``results/mpm_eval/coupling_chatter/chatter.json``.

    python benchmarks/mpm_eval/coupling_chatter.py            # ~30 s a scheme on 2 CPU cores
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np

from gmloco.eval.g1.policy import MjlabOnnxPolicy
from gmloco.eval.g1.scene import G1MpmScene
from gmloco.eval.g1.scene_cfg import G1MpmSceneCfg
from gmloco.eval.mpm.box_scene import MpmSolverCfg
from gmloco.eval.mpm.window import SandWindowCfg

ROOT = Path(__file__).resolve().parents[2]
POLICY = ROOT / "artifacts" / "ppo_rft3d" / "policy.onnx"
OUT = ROOT / "results" / "mpm_eval" / "coupling_chatter" / "chatter.json"
VARIANTS: dict[str, tuple[str, int]] = {
    "predict": ("predict", 1),
    "actual": ("actual", 1),
    "rewind": ("rewind", 1),
    "predict_mean2": ("predict", 2),
}
"""Label: (velocity hand-over scheme, wrench frames)."""
FRAMES, SKIP = 240, 40


def run(scheme: str, wrench_frames: int) -> dict[str, float | list[float] | None]:
    """Walk the G1 under one coupling scheme and reduce its per-frame sole forces (those the robot receives)."""
    cfg = G1MpmSceneCfg(window=SandWindowCfg(moving=True, length=1.0, width=0.6), wrench_frames=wrench_frames,
                        solver=MpmSolverCfg(voxel_size=0.04, frame_dt=0.005, rigid_substeps=1,
                                            velocity_handover=scheme))  # fmt: skip
    scene = G1MpmScene(cfg, MjlabOnnxPolicy(POLICY))
    scene.commands[:] = [1.0, 0.0, 0.0]
    per_frame: list[float] = []
    raw: list[float] = []
    simulate = scene.simulate

    def recorded() -> None:
        simulate()
        per_frame.append(float(scene.sand_wrench.numpy()[scene.foot_bodies][0, :, 2].sum()))
        raw.append(float(scene.sand_wrench_raw.numpy()[scene.foot_bodies][0, :, 2].sum()))

    scene.simulate = recorded  # type: ignore[method-assign]
    t0 = time.perf_counter()
    scene.run(FRAMES)
    f, mg = np.asarray(per_frame[SKIP:]), scene.robot_mass * 9.81
    z, sink = np.asarray(scene.base_q)[:, 0, 2], np.asarray(scene.sinkage)[:, 0]
    r = np.asarray(raw[SKIP:])
    return {
        "wall_s": round(time.perf_counter() - t0, 1),
        "raw_median_change_1_frame_N": float(np.median(np.abs(np.diff(r)))) if wrench_frames == 2 else None,
        "support_over_mg": float(f.mean() / mg),
        "support_over_mg_by_phase": [float(f[p::4].mean() / mg) for p in range(4)],
        "median_change_1_frame_N": float(np.median(np.abs(np.diff(f)))),
        "median_change_2_frames_N": float(np.median(np.abs(f[2:] - f[:-2]))),
        "median_force_N": float(np.median(f)),
        "pelvis_z_end_m": float(z[-1]),
        "sinkage_mean_cm": float(100.0 * sink[SKIP // 4 :].mean()),
    }


def main() -> None:
    """Run every scheme and write the JSON."""
    out = {label: run(*variant) for label, variant in VARIANTS.items()}
    OUT.parent.mkdir(parents=True, exist_ok=True)
    OUT.write_text(json.dumps({"frames": FRAMES, "skipped": SKIP, "schemes": out}, indent=1) + "\n")
    for s, r in out.items():
        print(s, r)


if __name__ == "__main__":
    main()
