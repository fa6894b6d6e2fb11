"""One time-boxed, resumable chunk of GM-Loco teacher training or student distillation on the GPU machine.

    python scripts/gpu/train_ts_chunk.py --stage teacher --max-minutes 9 --out $OUT/gm_loco_teacher
    python scripts/gpu/train_ts_chunk.py --stage student --max-minutes 9 --out $OUT/gm_loco_student

1. Seeds the run directory (``runs/gpu/<run>``, kept on a warm machine) from ``artifacts/<run>/checkpoint.pt`` when
   it has no checkpoint yet (a fresh machine). The student's first chunk starts from the teacher: the newest
   ``runs/gpu/gm_loco_teacher/model_*.pt``, else ``artifacts/gm_loco_teacher/checkpoint.pt`` (``--teacher-checkpoint``
   overrides); later student chunks resume from their own checkpoint, which carries the frozen teacher.
2. Trains with :func:`gmloco.train.train` (``TeacherPPO`` / ``StudentPPO``; time box ``--max-minutes`` minus
   ``--post-minutes`` kept for step 3). The DR leaves out the held-out (rho_c, mu_int) region
   (:data:`gmloco.train.teacher_student.DEFAULT_HELD_OUT`) unless ``--no-held-out``.
3. Rebuilds the newest checkpoint on a small play-mode env and rolls it out on the training DR's materials in deep
   sand (no hard floor, as the evaluations; the curriculum's floor would sit at the surface in play mode): R^2 / MAE of the
   decoded eta (teacher: psi(mu); student: psi(z_hat) and the teacher's psi(mu) on the student's states) and the
   student-vs-teacher action error. For the student it also exports ``policy.onnx`` (+ ``policy.json``) with deploy
   metadata and checks it against torch on random inputs and in a rollout with env resets (``OnnxPolicyRunner``).
4. Writes to ``--out``: ``checkpoint.pt`` (newest; without the optimizer state unless ``--full-checkpoint``: a run
   resumed from it starts a fresh Adam), ``summary.json`` (train metrics, post-training checks, config,
   this machine's curves from TensorBoard: reward, episode length, fps and every ``Loss/*`` term incl. the
   eta reconstruction / KL / eta R^2 of the teacher and the distillation terms of the student), and for the student
   ``policy.onnx`` + ``policy.json``.

``scripts/gpu/collect_chunk.py --run gm_loco_teacher|gm_loco_student`` (run here) merges a chunk into ``artifacts/``.
"""

from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
import time
from dataclasses import replace
from pathlib import Path
from typing import Any

RUNS = {"teacher": "gm_loco_teacher", "student": "gm_loco_student"}
"""Default run name per stage (``artifacts/<run>/``, ``runs/gpu/<run>/``)."""
DEFAULT_ITERATIONS = {"teacher": 5000, "student": 2000}
"""Total iterations per stage (``conf/exp/gm_loco.yaml``)."""
CURVE_TAGS = {
    "Train/mean_reward": "mean_reward",
    "Train/mean_episode_length": "mean_episode_length",
    "Perf/total_fps": "env_steps_per_s",
    "Policy/mean_std": "action_std",
    "Metrics/twist/error_vel_yaw": "yaw_rate_error",
    "Metrics/twist/error_heading": "heading_error",
    "Episode_Reward/track_yaw_target_exp": "reward_track_yaw_target",
    "Episode_Reward/track_ang_vel_z_exp": "reward_track_ang_vel_z",
    "Curriculum/sand_floor_levels/depth_mean": "floor_depth_m",
}
"""TensorBoard scalars of the curve besides the ``Loss/*`` terms (which are all taken); the yaw-tracking ones feed
the yaw panel of ``gmloco.train.learning_curves``, the floor depth its floor panel."""


