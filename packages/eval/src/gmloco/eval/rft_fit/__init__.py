# SPDX-License-Identifier: Apache-2.0
"""3D-RFT coefficients fitted from MPM plate intrusions (spec section 8)."""

from gmloco.eval.rft_fit.fit import (
    RftFitResult,
    fit_rft3d_coeffs,
    generic_from_coeffs,
    rft3d_design_matrix,
    save_rft3d_coeffs,
)
from gmloco.eval.rft_fit.plate import PlateIntrusionCfg, PlateRun, plate_path, run_plate_intrusion, run_plate_intrusions
from gmloco.eval.rft_fit.run import SPEC_CASES, RftFitCfg, plate_directions, rft_fit_smoke_cfg, run
from gmloco.eval.rft_fit.steady import plate_direction, plate_record, steady_alpha

__all__ = [
    "SPEC_CASES",
    "PlateIntrusionCfg",
    "PlateRun",
    "RftFitCfg",
    "RftFitResult",
    "fit_rft3d_coeffs",
    "generic_from_coeffs",
    "plate_direction",
    "plate_directions",
    "plate_path",
    "plate_record",
    "rft3d_design_matrix",
    "rft_fit_smoke_cfg",
    "run",
    "run_plate_intrusion",
    "run_plate_intrusions",
    "save_rft3d_coeffs",
    "steady_alpha",
]
