# SPDX-License-Identifier: Apache-2.0
"""``gmloco-logs PATH... --out DIR``: analyze G1 MCAP logs into a summary table and paper-style figures."""

from __future__ import annotations

import argparse
import sys

__all__ = ["main"]


def _parser() -> argparse.ArgumentParser:
    """Build the argument parser."""
    p = argparse.ArgumentParser(prog="gmloco-logs", description=__doc__)
    p.add_argument("paths", nargs="+", help="MCAP files or directories of them")
    p.add_argument("--out", required=True, help="output directory (summary.md/.csv/.json, figures/)")
    p.add_argument("--rate", type=float, default=100.0, help="analysis time base [Hz] (default 100)")
    p.add_argument("--no-figures", action="store_true", help="skip the PNG figures")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    return p


def main(argv: list[str] | None = None) -> int:
    """Run the CLI; return the exit code (1 when a file could not be analyzed, 2 for bad inputs)."""
    from gmloco.deploy.logs.analysis.report import analyze
    from gmloco.deploy.logs.analysis.run_analysis import AnalysisCfg

    args = _parser().parse_args(argv)
    try:
        result = analyze(args.paths, args.out, AnalysisCfg(rate_hz=args.rate), figures=not args.no_figures,
                         progress=not args.no_progress)  # fmt: skip
    except ValueError as exc:  # bad inputs or --out; nothing was analyzed or written
        print(f"error: {exc} Nothing was analyzed.", file=sys.stderr)
        return 2
    print(f"analyzed {len(result['runs'])} file(s) -> {args.out}/summary.md")
    for f in result["failures"]:
        print(f"FAILED {f['file']}: {f['error']}", file=sys.stderr)
    return 1 if result["failures"] else 0


if __name__ == "__main__":
    raise SystemExit(main())