def _parse(argv: list[str] | None) -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--stage", required=True, choices=sorted(RUNS))
    p.add_argument("--run", default=None, help="run name (default gm_loco_teacher / gm_loco_student)")
    p.add_argument(
        "--contact-model",
        default="rft3d",
        choices=["rft3d", "rft3d_calibrated", "heuristic_rft", "cone_multi", "rigid"],
    )
    p.add_argument("--terrain", default="flat", choices=["flat", "rough", "deep"])
    p.add_argument("--num-envs", type=int, default=4096)
    p.add_argument("--num-steps-per-env", type=int, default=24)
    p.add_argument("--max-iterations", type=int, default=None, help="total (default 5000 teacher, 2000 student)")
    p.add_argument("--max-minutes", type=float, default=9.0, help="whole call, post-training checks included")
    p.add_argument("--post-minutes", type=float, default=1.5, help="part of the budget kept for step 3")
    p.add_argument("--save-interval", type=int, default=50)
    p.add_argument("--history-length", type=int, default=50, help="N (1 s at 50 Hz)")
    p.add_argument("--latent-dim", type=int, default=16)
    p.add_argument("--curriculum-finish", type=int, default=1000, help="student: w_PPO / w_dist ramp end")
    p.add_argument(
        "--decoder-loss-weight",
        type=float,
        default=1.0,
        help="student: weight of (psi(z) - psi(z_hat))^2 (paper 1; the first run's 16-D latent error was ~7,000x the "
        "decoded-eta error, so the TCN learned z's non-terrain part first)",
    )
    p.add_argument("--no-held-out", action="store_true", help="let the DR draw the held-out region too")
    p.add_argument(
        "--reward-weight",
        action="append",
        default=[],
        metavar="NAME=WEIGHT",
        help="override one reward term's weight (repeatable; 0 drops the term), e.g. foot_clearance_l2=-50; "
        "pass the same overrides to every chunk of a run (the task is rebuilt from the arguments each chunk)",
    )
    p.add_argument(
        "--foot-clearance",
        choices=["penalty", "reward", "touchdown", "sinkage"],
        default=None,
        help="GranularTaskCfg.foot_clearance (default: the task's, the L2 penalty); 'touchdown' pays each swing's "
        "lift out of the footprint at touchdown; 'sinkage' as touchdown with a swing target of 9 cm above the surface "
        "plus the footprint's depth; pass the same value to every chunk of a run",
    )
    p.add_argument(
        "--foot-faces",
        choices=["sole", "box"],
        default=None,
        help="GranularTaskCfg.foot_faces (default: the task's, the sole only); 'box' samples all six faces of the "
        "foot box, so a buried swinging foot meets sand; pass the same value to every chunk of a run",
    )
    p.add_argument(
        "--floor-promotion",
        choices=["distance", "survival"],
        default=None,
        help="SandFloorCfg.promotion of the floor-depth curriculum (default: the task's, 'distance'); 'survival' "
        "lowers the floor after an episode that ran to its time limit and raises it after a fall; pass the same "
        "value to every chunk of a run",
    )
    p.add_argument(
        "--floor-depth-max",
        type=float,
        default=None,
        help="deepest floor of the floor-depth curriculum [m] (SandFloorCfg.depth_range's upper end; default: the "
        "task's, GM-Loco's 0.12); 0.30 puts the top levels below any foot, as the gate's and MPM's deep beds",
    )
    p.add_argument(
        "--floor-levels",
        type=int,
        default=None,
        help="number of levels of the floor-depth curriculum (SandFloorCfg.num_levels; default: the task's, 10); "
        "a resumed chunk puts each env at the level nearest to the floor depth its checkpoint saved",
    )
    p.add_argument(
        "--rft-extension-range",
        action="append",
        default=[],
        metavar="NAME=LO,HI",
        help="draw one fitted term of rft3d_calibrated per env from U[LO, HI] on reset (repeatable; "
        "GranularTaskCfg.rft_extension_ranges; NAME one of the per-world RftExtensionsCfg fields), e.g. "
        "added_mass=1,10; default: the fitted values",
    )
    p.add_argument(
        "--soft-share",
        type=float,
        default=None,
        help="share of the material draws whose rho_c comes from MaterialRangeCfg.soft_rho_c (500-800 kg/m^3, "
        "poppy seed's 638 inside) instead of packing x bulk density (default: the task's, 0, GM-Loco's draw); a "
        "resumed run names task.material.soft_share in --allow-changed",
    )
    p.add_argument(
        "--allow-changed",
        action="append",
        default=[],
        metavar="KEY",
        help="config key (dotted, or a prefix such as task.reward_weights) a resumed chunk may change on purpose "
        "(repeatable); without it a chunk whose config differs from the run's train_cfg.json is refused",
    )
    p.add_argument("--teacher-checkpoint", type=Path, default=None)
    p.add_argument(
        "--warm-start-ppo",
        type=Path,
        default=None,
        help="teacher: start a fresh run from this PPO checkpoint's actor and critic (e.g. artifacts/ppo_rft3d/checkpoint.pt)",
    )
    p.add_argument(
        "--warm-start-encoder",
        type=Path,
        default=None,
        help="student, first chunk of a new run: start the history encoder from this earlier student checkpoint "
        "(e.g. artifacts/gm_loco_student_clr50/checkpoint.pt) instead of from scratch",
    )
    p.add_argument(
        "--entropy-coef",
        type=float,
        default=None,
        help="teacher: PpoCfg.entropy_coef (default: the package's 0.005); a resumed run names "
        "rsl_rl_overrides.algorithm.entropy_coef in --allow-changed",
    )
    p.add_argument(
        "--curriculum-scale",
        type=float,
        default=None,
        help="GranularTaskCfg.curriculum_scale (default: the run's saved value; student: the teacher's)",
    )
    p.add_argument(
        "--full-checkpoint",
        action="store_true",
        help="bring back the optimizer state too (default: a slim checkpoint.pt, ~1/3 of the size, for artifacts/)",
    )
    p.add_argument(
        "--post-only",
        type=Path,
        default=None,
        help="no training: run step 3 (checks, student export) on this checkpoint, e.g. on a CPU when a chunk ended "
        "before them; --runs-root/<run> holds the chunk's metrics.json and TensorBoard events",
    )
    p.add_argument("--check-envs", type=int, default=64, help="envs of the post-training rollout")
    p.add_argument("--check-steps", type=int, default=250, help="steps of the post-training rollout (5 s)")
    p.add_argument("--check-warmup", type=int, default=50, help="steps after a reset left out of the eta metrics")
    p.add_argument("--parity-steps", type=int, default=40, help="student: ONNX rollout check steps")
    p.add_argument("--seed", type=int, default=42)
    p.add_argument("--device", default="cuda:0")
    p.add_argument("--runs-root", type=Path, default=Path("runs/gpu"))
    p.add_argument("--artifacts", type=Path, default=Path("artifacts"))
    p.add_argument("--out", type=Path, required=True)
    p.add_argument(
        "--gpus",
        type=int,
        nargs="+",
        default=[],
        help="CUDA device ids trained on data-parallel, one rank each (TrainRunCfg.gpus); default: --device alone",
    )
    args = p.parse_args(argv)
    if args.floor_depth_max is not None and not 0.0 < args.floor_depth_max <= 1.0:
        p.error(f"--floor-depth-max {args.floor_depth_max}: give the deepest floor in (0, 1] m, e.g. 0.30")
    if args.floor_levels is not None and not 2 <= args.floor_levels <= 100:
        p.error(f"--floor-levels {args.floor_levels}: give 2 to 100 levels, e.g. 11 (2 cm steps over 0-20 cm)")
    if args.entropy_coef is not None and (args.stage != "teacher" or not args.entropy_coef >= 0):
        p.error(f"--entropy-coef {args.entropy_coef}: a number >= 0, for --stage teacher only, e.g. 0.001")
    if args.soft_share is not None and not 0.0 <= args.soft_share <= 1.0:
        p.error(f"--soft-share {args.soft_share}: give a share in [0, 1], e.g. 0.25")
    args.rft_extension_ranges = {}
    for item in args.rft_extension_range:
        if (parsed := extension_range(item)) is None:
            p.error(
                f"--rft-extension-range {item!r}: expected NAME=LO,HI with NAME in {', '.join(_ext_columns())} and "
                "0 <= LO <= HI, e.g. added_mass=1,10"
            )
        args.rft_extension_ranges[parsed[0]] = parsed[1]
    if args.gpus:
        from gmloco.train.multi_gpu import cuda_device_count, gpus_problem

        if (problem := gpus_problem(args.gpus, cuda_device_count())) is not None:
            p.error(f"--gpus {' '.join(map(str, args.gpus))}: {problem}")
    return args


