# SPDX-License-Identifier: Apache-2.0
"""``--contact-model`` and ``--parts`` of the training gate: parsing, refusals, and the model reaching the env."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

import gmloco.contact as gc
from gmloco.contact.extensions_io import save_rft_extensions
from gmloco.train.gate import rollout
from gmloco.train.gate.__main__ import _cfg, _parse, main
from gmloco.train.gate.config import GATE_PARTS, GateCfg, GateThresholdsCfg
from gmloco.train.gate.rollout import gate_cells
from gmloco.train.gate.summary import gate_metrics, gate_pass

REPO = Path(__file__).resolve().parents[4]
"""Repository root (the committed artifacts)."""
POLICY = "artifacts/gm_loco_student_td"
"""A committed student run."""
FITTED = gc.RftExtensionsCfg(depth_exponent=1.2, lateral_scale=0.1, overburden=0.5)
"""A stand-in fit (the fitter's output format)."""


def test_flags_fill_the_gate_config(tmp_path: Path) -> None:
    """Defaults are today's gate (rft3d, every part); the flags set the config's fields, parts in summary order."""
    base = ["--policy", POLICY, "--out", str(tmp_path / "g.json")]
    default = _cfg(_parse(base))
    assert default.contact_model == "rft3d" and default.parts == GATE_PARTS == GateCfg().parts
    ext = save_rft_extensions(FITTED, tmp_path / "fit.json", {})
    cfg = _cfg(_parse([*base, "--contact-model", "rft3d_calibrated", "--rft-extensions", str(ext),
                       "--parts", "yaw, success"]))  # fmt: skip
    assert (cfg.contact_model, cfg.rft_extensions_file, cfg.parts) == ("rft3d_calibrated", str(ext), ("success", "yaw"))


@pytest.mark.parametrize(
    ("flag", "value", "message"),
    [("--contact-model", "mpm", "invalid choice: 'mpm'"), ("--parts", "success,speed", "unknown parts ['speed']"),
     ("--parts", ",", "unknown parts []")],
)  # fmt: skip
def test_bad_contact_model_or_parts_exit_2(
    flag: str, value: str, message: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """An unknown contact model or part stops the parser with exit 2 and names the choices."""
    with pytest.raises(SystemExit) as stop:
        main(["--policy", POLICY, "--out", str(tmp_path / "g.json"), flag, value])
    assert stop.value.code == 2
    assert message in capsys.readouterr().err


def test_missing_extensions_file_exits_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """rft3d_calibrated without its fitted file is refused before any env is built, naming the fit command."""
    monkeypatch.chdir(REPO)
    argv = ["--policy", POLICY, "--out", str(tmp_path / "g.json"), "--contact-model", "rft3d_calibrated",
            "--rft-extensions", str(tmp_path / "missing.json")]  # fmt: skip
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "missing.json: no fitted RFT extensions" in err and "gmloco.eval.calibration.fit_cli" in err
    assert not (tmp_path / "g.json").exists()


def test_parts_select_cells_and_null_the_rest() -> None:
    """--parts success runs only the forward cells of the speeds; the other keys are null and the gate not passed."""
    cfg = GateCfg(materials=("dry_sand",), speeds=(1.5,), yaw_rates=(0.5,), repeats=1, parts=("success",))
    cells = gate_cells(cfg)
    assert [(c.kind, c.command) for c in cells] == [("forward", (1.5, 0.0, 0.0))]
    apex = gate_cells(GateCfg(materials=("dry_sand",), speeds=(1.5,), repeats=1, parts=("success", "apex")))
    assert [c.command[0] for c in apex] == [1.5, 1.0]  # apex_speed 1 m/s added once
    rows = [{"cell": cells[0], "failed": False, "vel_error": 0.1, "yaw_rate": 0.0, "drift_deg": 1.0, "apex_m": []}]
    metrics = gate_metrics(cfg, rows) | {"gpu_minutes": 10.0}
    assert metrics["success_pct"] == {"dry_sand": {"1.5": 100.0}}
    assert all(metrics[k] is None for k in ("yaw_rate_ratio", "circle_dtw_m", "swing_apex_cm", "eta_r2_heldout"))
    verdict = gate_pass(metrics, GateThresholdsCfg(), cfg.materials, cfg.parts)
    assert verdict["success_pct"] is True and verdict["yaw_rate_ratio"] is None and verdict["all"] is False


@pytest.mark.slow
def test_calibrated_model_reaches_the_env(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """2 envs, 1 s, one speed, one material: the env's contact model is rft3d_calibrated with the file's terms."""
    monkeypatch.chdir(REPO)
    ext = save_rft_extensions(FITTED, tmp_path / "fit.json", {"dataset": "synthetic"})
    seen: list[tuple[str, Any]] = []
    original = rollout._rollout

    def spy(env: Any, *args: Any) -> dict[str, Any]:
        """Record the contact model of the env the gate built, then roll out."""
        seen.append((env.sand.task.contact_model, env.sand.model.cfg.extensions))
        return original(env, *args)

    monkeypatch.setattr(rollout, "_rollout", spy)
    out = tmp_path / "gate.json"
    argv = ["--policy", POLICY, "--out", str(out), "--episodes", "2", "--num-envs", "2", "--seconds", "1",
            "--materials", "dry_sand", "--speeds", "1.0", "--parts", "success",
            "--contact-model", "rft3d_calibrated", "--rft-extensions", str(ext)]  # fmt: skip
    assert main(argv) == 0
    assert seen == [("rft3d_calibrated", FITTED)]
    summary = json.loads(out.read_text())
    assert set(summary["success_pct"]) == {"dry_sand"} and 0.0 <= summary["success_pct"]["dry_sand"]["1"] <= 100.0
    assert summary["setup"]["contact_model"] == "rft3d_calibrated" and summary["setup"]["parts"] == ["success"]
    assert summary["setup"]["rft_extensions"]["values"]["lateral_scale"] == 0.1
    assert summary["yaw_rate_ratio"] is None and summary["pass"]["all"] is False
