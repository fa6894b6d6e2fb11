"""Contact-kernel cost per launch and its share of one G1 MuJoCo Warp physics step, measured in one run.

    source scripts/gpu/env.sh && python3 benchmarks/gpu/bench_contact.py --num-worlds 4096 --out runs/bench_contact

For every contact model and collider size (sole 5x5 = 25 points, six-face 5x5 = 150 points per foot) it times
``model.compute`` (the stateless part that runs inside the passive callback) and, for stateful models,
``model.update_state`` and ``model.compute_and_update_state`` (``step_s``: both in one call; one launch of
``rft3d_foot_wrench_kernel`` with ``advance=1`` on the fused 3D-RFT path, else the two calls), each captured in
a CUDA graph of ``--reps`` calls. Each record lists the kernels every timed call launches (``launches``,
recorded by intercepting ``wp.launch`` / ``wp.launch_tiled`` during one untimed call) and, for stateful models,
``step_max_rel_diff_vs_two_calls``: max relative difference of the wrench and every state array between
compute_and_update_state() and compute() + update_state() after one substep (0 expected). The reference is one
physics substep of mjlab's stock G1 (``env.sim.step()``, rigid contact) at the same world count, built in the
same process (``--skip-sim`` leaves it out). ``share_of_substep`` = (compute + update_state) / substep;
``share_of_substep_step`` = compute_and_update_state / substep.

Paths (``--paths``, default both): ``fused`` (``model.fused = True``, the default: 3D-RFT elements + per-foot tile
sum in one launch, tiled per-foot sums for the other models) under the plain key (``rft3d/150pt``), and
``unfused`` (``model.fused = False``: per-point pass + one-thread-per-foot sum) under ``<key>/unfused``. Both
paths share update_state (one launch, no force pass); compute_and_update_state is one launch only on the fused
3D-RFT path. Each fused record also carries ``wrench_max_rel_diff_vs_unfused``: max |W_fused - W_unfused| /
max |W_unfused| after one compute on the benchmark state (float32 round-off expected, ~1e-6). ``rft3d_viscous``
is 3D-RFT with ``static_friction=False`` (the cost of the stick anchors).

Kernel variants (``--variants``, default ``default``; ``all`` = every one): the fused 3D-RFT kernels compiled with
other register caps (``gmloco.contact.kernels_rft3d.FUSED_VARIANTS``), selected through ``model.fused_variant``,
and each of them with the suffix ``-nopoints`` (``model.point_outputs`` False: no per-point stores). Each 3D-RFT
fused record carries ``variant``; every other variant gets its own record ``<key>/<variant>`` right after the
default one (same process, same state): compute_s, step_s and ``max_rel_diff_vs_default``, the max relative
difference of the wrench, the per-point outputs (not for ``-nopoints``) and every state array to the default kernels
after compute() and then compute_and_update_state() from the benchmark state (0 expected). ``cap96``'s kernels are
the default ones (both capped at 96): a repeat measurement in the same run. A variant comparison on the GPU, e.g.
(about 3 min, mostly NVRTC compiles)::

    python3 benchmarks/gpu/bench_contact.py --models rft3d --paths fused --variants all --skip-sim \
        --reps 1000 --repeat 5 --warm-s 0.5 --out $OUT/variants

Timing: ``--repeat`` timed graph launches per call, the median recorded as ``<call>_s`` (all of them as
``<call>_s_runs`` when more than one), after untimed graph launches for ``--warm-s`` seconds (default: one, as
before). On CUDA ``gpu_clocks[<key>]`` holds nvidia-smi's clocks, power and throttle reasons after each record.

Time box and resume: the JSON (``<out>/bench_contact.json``) is rewritten atomically after every record; a rerun
with the same ``--out`` skips the records already there (``--force`` redoes them). The run stops starting new
records after ``--max-minutes`` and exits with 3 (``"complete": false``); rerun the same command to continue.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any, Literal

import numpy as np

MODELS = ("rft3d", "rft3d_viscous", "heuristic_rft", "cone_multi", "cone_single")
"""Benchmarked model variants (``rft3d_viscous``: 3D-RFT without static friction)."""
PATHS = ("fused", "unfused")
"""Kernel paths of compute(): ``model.fused`` True / False."""
VARIANT_MODELS = ("rft3d", "rft3d_viscous")
"""Models whose fused path has kernel variants (``model.fused_variant``)."""


def all_variants() -> tuple[str, ...]:
    """Return every fused 3D-RFT kernel variant name, ``"default"`` first."""
    from gmloco.contact.kernels_rft3d import FUSED_VARIANTS

    return (*FUSED_VARIANTS, *(v + NOPOINTS for v in FUSED_VARIANTS))


NOPOINTS = "-nopoints"
"""Variant-name suffix: the same kernel variant with ``model.point_outputs`` False (no per-point stores)."""


def split_variant(variant: str) -> tuple[str, bool]:
    """Return (kernel variant, point_outputs) of a benchmark variant name (``<variant>[-nopoints]``)."""
    if variant.endswith(NOPOINTS):
        return variant.removesuffix(NOPOINTS), False
    return variant, True


def _parse(argv: list[str] | None = None) -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--num-worlds", type=int, default=4096)
    p.add_argument("--reps", type=int, default=200, help="launches per timed CUDA graph")
    p.add_argument("--repeat", type=int, default=1, help="timed graph launches per call (median recorded)")
    p.add_argument("--warm-s", type=float, default=0.0, help="untimed graph launches for this long first [s]")
    p.add_argument("--device", default="cuda:0")
    p.add_argument("--skip-sim", action="store_true", help="do not build the G1 env for the step reference")
    p.add_argument("--paths", default=",".join(PATHS), help="comma list of compute() paths: fused, unfused")
    p.add_argument("--models", default=",".join(MODELS), help="comma list of model variants")
    p.add_argument("--variants", default="default", help="comma list of fused 3D-RFT kernel variants, or all")
    p.add_argument("--out", type=Path, default=Path("bench_contact"), help="output folder (bench_contact.json)")
    p.add_argument("--max-minutes", type=float, default=9.0, help="start no new record after this [min]")
    p.add_argument("--force", action="store_true", help="redo records already in the JSON")
    return p.parse_args(argv)


def _time_graph(fn: Callable[[], object], reps: int, device: str, repeat: int = 1, warm_s: float = 0.0) -> list[float]:
    """Seconds per call of ``fn`` in each of ``repeat`` timed runs of ``reps`` calls (one CUDA graph when on CUDA).

    One untimed graph launch first, repeated until ``warm_s`` seconds have passed (GPU clocks up from idle).
    """
    import warp as wp

    fn()  # compile + warm up
    wp.synchronize()
    graph = None
    if wp.get_device(device).is_cuda:
        with wp.ScopedCapture(device=device) as cap:
            for _ in range(reps):
                fn()
        graph = cap.graph
        assert graph is not None
        t_warm = time.perf_counter()
        wp.capture_launch(graph)  # warm
        wp.synchronize()
        while time.perf_counter() - t_warm < warm_s:
            wp.capture_launch(graph)
            wp.synchronize()

    def launch() -> None:
        if graph is None:
            for _ in range(reps):
                fn()
        else:
            wp.capture_launch(graph)

    runs = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        launch()
        wp.synchronize()
        runs.append((time.perf_counter() - t0) / reps)
    return runs


def _timed(calls: dict[str, Callable[[], object]], args: argparse.Namespace) -> dict[str, Any]:
    """Return ``<call>_s`` (median over ``--repeat`` timed runs) and, when repeat > 1, ``<call>_s_runs``."""
    rec: dict[str, Any] = {}
    for k, fn in calls.items():
        runs = _time_graph(fn, args.reps, args.device, args.repeat, args.warm_s)
        rec[f"{k}_s"] = float(np.median(runs))
        if args.repeat > 1:
            rec[f"{k}_s_runs"] = runs
    return rec


def _gpu_clocks() -> str | None:
    """Return nvidia-smi's SM / max SM / memory clocks [MHz], power [W], temperature [C] and throttle reasons."""
    import subprocess

    query = "clocks.sm,clocks.max.sm,clocks.mem,power.draw,temperature.gpu,clocks_throttle_reasons.active"
    try:
        out = subprocess.run(
            ["nvidia-smi", f"--query-gpu={query}", "--format=csv,noheader"], capture_output=True, text=True, timeout=20
        )
    except (OSError, subprocess.TimeoutExpired):
        return None
    return f"{query}: {out.stdout.strip()}" if out.returncode == 0 else None


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
        wp.zeros(shape, dtype=wp.spatial_vectorf, device=device),
    )