def _newest(folder: Path) -> Path | None:
    """Newest ``model_<it>.pt`` in ``folder``."""
    from gmloco.train.rl.runner import latest_checkpoint

    return latest_checkpoint(folder) if folder.is_dir() else None


def _seed_run_dir(run_dir: Path, artifact: Path) -> int | None:
    """Copy the committed checkpoint and its run config into an empty run directory; return its iteration.

    The config (``train_cfg.json``, else the ``train_cfg`` of a chunk's ``summary.json``) is what the resume check
    of ``gmloco.train.resume`` compares the chunk's config with.
    """
    if _newest(run_dir) is not None or not (artifact / "checkpoint.pt").exists():
        return None
    import torch

    it = int(torch.load(artifact / "checkpoint.pt", map_location="cpu", weights_only=False)["iter"])
    shutil.copy(artifact / "checkpoint.pt", run_dir / f"model_{it}.pt")
    if (artifact / "train_cfg.json").exists():
        shutil.copy(artifact / "train_cfg.json", run_dir / "train_cfg.json")
    elif (artifact / "summary.json").exists():
        saved = json.loads((artifact / "summary.json").read_text()).get("train_cfg")
        if saved:
            (run_dir / "train_cfg.json").write_text(json.dumps(saved, indent=1))
    return it


