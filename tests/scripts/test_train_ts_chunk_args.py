# SPDX-License-Identifier: Apache-2.0
"""scripts/gpu/train_ts_chunk.py: ``--reward-weight`` overrides reach the task (fast, no env built)."""

from __future__ import annotations

from types import ModuleType

import pytest

from tests.contact.by_path import load_module


def _load() -> ModuleType:
    return load_module("gpu_train_ts_chunk", "scripts/gpu/train_ts_chunk.py")


def test_reward_weight_items_parse_and_reach_the_task() -> None:
    """Repeated NAME=WEIGHT items become the task's reward_weights; without any the task keeps its defaults."""
    chunk = _load()
    assert chunk.reward_weights(["foot_clearance_l2=-50", " feet_air_time = 1.5"]) == {
        "foot_clearance_l2": -50.0,
        "feet_air_time": 1.5,
    }
    base = ["--stage", "teacher", "--out", "unused", "--no-held-out"]
    task = chunk._task(chunk._parse([*base, "--reward-weight", "foot_clearance_l2=-50"]))
    assert task.reward_weights == {"foot_clearance_l2": -50.0}
    assert chunk._task(chunk._parse(base)).reward_weights == {}

    from gmloco.train.tasks.g1_granular.rewards_cfg import make_rewards_cfg

    assert make_rewards_cfg(task)["foot_clearance_l2"].weight == -50.0


@pytest.mark.parametrize("item", ["foot_clearance_l2", "=3", "foot_clearance_l2=high"])
def test_malformed_reward_weight_exits_with_the_expected_form(item: str) -> None:
    """A malformed item stops the script and says which form is expected."""
    with pytest.raises(SystemExit, match="NAME=WEIGHT"):
        _load().reward_weights([item])


def test_foot_clearance_touchdown_swaps_the_swing_term() -> None:
    """--foot-clearance touchdown adds the lift paid at touchdown to the L2 penalty; both weights can be overridden."""
    chunk = _load()
    base = ["--stage", "teacher", "--out", "unused", "--no-held-out", "--foot-clearance", "touchdown"]
    weights = ["--reward-weight", "swing_height_at_touchdown=40", "--reward-weight", "foot_clearance_l2=-50"]
    task = chunk._task(chunk._parse([*base, *weights]))
    assert task.foot_clearance == "touchdown"

    from gmloco.train.tasks.g1_granular.rewards_cfg import make_rewards_cfg

    rewards = make_rewards_cfg(task)
    assert rewards["foot_clearance_l2"].weight == -50.0 and rewards["swing_height_at_touchdown"].weight == 40.0
    assert rewards["swing_height_at_touchdown"].params["relative"] is True


def test_foot_faces_box_reaches_the_contact_model_cfg() -> None:
    """--foot-faces box makes the RFT models sample all six faces of the foot box (6 x 25 points, not 25)."""
    chunk = _load()
    task = chunk._task(chunk._parse(["--stage", "teacher", "--out", "unused", "--no-held-out", "--foot-faces", "box"]))
    assert task.foot_faces == "box"

    from gmloco.contact.colliders import box_collider
    from gmloco.train.contact_models import contact_model_cfg

    for name in ("rft3d", "heuristic_rft"):
        assert len(box_collider(contact_model_cfg(name, task.foot_faces).collider).areas) == 150
        assert len(box_collider(contact_model_cfg(name).collider).areas) == 25
    assert chunk._task(chunk._parse(["--stage", "teacher", "--out", "unused", "--no-held-out"])).foot_faces == "sole"


@pytest.mark.parametrize(("gpus", "words"), [(["0", "0"], "named more than once"), (["-1"], "negative GPU ids")])
def test_bad_gpus_exit_2(gpus: list[str], words: str, capsys: pytest.CaptureFixture[str]) -> None:
    """``--gpus`` naming a GPU twice or a negative id stops the script with exit code 2 and names the problem."""
    with pytest.raises(SystemExit) as info:
        _load()._parse(["--stage", "teacher", "--out", "unused", "--gpus", *gpus])
    assert info.value.code == 2 and words in capsys.readouterr().err


def test_gpus_reach_the_parsed_args() -> None:
    """Without ``--gpus`` the run trains on ``--device`` alone."""
    assert _load()._parse(["--stage", "teacher", "--out", "unused"]).gpus == []


def test_floor_depth_max_deepens_the_curriculum_only() -> None:
    """--floor-depth-max sets the deepest level's floor [m]; the shallowest and the level count stay the task's."""
    chunk = _load()
    base = ["--stage", "teacher", "--out", "unused", "--no-held-out"]
    default = chunk._task(chunk._parse(base)).terrain.floor
    floor = chunk._task(chunk._parse([*base, "--floor-depth-max", "0.3"])).terrain.floor
    assert default.depth_range == (0.0, 0.12)
    assert floor.depth_range == (0.0, 0.3) and floor.num_levels == default.num_levels


