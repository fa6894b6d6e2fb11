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


@pytest.mark.parametrize("stage", ["train_teacher", "distill"])
def test_gpus_without_cuda_is_bad_input(stage: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """``<stage>.gpus`` on a machine without CUDA names the key and says to leave it empty; empty passes."""
    import gmloco.train.multi_gpu as multi_gpu

    monkeypatch.setattr(multi_gpu, "cuda_device_count", lambda: 0)
    section = {"contact_model": "rft3d", "jump": None, "gpus": [0, 1]}
    cfg = OmegaConf.create({"stages": [stage], stage: section, "train_teacher": section})
    assert isinstance(cfg, DictConfig)
    found = input_problem(cfg)
    assert found is not None
    key, message = found
    assert key == f"{stage}.gpus" and "no CUDA device" in message and "leave gpus empty" in message
    cfg[stage].gpus = []
    cfg.train_teacher.gpus = []
    assert input_problem(cfg) is None
