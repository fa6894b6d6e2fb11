# SPDX-License-Identifier: Apache-2.0
"""Command line of the extension fit: exit 0 accepted, 1 held-out error not improved (nothing written), 2 bad input.

python -m gmloco.eval.calibration.fit_cli --dataset results/sand_calibration/dataset/dry_sand.npz
        --robot g1 --rate-hz 100 --out results/sand_calibration/fit_dry_sand.json
        --write-default results/sand_calibration/rft3d_calibrated.json

``--params`` names the fitted terms; ``--fixed NAME=VALUE`` holds others at a value (the rest keep the published
model's, i.e. off).
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import asdict

from gmloco.eval.calibration.dataset import ContractError, file_sha256, load_dataset
from gmloco.eval.calibration.fit import FIT_BOUNDS, SandFitCfg, fit_extensions, write_default, write_report


def _fixed_term(text: str) -> tuple[str, float]:
    """Parse ``NAME=VALUE`` of ``--fixed`` (argparse exits 2 on a malformed one)."""
    name, sep, value = text.partition("=")
    try:
        if not sep:
            raise ValueError
        return name.strip(), float(value)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected NAME=VALUE (e.g. added_mass=1), got {text!r}") from None


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    """Parse the command line."""
    p = argparse.ArgumentParser(
        prog="python -m gmloco.eval.calibration.fit_cli", description=(__doc__ or "").splitlines()[0]
    )
    p.add_argument("--dataset", required=True, help="<material>.npz from python -m gmloco.eval.calibration")
    p.add_argument("--robot", default="g1")
    p.add_argument("--rate-hz", type=float, default=None, help="expected recording rate [Hz]")
    p.add_argument("--params", nargs="+", default=list(SandFitCfg().params), choices=list(FIT_BOUNDS))
    p.add_argument("--plastic-unloading", choices=["off", "on", "both"], default="both")
    p.add_argument("--at-rest", choices=["none", "unloading"], default="unloading")
    p.add_argument(
        "--torque-weight",
        type=float,
        default=SandFitCfg().torque_weight,
        help="weight of the yaw-torque residual against the force residual (0: forces only)",
    )
    p.add_argument(
        "--fixed",
        type=_fixed_term,
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="hold a term at a value instead of fitting it (repeatable; not also in --params), e.g. the added mass "
        "that walks identify: --fixed added_mass=1",
    )
    p.add_argument("--min-improvement", type=float, default=0.0, help="relative held-out error reduction required")
    p.add_argument("--out", required=True, help="fit report JSON")
    p.add_argument("--write-default", default=None, help="write the fitted terms here if the fit is accepted")
    return p.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    """Fit, report, and write the default only for an accepted fit; return the exit code."""
    a = parse_args(argv)
    try:
        cfg = SandFitCfg(params=tuple(a.params), plastic_unloading=a.plastic_unloading, at_rest=a.at_rest,
                         robot=a.robot, rate_hz=a.rate_hz, min_improvement=a.min_improvement,
                         torque_weight=a.torque_weight, fixed=tuple(a.fixed))  # fmt: skip
        ds = load_dataset(a.dataset)
        result = fit_extensions(ds, cfg)
    except (ContractError, FileNotFoundError, ValueError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    provenance = {"dataset": a.dataset, "dataset_sha256": file_sha256(a.dataset), "material": ds.material,
                  "source": ds.source, "fit": asdict(cfg)}  # fmt: skip
    write_report(result, a.out, provenance)
    written = write_default(result, a.write_default, a.dataset, cfg) if a.write_default else None
    summary = {"accepted": result.accepted, "heldout_before_N": result.error_before["heldout"],
               "heldout_after_N": result.error_after["heldout"], "default_written": str(written) if written else None,
               "torque_z_error_after_Nm": result.torque_error_after}  # fmt: skip
    print(json.dumps(summary, indent=1))
    if not result.accepted:
        print("held-out force error did not improve: the fitted terms were NOT written as a default", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