def _model_cfgs(faces: Literal["sole", "box"]) -> dict[str, Any]:
    """Return the benchmarked model configs on the 5x5 G1 foot collider with ``faces`` (sole or box)."""
    from gmloco.contact import (
        ColliderBoxCfg,
        ContactConeMultiCfg,
        ContactConeSingleCfg,
        ContactHeuristicRFTCfg,
        ContactRFT3DCfg,
    )

    collider = ColliderBoxCfg(faces=faces, resolution=5)
    return {
        "rft3d": ContactRFT3DCfg(collider=collider),
        "rft3d_viscous": ContactRFT3DCfg(collider=collider, static_friction=False),
        "heuristic_rft": ContactHeuristicRFTCfg(collider=collider),
        "cone_multi": ContactConeMultiCfg(collider=collider),
        "cone_single": ContactConeSingleCfg(),
    }


def _prepared_model(
    cfg: Any, num_worlds: int, device: str, fused: bool, variant: str = "default"
) -> tuple[Any, tuple[Any, ...]]:
    """Return a model on dry sand with its state at the benchmark pose (same branch mix as the timed loop)."""
    from gmloco.contact import MATERIAL_PRESETS, make_contact_model

    sand = MATERIAL_PRESETS["dry_sand"]
    model = make_contact_model(cfg, num_worlds, 2, device)
    model.fused = fused
    kernel_variant, model.point_outputs = split_variant(variant)
    if kernel_variant != "default":
        model.fused_variant = kernel_variant  # pyright: ignore[reportAttributeAccessIssue] (3D-RFT models only)
    w = np.ones(num_worlds)
    model.set_materials(w * sand.rho_c, w * sand.mu_int, w * sand.mu_surf)
    state = _foot_state(num_worlds, device)
    model.update_state(*state[:5])  # z_max and anchors at the current pose
    return model, state


