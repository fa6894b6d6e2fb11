# SPDX-License-Identifier: Apache-2.0
"""``gmloco-mismatch --real REAL.mcap [--real MORE.mcap ...] [--sim SIM.mcap] --out DIR``: name the missing physics.

Several ``--real`` recordings of one robot make one diagnosis.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from dataclasses import replace
from pathlib import Path

__all__ = ["main"]


def _parser() -> argparse.ArgumentParser:
    """Command-line interface."""
    p = argparse.ArgumentParser(prog="gmloco-mismatch", description=__doc__)
    p.add_argument(
        "--real",
        required=True,
        type=Path,
        action="append",
        help="real G1 recording (MCAP, project schema); repeat it to combine several recordings of one robot "
        "(same robot, joint order and sample rate) into one diagnosis",
    )
    p.add_argument(
        "--sim", type=Path, default=None, help="simulated counterpart; default: replay the real commands in MuJoCo"
    )
    p.add_argument(
        "--out", required=True, type=Path, help="output directory (report.json, report.md, plots, config_patch.json)"
    )
    p.add_argument("--effects", default=None, help="comma-separated effect ids to screen (default: the whole library)")
    p.add_argument(
        "--horizon",
        type=int,
        default=None,
        help="shooting horizon [samples]; default 60 ms at the recording's rate (30 samples at 500 Hz, 3 at 50 Hz)",
    )
    p.add_argument(
        "--ground",
        default="plane",
        help="nominal ground: 'plane' (MuJoCo soft contact) or 'sand[:MATERIAL]' (the project's 3D-RFT sand, "
        "default material dry_sand; gmloco.contact.MATERIAL_PRESETS)",
    )
    p.add_argument(
        "--support",
        choices=("free", "gantry", "fixed"),
        default=None,
        help="how the pelvis was held, overriding the run metadata's 'support': free (on its own feet) or gantry / "
        "fixed (pelvis welded in place, only the joints move)",
    )
    p.add_argument(
        "--workers",
        type=int,
        default=2,
        help="processes for independent replays and fits (results do not depend on it; default 2)",
    )
    p.add_argument("--no-plots", action="store_true", help="skip matplotlib plots")
    return p


_BLAS_THREAD_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


def _one_blas_thread() -> None:
    """Ask numpy's BLAS for one thread unless the caller chose otherwise.

    The analysis runs its parallel work in ``--workers`` processes; a BLAS thread pool per process on top of them
    oversubscribes the cores, and idle pool threads spin after every call. Takes effect only if numpy is not
    imported yet (the command line), never for a caller that imported it first.
    """
    if "numpy" not in sys.modules:
        for var in _BLAS_THREAD_VARS:
            os.environ.setdefault(var, "1")


def main(argv: list[str] | None = None) -> int:
    """Run the analysis; exit code 0 for a report on valid input, 2 for unreadable or invalid input.

    Every contract finding is printed; an ``invalid_input`` verdict (any contract error) still writes its report,
    which says what is wrong, and exits with 2.
    """
    _one_blas_thread()
    from rich.console import Console
    from rich.markup import escape
    from rich.progress import Progress, TimeElapsedColumn

    from gmloco.deploy.mismatch.effects import check_effect_ids
    from gmloco.deploy.mismatch.io import read_recording
    from gmloco.deploy.mismatch.multi import analyze_many
    from gmloco.deploy.mismatch.pipeline import AnalysisCfg
    from gmloco.deploy.mismatch.replay import parse_ground, replay_cfg_for_rate
    from gmloco.deploy.mismatch.report import write_report

    args = _parser().parse_args(argv)
    console = Console(stderr=True)
    try:
        effects = None if not args.effects else check_effect_ids(s.strip() for s in args.effects.split(","))
    except ValueError as exc:
        console.print(f"[red]error:[/] --effects: {escape(str(exc))} Nothing was analysed.")
        return 2
    recs = []
    for path in args.real:
        try:
            recs.append(read_recording(path))
        except (OSError, ValueError) as exc:
            console.print(f"[red]cannot read {path}: {exc}")
            return 2
    if args.sim is not None:
        console.print(
            "[yellow]--sim given: the simulated log is checked for its contract only; residuals come from replay at the real states (short horizons), which a free-running sim log cannot provide."
        )
        try:
            read_recording(args.sim)
        except (OSError, ValueError) as exc:
            console.print(f"[red]cannot read {args.sim}: {exc}")
            return 2
    if args.support is not None:
        recs = [replace(rec, support=args.support) for rec in recs]
    try:  # the physics step and the time spans follow the recording's rate (MPM recordings are 50 Hz, a G1 500 Hz)
        ground, material = parse_ground(args.ground)
        replay = replay_cfg_for_rate(1.0 / recs[0].dt, ground, material, args.horizon)
    except ValueError as exc:  # a misspelt --ground or a --horizon below 1 sample
        console.print(f"[red]--{exc}")
        return 2
    if args.workers < 1:
        console.print(f"[red]error:[/] --workers {args.workers}: give at least 1 process. Nothing was analysed.")
        return 2
    cfg = AnalysisCfg(replay=replay)
    cfg.attribution.effects = effects
    cfg.attribution.workers = args.workers
    with Progress(*Progress.get_default_columns(), TimeElapsedColumn(), console=console) as prog:
        task = prog.add_task("mismatch", total=1.0)
        res = analyze_many(recs, cfg, lambda msg, f: prog.update(task, completed=f, description=msg))
    write_report(res, args.out, plots=not args.no_plots)
    r = res.report
    for issue in r.get("contract", []):
        colour = "red" if issue["severity"] == "error" else "yellow"
        console.print(f"[{colour}]contract {issue['severity']} [{issue['check']}]: {issue['message']}")
    console.print(f"verdict: [bold]{r['verdict']}[/bold]" + (f", winner {r['winner']}" if r.get("winner") else ""))
    print(json.dumps({"verdict": r["verdict"], "winner": r.get("winner"), "report": str(args.out / "report.json")}))
    return 2 if r["verdict"] == "invalid_input" else 0


if __name__ == "__main__":
    sys.exit(main())