def _copy_checkpoint(src: Path, dst: Path, slim: bool) -> None:
    """Copy a checkpoint; ``slim`` drops the optimizer state (resuming from it starts a fresh Adam).

    Every committed file travels with each device call (64 MiB in all, wheel parts included); the teacher's Adam
    state is two thirds of its 22 MB checkpoint. The run directory on the machine keeps the full checkpoints.
    """
    if not slim:
        shutil.copy(src, dst)
        return
    import torch

    ckpt = torch.load(src, map_location="cpu", weights_only=False)
    ckpt.pop("optimizer_state_dict", None)
    torch.save(ckpt, dst)


def _teacher_checkpoint(args: argparse.Namespace) -> Path:
    """The teacher the student starts from (see the module docstring for the order)."""
    for path in (args.teacher_checkpoint, _newest(args.runs_root / RUNS["teacher"])):
        if path is not None:
            return Path(path)
    committed = args.artifacts / RUNS["teacher"] / "checkpoint.pt"
    if committed.exists():
        return committed
    sys.exit(f"no teacher checkpoint: pass --teacher-checkpoint or train the teacher first ({committed} missing)")


def _curriculum_scale(args: argparse.Namespace) -> float | None:
    """``--curriculum-scale``, else the run's saved value, else (student) the teacher run's; None: task default."""
    if args.curriculum_scale is not None:
        return args.curriculum_scale
    run = args.run or RUNS[args.stage]
    candidates = [args.runs_root / run / "train_cfg.json"]
    if args.stage == "student":
        teacher = RUNS["teacher"]
        candidates += [args.runs_root / teacher / "train_cfg.json", args.artifacts / teacher / "train_cfg.json"]
    for path in candidates:
        if path.exists():
            return json.loads(path.read_text())["task"].get("curriculum_scale")
    return None


def _ext_columns() -> tuple[str, ...]:
    """The per-world fitted-term names that the DR may draw (``gmloco.contact.kernels_rft3d_ext.EXT_COLUMNS``)."""
    from gmloco.contact.kernels_rft3d_ext import EXT_COLUMNS

    return EXT_COLUMNS


def extension_range(item: str) -> tuple[str, tuple[float, float]] | None:
    """Parse ``NAME=LO,HI`` into ``(NAME, (LO, HI))``; None when malformed, unknown or not 0 <= LO <= HI."""
    name, sep, values = item.partition("=")
    parts = values.split(",")
    if not sep or name not in _ext_columns() or len(parts) != 2:
        return None
    try:
        lo, hi = float(parts[0]), float(parts[1])
    except ValueError:
        return None
    return (name, (lo, hi)) if 0.0 <= lo <= hi else None


