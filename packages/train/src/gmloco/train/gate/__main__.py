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
from typing import get_args

from gmloco.train.config import ContactModelName
from gmloco.train.gate.config import GATE_PARTS, GateCfg, GatePart


def _floats(text: str) -> tuple[float, ...]:
    """Parse ``"0.5,1.0"``."""
    try:
        values = tuple(float(x) for x in text.split(",") if x.strip())
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: expected comma-separated numbers, e.g. 0.5,1.0") from None
    if not values:
        raise argparse.ArgumentTypeError("expected at least one number")
    return values


def _positive_int(text: str) -> int:
    """Parse an integer >= 1."""
    if not text.isdigit() or int(text) < 1:
        raise argparse.ArgumentTypeError(f"{text!r}: expected an integer >= 1")
    return int(text)


def _positive_float(text: str) -> float:
    """Parse a number > 0."""
    try:
        value = float(text)
    except ValueError:
        value = -1.0
    if not value > 0:
        raise argparse.ArgumentTypeError(f"{text!r}: expected a number > 0")
    return value


def _parts(text: str) -> tuple[GatePart, ...]:
    """Parse ``"success,yaw"`` into gate parts (each once, in the summary's order)."""
    names = {x.strip() for x in text.split(",") if x.strip()}
    unknown = sorted(names - set(GATE_PARTS))
    if not names or unknown:
        raise argparse.ArgumentTypeError(f"{text!r}: unknown parts {unknown}; choose from {','.join(GATE_PARTS)}")
    return tuple(p for p in GATE_PARTS if p in names)


def _parse(argv: Sequence[str] | None) -> argparse.Namespace:
    """Arguments (argparse exits 2 on a malformed one)."""
    d = GateCfg()
    p = argparse.ArgumentParser(prog="python -m gmloco.train.gate", description=(__doc__ or "").splitlines()[0])
    p.add_argument("--policy", required=True, help="run folder, e.g. artifacts/gm_loco_student_td")
    p.add_argument("--out", required=True, help="summary JSON, e.g. results/training_gate/summary.json")
    p.add_argument("--episodes", type=_positive_int, default=d.repeats, help="episodes per cell")
    p.add_argument("--seconds", type=_positive_float, default=d.duration_s, help="episode length [s]")
    p.add_argument("--num-envs", type=_positive_int, default=d.num_envs, help="envs stepped at once")
    p.add_argument("--materials", default=",".join(d.materials), help="presets, stiffest first")
    p.add_argument("--speeds", type=_floats, default=d.speeds, help="forward speeds [m/s]")
    p.add_argument("--yaw-rates", type=_floats, default=d.yaw_rates, help="yaw rates [rad/s], none zero")
    p.add_argument("--held-out-grid", default="3,3", help="held-out materials along rho_c,mu_int")
    p.add_argument("--contact-model", choices=get_args(ContactModelName), default=d.contact_model,
                   help="granular contact model of the simulator")  # fmt: skip
    p.add_argument("--rft-extensions", default=d.rft_extensions_file, help="fitted terms of rft3d_calibrated")
    p.add_argument(
        "--parts", type=_parts, default=d.parts, help=f"parts measured, e.g. success (default {','.join(d.parts)})"
    )
    p.add_argument(
        "--floor-depth",
        type=_positive_float,
        default=None,
        help="feet meet a hard floor this far below the surface [m], as over the training floors (default: none, "
        "a 30 cm bed as on MPM)",
    )
    p.add_argument("--device", default=d.device)
    p.add_argument("--seed", type=int, default=d.seed)
    return p.parse_args(argv)


def _cfg(args: argparse.Namespace) -> GateCfg:
    """The gate config of the arguments; ValueError names a bad value."""
    import gmloco.contact as gc  # here, not at the top: it pulls Warp, which --help does not need

    materials = tuple(m.strip() for m in args.materials.split(",") if m.strip())
    unknown = [m for m in materials if m not in gc.MATERIAL_PRESETS]
    if not materials or unknown:
        raise ValueError(
            f"--materials {args.materials!r}: unknown {unknown}; choose from {sorted(gc.MATERIAL_PRESETS)}"
        )
    if any(w == 0.0 for w in args.yaw_rates):
        raise ValueError("--yaw-rates: 0 has no achieved/commanded ratio; straight walking is in --speeds")
    grid = tuple(int(x) for x in args.held_out_grid.split(",")) if args.held_out_grid.count(",") == 1 else ()
    if len(grid) != 2 or min(grid) < 1 or grid[0] * grid[1] < 2:
        raise ValueError(
            f"--held-out-grid {args.held_out_grid!r}: expected two integers >= 1 with at least two points (R^2 of "
            "the decoded eta needs more than one material), e.g. 3,3"
        )
    if args.contact_model == "rft3d_calibrated":
        from gmloco.contact.extensions_io import load_rft_extensions  # Warp, as above

        load_rft_extensions(args.rft_extensions)  # a missing or malformed file stops here, before any env is built
    floor = GateCfg().floor
    if args.floor_depth is not None:
        floor = replace(floor, enabled=True, depth_range=(args.floor_depth, args.floor_depth))
    return GateCfg(
        floor=floor,
        policy_dir=args.policy,
        out_path=args.out,
        repeats=args.episodes,
        duration_s=args.seconds,
        num_envs=args.num_envs,
        materials=materials,
        speeds=args.speeds,
        yaw_rates=args.yaw_rates,
        held_out_grid=(grid[0], grid[1]),
        contact_model=args.contact_model,
        rft_extensions_file=args.rft_extensions,
        parts=args.parts,
        device=args.device,
        seed=args.seed,
    )


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
