# SPDX-License-Identifier: Apache-2.0
"""Command line of the MPM evaluation without Hydra (the GPU machine): ``python -m gmloco.eval.g1.cli``.

    python -m gmloco.eval.g1.cli --out results/mpm_eval/ppo_rft3d --terrains dry_sand --num-episodes 100
        --robots-per-batch 32 --max-minutes 8.5

Time-boxed and resumable (rerun with the same ``--out``); prints the summary metrics as JSON.
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import replace

from gmloco.eval.g1.cli_flags import (
    FLAGS,
    add_flags,
    cfg_from_flags,
    flag_args,
    flag_problem,
    get_value,
    unflagged,
    with_values,
)
from gmloco.eval.g1.config import G1EvalCfg
from gmloco.eval.g1.policy import policy_problem
from gmloco.eval.g1.run import resume_problem, run
from gmloco.eval.mpm.box_scene import frame_dt_problem

__all__ = ["cfg_from_args", "cli_args", "main"]

PER_PROCESS = frozenset({"--out", "--shard", "--max-minutes", "--device"})
"""Flags a caller running several processes sets per process (left out by :func:`cli_args`)."""
NOT_PASSED = frozenset({"out_dir", "shard", "shards", "max_minutes", "device", "policy_name"})
"""Fields :func:`cli_args` does not carry: set per process, or (``policy_name``) used only by the pooled outputs."""


def _parse(argv: list[str] | None) -> argparse.Namespace:
    """Parse and check the command line; a bad value is a usage error (exit code 2) naming it."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", required=True, help="output folder (G1EvalCfg.out_dir); rerun with it to resume")
    p.add_argument(
        "--shard",
        default="0/1",
        help="I/N: score the share I (0 .. N-1) of each cell's episodes, those with index k %% N == I "
        "(several GPUs split one row; paper_tables pools the folders)",
    )
    add_flags(p)
    a = p.parse_args(argv)
    if (problem := frame_dt_problem(a.frame_dt)) is not None:
        p.error(f"--frame-dt: {problem}")
    try:
        a.shard, a.shards = (int(x) for x in a.shard.split("/"))
    except ValueError:
        p.error(f"--shard {a.shard!r}: write I/N, e.g. 2/4 for the third of four shares")
    if not 0 <= a.shard < a.shards:
        p.error(f"--shard {a.shard}/{a.shards}: the share I must be 0 .. N-1")
    for flag in FLAGS:
        if (problem := flag_problem(flag, getattr(a, flag.dest))) is not None:
            p.error(problem)
    return a


def cfg_from_args(a: argparse.Namespace) -> G1EvalCfg:
    """The evaluation config of parsed command-line arguments."""
    return replace(cfg_from_flags(a, G1EvalCfg()), out_dir=a.out, shard=a.shard, shards=a.shards)


def cli_args(cfg: G1EvalCfg, cells: bool = True) -> list[str]:
    """The command-line arguments that give back ``cfg`` (the inverse of :func:`cfg_from_args`).

    Leaves out what a caller running several processes sets per process: ``--out``, ``--shard``, ``--max-minutes``
    and ``--device``; ``cells=False`` also leaves out ``--terrains`` and ``--scenarios`` (one task per cell).

    Raises:
        ValueError: ``cfg`` holds a setting the command line cannot express (e.g. other failure rules).
    """
    flags = tuple(f for f in FLAGS if f.name not in PER_PROCESS)
    passed = with_values(G1EvalCfg(), {f.path: get_value(cfg, f.path) for f in flags})
    if missing := [k for k in unflagged(cfg, passed) if k not in NOT_PASSED]:
        raise ValueError(f"{', '.join(missing)} differ from the defaults: the command line cannot pass them")
    if not cells:
        flags = tuple(f for f in flags if f.name not in ("--terrains", "--scenarios"))
    return flag_args(cfg, flags)


def main(argv: list[str] | None = None) -> None:
    """Run the evaluation from command-line arguments; exit code 2 for bad arguments or a policy that is no ONNX."""
    a = _parse(argv)
    if (problem := policy_problem(a.policy)) is not None:  # checked before Warp and Newton start
        print(f"error: --policy {problem}. Nothing was run.", file=sys.stderr)
        raise SystemExit(2)
    cfg = cfg_from_args(a)
    if (problem := resume_problem(cfg)) is not None:
        print(f"error: {problem}. Nothing was run.", file=sys.stderr)
        raise SystemExit(2)
    metrics, complete = run(cfg)
    print(json.dumps({"complete": complete, **{k: v for k, v in metrics.items() if "/v" not in k}}, indent=1))


if __name__ == "__main__":
    main()