def reward_weights(items: list[str]) -> dict[str, float]:
    """Parse ``--reward-weight NAME=WEIGHT`` items into ``GranularTaskCfg.reward_weights``; exit on a malformed one."""
    out: dict[str, float] = {}
    for item in items:
        name, sep, value = item.partition("=")
        try:
            if not sep or not name.strip():
                raise ValueError(item)
            out[name.strip()] = float(value)
        except ValueError:
            sys.exit(f"--reward-weight {item!r}: expected NAME=WEIGHT with a number, e.g. foot_clearance_l2=-50")
    return out


def _task(args: argparse.Namespace) -> Any:
    """The granular task: one actor frame (history goes through the encoders), DR without the held-out region."""
    from gmloco.train import g1_granular_task
    from gmloco.train.teacher_student.heldout import with_held_out

    task = replace(g1_granular_task(args.contact_model, args.terrain), policy_history_length=1)
    if args.foot_clearance is not None:
        task = replace(task, foot_clearance=args.foot_clearance)
    if args.foot_faces is not None:
        task = replace(task, foot_faces=args.foot_faces)
    if args.floor_promotion is not None:
        from gmloco.train.config import FloorPromotion

        floor = replace(task.terrain.floor, promotion=FloorPromotion(args.floor_promotion))
        task = replace(task, terrain=replace(task.terrain, floor=floor))
    if args.floor_depth_max is not None:
        floor = replace(task.terrain.floor, depth_range=(task.terrain.floor.depth_range[0], args.floor_depth_max))
        task = replace(task, terrain=replace(task.terrain, floor=floor))
    if args.floor_levels is not None:
        floor = replace(task.terrain.floor, num_levels=args.floor_levels)
        task = replace(task, terrain=replace(task.terrain, floor=floor))
    if args.rft_extension_ranges:
        task = replace(task, rft_extension_ranges=dict(args.rft_extension_ranges))
    if args.soft_share is not None:
        task = replace(task, material=replace(task.material, soft_share=args.soft_share))
    weights = reward_weights(args.reward_weight)
    if weights:
        task = replace(task, reward_weights=weights)
    scale = _curriculum_scale(args)
    if scale is not None:
        task = replace(task, curriculum_scale=scale)
    if args.no_held_out:
        return task
    try:
        return with_held_out(task)
    except (NotImplementedError, ValueError) as err:
        sys.exit(f"{err}; the DR would draw the held-out materials too. Run with --no-held-out to accept that.")


def _entries(args: argparse.Namespace) -> dict[str, Any]:
    """rsl-rl entries of the stage (paper network sizes, package defaults)."""
    from gmloco.train.teacher_student import DistillCfg, ObsGroupsCfg, StudentCfg, TeacherCfg, student_train_entries

    teacher = TeacherCfg(latent_dim=args.latent_dim)
    if args.entropy_coef is not None:
        teacher = replace(teacher, ppo=replace(teacher.ppo, entropy_coef=args.entropy_coef))
    if args.stage == "teacher":
        return teacher.to_rsl_rl(ObsGroupsCfg())
    student = StudentCfg(history_length=args.history_length)
    distill = DistillCfg(curriculum_finish=args.curriculum_finish, decoder_loss_weight=args.decoder_loss_weight)
    return student_train_entries(teacher, student, distill)


def _curve(run_dir: Path) -> dict[str, list[float]]:
    """This machine's TensorBoard scalars by iteration: reward, episode length, fps, std and every Loss/* term."""
    from tensorboard.backend.event_processing.event_accumulator import EventAccumulator

    series: dict[int, dict[str, float]] = {}
    names: dict[str, str] = {}
    for events in sorted(run_dir.rglob("events.out.tfevents.*")):
        acc = EventAccumulator(str(events), size_guidance={"scalars": 0})
        acc.Reload()
        for tag in acc.Tags()["scalars"]:
            name = CURVE_TAGS.get(tag) or (tag.replace("Loss/", "loss_") if tag.startswith("Loss/") else None)
            if name is None:
                continue
            names[tag] = name
            for ev in acc.Scalars(tag):
                series.setdefault(ev.step, {})[name] = ev.value
    its = sorted(series)
    out: dict[str, list[float]] = {"iteration": [float(i) for i in its]}
    for name in sorted(set(names.values()) | set(CURVE_TAGS.values())):
        out[name] = [series[i].get(name, float("nan")) for i in its]
    return out