def _wrench_rel_diff(cfg: Any, num_worlds: int, device: str) -> float:
    """Max |W_fused - W_unfused| / max |W_unfused| of one compute() on the benchmark state."""
    out = []
    for fused in (True, False):
        model, state = _prepared_model(cfg, num_worlds, device, fused)
        model.compute(*state)
        out.append(state[5].numpy().astype(np.float64))
    return float(np.abs(out[0] - out[1]).max() / max(np.abs(out[1]).max(), 1e-30))


FACES: tuple[tuple[Literal["sole", "box"], int], ...] = (("sole", 25), ("box", 150))
"""Collider faces and the points per foot they give at resolution 5."""


def record_keys(
    models: list[str], paths: list[str], variants: tuple[str, ...] = ("default",)
) -> list[tuple[str, str, Literal["sole", "box"], str, str]]:
    """Return (key, model, faces, path, variant) of every record, in run order.

    Non-default ``variants`` add fused 3D-RFT records ``<key>/<variant>`` right after the default fused record.
    """
    keys = []
    for faces, points in FACES:
        for name in models:
            if name == "cone_single" and faces == "box":
                continue  # one point per foot whatever the collider
            for path in paths:
                key = f"{name}/{points if name != 'cone_single' else 1}pt" + ("" if path == "fused" else f"/{path}")
                keys.append((key, name, faces, path, "default"))
                if path == "fused" and name in VARIANT_MODELS:
                    keys += [(f"{key}/{v}", name, faces, path, v) for v in variants if v != "default"]
    return keys


def _launches(fn: Callable[[], object]) -> list[str]:
    """Return the kernel names ``fn`` launches, in order (``wp.launch`` / ``wp.launch_tiled`` intercepted once)."""
    import warp as wp

    names: list[str] = []
    originals = wp.launch, wp.launch_tiled

    def recorder(original: Callable[..., Any]) -> Callable[..., Any]:
        def record(kernel: Any, *a: Any, **kw: Any) -> Any:
            names.append(kernel.key)
            return original(kernel, *a, **kw)

        return record

    wp.launch, wp.launch_tiled = recorder(originals[0]), recorder(originals[1])
    try:
        fn()
    finally:
        wp.launch, wp.launch_tiled = originals
    return names


