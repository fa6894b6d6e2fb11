# SPDX-License-Identifier: Apache-2.0
"""The ``eval_mpm`` section is a ``G1EvalCfg``: every setting, nested ones too, reaches the evaluation."""

from __future__ import annotations

from collections.abc import Callable

import pytest
from omegaconf import DictConfig

from gmloco.eval.g1.config import G1EvalCfg
from workflows import eval_mpm


def test_section_settings_reach_the_eval_cfg(compose: Callable[..., DictConfig]) -> None:
    """Window (size and lead), bed, lanes (and retiring them) and numerics set in the section reach the evaluation."""
    cfg = compose(
        "+exp=gm_loco",
        "+scale=full",
        "eval_mpm.window.length=0.8",
        "eval_mpm.window.width=0.5",
        "eval_mpm.window.lead=-0.1",
        "eval_mpm.bed_depth=0.25",
        "eval_mpm.robots_per_batch=50",
        "eval_mpm.solver.max_iterations=400",
        "eval_mpm.solver.velocity_handover=rewind",
        "eval_mpm.failure.max_tilt=0.5",
        "eval_mpm.retire_idle_lanes=false",
        "eval_mpm.fit_time_box=false",
        "eval_mpm.speeds=[1.0,2.0]",
        "device=cpu",
    )
    out = eval_mpm.eval_cfg(cfg)
    assert type(out) is G1EvalCfg
    assert (out.window.length, out.window.width, out.window.lead, out.window.moving) == (0.8, 0.5, -0.1, True)
    assert (out.bed_depth, out.robots_per_batch, out.solver.max_iterations) == (0.25, 50, 400)
    assert out.solver.velocity_handover == "rewind" and out.failure.max_tilt == 0.5
    assert out.retire_idle_lanes is False and out.fit_time_box is False
    assert out.speeds == (1.0, 2.0) and out.scenarios == ("straight", "circle") and out.terrains[0] == "basalt"
    assert (out.seed, out.device) == (42, "cpu") and out.policy_name == "gm_loco"
    assert out.policy_path.endswith("export/policy.onnx")


def test_default_section_matches_the_eval_defaults(compose: Callable[..., DictConfig]) -> None:
    """Without overrides the pipeline scores at ``G1EvalCfg``'s defaults (one accepted setting, not two)."""
    out = eval_mpm.eval_cfg(compose("+exp=gm_loco", "+scale=full"))
    base = G1EvalCfg()
    assert out.window == base.window
    assert (out.bed_depth, out.cell_capacity_factor) == (base.bed_depth, base.cell_capacity_factor)
    assert (out.retire_idle_lanes, out.fit_time_box) == (base.retire_idle_lanes, base.fit_time_box)
    assert out.solver == base.solver and out.failure == base.failure
    assert out.device is None  # device=auto: Warp's default


def test_a_frozen_package_section_takes_yaml_and_command_line_values(compose: Callable[..., DictConfig]) -> None:
    """The frozen ``G1EvalCfg`` section accepts the smoke scale's nested values and refuses an unknown key by name."""
    from workflows.config_errors import ConfigInputError

    cfg = compose("+exp=gm_loco", "+scale=smoke", "eval_mpm.window.width=0.7")
    out = eval_mpm.eval_cfg(cfg)
    assert (out.solver.voxel_size, out.window.length, out.window.width) == (0.05, 1.0, 0.7)
    with pytest.raises(ConfigInputError, match="voxel_size"):
        compose("+exp=gm_loco", "eval_mpm.voxel_size=0.04")


def test_gpus_send_the_stage_to_the_several_gpu_runner(
    compose: Callable[..., DictConfig], monkeypatch: pytest.MonkeyPatch
) -> None:
    """eval_mpm.gpus=[0,1] runs run_on_gpus with those GPUs and the section's config; empty runs in process."""
    import gmloco.eval.g1.gpus as g1_eval_gpus
    import gmloco.eval.g1.run as g1_eval

    calls: list[tuple[str, object]] = []
    monkeypatch.setattr(g1_eval_gpus, "run_on_gpus", lambda c, g: calls.append(("gpus", g)) or ({"m": 1.0}, True))
    monkeypatch.setattr(g1_eval, "run", lambda c: calls.append(("one", c.out_dir)) or ({"m": 2.0}, True))
    assert eval_mpm.run(compose("+exp=gm_loco", "+scale=full", "eval_mpm.gpus=[0,1]")) == {"m": 1.0}
    assert eval_mpm.run(compose("+exp=gm_loco", "+scale=full")) == {"m": 2.0}
    assert calls[0] == ("gpus", ["0", "1"]) and calls[1][0] == "one"
