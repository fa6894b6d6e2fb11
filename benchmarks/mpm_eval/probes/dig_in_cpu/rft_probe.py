# SPDX-License-Identifier: Apache-2.0
"""CPU probe: one exported mjlab policy walking in the TRAINING simulator (MuJoCo + 3D-RFT), logged per policy step.

The counterpart of ``benchmarks/mpm_eval/policy_probe.py`` in the simulator the policies were trained in: the play env
of ``gmloco.train.evaluation`` (``_build_env``, the baseline's observation layout from the ONNX metadata), one env,
material pinned to a preset, fixed forward command. It logs, at every 50 Hz policy step, the same quantities as the
MPM probe, computed on the same sole box (``gmloco.eval.g1.soles.SoleCfg`` in the ankle-roll-link frame): the
depth of each sole's lowest corner (``low``) and mid-plane (``mid``, mean of the 8 corners) below the free surface
(z = 0), the sole pitch (positive = heel down), the vertical granular force on each foot, pelvis height / x / v_x /
pitch. Appends one JSON record per run to ``--log``.

    uv run python benchmarks/mpm_eval/probes/dig_in_cpu/rft_probe.py --policy artifacts/ppo_rft3d/policy.onnx --label rft_v1
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path
from typing import Any

import numpy as np
import torch

from gmloco.eval.g1.soles import SoleCfg
from gmloco.train import evaluation as ev
from gmloco.train.sand import FOOT_BODIES


def sole_corners(pos: np.ndarray, mat: np.ndarray, sole: SoleCfg) -> np.ndarray:
    """World corners of both sole boxes [m], [2, 8, 3], from the ankle-roll-link poses ``pos`` [2, 3], ``mat`` [2, 3, 3]."""
    c, h = np.array(sole.center), np.array(sole.half_extents)
    local = c + h * np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    return np.einsum("fij,kj->fki", mat, local) + pos[:, None, :]


def probe_row(env: Any, foot_ids: list[int], sole: SoleCfg, t: float, i: int = 0) -> dict[str, Any]:
    """The MPM probe's quantities of env ``i`` now: pelvis, both sole boxes' depths and pitch, sand force per foot."""
    robot, d = env.scene["robot"], env.sim.data
    pos = d.xpos[i, foot_ids].cpu().numpy()
    mat = d.xmat[i, foot_ids].cpu().numpy().reshape(2, 3, 3)
    c = sole_corners(pos, mat, sole)
    low, mid = -c[..., 2].min(axis=1), -c[..., 2].mean(axis=1)
    pitch = np.degrees(np.arctan2(c[:, 4:, 2].mean(1) - c[:, :4, 2].mean(1), c[:, 4:, 0].mean(1) - c[:, :4, 0].mean(1)))
    w, x, y, z = robot.data.root_link_quat_w[i].cpu().numpy()
    bpitch = float(np.degrees(np.arcsin(np.clip(2 * (w * y - z * x), -1, 1))))
    coupling = env.sand.coupling
    ff = coupling.foot_force_w[i].cpu().numpy() if coupling is not None else np.zeros((2, 3))
    rp = robot.data.root_link_pos_w[i].cpu().numpy()
    rv = robot.data.root_link_lin_vel_w[i].cpu().numpy()
    return dict(
        t=round(t, 3), pz=round(float(rp[2]), 4), px=round(float(rp[0]), 3), vx=round(float(rv[0]), 3),
        vz=round(float(rv[2]), 3), low=[round(float(v), 4) for v in low], mid=[round(float(v), 4) for v in mid],
        pitch=[round(float(v), 1) for v in pitch], fz=[round(float(v), 1) for v in ff[:, 2]],
        fx=[round(float(v), 1) for v in ff[:, 0]], pitch_deg=round(bpitch, 1),
    )  # fmt: skip


def main() -> None:
    """Run one rollout and append its record to the log."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--policy", type=Path, required=True)
    p.add_argument("--label", required=True)
    p.add_argument("--material", default="dry_sand")
    p.add_argument("--vx", type=float, default=1.0, help="forward velocity command [m/s]")
    p.add_argument("--duration", type=float, default=3.0, help="simulated time [s]")
    p.add_argument("--contact-model", default="rft3d")
    p.add_argument("--log", type=Path, default=Path("results/mpm_eval/probes/dig_in_cpu/runs.jsonl"))
    args = p.parse_args()

    import onnxruntime as ort

    t0 = time.time()
    cfg = ev.EvalCfg(policy_path=str(args.policy), contact_model=args.contact_model, materials=(args.material,),
                     speeds=(args.vx,), repeats=1, duration_s=args.duration, device="cpu")  # fmt: skip
    meta = ev._read_metadata(str(args.policy))
    env = ev._build_env(cfg, meta, 1)
    sole = SoleCfg()
    rows: list[dict[str, Any]] = []
    try:
        commands = ev._pin_cells(env, ev._cells(cfg))
        term = env.command_manager.get_term("twist")
        env.reset()
        term.vel_command_b[:] = commands
        obs = env.observation_manager.compute(update_history=True, env_ids=torch.arange(1, device=env.device))
        session = ort.InferenceSession(str(args.policy), providers=["CPUExecutionProvider"])
        name = session.get_inputs()[0].name
        robot = env.scene["robot"]
        local_ids = robot.find_bodies(FOOT_BODIES, preserve_order=True)[0]
        foot_ids = [int(robot.indexing.body_ids[i]) for i in local_ids]
        mass = float(env.sim.mj_model.body_subtreemass[1])
        steps = round(args.duration / env.step_dt)
        fell_at = None
        for k in range(steps + 1):
            rows.append(probe_row(env, foot_ids, sole, k * env.step_dt))
            if k == steps:
                break
            actor_obs = obs["actor"].cpu().numpy().astype(np.float32)
            action = session.run(None, {name: actor_obs})[0]
            obs, _, terminated, _, _ = env.step(torch.as_tensor(action, device=env.device))
            if bool(terminated[0]) and fell_at is None:
                fell_at = round((k + 1) * env.step_dt, 3)
                break
    finally:
        env.close()
    lows = np.array([max(r["low"]) for r in rows])
    fz = np.array([sum(r["fz"]) for r in rows])
    half = len(rows) // 2
    rec = dict(
        label=args.label, sim="mujoco+" + args.contact_model, policy=str(args.policy), material=args.material,
        vx_cmd=args.vx, duration=args.duration, step_dt=env.step_dt, mass=round(mass, 2), first_fall_s=fell_at,
        lowest_max=round(float(lows.max()), 4), lowest_mean=round(float(lows.mean()), 4),
        support2=round(float(fz[half:].mean() / (mass * 9.81)), 3), mean_vx=round(float(np.mean([r["vx"] for r in rows[half:]])), 3),
        rows=rows, s=round(time.time() - t0, 1),
    )  # fmt: skip
    args.log.parent.mkdir(parents=True, exist_ok=True)
    with args.log.open("a") as f:
        f.write(json.dumps(rec) + "\n")
    for r in rows[:: max(1, len(rows) // 30)]:
        print(args.label, r, flush=True)
    print(args.label, {k: v for k, v in rec.items() if k != "rows"}, flush=True)


if __name__ == "__main__":
    main()