def _last_values(curve: dict[str, list[float]], window: int = 10) -> dict[str, float]:
    """Mean of the last ``window`` finite values of every curve column (per-term state at the end of the chunk)."""
    out = {}
    for name, values in curve.items():
        finite = [v for v in values[-window:] if v == v]  # drop NaN
        if name != "iteration" and finite:
            out[name] = sum(finite) / len(finite)
    return out


def _post_checks(args: argparse.Namespace, task: Any, checkpoint: Path, run_dir: Path) -> dict[str, Any]:
    """Decoded-eta rollout on the DR (deep sand, no floor); for the student also the ONNX export and parity checks."""
    import torch

    from gmloco.train.evaluation import RolloutCriteriaCfg
    from gmloco.train.evaluation_ts import decoded_eta_check
    from gmloco.train.teacher_student.export_student import (
        build_runner,
        export_student_onnx,
        rollout_parity_check,
        student_policy_metadata,
    )

    # Parity against onnxruntime needs full-precision convolutions: cuDNN's default TF32 puts the TCN 5e-4 off.
    torch.backends.cudnn.allow_tf32 = False
    torch.backends.cuda.matmul.allow_tf32 = False
    # Deep sand as in the evaluations: in play mode there is no floor curriculum, so the training floor would stay
    # at level 0 (at the surface) and the feet would never sink (nothing for the student to sense eta from).
    play = replace(task, play=True, terrain=replace(task.terrain, floor=RolloutCriteriaCfg().floor))
    runner = build_runner(
        play, _entries(args), args.history_length, checkpoint, args.device, args.check_envs, args.seed + 1
    )
    try:
        checks: dict[str, Any] = {}
        if args.stage == "student":
            commit = subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True).stdout.strip()
            metadata = student_policy_metadata(
                runner,
                task,
                args.history_length,
                args.latent_dim,
                f"{run_dir.name}/{checkpoint.name}",
                commit or "unknown",
            )
            path, err = export_student_onnx(runner, args.out / "policy.onnx", metadata)
            (args.out / "policy.json").write_text(json.dumps(metadata.to_dict(), indent=1))
            checks |= {"onnx_max_abs_diff": err}
            checks |= rollout_parity_check(runner, path, args.parity_steps, force_reset_after=args.parity_steps // 2)
        checks |= decoded_eta_check(runner, args.check_steps, args.check_warmup)
    finally:
        runner.env.close()
    return checks


def _write_summary(out: Path, summary: dict[str, Any], printed: dict[str, Any]) -> None:
    """Write ``summary.json`` (curves keep NaN, as train_chunk.py's, for collect_chunk.py) and print ``printed``."""
    from gmloco.train.evaluation_ts import finite_json

    clean = finite_json({k: v for k, v in summary.items() if k != "curve"}) | {"curve": summary["curve"]}
    (out / "summary.json").write_text(json.dumps(clean, indent=1, default=str))
    print(json.dumps(finite_json(printed), indent=1, default=str))


def _guarded_post_checks(args: argparse.Namespace, task: Any, checkpoint: Path, run_dir: Path) -> dict[str, Any]:
    """Step 3, whose failure (e.g. an export parity error) is recorded instead of losing the chunk's summary."""
    try:
        return _post_checks(args, task, checkpoint, run_dir)
    except Exception as err:  # the checkpoint is already in --out; rerun step 3 with --post-only
        import traceback

        traceback.print_exc()
        return {"post_check_error": f"{type(err).__name__}: {err}"}


def _post_only(args: argparse.Namespace, run: str, run_dir: Path, t0: float) -> dict[str, Any]:
    """Step 3 alone on ``--post-only``; the summary marks it, and takes metrics and curve from ``run_dir``."""
    ckpt = args.post_only
    _copy_checkpoint(ckpt, args.out / "checkpoint.pt", slim=not args.full_checkpoint)
    task = _task(args)
    checks = _guarded_post_checks(args, task, ckpt, run_dir)
    metrics_file, cfg_file = run_dir / "metrics.json", run_dir / "train_cfg.json"
    summary: dict[str, Any] = {
        "script": "scripts/gpu/train_ts_chunk.py",
        "run": run,
        "stage": args.stage,
        "post_only": str(ckpt),
        "args": {k: str(v) for k, v in vars(args).items()},
        "checkpoint": ckpt.name,
        "metrics": json.loads(metrics_file.read_text()) if metrics_file.exists() else {},
        "checks": checks,
        "train_cfg": json.loads(cfg_file.read_text()) if cfg_file.exists() else {},
        "curve": (curve := _curve(run_dir)),
        "last_values": _last_values(curve),
        "wall_s": time.monotonic() - t0,
        "device": args.device,
    }
    _write_summary(args.out, summary, {"checks": checks})
    return summary


def main(argv: list[str] | None = None) -> dict[str, Any]:
    """Run one chunk and write the files that come back; return the summary."""
    args = _parse(argv)
    t0 = time.monotonic()
    from gmloco.train import TrainRunCfg, train

    run = args.run or RUNS[args.stage]
    run_dir = args.runs_root / run
    run_dir.mkdir(parents=True, exist_ok=True)
    args.out.mkdir(parents=True, exist_ok=True)
    if args.post_only is not None:
        return _post_only(args, run, run_dir, t0)
    seeded = _seed_run_dir(run_dir, args.artifacts / run)
    init = None
    if args.stage == "student" and _newest(run_dir) is None:
        init = _teacher_checkpoint(args)
    task = _task(args)
    cfg = TrainRunCfg(
        task=task,
        num_envs=args.num_envs,
        max_iterations=args.max_iterations or DEFAULT_ITERATIONS[args.stage],
        max_minutes=args.max_minutes - args.post_minutes,
        seed=args.seed,
        device=args.device,
        gpus=tuple(args.gpus),
        run_dir=str(run_dir),
        save_interval=args.save_interval,
        num_steps_per_env=args.num_steps_per_env,
        export_onnx=False,
        rsl_rl_overrides=_entries(args),
        history_length=args.history_length,
        init_checkpoint=None if init is None else str(init),
        warm_start_ppo=None if args.stage != "teacher" or args.warm_start_ppo is None else str(args.warm_start_ppo),
        warm_start_student_encoder=None
        if init is None or args.warm_start_encoder is None
        else str(args.warm_start_encoder),
        allow_changed=tuple(args.allow_changed),
    )
    from gmloco.train.resume import ResumeError

    try:
        metrics = train(cfg)
    except ResumeError as err:
        print(f"train_ts_chunk: {err}", file=sys.stderr)
        sys.exit(2)
    ckpt = _newest(run_dir)
    assert ckpt is not None, f"train() left no checkpoint in {run_dir}"
    _copy_checkpoint(ckpt, args.out / "checkpoint.pt", slim=not args.full_checkpoint)
    t_post = time.monotonic()
    checks = _guarded_post_checks(args, task, ckpt, run_dir)
    import torch

    summary: dict[str, Any] = {
        "script": "scripts/gpu/train_ts_chunk.py",
        "run": run,
        "stage": args.stage,
        "args": {k: str(v) for k, v in vars(args).items()},
        "seeded_from_artifact_iteration": seeded,
        "teacher_checkpoint": None if init is None else str(init),
        "held_out_excluded": not args.no_held_out,
        "checkpoint": ckpt.name,
        "metrics": metrics,
        "checks": checks,
        "train_cfg": json.loads((run_dir / "train_cfg.json").read_text()),
        "curve": (curve := _curve(run_dir)),
        "last_values": _last_values(curve),
        "post_checks_s": time.monotonic() - t_post,
        "wall_s": time.monotonic() - t0,
        "commit": subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True).stdout.strip() or None,
        "device": torch.cuda.get_device_name(0) if torch.cuda.is_available() else "cpu",
    }
    _write_summary(args.out, summary, {"metrics": metrics, "checks": checks})
    return summary


if __name__ == "__main__":
    main()
