# SPDX-License-Identifier: Apache-2.0
"""MPM plate sweep smoke on CPU: the plate feels the sand, the fit runs end to end and resumes."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from gmloco.contact.coefficients import load_rft3d_coeffs
from gmloco.eval.rft_fit import rft_fit_smoke_cfg, run


@pytest.fixture(scope="module")
def smoke(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict]:
    """Two plate runs (straight down; a vertical plate dragged sideways) on a 4 cm-voxel bed (~2k particles)."""
    out = tmp_path_factory.mktemp("rft_fit")
    return out, run(rft_fit_smoke_cfg(str(out)))


def _runs(out: Path) -> dict[tuple[float, float, float], dict]:
    """Plate-run records keyed by (gamma, beta, psi)."""
    lines = (out / "plate_runs.jsonl").read_text().splitlines()
    return {(r["gamma_deg"], r["beta_deg"], r["psi_deg"]): r for r in map(json.loads, lines)}


def test_plate_feels_resistive_force_growing_with_depth(smoke: tuple[Path, dict]) -> None:
    """Pushed down, the plate gets an upward force that grows with depth (RFT: F = alpha A d, alpha_z > 0)."""
    down = _runs(smoke[0])[(90.0, 0.0, 0.0)]
    f = np.array(down["force_series"])
    d = np.array(down["depth_series"])
    assert down["G"][2] > 0.02  # measured 0.21 at 4 cm voxels (PNAS: 0.876; README on the scale gap)
    shallow, deep = f[(d > 0.0) & (d < 0.05), 2], f[d > 0.075, 2]
    assert deep.mean() > 1.5 * shallow.mean() > 0.0
    assert abs(down["G"][0]) < 0.2 * down["G"][2] and abs(down["G"][1]) < 0.2 * down["G"][2]  # symmetry


def test_dragged_wall_is_resisted_and_lifted(smoke: tuple[Path, dict]) -> None:
    """A vertical plate moved along +x at depth gets F_x < 0 and an upward F_z (PNAS case G: (-0.23, 0, +0.09))."""
    wall = _runs(smoke[0])[(0.0, 90.0, 0.0)]
    assert wall["G"][0] < -0.02 and wall["G"][2] > 0.0
    assert wall["x"] == [0.0, 0.0, -1.0]  # n_z = 0 ties flip (spec 1.1 step 2), as in the PNAS table


def test_fit_outputs_and_resume(smoke: tuple[Path, dict]) -> None:
    """Summary, table and a loadable coefficient file; a second call runs no plate again."""
    out, summary = smoke
    assert summary["complete"] and summary["runs_used"] == 2 and summary["runs_zero_force"] == 0
    assert load_rft3d_coeffs(out / "rft3d_fitted.json").shape == (20, 3)
    assert len((out / "plate_G.csv").read_text().splitlines()) == 3
    again = run(rft_fit_smoke_cfg(str(out)))
    assert again["runs_done"] == 2 and again["wall_s_this_run"] < summary["wall_s_this_run"]
