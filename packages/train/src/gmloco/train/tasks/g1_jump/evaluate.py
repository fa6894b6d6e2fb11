# SPDX-License-Identifier: Apache-2.0
r"""Score jump policies in the training simulator: ``python -m gmloco.train.tasks.g1_jump.evaluate``.

Example (the two policies of issue 39, 20 attempts per medium, on the GPU)::

    python -m gmloco.train.tasks.g1_jump.evaluate \
        --run ppo_rft3d=runs/jump_rft3d/gpu/train_teacher --run ppo_rigid=runs/jump_rigid/gpu/train_teacher \
        --device cuda:0 --out results/jump

Every policy jumps ``--attempts`` times on each ``--materials`` preset with 3D-RFT sand contact (the training
simulator), unassisted, from the reference's first frame. Writes ``<out>/summary.json`` keyed
``policy -> medium -> "training_sim" -> {success_pct, height_error_pct, takeoff_slip_cm, sinkage_cm, episodes}``,
(a metric with no value, e.g. the take-off slip of policies that never took off, is null),
``<out>/fig_jump_trace.png`` (pelvis height and sole depth of each policy's first attempt on the first material)
and ``<out>/manifest.json`` (the command and settings). Bad arguments exit with code 2.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from gmloco.deploy.atomic_io import atomic_write_json

__all__ = ["main"]

SIMULATOR = "training_sim"
"""Simulator key of these results (MPM results come from ``gmloco.eval``)."""
MODULE = "gmloco.train.tasks.g1_jump.evaluate"
"""Module path written into the manifest."""


def _finite(obj: object) -> object:
    """``obj`` with every non-finite float replaced by None (strict JSON has no NaN)."""
    if isinstance(obj, dict):
        return {k: _finite(v) for k, v in obj.items()}
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


def _write_json(path: Path, payload: object) -> None:
    """Write ``payload`` as strict JSON to ``path`` atomically (NaN becomes null)."""
    atomic_write_json(path, _finite(payload), allow_nan=False, newline=True)


def _parse_runs(items: list[str]) -> dict[str, Path]:
    """``name=dir`` pairs; raise ValueError naming the bad one."""
    runs = {}
    for item in items:
        name, sep, folder = item.partition("=")
        if not sep or not name or not folder:
            raise ValueError(f"--run {item!r}: expected NAME=RUN_DIR, e.g. ppo_rft3d=runs/jump_rft3d/gpu/train_teacher")
        if not (Path(folder) / "train_cfg.json").is_file():
            raise ValueError(f"--run {item!r}: {folder} has no train_cfg.json; pass a jump run's train_teacher folder")
        runs[name] = Path(folder)
    return runs


def _parser() -> argparse.ArgumentParser:
    """Command-line options."""
    p = argparse.ArgumentParser(prog=f"python -m {MODULE}", description=(__doc__ or "").splitlines()[0])
    p.add_argument("--run", action="append", required=True, help="NAME=RUN_DIR of a jump training run (repeat)")
    p.add_argument("--materials", nargs="+", default=["basalt", "dry_sand", "poppy_seed"], help="material presets")
    p.add_argument("--attempts", type=int, default=20, help="jumps per policy and material")
    p.add_argument("--device", default="cpu", help="torch / warp device, e.g. cuda:0")
    p.add_argument("--out", type=Path, default=Path("results/jump"), help="output folder")
    return p


def _check(args: argparse.Namespace) -> dict[str, Path]:
    """Validate the arguments; raise ValueError with the fix."""
    import gmloco.contact as gc  # here, not at the top: it pulls Warp, which --help does not need

    unknown = sorted(set(args.materials) - set(gc.MATERIAL_PRESETS))
    if unknown:
        raise ValueError(f"--materials {unknown}: not presets; choose from {sorted(gc.MATERIAL_PRESETS)}")
    if args.attempts < 1:
        raise ValueError(f"--attempts {args.attempts}: must be >= 1")
    return _parse_runs(args.run)


def main(argv: list[str] | None = None) -> int:
    """Command-line entry; returns the exit code (2 on bad arguments)."""
    args = _parser().parse_args(argv)
    try:
        runs = _check(args)
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    from gmloco.train.tasks.g1_jump.evaluation import JumpEvalCfg, evaluate_jump_run, fig_jump_trace

    args.out.mkdir(parents=True, exist_ok=True)
    summary: dict[str, dict[str, dict[str, dict[str, float]]]] = {}
    first_traces = {}
    for name, run in runs.items():
        for material in args.materials:
            cfg = JumpEvalCfg(contact_model="rft3d", material=material, attempts=args.attempts, device=args.device)
            scores, traces = evaluate_jump_run(run, cfg)
            summary.setdefault(name, {})[material] = {SIMULATOR: scores}
            first_traces.setdefault(name, traces[0])
            print(f"{name} on {material}: {scores}")
    _write_json(args.out / "summary.json", summary)
    fig_jump_trace(first_traces, args.out / "fig_jump_trace.png")
    manifest = {
        "command": f"python -m {MODULE} " + " ".join(sys.argv[1:] if argv is None else argv),
        "runs": {k: str(v) for k, v in runs.items()},
        "materials": args.materials,
        "attempts": args.attempts,
        "simulator": "mjlab G1 + gmloco 3D-RFT sand contact (training simulator), assist off, no RSI, no DR",
    }
    _write_json(args.out / "manifest.json", manifest)
    return 0


if __name__ == "__main__":
    sys.exit(main())
