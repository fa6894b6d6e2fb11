# SPDX-License-Identifier: Apache-2.0
"""Stage-input checks that need no stage to run (``workflows/input_checks.py``)."""

from __future__ import annotations

from pathlib import Path

import pytest
from omegaconf import DictConfig, OmegaConf

from workflows.input_checks import input_problem


def _cfg(contact_model: str) -> DictConfig:
    cfg = OmegaConf.create(
        {"stages": ["train_teacher"], "train_teacher": {"contact_model": contact_model, "jump": None}}
    )
    assert isinstance(cfg, DictConfig)
    return cfg


def test_calibrated_contact_model_needs_its_fitted_terms(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """rft3d_calibrated without the fitted file is bad input naming the file and the fit; with it, no problem."""
    monkeypatch.chdir(tmp_path)
    found = input_problem(_cfg("rft3d_calibrated"))
    assert found is not None
    key, message = found
    assert key == "train_teacher.contact_model"
    assert "results/sand_calibration/rft3d_calibrated.json" in message and "fit_cli" in message
    fitted = tmp_path / "results/sand_calibration/rft3d_calibrated.json"
    fitted.parent.mkdir(parents=True)
    fitted.write_text("{}")
    assert input_problem(_cfg("rft3d_calibrated")) is None
    assert input_problem(_cfg("rft3d")) is None
