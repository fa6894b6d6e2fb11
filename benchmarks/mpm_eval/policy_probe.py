# SPDX-License-Identifier: Apache-2.0
"""CPU probe: one exported policy driving the G1 on MPM dry sand (or a rigid floor), logged per frame.

The scratch probe behind ``G1_SINKAGE.md``'s "policy on sand, 1 s" rows, made reusable for any exported policy
(mjlab actor or gmloco student, ``gmloco.eval.g1.policy.load_policy``). Same scene: ``G1MpmScene`` on
``terrain_cfg("dry_sand", depth)``, 5 cm voxels, 50 Gauss-Seidel iterations, sparse grid, 100 Hz frames, 200 Hz
physics; a static 0.6 x 0.5 m window (``--window small``) or the evaluation's moving 1.8 x 1.0 m window
(``--window eval``). The numerics are defaults that ``--frame-dt``, ``--substeps``, ``--effective-mass`` and
``--grid`` change. Rows also log the x sand force per foot and the sand height ahead of each sole (heave).
``--rigid``: no sand, the soles stand on the rigid floor (MuJoCo contact), as the probe's
rigid-floor control did. Appends one JSON record per run to ``--log``; prints the rows and a summary.

    uv run python benchmarks/mpm_eval/policy_probe.py --policy artifacts/ppo_rft3d/policy.onnx --label rft3d_v0
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path
from typing import Any

import numpy as np

from gmloco.eval.g1.policy import StudentOnnxPolicy, load_policy
from gmloco.eval.g1.scene import G1MpmScene
from gmloco.eval.g1.scene_cfg import G1MpmSceneCfg
from gmloco.eval.g1.soles import SoleCfg
from gmloco.eval.mpm.box_scene import MpmSolverCfg, frame_dt_problem
from gmloco.eval.mpm.window import SandWindowCfg
from gmloco.eval.mpm.window_terrain import terrain_cfg


def make(policy: Any, args: argparse.Namespace) -> G1MpmScene:
    """The probe's scene: dry sand, 5 cm voxels, static small window or the evaluation's moving one."""
    if args.window == "small":
        window = SandWindowCfg(moving=False, length=0.6, width=0.5, lead=0.0)
    else:
        window = SandWindowCfg(moving=True, length=1.8, width=1.0, lead=0.2)
    depth = 0.1 if args.rigid else args.depth
    cfg = G1MpmSceneCfg(
        terrain=terrain_cfg("dry_sand", depth=depth),
        window=window,
        solver=MpmSolverCfg(
            voxel_size=args.voxel,
            frame_dt=args.frame_dt,
            rigid_substeps=args.substeps,
            max_iterations=args.iterations,
            grid_type=args.grid,
            velocity_handover=args.handover,
        ),
        sole=SoleCfg(effective_mass=args.effective_mass),
        commands=((args.vx, 0.0, 0.0),),
        # rigid floor: the soles start 5 mm above the floor at z = -depth
        drop_height=-(depth - 0.005) if args.rigid else 0.005,
    )
    return G1MpmScene(cfg, policy)


def rigid_only(scene: G1MpmScene) -> None:
    """Replace the coupled frame by PD + rigid substeps only (no sand: the soles meet the floor)."""
    from gmloco.eval.mpm.kernels_coupling import eval_pd_joint_force

    def sim() -> None:
        for _ in range(scene.cfg.solver.rigid_substeps):
            eval_pd_joint_force(scene.pd["kp"], scene.pd["kd"], scene.pd["q_idx"], scene.pd["qd_idx"],
                                scene.coords_per_robot, scene.dofs_per_robot, scene.state_0.joint_q,
                                scene.state_0.joint_qd, scene.targets, scene.control.joint_f)  # fmt: skip
            scene.state_0.clear_forces()
            scene.rigid.step(scene.state_0, scene.state_1, scene.control, scene.contacts, scene.sim_dt)
            scene.state_0, scene.state_1 = scene.state_1, scene.state_0

    scene.simulate = sim


def roll_pitch(q_xyzw: np.ndarray) -> tuple[float, float]:
    """Roll and pitch [rad] of a pelvis quaternion (x, y, z, w)."""
    x, y, z, w = q_xyzw
    roll = np.arctan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    pitch = np.arcsin(np.clip(2 * (w * y - z * x), -1.0, 1.0))
    return float(roll), float(pitch)


def snap(scene: G1MpmScene, policy: Any) -> dict[str, Any]:
    """Pelvis height, sole depths (lowest corner / mid-plane), sole pitch, sand force and the decoded eta."""
    st = scene._read_state()
    c = scene._sole_corners(st["body_q"])[0]  # [2, 8, 3], surface at z = 0
    low = -(c[..., 2].min(axis=1))
    mid = -(c[..., 2].mean(axis=1))
    pitch = np.degrees(np.arctan2(c[:, 4:, 2].mean(1) - c[:, :4, 2].mean(1), c[:, 4:, 0].mean(1) - c[:, :4, 0].mean(1)))
    roll, bpitch = roll_pitch(st["base_q"][0, 3:7])
    row = dict(
        pz=round(float(st["base_q"][0, 2]), 4), px=round(float(st["base_q"][0, 0]), 3),
        vx=round(float(st["base_qd"][0, 0]), 3), vz=round(float(st["base_qd"][0, 2]), 3),
        low=[round(float(v), 4) for v in low], mid=[round(float(v), 4) for v in mid],
        pitch=[round(float(v), 1) for v in pitch], fz=[round(float(v), 1) for v in st["foot_force"][0, :, 2]],
        roll_deg=round(float(np.degrees(roll)), 1), pitch_deg=round(float(np.degrees(bpitch)), 1),
    )  # fmt: skip
    row["fx"] = [round(float(v), 1) for v in st["foot_force"][0, :, 0]]
    if hasattr(scene, "sand_state") and scene.sand_state is not None:
        # sand heave: highest particle within 12 cm ahead of each sole's front edge (|dy| < 6 cm) and in the window
        pq = scene.sand_state.particle_q.numpy()
        ahead = []
        for i in range(2):
            front, y = c[i, :, 0].max(), c[i, :, 1].mean()
            sel = (pq[:, 0] > front) & (pq[:, 0] < front + 0.12) & (np.abs(pq[:, 1] - y) < 0.06)
            ahead.append(round(float(pq[sel, 2].max()), 4) if sel.any() else None)
        row["sand_ahead_z"] = ahead
        row["sand_max_z"] = round(float(pq[:, 2].max()), 4)
    if isinstance(policy, StudentOnnxPolicy) and policy.runner.eta is not None:
        row["eta"] = round(float(np.asarray(policy.runner.eta).reshape(-1)[0]), 4)
    return row


def main() -> None:
    """Run one probe and append its record to the log."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--policy", type=Path, required=True)
    p.add_argument("--label", required=True)
    p.add_argument("--frames", type=int, default=100, help="100 Hz frames")
    p.add_argument("--every", type=int, default=10, help="log every N frames")
    p.add_argument("--vx", type=float, default=0.0, help="forward velocity command [m/s]")
    p.add_argument("--depth", type=float, default=0.3, help="bed depth [m]")
    p.add_argument("--voxel", type=float, default=0.05, help="voxel size [m]")
    p.add_argument("--iterations", type=int, default=50)
    p.add_argument("--window", choices=("small", "eval"), default="small")
    p.add_argument("--rigid", action="store_true", help="no sand: rigid floor only")
    p.add_argument("--frame-dt", type=float, default=0.01, help="MPM frame = coupling period [s]")
    p.add_argument("--substeps", type=int, default=2, help="rigid substeps per frame (physics dt = frame-dt / this)")
    p.add_argument("--effective-mass", type=float, default=None, help="SoleCfg.effective_mass [kg]; default m / 2")
    p.add_argument("--grid", choices=("sparse", "dense"), default="sparse", help="MPM grid type")
    p.add_argument(
        "--handover",
        choices=("predict", "rewind", "actual"),
        default="predict",
        help="coupling: collider velocity MPM sees (MpmSolverCfg.velocity_handover; before the hand-over probes: rewind)",
    )
    p.add_argument("--duration", type=float, default=None, help="simulated time [s]; overrides --frames")
    p.add_argument("--log", type=Path, default=Path("results/mpm_eval/policies_cpu.jsonl"))
    args = p.parse_args()
    if (problem := frame_dt_problem(args.frame_dt)) is not None:  # the policy runs at 50 Hz on whole frames
        p.error(f"--frame-dt: {problem}")
    if args.substeps < 1:
        p.error(f"--substeps {args.substeps} must be >= 1 (rigid steps per MPM frame)")
    if args.duration is not None:
        args.frames = round(args.duration / args.frame_dt)
    t = time.time()
    policy = load_policy(args.policy)
    scene = make(policy, args)
    if args.rigid:
        rigid_only(scene)
    mg = scene.robot_mass * 9.81
    rows: list[dict[str, Any]] = [{"f": 0, "t": 0.0, **snap(scene, policy)}]
    for k in range(args.frames):
        scene.step()
        if (k + 1) % args.every == 0:
            rows.append({"f": k + 1, "t": round((k + 1) * args.frame_dt, 4), **snap(scene, policy)})
    for r in rows:
        print(args.label, r, flush=True)
    fz = np.array([sum(r["fz"]) for r in rows[len(rows) // 2 :]]) / mg
    # 50 Hz pelvis log: fall = pelvis < 0.2 m above the surface or |roll| / |pitch| > pi / 4 (the evaluation's rule)
    bq = np.asarray(scene.base_q)[:, 0]
    tilt = np.array([max(abs(a) for a in roll_pitch(q[3:7])) for q in bq])
    fell = (bq[:, 2] < 0.2) | (tilt > np.pi / 4)
    first_fall = float(np.argmax(fell) * scene.spec.policy_dt) if fell.any() else None
    eta = [r["eta"] for r in rows if "eta" in r]
    swing = swing_summary(rows, first_fall)
    rec = dict(
        label=args.label, policy=str(args.policy), vx_cmd=args.vx, window=args.window, rigid=args.rigid,
        depth=0.1 if args.rigid else args.depth, voxel=args.voxel, iterations=args.iterations, frames=args.frames,
        frame_dt=args.frame_dt, substeps=args.substeps, effective_mass=args.effective_mass, grid=args.grid,
        handover=args.handover,
        mass=round(scene.robot_mass, 2), particles=scene.particle_count, rows=rows,
        support2=round(float(fz.mean()), 2), support_50hz=round(float(scene.support_ratio()[0]), 2),
        pelvis_min=round(min(float(bq[:, 2].min()), min(r["pz"] for r in rows)), 4), max_abs_sole_pitch=max(abs(v) for r in rows for v in r["pitch"]),
        max_tilt_deg=round(float(np.degrees(tilt.max())), 1), first_fall_s=first_fall,
        mean_vx=round(float((bq[-1, 0] - bq[0, 0]) / ((len(bq) - 1) * scene.spec.policy_dt)), 3),
        eta_mean_2nd_half=round(float(np.mean(eta[len(eta) // 2 :])), 4) if eta else None, **swing,
        s=round(time.time() - t, 1),
    )  # fmt: skip
    args.log.parent.mkdir(parents=True, exist_ok=True)
    with args.log.open("a") as f:
        f.write(json.dumps(rec) + "\n")
    keys = ("support2", "support_50hz", "pelvis_min", "max_abs_sole_pitch", "max_tilt_deg", "first_fall_s", "mean_vx",
            *swing)  # fmt: skip
    print(args.label, {k: rec[k] for k in (*keys, "eta_mean_2nd_half", "s")}, flush=True)


def swing_summary(rows: list[dict[str, Any]], fall_s: float | None, threshold: float = 40.0) -> dict[str, Any]:
    """Swing summary of the logged rows before the fall.

    Apex and lift of the lowest sole corner and of the sole's mid-plane above the initial surface [m]
    (``swing_clearance``, a foot in swing below ``threshold`` N of sand force), and the mean x sand force on
    swinging feet [N] (negative: the sand drags the swinging foot back).
    """
    from gmloco.eval.metrics.locomotion import swing_clearance

    alive = [r for r in rows if fall_s is None or r["t"] < fall_s]
    if len(alive) < 3:
        return {}
    fz = np.array([r["fz"] for r in alive])
    low = swing_clearance(-np.array([r["low"] for r in alive]), fz, threshold=threshold, min_steps=2)
    mid = swing_clearance(-np.array([r["mid"] for r in alive]), fz, threshold=threshold, min_steps=2)
    fx = np.array([r["fx"] for r in alive])
    rnd = lambda x: None if not np.isfinite(x) else round(float(x), 4)  # noqa: E731
    return {"swings": low.swings, "swing_apex_low": rnd(low.apex), "swing_lift_low": rnd(low.lift),
            "swing_apex_mid": rnd(mid.apex), "swing_lift_mid": rnd(mid.lift),
            "swing_drag_x": rnd(fx[fz < threshold].mean()) if (fz < threshold).any() else None}  # fmt: skip


if __name__ == "__main__":
    main()