def _step_vs_two_calls(cfg: Any, num_worlds: int, device: str, fused: bool) -> float:
    """Max |x_step - x_two| / max |x_two| over the wrench and every state array after one substep.

    x_step: ``compute_and_update_state()``; x_two: ``compute(); update_state()``; both from the benchmark state
    (0 expected: same element functions, same sum order).
    """
    out = []
    for one_call in (True, False):
        model, state = _prepared_model(cfg, num_worlds, device, fused)
        if one_call:
            model.compute_and_update_state(*state)
        else:
            model.compute(*state)
            model.update_state(*state[:5])
        arrays = [state[5], model.depth_max, model.ema_tau, model.vel_prev, model.anchor, model.force_prev]
        out.append([a.numpy().astype(np.float64) for a in arrays])
    return max(float(np.abs(a - b).max() / max(np.abs(b).max(), 1e-30)) for a, b in zip(*out, strict=True))


STATE_ARRAYS = ("depth_max", "ema_tau", "vel_prev", "anchor", "force_prev")
POINT_ARRAYS = ("point_force", "point_depth", "point_vel")


def _variant_vs_default(cfg: Any, num_worlds: int, device: str, variant: str) -> float:
    """Max relative difference of a variant to the default fused kernels (0 expected).

    From the benchmark state, compute() then compute_and_update_state() on both; compared after each: the wrench
    and the per-point outputs, and after the step also every state array.
    """
    outs: list[list[np.ndarray]] = []
    points = POINT_ARRAYS if split_variant(variant)[1] else ()  # without point outputs: wrench and state only
    for v in ("default", variant):
        model, state = _prepared_model(cfg, num_worlds, device, True, v)
        arrays = []
        model.compute(*state)
        arrays += [state[5].numpy().copy(), *(getattr(model, n).numpy().copy() for n in points)]
        model.compute_and_update_state(*state)
        arrays += [state[5].numpy().copy(), *(getattr(model, n).numpy().copy() for n in (*points, *STATE_ARRAYS))]
        outs.append([a.astype(np.float64) for a in arrays])
    return max(float(np.abs(a - b).max() / max(np.abs(b).max(), 1e-30)) for b, a in zip(*outs, strict=True))


def bench_variant_record(name: str, faces: Literal["sole", "box"], variant: str, args: argparse.Namespace) -> dict:
    """Seconds per call of a fused 3D-RFT kernel variant's compute (and step), with its difference to the default."""
    cfg = _model_cfgs(faces)[name]
    model, state = _prepared_model(cfg, args.num_worlds, args.device, True, variant)
    calls: dict[str, Callable[[], object]] = {
        "compute": lambda: model.compute(*state),
        "step": lambda: model.compute_and_update_state(*state),
    }
    rec: dict[str, Any] = {"variant": variant}
    rec.update(_timed(calls, args))
    rec["launches"] = {k: _launches(fn) for k, fn in calls.items()}
    rec["max_rel_diff_vs_default"] = _variant_vs_default(cfg, args.num_worlds, args.device, variant)
    return rec


def bench_record(
    name: str, faces: Literal["sole", "box"], path: str, args: argparse.Namespace, paths: list[str]
) -> dict[str, Any]:
    """Seconds per call of one model's compute / update_state / compute_and_update_state on one path.

    ``launches`` names the kernels each timed call launches (recorded, not assumed).
    """
    cfg = _model_cfgs(faces)[name]
    model, state = _prepared_model(cfg, args.num_worlds, args.device, path == "fused")
    calls: dict[str, Callable[[], object]] = {"compute": lambda: model.compute(*state)}
    if model.is_stateful:
        calls["update_state"] = lambda: model.update_state(*state[:5])
        calls["step"] = lambda: model.compute_and_update_state(*state)
    rec: dict[str, Any] = _timed(calls, args)
    if path == "fused" and name in VARIANT_MODELS:
        rec["variant"] = "default"
    rec["launches"] = {k: _launches(fn) for k, fn in calls.items()}
    if path == "fused" and "unfused" in paths:
        rec["wrench_max_rel_diff_vs_unfused"] = _wrench_rel_diff(cfg, args.num_worlds, args.device)
    if model.is_stateful:
        rec["step_max_rel_diff_vs_two_calls"] = _step_vs_two_calls(cfg, args.num_worlds, args.device, path == "fused")
    return rec


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


