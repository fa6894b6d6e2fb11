"""Contact-kernel cost per launch and its share of one G1 MuJoCo Warp physics step, measured in one run.

    python scripts/gpu/bench_contact.py --num-worlds 4096 --out $OUT/bench_contact.json

For every contact model and collider size (sole 5x5 = 25 points, six-face 5x5 = 150 points per foot) it
times ``model.compute`` (the stateless part that runs inside the passive callback) and, for stateful models,
``model.update_state``, each captured in a CUDA graph of ``--reps`` launches. The reference is one physics
substep of mjlab's stock G1 (``env.sim.step()``, rigid contact) at the same world count, built in the same
process.

``--paths fused,reference`` (default) times both kernel paths of each model: ``fused`` (``model.fused = True``,
the default: 3D-RFT points + per-foot tile sum in one launch, tiled sums for the other models, update_state
without a force pass) under the plain key (``rft3d/150pt``) and ``reference`` (``model.fused = False``: the
previous per-point pass, one-thread-per-foot loop and recomputing update_state) under ``<key>/reference``.
Each fused record also carries ``wrench_max_rel_diff_vs_reference``: max |W_fused - W_ref| / max |W_ref| on
the benchmark state after one compute (float32 round-off expected, ~1e-6).
"""

from __future__ import annotations

import argparse
import json
import os
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np


def _parse() -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--num-worlds", type=int, default=4096)
    p.add_argument("--reps", type=int, default=200)
    p.add_argument("--device", default="cuda:0")
    p.add_argument("--skip-sim", action="store_true", help="do not build the G1 env for the step reference")
    p.add_argument("--paths", default="fused,reference", help="comma list of kernel paths: fused, reference")
    p.add_argument("--out", type=Path, default=Path("bench_contact.json"))
    return p.parse_args()


def _time_graph(fn: Callable[[], object], reps: int, device: str) -> float:
    """Mean seconds per call of ``fn``; launched ``reps`` times inside one CUDA graph when on CUDA."""
    import warp as wp

    fn()  # compile + warm up
    wp.synchronize()
    if wp.get_device(device).is_cuda:
        with wp.ScopedCapture(device=device) as cap:
            for _ in range(reps):
                fn()
        wp.capture_launch(cap.graph)  # warm
        wp.synchronize()
        t0 = time.perf_counter()
        wp.capture_launch(cap.graph)
        wp.synchronize()
        return (time.perf_counter() - t0) / reps
    t0 = time.perf_counter()
    for _ in range(reps):
        fn()
    wp.synchronize()
    return (time.perf_counter() - t0) / reps


def _foot_state(num_worlds: int, device: str, seed: int = 0) -> tuple[Any, ...]:
    """Feet 1 cm into flat sand, tilted a little, moving down and forward (most points submerged, leading)."""
    import warp as wp

    rng = np.random.default_rng(seed)
    shape = (num_worlds, 2)
    pos = np.zeros((*shape, 3), np.float32)
    pos[..., 0] = rng.uniform(-1, 1, shape)
    pos[..., 1] = rng.uniform(-1, 1, shape)
    pos[..., 2] = 0.03539 - 0.01 + rng.uniform(-0.005, 0.005, shape)
    ang = rng.uniform(-0.1, 0.1, shape)
    mat = np.zeros((*shape, 3, 3), np.float32)
    mat[..., 0, 0] = np.cos(ang)
    mat[..., 0, 2] = np.sin(ang)
    mat[..., 1, 1] = 1.0
    mat[..., 2, 0] = -np.sin(ang)
    mat[..., 2, 2] = np.cos(ang)
    vel = np.stack([rng.uniform(0, 1, shape), rng.uniform(-0.2, 0.2, shape), rng.uniform(-0.5, 0, shape)], -1)
    angv = rng.uniform(-1, 1, (*shape, 3))
    com = pos.copy()
    com[..., 0] += 0.03
    arr = lambda a, dt: wp.array(a.astype(np.float32), dtype=dt, device=device)  # noqa: E731
    return (
        arr(pos, wp.vec3),
        arr(mat, wp.mat33),
        arr(vel, wp.vec3),
        arr(angv, wp.vec3),
        arr(com, wp.vec3),
        wp.zeros(shape, dtype=wp.spatial_vector, device=device),
    )


