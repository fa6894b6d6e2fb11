# SPDX-License-Identifier: Apache-2.0
"""Jump evaluation in the training simulator: traces, summary keys, the figure (a standing policy never jumps)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import torch

from gmloco.train.tasks.g1_jump.evaluation import JumpEvalCfg, evaluate_jump, fig_jump_trace, summarize


def _stand(obs: dict[str, torch.Tensor]) -> torch.Tensor:
    """Zero action: hold the default pose."""
    return torch.zeros(obs["actor"].shape[0], 29)


@pytest.mark.slow
def test_zero_action_policy_never_lands_a_jump(tmp_path: Path) -> None:
    """On rigid ground the zero action (mjlab's soft PD gains) sags and topples before the push-off: 0 % success.

    The trace stops at the failure, the reference track runs on: its pelvis rises 3.5 cm in flight (the shipped
    vertical jump), so the height error of a robot that never took off is about 100 %.
    """
    cfg = JumpEvalCfg(contact_model="rigid", attempts=2, policy_history_length=1)
    summary, traces = evaluate_jump(_stand, cfg)
    assert set(summary) == {"success_pct", "height_error_pct", "takeoff_slip_cm", "sinkage_cm", "episodes"}
    assert summary["episodes"] == 2.0 and summary["success_pct"] == 0.0
    assert summary["height_error_pct"] > 80.0
    # Rigid floor: the soles rest on it, at most a few mm of contact penetration.
    assert summary["sinkage_cm"] < 0.5
    tr = traces[0]
    assert tr.feet_pos.shape == (tr.base_pos.shape[0], 2, 3)
    assert tr.base_pos.shape[0] < tr.ref_base_pos.shape[0]
    assert tr.ref_base_pos[:, 2].max() - tr.ref_base_pos[0, 2] == pytest.approx(0.035, abs=0.003)
    np.testing.assert_allclose(tr.ref_base_pos[0], tr.base_pos[0], atol=0.05)
    out = fig_jump_trace({"stand": tr}, tmp_path / "fig" / "jump.png")
    assert out.stat().st_size > 10_000


def test_bad_attempts_and_empty_summary_are_refused() -> None:
    """No attempts is a clear error."""
    with pytest.raises(ValueError, match="attempts"):
        evaluate_jump(_stand, JumpEvalCfg(attempts=0))
    with pytest.raises(ValueError, match="no attempts"):
        summarize([])


@pytest.mark.parametrize(
    "argv",
    [
        ["--run", "x"],
        ["--run", "x=/nonexistent/run"],
        ["--run", "x=.", "--materials", "mud"],
        ["--run", "x=.", "--attempts", "0"],
    ],
)
def test_evaluate_cli_refuses_bad_arguments(argv: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    """Bad --run / --materials / --attempts exit with code 2 and say what to pass."""
    from gmloco.train.tasks.g1_jump.evaluate import main

    assert main(argv) == 2
    assert "error: --" in capsys.readouterr().err