def _write(path: Path, res: dict[str, Any]) -> None:
    """Write ``res`` as JSON through a temporary file and os.replace (atomic)."""
    tmp = path.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(res, indent=1))
    os.replace(tmp, path)


def _device_name(device: str) -> str:
    """Return the GPU name (torch) or "cpu"."""
    if not device.startswith("cuda"):
        return "cpu"
    import torch

    return torch.cuda.get_device_name(torch.device(device))


def _shares(res: dict[str, Any]) -> None:
    """Add each record's per-substep contact cost / G1 substep when the substep was measured.

    ``share_of_substep``: compute + update_state (two calls); ``share_of_substep_step``: compute_and_update_state
    (stateful models; one launch on the fused 3D-RFT path).
    """
    step = res.get("g1_substep_s")
    for rec in res["models"].values():
        if step:
            if "update_state_s" in rec or "max_rel_diff_vs_default" not in rec:  # variants: no update_state
                rec["share_of_substep"] = (rec["compute_s"] + rec.get("update_state_s", 0.0)) / step
            if "step_s" in rec:
                rec["share_of_substep_step"] = rec["step_s"] / step


def main(argv: list[str] | None = None) -> int:
    """Run (or continue) the benchmark, write one JSON; return 0 when complete, 3 when the time box stopped it."""
    args = _parse(argv)
    t_start = time.perf_counter()
    os.environ.setdefault("MUJOCO_GL", "disable")
    import warp as wp

    wp.init()
    paths, models = args.paths.split(","), args.models.split(",")
    variants = all_variants() if args.variants == "all" else tuple(args.variants.split(","))
    unknown = sorted({*paths} - {*PATHS}) + sorted({*models} - {*MODELS}) + sorted({*variants} - {*all_variants()})
    if unknown:
        print(f"unknown path / model / variant {unknown}: paths are {PATHS}, models {MODELS}", file=sys.stderr)
        return 2
    args.out.mkdir(parents=True, exist_ok=True)
    out_file = args.out / "bench_contact.json"
    res: dict[str, Any] = json.loads(out_file.read_text()) if out_file.exists() and not args.force else {}
    setup = {"device": _device_name(args.device), "num_worlds": args.num_worlds, "reps": args.reps}
    setup.update(repeat=args.repeat, warm_s=args.warm_s)
    if res and {k: res.get(k) for k in setup} != setup:
        print(f"{out_file} holds another setup {[res.get(k) for k in setup]}; use --force or another --out")
        return 2
    res.update(setup, paths=paths, variants=list(variants), models=res.get("models", {}), complete=False)
    todo = [r for r in record_keys(models, paths, variants) if r[0] not in res["models"]]
    want_sim = not args.skip_sim and "g1_substep_s" not in res
    for key, name, faces, path, variant in todo:
        if time.perf_counter() - t_start > 60.0 * args.max_minutes:
            break
        if variant == "default":
            res["models"][key] = bench_record(name, faces, path, args, paths)
        else:
            res["models"][key] = bench_variant_record(name, faces, variant, args)
        if args.device.startswith("cuda"):  # clocks right after the record (lower SM clock: slower kernels)
            res.setdefault("gpu_clocks", {})[key] = _gpu_clocks()
        print(key, res["models"][key], flush=True)
        _write(out_file, res)
    else:
        if want_sim and time.perf_counter() - t_start < 60.0 * args.max_minutes:
            res.update(bench_step(args.num_worlds, args.device))
        res["complete"] = all(k in res["models"] for k, *_ in record_keys(models, paths, variants)) and (
            args.skip_sim or "g1_substep_s" in res
        )
    _shares(res)
    _write(out_file, res)
    print(json.dumps(res, indent=1))
    return 0 if res["complete"] else 3


if __name__ == "__main__":
    sys.exit(main())
