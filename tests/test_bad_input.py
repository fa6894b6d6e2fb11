# SPDX-License-Identifier: Apache-2.0
"""Bad input gives one paragraph naming the key and the valid choices, exit code 2, and no traceback."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest
from omegaconf import DictConfig

from tests.pipeline_helpers import plain_python_env, run_cli
from workflows.config_errors import ConfigInputError
from workflows.run_dir import atomic_write_json

CASES = [
    # (overrides, key named in the error, words the message must contain)
    (["+exp=gm_lco"], "exp", ["gm_loco", "ppo_rigid", "did you mean 'gm_loco'"]),
    ([], "exp_name", ["+exp=<name>", "gm_loco"]),
    (["exp=gm_loco"], "exp", ["+exp=<option>"]),
    (["+exp=gm_loco", "train_teacher.num_envz=8"], "train_teacher.num_envz", ["num_envs", "max_iterations"]),
    (["+exp=gm_loco", "trainn.num_envs=8"], "trainn.num_envs", ["train_teacher", "seed"]),
    (["+expp=gm_loco"], "expp", ["exp", "Config groups"]),
    (["+exp=gm_loco", "+train_teacher.foo=1"], "train_teacher.foo", ["num_envs"]),
    (["+exp=gm_loco", "seed=abc"], "seed", ["abc"]),
    (["+exp=gm_loco", "train_teacher.contact_model=rft"], "train_teacher.contact_model", ["rft3d", "rigid"]),
    (["+exp=gm_loco", "stages=[train]"], "stages", ["train_teacher", "mismatch"]),
    (["+exp=gm_loco", "force=[exprt]"], "force", ["export"]),
    (["+exp=gm_loco", "+scale=huge"], "scale", ["full", "smoke"]),
    (["+exp=gm_loco", "tracking=nope"], "tracking", ["from 'tracking=nope'", "default"]),
    (["+exp=gm_loco", "tracking=null"], "tracking", ["'tracking=null' cannot unset", "tracking=<option>", "default"]),
    (["+exp=gm_loco", "+scale=smoke", "+scale=full"], "scale", ["chosen more than once", "+scale=<option>", "full"]),
    # numeric values outside the range their schema field declares (workflows/config_ranges.py)
    (["+exp=gm_loco", "eval_mpm.num_episodes=-1"], "eval_mpm.num_episodes", ["=-1 ", "an integer >= 1"]),
    (["+exp=gm_loco", "train_teacher.num_envs=-3"], "train_teacher.num_envs", ["=-3 ", "an integer >= 1"]),
    (["+exp=gm_loco", "max_minutes=-1"], "max_minutes", ["=-1.0 ", "a number > 0"]),
    (["+exp=gm_loco", "distill.max_minutes=0"], "distill.max_minutes", ["a number > 0"]),
    (["+exp=gm_loco", "train_teacher.ppo.gamma=1.5"], "train_teacher.ppo.gamma", ["a number in [0, 1]"]),
    (["+exp=gm_loco", "eval_mpm.speeds=[1.0,-2]"], "eval_mpm.speeds", ["element -2.0", "> 0"]),
    (["+exp=ppo_rigid", "seed=-1"], "seed", ["in [0, 4294967295]"]),
    (
        ["+exp=jump_rft3d", "train_teacher.jump.assist.initial_scale=1.5"],
        "train_teacher.jump.assist.initial_scale",
        ["a number in [0, 1]"],
    ),
    (
        ["+exp=jump_rigid", "train_teacher.jump.assist_scale_step=0.05"],
        "train_teacher.jump.assist_scale_step",
        ["assist", "rewards"],
    ),
    # inputs of the selected stages (workflows/input_checks.py)
    (["+exp=gm_loco", "mismatch.effects=[actuator.dleay]"], "mismatch.effects", ["did you mean 'actuator.delay'"]),
    (["+exp=gm_loco", "mismatch.real=README.md"], "mismatch.real", ["not an MCAP recording"]),
    (["+exp=gm_loco", "analyze_logs.inputs=[/nonexistent/logs]"], "analyze_logs.inputs", ["does not exist"]),
    (["+exp=ppo_rigid", "train_teacher.material.mu_int=[0.6,0.3]"], "train_teacher.material.mu_int", ["not a range"]),
    (["+exp=gm_loco", "train_teacher.gpus=[0,0]"], "train_teacher.gpus", ["[0] are named more than once"]),
    (
        ["+exp=gm_loco", "+train_teacher.task.material.mu_intt.0=0.3"],
        "train_teacher.task.material.mu_intt.0",
        ["no key 'mu_intt' in train_teacher.task.material", "valid keys"],
    ),
    (
        ["+exp=ppo_rigid", "+train_teacher.task.material.mu_int.0=0.95"],
        "train_teacher.task.material.mu_int.0",
        ["low > high"],
    ),
    (["+exp=jump_rigid", "+train_teacher.task.episode_length_s=5"], "train_teacher.task", ["train_teacher.jump"]),
    (["+exp=gm_loco", "distill.gpus=[1,-1]"], "distill.gpus", ["element -1", ">= 0"]),
]


@pytest.mark.parametrize(("overrides", "key", "words"), CASES)
def test_bad_input_names_key_and_choices(
    compose: Callable[..., DictConfig], overrides: list[str], key: str, words: list[str]
) -> None:
    """Each bad command line raises ConfigInputError naming ``key`` and listing the valid choices."""
    with pytest.raises(ConfigInputError) as info:
        compose(*overrides)
    assert info.value.key == key
    message = str(info.value)
    assert "\n" not in message
    for word in words:
        assert word in message


@pytest.mark.parametrize(
    ("args", "key"),
    [
        (["+exp=gm_lco"], "gm_lco"),
        (["+exp=gm_loco", "train_teacher.num_envz=8"], "train_teacher.num_envz"),
        ([], "+exp"),
        (["+exp=gm_loco", "contact=rft4d"], "contact=rft4d"),
        (["+exp=gm_loco", "eval_mpm.num_episodes=-1"], "eval_mpm.num_episodes=-1"),
        (["+exp=gm_loco", "train_teacher.gpus=[0,0]"], "train_teacher.gpus"),
    ],
)
def test_cli_bad_input_exits_2_without_traceback(args: list[str], key: str) -> None:
    """The command line exits with 2, names the key, prints no traceback and creates no run directory."""
    res = run_cli(["workflows/full_pipeline.py", *args, "paths.runs_dir=/nonexistent/should-not-be-created"])
    assert res.returncode == 2, res.stderr
    assert key in res.stderr.replace("\n", " ")
    assert "Traceback" not in res.stderr
    assert "Nothing was run" in res.stderr.replace("\n", " ")


def test_hydra_full_error_shows_the_traceback() -> None:
    """``HYDRA_FULL_ERROR=1`` lets the original exception through with its traceback."""
    env = plain_python_env() | {"HYDRA_FULL_ERROR": "1"}
    res = run_cli(["workflows/full_pipeline.py", "+exp=gm_lco"], env=env)
    assert res.returncode != 0
    assert "Traceback" in res.stderr


def test_cli_refuses_another_experiment_in_a_run_dir(tmp_path: Path) -> None:
    """``+exp=ppo_rft3d run_dir=<a gm_loco run>`` exits 2 before Hydra writes its record into the folder."""
    atomic_write_json(tmp_path / "manifest.json", {"version": 1, "exp_name": "gm_loco", "stages": {}})
    res = run_cli(["workflows/full_pipeline.py", "+exp=ppo_rft3d", f"run_dir={tmp_path}", "+scale=smoke"])
    assert res.returncode == 2, res.stderr
    message = " ".join(res.stderr.split())
    assert "holds a 'gm_loco' run" in message and "+exp=gm_loco" in message and "Traceback" not in message
    assert sorted(p.name for p in tmp_path.iterdir()) == ["manifest.json"]
