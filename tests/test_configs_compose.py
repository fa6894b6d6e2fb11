# SPDX-License-Identifier: Apache-2.0
"""Every config under ``conf/`` composes, passes the entry checks and instantiates its schema dataclasses."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from pathlib import Path

import pytest
from omegaconf import DictConfig, OmegaConf

from workflows.config_errors import CONF_DIR, ConfigInputError, default_groups, group_options, groups
from workflows.schemas import ContactModelName, PipelineCfg, StageCfg, SweepCfg
from workflows.stage_registry import stage_names

EXPS = group_options("exp")
"""Every experiment config."""
DEFAULT_GROUPS = default_groups()
"""Groups in ``full_pipeline.yaml``'s defaults list (chosen without ``+``)."""
GROUP_OPTIONS = [(g, o) for g in groups() if g != "exp" for o in group_options(g)]
"""Every (group, option) pair except experiments."""


def _instantiate(cfg: DictConfig) -> PipelineCfg:
    """Convert to the schema dataclasses (fails on any type mismatch or unresolvable interpolation)."""
    obj = OmegaConf.to_object(cfg)
    assert isinstance(obj, PipelineCfg)
    return obj


def test_conf_has_the_house_groups() -> None:
    """The config tree has exp/, sweep/, debug/, paths/, hydra/ and the scales."""
    assert {"exp", "sweep", "debug", "paths", "scale"} <= set(groups())
    assert (CONF_DIR / "hydra" / "default.yaml").is_file()
    assert {"full", "smoke"} <= set(group_options("scale"))
    assert {"gm_loco", "ppo_rft3d", "ppo_heuristic_rft", "ppo_cone_multi", "ppo_rigid"} <= set(EXPS)


def test_every_yaml_is_composed_by_this_module() -> None:
    """Every YAML file under conf/ is the primary config, Hydra's, or covered by EXPS / GROUP_OPTIONS."""
    covered = {CONF_DIR / "full_pipeline.yaml", *(CONF_DIR / "hydra").glob("*.yaml")}
    covered |= {CONF_DIR / "exp" / f"{e}.yaml" for e in EXPS}
    covered |= {CONF_DIR / g / f"{o}.yaml" for g, o in GROUP_OPTIONS}
    found = {p for p in CONF_DIR.rglob("*.yaml") if "local" not in p.relative_to(CONF_DIR).parts}
    assert found == covered


@pytest.mark.parametrize("scale", ["full", "smoke"])
@pytest.mark.parametrize("exp", EXPS)
def test_exp_composes_and_instantiates(compose: Callable[..., DictConfig], exp: str, scale: str) -> None:
    """``+exp=<exp> +scale=<scale>`` composes, resolves and becomes typed dataclasses.

    ``ppo_rft3d_calibrated`` is bad input until a calibration fit has written its terms: then it must be refused.
    """
    from gmloco.train.config import GranularTaskCfg

    if exp == "ppo_rft3d_calibrated" and not Path(GranularTaskCfg().rft_extensions_file).is_file():
        with pytest.raises(ConfigInputError, match="rft3d_calibrated reads the fitted terms"):
            compose(f"+exp={exp}", f"+scale={scale}")
        return
    obj = _instantiate(compose(f"+exp={exp}", f"+scale={scale}"))
    assert obj.exp_name == exp
    assert obj.scale.value == scale
    assert set(obj.stages) <= set(stage_names())
    assert isinstance(obj.train_teacher.contact_model, ContactModelName)
    for name in stage_names():
        stage = getattr(obj, name)
        assert all(hasattr(stage, f.name) for f in dataclasses.fields(StageCfg))  # eval_mpm: a G1EvalCfg
        assert Path(stage.out_dir).is_absolute() and Path(stage.out_dir).name == name
        assert Path(stage.out_dir).parent == Path(obj.run_dir)


@pytest.mark.parametrize(("group", "option"), GROUP_OPTIONS)
def test_group_option_composes(compose: Callable[..., DictConfig], group: str, option: str) -> None:
    """Each option of every other group composes on top of ``+exp=gm_loco``."""
    prefix = "" if group in DEFAULT_GROUPS else "+"
    obj = _instantiate(compose("+exp=gm_loco", f"{prefix}{group}={option}"))
    if group == "sweep":
        assert isinstance(obj.sweep, SweepCfg)


def test_smoke_scale_shrinks_the_experiment(compose: Callable[..., DictConfig]) -> None:
    """Smoke scale overrides the experiment's sizes even though ``+exp`` comes first on the command line."""
    full = _instantiate(compose("+exp=gm_loco", "+scale=full"))
    smoke = _instantiate(compose("+exp=gm_loco", "+scale=smoke"))
    assert smoke.train_teacher.num_envs < full.train_teacher.num_envs
    assert smoke.train_teacher.max_iterations < full.train_teacher.max_iterations
    assert smoke.eval_mpm.num_episodes < full.eval_mpm.num_episodes


def test_full_scale_scores_mpm_at_the_accepted_setting(compose: Callable[..., DictConfig]) -> None:
    """Full scale: the accepted setting (3 cm / 500 it / 5 ms x 1 step, 30 cm, 1.4 x 0.6 m); smoke: fast numerics."""
    full = _instantiate(compose("+exp=gm_loco", "+scale=full")).eval_mpm
    smoke = _instantiate(compose("+exp=gm_loco", "+scale=smoke")).eval_mpm
    solver, smoke_solver = full.solver, smoke.solver
    assert (solver.voxel_size, solver.max_iterations, solver.frame_dt, solver.rigid_substeps) == (0.03, 500, 0.005, 1)
    assert (full.bed_depth, full.window.length, full.window.width) == (0.30, 1.4, 0.6)
    assert (smoke_solver.voxel_size, smoke_solver.max_iterations) == (0.05, 50)
    assert (smoke_solver.frame_dt, smoke_solver.rigid_substeps) == (0.01, 2)


def test_ablation_exps_select_their_contact_model(compose: Callable[..., DictConfig]) -> None:
    """``+exp=ppo_<model>`` runs only the train stage with that contact model."""
    for model in ("rft3d", "heuristic_rft", "cone_multi", "rigid"):
        cfg = compose(f"+exp=ppo_{model}")
        assert list(cfg.stages) == ["train_teacher"]
        assert cfg.train_teacher.contact_model.value == model
