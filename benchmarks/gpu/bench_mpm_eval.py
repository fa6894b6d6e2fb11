# SPDX-License-Identifier: Apache-2.0
"""Time the G1-on-MPM evaluation (naive bed, moving window, several robots per solver) and check voxel convergence.

One time-boxed, resumable call; one JSON out.

Superseded for issue 9's numbers (the accepted-setting runs): this benchmark steps 10 ms frames x 2 rigid steps with 50 rheology
iterations by default, numerics the convergence check has since rejected (``docs/mpm_eval.md``). The cost of the
accepted setting (3 cm, 500 iterations, 5 ms frames) is measured with ``g1_eval_cli`` itself on short episodes
(``results/mpm_eval/convergence/accepted_setting/sweep.jsonl``). Kept for its naive / window / multi comparison (``BENCHMARKS.md``).

    source scripts/gpu/env.sh
    python benchmarks/gpu/bench_mpm_eval.py --out $OUT/bench --max-minutes 8.5

Every case builds a ``G1MpmScene`` (dry sand, the policy walking at 1.0 / 1.5 / 2.0 / 2.5 m/s cycled over robots),
captures a frame graph when it can, steps ``--frames`` frames and records frames/s. A 10 s episode is 1000 frames,
so a batch of R robots takes build + capture + 1000 / fps seconds: episodes/min = 60 R / that. Cases run in
priority order and are skipped when their predicted time would overrun the time box; ``bench.json`` is rewritten
after each case (rerun with the same ``--out`` to resume: measured cases are kept, skipped and failed ones run
again; each call first warms up, i.e. loads or compiles the kernels, apart from the timed cases).

Convergence check (``convergence`` in the JSON): for each voxel size, the multi-robot case's mean sinkage of the
feet over the last half of the run, the pelvis height and the mean forward velocity (over robots), plus a standing
robot's sinkage on 30 cm of sand after ``--stand-frames`` frames; the relative change of each against the finest
voxel measured. The standing robot holds the default pose with PD gains ``--stand-gain`` x the policy's: with the
policy's own gains the PD-only G1 folds at the knees and ankles and tips over even on rigid ground
(``results/mpm_eval/G1_SINKAGE.md``), so its sinkage would measure posture, not sand. A voxel is accepted when
sinkage and pelvis height are within ``--tol`` (relative) of the finest, or within a quarter of its particle
spacing, and the forward velocity within ``--tol`` m/s; never when a foot reached 80 % of the bed depth (the rigid
floor, which the soles stand on through MuJoCo contacts, then sets the sinkage at every resolution).

Per case, ``soles_on_floor`` / ``soles_below_floor`` count the robots whose lowest sole corner reached the rigid
floor (the floor carried that foot for a while: the bed was too shallow) / went more than 1 cm below it (must be 0).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import time
import traceback
from argparse import Namespace
from pathlib import Path
from typing import Any

import numpy as np

SPEEDS = (1.0, 1.5, 2.0, 2.5)
METRICS = ("sinkage_m", "pelvis_z_m", "vx_mps")
_AS_WORLDS = {"auto": None, "yes": True, "no": False}


def _parse() -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", type=Path, required=True)
    p.add_argument("--policy", default="artifacts/ppo_rft3d/policy.onnx")
    p.add_argument("--voxels", type=float, nargs="+", default=[0.05, 0.04, 0.03])
    p.add_argument("--robots", type=int, default=32, help="robots of the multi-robot cases")
    p.add_argument("--frames", type=int, default=150, help="frames timed per case (100 Hz)")
    p.add_argument("--stand-frames", type=int, default=100, help="frames of the PD-only standing check")
    p.add_argument("--stand-gain", type=float, default=10.0, help="PD gain factor of the standing check's robot")
    p.add_argument(
        "--naive-voxels", type=float, nargs="*", default=None, help="voxels of the naive case (default: coarsest)"
    )
    p.add_argument("--max-minutes", type=float, default=8.5)
    p.add_argument(
        "--iters",
        type=int,
        default=50,
        help="rheology iterations (the dig-in probes' eval default; the accepted setting uses 500)",
    )
    p.add_argument("--iters-check", type=int, default=250, help="iterations of the iteration-convergence case")
    p.add_argument("--tol", type=float, default=0.15, help="relative tolerance of the convergence check")
    p.add_argument("--device", default=None)
    p.add_argument("--window-length", type=float, default=1.8)
    p.add_argument("--window-width", type=float, default=1.0)
    p.add_argument(
        "--robots-as-worlds",
        choices=("auto", "yes", "no"),
        default="auto",
        help="one MuJoCo world per robot (auto: on CUDA); 'no' puts all robots in one world (diagnostics)",
    )
    return p.parse_args()


def _write_json(path: Path, data: Any) -> None:
    """Write JSON atomically (tmp + os.replace)."""
    tmp = path.with_suffix(".tmp")
    tmp.write_text(json.dumps(data, indent=1, default=str))
    os.replace(tmp, path)


def _cases(args: argparse.Namespace) -> list[dict[str, Any]]:
    """Cases in priority order: coarse window / multi / naive first, then finer voxels, the standing check."""
    coarse = max(args.voxels)
    naive = args.naive_voxels if args.naive_voxels is not None else [coarse]
    cases = [
        {"mode": "window", "voxel": coarse, "robots": 1},
        {"mode": "multi", "voxel": coarse, "robots": args.robots},
    ]
    cases += [{"mode": "naive", "voxel": v, "robots": 1} for v in naive]
    for v in sorted(args.voxels, reverse=True):
        if v != coarse:
            cases += [{"mode": "multi", "voxel": v, "robots": args.robots}, {"mode": "window", "voxel": v, "robots": 1}]
    # rheology iterations are a convergence dimension too (issue 5: plate forces): the coarse multi case again
    cases += [{"mode": "multi", "voxel": coarse, "robots": args.robots, "iters": args.iters_check}]
    cases += [{"mode": "stand", "voxel": v, "robots": 4} for v in sorted(args.voxels, reverse=True)]
    return cases


def _key(c: dict[str, Any]) -> str:
    """Case id in ``bench.json``: mode, voxel, robots (and rheology iterations when not the default)."""
    iters = f"/it{c['iters']}" if "iters" in c else ""
    return f"{c['mode']}/v{c['voxel']:g}/r{c['robots']}{iters}"


def _scene_cfg(case: dict[str, Any], args: argparse.Namespace) -> Any:
    """Scene of one case: moving window (window, multi, stand) or a static bed over a 2.5 m/s x 10 s course."""
    from gmloco.eval.g1.scene_cfg import G1MpmSceneCfg
    from gmloco.eval.mpm.box_scene import MpmSolverCfg
    from gmloco.eval.mpm.window import SandWindowCfg
    from gmloco.eval.mpm.window_terrain import terrain_cfg

    n, voxel = case["robots"], case["voxel"]
    win = SandWindowCfg(moving=True, length=args.window_length, width=args.window_width)
    if case["mode"] == "naive":  # 25 m course + 0.6 m margins, as g1_eval builds it for moving_window=false
        win = SandWindowCfg(moving=False, length=26.2, width=args.window_width, lead=12.5)
    if case["mode"] == "stand":
        win = SandWindowCfg(moving=True, length=0.9, width=0.6, lead=0.0)
    # the standing check stands on 30 cm of sand so that the rigid floor cannot set its sinkage
    terrain = terrain_cfg("dry_sand", depth=0.30 if case["mode"] == "stand" else 0.15)
    h = voxel / win.particles_per_voxel
    particles = int(np.ceil(win.length / h) * np.ceil(win.width / h) * round(terrain.depth / h)) * n
    solver = MpmSolverCfg(voxel_size=voxel, frame_dt=0.01, rigid_substeps=2,
                          max_active_cell_count=int(3.0 * particles / 8) + 64,
                          max_iterations=int(case.get("iters", args.iters)))  # fmt: skip
    cmds = ((0.0, 0.0, 0.0),) if case["mode"] == "stand" else tuple((v, 0.0, 0.0) for v in SPEEDS)
    return G1MpmSceneCfg(terrain=terrain, window=win, num_robots=n, lane_spacing=args.window_width + 2.0,
                         solver=solver, commands=cmds, device=args.device,
                         robots_as_worlds=_AS_WORLDS[getattr(args, "robots_as_worlds", "auto")])  # fmt: skip


def _run_case(case: dict[str, Any], args: argparse.Namespace) -> dict[str, Any]:
    """Build, capture, step; return timings and the physics metrics of the convergence check."""
    from gmloco.eval.g1.policy import load_policy
    from gmloco.eval.g1.scene import G1MpmScene

    cfg = _scene_cfg(case, args)
    policy = load_policy(args.policy, case["robots"])
    t0 = time.perf_counter()
    driver: Any = policy
    # the standing robot: stiff joints hold the default pose (mjlab's gains alone fold it, even on rigid ground)
    if case["mode"] == "stand":
        k = float(getattr(args, "stand_gain", 10.0))
        driver = dataclasses.replace(policy.spec, kp=policy.spec.kp * k, kd=policy.spec.kd * k)
    scene = G1MpmScene(cfg, driver)
    build_s = time.perf_counter() - t0
    t0 = time.perf_counter()
    scene.capture()
    capture_s = time.perf_counter() - t0
    frames = args.stand_frames if case["mode"] == "stand" else args.frames
    scene.run(frames)
    if cfg.solver.max_active_cell_count > 0:
        scene.mpm.check_sparse_grid_rebuild_status()  # raises when the fixed-capacity grid overflowed
    fps = scene.frames_per_second
    episode_s = build_s + capture_s + 1000.0 / fps
    q, qd = np.asarray(scene.base_q), np.asarray(scene.base_qd)
    half = len(q) // 2
    return {
        **case, "particles": scene.particle_count, "graph": scene.graph is not None,
        "capture_error": scene.capture_error, "build_s": build_s,
        "capture_s": capture_s, "frames": scene.frame, "frames_per_s": fps,
        "robot_frames_per_s": fps * case["robots"], "batch_episode_s": episode_s,
        "episodes_per_min": 60.0 * case["robots"] / episode_s,
        "minutes_per_100_episodes": 100.0 / (60.0 * case["robots"] / episode_s),
        "sinkage_m": float(np.mean(np.asarray(scene.foot_sinkage)[half:])),
        "max_sinkage_m": float(np.max(scene.sinkage)), "depth_m": cfg.terrain.depth,
        "pelvis_z_m": float(np.mean(q[half:, :, 2])), "vx_mps": float(np.mean(qd[half:, :, 0])),
        "support_ratio": float(np.mean(scene.support_ratio())),
        "fallen": int(np.sum(q[-1, :, 2] < 0.2)),
        # a sole corner more than 1 cm below the rigid floor at any sample (the floor contact should prevent it)
        "soles_below_floor": int(np.sum(np.asarray(scene.sinkage).max(axis=0) > cfg.terrain.depth + 0.01)),
        # a sole that reached the floor: the floor, not the sand, carried that foot for a while
        "soles_on_floor": int(np.sum(np.asarray(scene.sinkage).max(axis=0) > cfg.terrain.depth - 0.005)),
        # pelvis below the rigid floor (z = -depth): the robot went through bed and floor, the timing is not a walk's
        "through_floor": int(np.sum(q[-1, :, 2] < -cfg.terrain.depth)), "device": str(scene.device),
    }  # fmt: skip


def _measured(r: dict[str, Any], keys: tuple[str, ...] = ("frames_per_s",)) -> bool:
    """True for a record holding the given numbers (a measured case), False for skipped or failed ones."""
    return "error" not in r and "skipped" not in r and all(k in r for k in keys)


def _convergence(results: dict[str, dict[str, Any]], tol: float) -> dict[str, Any]:
    """Metrics per voxel against the finest voxel measured (multi-robot walking and standing cases)."""
    out: dict[str, Any] = {}
    for mode, keys in (("multi", ("sinkage_m", "pelvis_z_m", "vx_mps")), ("stand", ("sinkage_m", "pelvis_z_m"))):
        # measured records only: a skipped or failed case carries no metrics (a partial bench.json holds both)
        rs = sorted((r for r in results.values() if r.get("mode") == mode and _measured(r, keys)
                     and "iters" not in r),
                    key=lambda r: r["voxel"])  # fmt: skip
        if not rs:
            continue
        ref = rs[0]
        rows = []
        for r in rs:
            row: dict[str, Any] = {"voxel": r["voxel"], **{k: r[k] for k in keys}}
            ok = True
            for k in keys:
                d = abs(r[k] - ref[k])
                # velocities: an absolute tolerance [m/s]; lengths: relative, but never below a quarter of the
                # finest particle spacing (sinkage is read on a particle bed: smaller differences are not resolved)
                bound = tol if k == "vx_mps" else max(tol * abs(ref[k]), 0.25 * ref["voxel"] / 2)
                ok &= d <= bound
                row[f"{k}_change"] = d
            # a foot that reached the rigid floor makes every resolution look alike: no verdict from such a run
            floor = max(r.get("max_sinkage_m", 0.0), ref.get("max_sinkage_m", 0.0)) >= 0.8 * r.get("depth_m", 0.15)
            row["floor_reached"] = bool(floor)
            row["accepted"] = (bool(ok) and not floor) if r is not ref else None
            rows.append(row)
        out[mode] = {"reference_voxel": ref["voxel"], "rows": rows}
    many = [r for r in results.values() if "iters" in r and _measured(r, METRICS)]
    for r in many:  # the same case with more rheology iterations is the reference
        base = next(
            (
                b
                for b in results.values()
                if b.get("mode") == r["mode"]
                and b.get("voxel") == r["voxel"]
                and b.get("robots") == r["robots"]
                and "iters" not in b
                and _measured(b, METRICS)
            ),
            None,
        )
        if base is not None:
            out["iterations"] = {
                "voxel": r["voxel"], "iterations": r["iters"],
                **{f"{k}_change": abs(base[k] - r[k]) for k in METRICS},
                **{f"{k}_at_{r['iters']}": r[k] for k in METRICS},
            }  # fmt: skip
    return out


def replace(args: Namespace, **changes: Any) -> Namespace:
    """Copy of the parsed arguments with some changed."""
    return Namespace(**{**vars(args), **changes})


def main() -> None:
    """Run the cases within the time box; write ``<out>/bench.json`` after each."""
    args = _parse()
    args.out.mkdir(parents=True, exist_ok=True)
    path = args.out / "bench.json"
    doc: dict[str, Any] = json.loads(path.read_text()) if path.exists() else {"results": {}}
    results: dict[str, dict[str, Any]] = doc["results"]
    t_start, budget = time.perf_counter(), 60.0 * args.max_minutes
    todo = [c for c in _cases(args) if not _measured(results.get(_key(c), {}))]  # skipped / failed: run again
    if todo:  # every process compiles / loads its kernels once, so no case's build time includes JIT compilation
        t0 = time.perf_counter()
        _run_case({"mode": "window", "voxel": max(args.voxels), "robots": 2}, replace(args, frames=3))
        warm = time.perf_counter() - t0
        doc.setdefault("warmup_s", warm)  # the first call's (cold cache); every call's in warmups_s
        doc["warmups_s"] = [*doc.get("warmups_s", []), warm]
        print(f"[bench] warm-up (kernel compilation / loading) {warm:.0f} s", flush=True)
    for case in todo:
        key = _key(case)
        left = budget - (time.perf_counter() - t_start)
        guess = _predict(case, results, args.stand_frames if case["mode"] == "stand" else args.frames)
        if guess > left:
            results[key] = {**case, "skipped": f"predicted {guess:.0f} s > {left:.0f} s left"}
            continue
        print(f"[bench] {key} (left {left:.0f} s)", flush=True)
        try:
            results[key] = _run_case(case, args)
            r = results[key]
            print(f"[bench] {key}: {r['particles']} particles, {r['frames_per_s']:.1f} frames/s, "
                  f"{r['episodes_per_min']:.1f} episodes/min, build {r['build_s']:.0f} s, fallen {r['fallen']}, "
                  f"soles on / below the floor {r['soles_on_floor']} / {r['soles_below_floor']}, "
                  f"through the floor {r['through_floor']} of {r['robots']}", flush=True)  # fmt: skip
        except Exception as exc:  # one failing case must not lose the others
            results[key] = {**case, "error": repr(exc), "traceback": traceback.format_exc()[-2000:]}
            print(f"[bench] {key} failed: {exc!r}", flush=True)
        doc.update({"results": results, "convergence": _convergence(results, args.tol), "args": vars(args)})
        _write_json(path, doc)
    doc.update({"results": results, "convergence": _convergence(results, args.tol), "args": vars(args)})
    _write_json(path, doc)
    print(json.dumps(doc["convergence"], indent=1, default=str))


def _predict(case: dict[str, Any], results: dict[str, dict[str, Any]], frames: int) -> float:
    """Rough wall time of a case [s]: mean build + frames x max(fastest frame, particles x slowest s/particle)."""
    done = [r for r in results.values() if "frames_per_s" in r]
    if not done:
        return 60.0
    same = [r for r in done if r["mode"] == case["mode"]] or done
    ref = same[0]
    particles = ref["particles"] * (ref["voxel"] / case["voxel"]) ** 3 * case["robots"] / ref["robots"]
    per_particle = max(1.0 / (r["frames_per_s"] * r["particles"]) for r in done)
    frame_s = max(min(1.0 / r["frames_per_s"] for r in done), per_particle * particles)
    return float(np.mean([r["build_s"] + r["capture_s"] for r in done])) + frames * frame_s


if __name__ == "__main__":
    main()