@pytest.mark.parametrize("depth", ["0", "-0.1", "1.5"])
def test_bad_floor_depth_max_exits_2(depth: str, capsys: pytest.CaptureFixture[str]) -> None:
    """A depth outside (0, 1] m is refused with exit 2 and says what to give."""
    with pytest.raises(SystemExit) as exc:
        _load()._parse(["--stage", "teacher", "--out", "unused", "--floor-depth-max", depth])
    assert exc.value.code == 2 and "deepest floor in (0, 1] m" in capsys.readouterr().err


def test_floor_levels_sets_the_level_count_only() -> None:
    """--floor-levels sets the curriculum's level count; the depth range stays as given."""
    chunk = _load()
    base = ["--stage", "teacher", "--out", "unused", "--no-held-out", "--floor-depth-max", "0.2"]
    floor = chunk._task(chunk._parse([*base, "--floor-levels", "11"])).terrain.floor
    assert floor.num_levels == 11 and floor.depth_range == (0.0, 0.2)


@pytest.mark.parametrize("levels", ["1", "0", "101"])
def test_bad_floor_levels_exit_2(levels: str, capsys: pytest.CaptureFixture[str]) -> None:
    """Fewer than 2 or more than 100 levels are refused with exit 2."""
    with pytest.raises(SystemExit) as exc:
        _load()._parse(["--stage", "teacher", "--out", "unused", "--floor-levels", levels])
    assert exc.value.code == 2 and "give 2 to 100 levels" in capsys.readouterr().err


def test_rft_extension_range_reaches_the_task() -> None:
    """--rft-extension-range NAME=LO,HI becomes GranularTaskCfg.rft_extension_ranges; none keeps the fitted values."""
    chunk = _load()
    base = ["--stage", "teacher", "--out", "unused", "--no-held-out", "--contact-model", "rft3d_calibrated"]
    assert chunk._task(chunk._parse(base)).rft_extension_ranges == {}
    args = chunk._parse([*base, "--rft-extension-range", "added_mass=1,10", "--rft-extension-range", "overburden=0,2"])
    assert chunk._task(args).rft_extension_ranges == {"added_mass": (1.0, 10.0), "overburden": (0.0, 2.0)}


@pytest.mark.parametrize("item", ["added_mass", "added_mass=10,1", "added_mass=-1,2", "mass=1,2", "added_mass=1,x"])
def test_bad_rft_extension_range_exits_2(item: str, capsys: pytest.CaptureFixture[str]) -> None:
    """A malformed, unknown or inverted range is refused with exit 2 and names the fields."""
    with pytest.raises(SystemExit) as exc:
        _load()._parse(["--stage", "teacher", "--out", "unused", "--rft-extension-range", item])
    assert exc.value.code == 2 and "expected NAME=LO,HI" in capsys.readouterr().err


def test_entropy_coef_reaches_the_teacher_algorithm_only() -> None:
    """--entropy-coef sets the teacher PPO's entropy coefficient in the rsl-rl entries; the default stays 0.005."""
    chunk = _load()
    base = ["--stage", "teacher", "--out", "unused"]
    assert chunk._entries(chunk._parse(base))["algorithm"]["entropy_coef"] == 0.005
    assert chunk._entries(chunk._parse([*base, "--entropy-coef", "0.001"]))["algorithm"]["entropy_coef"] == 0.001


@pytest.mark.parametrize(
    "argv", [["--stage", "teacher", "--entropy-coef", "-1"], ["--stage", "student", "--entropy-coef", "0.001"]]
)
def test_bad_entropy_coef_exits_2(argv: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    """A negative coefficient, or one given to the student (its PPO has its own), is refused with exit 2."""
    with pytest.raises(SystemExit) as exc:
        _load()._parse([*argv, "--out", "unused"])
    assert exc.value.code == 2 and "--entropy-coef" in capsys.readouterr().err


def test_soft_share_reaches_the_material_draw() -> None:
    """--soft-share sets MaterialRangeCfg.soft_share; without it the task keeps GM-Loco's draw (0)."""
    chunk = _load()
    base = ["--stage", "teacher", "--out", "unused", "--no-held-out"]
    assert chunk._task(chunk._parse(base)).material.soft_share == 0.0
    assert chunk._task(chunk._parse([*base, "--soft-share", "0.25"])).material.soft_share == 0.25


@pytest.mark.parametrize("share", ["-0.1", "1.5"])
def test_bad_soft_share_exits_2(share: str, capsys: pytest.CaptureFixture[str]) -> None:
    """A share outside [0, 1] is refused with exit 2."""
    with pytest.raises(SystemExit) as exc:
        _load()._parse(["--stage", "teacher", "--out", "unused", "--soft-share", share])
    assert exc.value.code == 2 and "share in [0, 1]" in capsys.readouterr().err