def _wrench_rel_diff(cfg: Any, num_worlds: int, device: str, material: Any) -> float:
    """Max |W_fused - W_reference| / max |W_reference| of one compute() on the benchmark state."""
    from gmloco.contact import make_contact_model

    out = []
    for fused in (True, False):
        model = make_contact_model(cfg, num_worlds, 2, device)
        model.fused = fused
        w = np.ones(num_worlds)
        model.set_materials(w * material.rho_c, w * material.mu_int, w * material.mu_surf)
        state = _foot_state(num_worlds, device)
        model.update_state(*state[:5])  # z_max at the current depth: the same branch mix as the timed loop
        model.compute(*state)
        out.append(state[5].numpy().astype(np.float64))
    return float(np.abs(out[0] - out[1]).max() / max(np.abs(out[1]).max(), 1e-30))


def bench_models(num_worlds: int, reps: int, device: str, paths: list[str]) -> dict[str, dict[str, float]]:
    """Seconds per launch of each model's compute / update_state for 25 and 150 points per foot, per path."""
    from gmloco.contact import (
        MATERIAL_PRESETS,
        ColliderBoxCfg,
        ContactConeMultiCfg,
        ContactConeSingleCfg,
        ContactHeuristicRFTCfg,
        ContactRFT3DCfg,
        make_contact_model,
    )

    sand = MATERIAL_PRESETS["dry_sand"]
    out: dict[str, dict[str, float]] = {}
    for faces, points in (("sole", 25), ("box", 150)):
        collider = ColliderBoxCfg(faces=faces, resolution=5)
        cfgs = {
            "rft3d": ContactRFT3DCfg(collider=collider),
            "heuristic_rft": ContactHeuristicRFTCfg(collider=collider),
            "cone_multi": ContactConeMultiCfg(collider=collider),
            "cone_single": ContactConeSingleCfg(),
        }
        for name, cfg in cfgs.items():
            if name == "cone_single" and faces == "box":
                continue  # one point per foot whatever the collider
            for path in paths:
                model = make_contact_model(cfg, num_worlds, 2, device)
                model.fused = path == "fused"
                w = np.ones(num_worlds)
                model.set_materials(w * sand.rho_c, w * sand.mu_int, w * sand.mu_surf)
                state = _foot_state(num_worlds, device)
                key = f"{name}/{points if name != 'cone_single' else 1}pt" + ("" if path == "fused" else f"/{path}")
                rec = {"compute_s": _time_graph(lambda m=model, s=state: m.compute(*s), reps, device)}
                if getattr(model, "is_stateful", False):
                    rec["update_state_s"] = _time_graph(lambda m=model, s=state: m.update_state(*s[:5]), reps, device)
                if path == "fused" and "reference" in paths:
                    rec["wrench_max_rel_diff_vs_reference"] = _wrench_rel_diff(cfg, num_worlds, device, sand)
                out[key] = rec
                print(key, rec, flush=True)
    return out


def bench_step(num_worlds: int, device: str) -> dict[str, float]:
    """Seconds per physics substep of mjlab's stock G1 (rigid contact) at ``num_worlds``."""
    import mjlab.tasks  # noqa: F401
    import warp as wp
    from mjlab.envs import ManagerBasedRlEnv
    from mjlab.tasks.registry import load_env_cfg

    env_cfg = load_env_cfg("Mjlab-Velocity-Flat-Unitree-G1")
    env_cfg.scene.num_envs = num_worlds
    env = ManagerBasedRlEnv(cfg=env_cfg, device=device)
    env.reset()
    for _ in range(50):
        env.sim.step()
    wp.synchronize()
    n = 400
    t0 = time.perf_counter()
    for _ in range(n):
        env.sim.step()
    wp.synchronize()
    dt = (time.perf_counter() - t0) / n
    env.close()
    return {"g1_substep_s": dt}


def main() -> None:
    """Run the benchmark and write one JSON."""
    args = _parse()
    os.environ.setdefault("MUJOCO_GL", "disable")
    import torch
    import warp as wp

    wp.init()
    res: dict[str, object] = {
        "device": torch.cuda.get_device_name(0) if torch.cuda.is_available() else "cpu",
        "num_worlds": args.num_worlds,
        "reps": args.reps,
    }
    res["paths"] = args.paths.split(",")
    res["models"] = bench_models(args.num_worlds, args.reps, args.device, res["paths"])
    if not args.skip_sim:
        res.update(bench_step(args.num_worlds, args.device))
        step = res["g1_substep_s"]
        for rec in res["models"].values():  # type: ignore[union-attr]
            total = rec["compute_s"] + rec.get("update_state_s", 0.0)
            rec["share_of_substep"] = total / step  # type: ignore[operator]
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(res, indent=1))
    print(json.dumps(res, indent=1))


if __name__ == "__main__":
    main()
