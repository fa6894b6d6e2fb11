# SPDX-License-Identifier: Apache-2.0
"""The rft3d_calibrated contact model: fitted extensions from file, and their per-env domain randomization."""

from __future__ import annotations

from pathlib import Path

import pytest
import torch

import gmloco.contact as gc
from gmloco.contact.extensions_io import save_rft_extensions
from gmloco.train.config import MaterialRangeCfg
from gmloco.train.contact_models import MaterialWriter, contact_model_cfg, extension_dr_columns

FITTED = gc.RftExtensionsCfg(depth_exponent=1.2, lateral_scale=0.1, overburden=0.5)
"""A stand-in fit (the fitter's output format)."""


def test_calibrated_cfg_reads_the_fitted_file(tmp_path: Path) -> None:
    """rft3d_calibrated is rft3d with the file's extensions; a missing file names the fit command."""
    path = save_rft_extensions(FITTED, tmp_path / "fit.json", {"dataset": "synthetic"})
    cfg = contact_model_cfg("rft3d_calibrated", "box", str(path))
    assert cfg.extensions == FITTED
    assert cfg.collider == contact_model_cfg("rft3d", "box").collider
    with pytest.raises(FileNotFoundError, match=r"gmloco\.eval\.calibration\.fit"):
        contact_model_cfg("rft3d_calibrated", "sole", str(tmp_path / "missing.json"))


def test_extension_ranges_are_drawn_per_env(tmp_path: Path) -> None:
    """Ranges of terms that are on are drawn into the model's per-world values on reset, within bounds."""
    cfg = contact_model_cfg("rft3d_calibrated", "sole", str(save_rft_extensions(FITTED, tmp_path / "f.json", {})))
    model = gc.make_contact_model(cfg, 8, 2, "cpu")
    writer = MaterialWriter(model, MaterialRangeCfg(), "cpu", {"lateral_scale": (0.05, 0.2)})
    writer.draw(torch.arange(8))
    lateral = model.ext_values.numpy()[:, 3]
    assert lateral.min() >= 0.05 and lateral.max() <= 0.2 and lateral.std() > 0.0
    assert (model.ext_values.numpy()[:, 0] == 1.2).all()  # depth exponent not randomized: the fitted value


def test_extension_ranges_are_validated(tmp_path: Path) -> None:
    """Unknown names, terms that are off, reversed and out-of-range bounds are refused with the reason."""
    cfg = contact_model_cfg("rft3d_calibrated", "sole", str(save_rft_extensions(FITTED, tmp_path / "f.json", {})))
    model = gc.make_contact_model(cfg, 2, 2, "cpu")
    for ranges, reason in [
        ({"bogus": (0.0, 1.0)}, "unknown"),
        ({"added_mass": (0.0, 1.0)}, "is off"),
        ({"lateral_scale": (0.3, 0.1)}, "lo <= hi"),
        ({"depth_exponent": (-1.0, 1.0)}, "depth_exponent"),
    ]:
        with pytest.raises(ValueError, match=reason):
            extension_dr_columns(model, ranges)
    plain = gc.make_contact_model(gc.ContactHeuristicRFTCfg(), 2, 2, "cpu")
    with pytest.raises(ValueError, match="3D-RFT"):
        extension_dr_columns(plain, {"lateral_scale": (0.1, 0.2)})
