# SPDX-License-Identifier: Apache-2.0
"""Command line of the training gate (exit 2 on bad input).

Example: ``python -m gmloco.train.gate --policy artifacts/gm_loco_student_td --out results/training_gate/summary.json
--device cuda:0 --num-envs 1024``. A success-by-speed table in the calibrated simulator: ``--contact-model
rft3d_calibrated --parts success``.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Sequence
from dataclasses import replace

from gmloco.deploy.config_cli import Flag, add_flags, cfg_from_flags, check_flags
from gmloco.train.gate.config import GATE_PARTS, GateCfg, GatePart


def _parts(text: str) -> tuple[GatePart, ...]:
    """Parse ``"success,yaw"`` into gate parts (each once, in the summary's order)."""
    names = {x.strip() for x in text.split(",") if x.strip()}
    unknown = sorted(names - set(GATE_PARTS))
    if not names or unknown:
        raise argparse.ArgumentTypeError(f"{text!r}: unknown parts {unknown}; choose from {','.join(GATE_PARTS)}")
    return tuple(p for p in GATE_PARTS if p in names)


def _positive_float(text: str) -> float:
    """Parse a number > 0."""
    try:
        value = float(text)
    except ValueError:
        value = -1.0
    if not value > 0:
        raise argparse.ArgumentTypeError(f"{text!r}: expected a number > 0")
    return value


FLAGS: tuple[Flag, ...] = (
    Flag("--episodes", "repeats"),
    Flag("--seconds", "duration_s"),
    Flag("--num-envs", "num_envs"),
    Flag("--materials", "materials", sep=","),
    Flag("--speeds", "speeds", sep=","),
    Flag("--yaw-rates", "yaw_rates", sep=","),
    Flag("--held-out-grid", "held_out_grid", sep=","),
    Flag("--contact-model", "contact_model"),
    Flag("--rft-extensions", "rft_extensions_file"),
    Flag("--parts", "parts", sep=",", parse=_parts),
    Flag("--device", "device"),
    Flag("--seed", "seed"),
)
"""Every ``GateCfg`` field the command line sets (lists as one comma-separated word, as the recorded commands write
them); ``--policy``, ``--out`` and ``--floor-depth`` are the command line's own."""


def _parse(argv: Sequence[str] | None) -> argparse.Namespace:
    """Arguments (exit code 2 on a malformed or out-of-range one)."""
    p = argparse.ArgumentParser(prog="python -m gmloco.train.gate", description=(__doc__ or "").splitlines()[0])
    p.add_argument("--policy", required=True, help="run folder (GateCfg.policy_dir), e.g. artifacts/gm_loco_student_td")
    p.add_argument(
        "--out", required=True, help="summary JSON (GateCfg.out_path), e.g. results/training_gate/summary.json"
    )
    add_flags(p, GateCfg(), FLAGS)
    p.add_argument(
        "--floor-depth",
        type=_positive_float,
        default=None,
        help="feet meet a hard floor this far below the surface [m], as over the training floors (default: none, "
        "a 30 cm bed as on MPM)",
    )
    args = p.parse_args(argv)
    check_flags(p, args, GateCfg, FLAGS)
    return args


def _cfg(args: argparse.Namespace) -> GateCfg:
    """The gate config of the arguments; ValueError names a bad value."""
    import gmloco.contact as gc  # here, not at the top: it pulls Warp, which --help does not need

    floor = GateCfg().floor
    if args.floor_depth is not None:
        floor = replace(floor, enabled=True, depth_range=(args.floor_depth, args.floor_depth))
    cfg: GateCfg = cfg_from_flags(args, GateCfg(policy_dir=args.policy, out_path=args.out, floor=floor), FLAGS)
    if unknown := [m for m in cfg.materials if m not in gc.MATERIAL_PRESETS]:
        raise ValueError(
            f"--materials {','.join(cfg.materials)!r}: unknown {unknown}; choose from {sorted(gc.MATERIAL_PRESETS)}"
        )
    if any(w == 0.0 for w in cfg.yaw_rates):
        raise ValueError("--yaw-rates: 0 has no achieved/commanded ratio; straight walking is in --speeds")
    if cfg.held_out_grid[0] * cfg.held_out_grid[1] < 2:
        raise ValueError(
            f"--held-out-grid {','.join(map(str, cfg.held_out_grid))!r}: expected at least two points (R^2 of the "
            "decoded eta needs more than one material), e.g. 3,3"
        )
    if cfg.contact_model == "rft3d_calibrated":
        from gmloco.contact.extensions_io import load_rft_extensions  # Warp, as above

        load_rft_extensions(cfg.rft_extensions_file)  # a missing or malformed file stops here, before any env is built
    return cfg


def main(argv: Sequence[str] | None = None) -> int:
    """Run the gate; print the pass map; return the exit code (2: bad input)."""
    from gmloco.train.gate.policy import GateInputError

    args = _parse(argv)
    try:
        cfg = _cfg(args)
        from gmloco.train.gate.run import run_gate

        summary = run_gate(cfg)
    except (GateInputError, FileNotFoundError, ValueError) as err:
        print(f"gmloco.train.gate: {err}", file=sys.stderr)
        return 2
    print(json.dumps({"pass": summary["pass"], "out": args.out}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
