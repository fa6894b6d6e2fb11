# SPDX-License-Identifier: Apache-2.0
"""The ``contact``, ``material``, ``ppo`` and ``eval`` config groups write existing schema fields and nothing else."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import pytest
from omegaconf import DictConfig, OmegaConf

from gmloco.contact import MATERIAL_PRESETS
from workflows.config_errors import CONF_DIR, ConfigInputError, default_groups, group_options
from workflows.schemas import ContactModelName, PipelineCfg

CONTACTS = group_options("contact")
"""Every ``conf/contact/*.yaml``."""
MATERIALS = group_options("material")
"""Every ``conf/material/*.yaml``."""
EXPS = ("gm_loco", "ppo_rigid")
"""One experiment per algorithm (VAE teacher, vanilla PPO) that the groups are composed on."""
EXP_CONTACT_MODELS = {
    "gm_loco": "rft3d",
    "jump_rft3d": "rft3d",
    "jump_rigid": "rigid",
    "ppo_cone_multi": "cone_multi",
    "ppo_heuristic_rft": "heuristic_rft",
    "ppo_rft3d": "rft3d",
    "ppo_rft3d_calibrated": "rft3d_calibrated",
    "ppo_rigid": "rigid",
}
"""``train_teacher.contact_model`` of each experiment, as each ``conf/exp`` file wrote it as a plain value."""
FIXED = ("run_name=fixed",)
"""Pins the one time-dependent value, so two compositions can be compared."""


def _resolved(compose: Callable[..., DictConfig], *overrides: str) -> Any:
    """The resolved config as plain containers, or the bad-input message (``rft3d_calibrated`` without its fit)."""
    try:
        cfg = compose(*overrides, *FIXED)
    except ConfigInputError as e:
        return f"ConfigInputError({e.key}): {e}"
    assert isinstance(OmegaConf.to_object(cfg), PipelineCfg)  # every value has its schema type
    return OmegaConf.to_container(cfg, resolve=True)


def test_group_options_are_the_package_names() -> None:
    """One contact file per schema contact model, one material file per ``gmloco.contact.MATERIAL_PRESETS`` key."""
    assert sorted(m.value for m in ContactModelName) == CONTACTS
    assert sorted(MATERIAL_PRESETS) == MATERIALS
    assert {"contact", "material"} <= set(default_groups())  # chosen without '+'


@pytest.mark.parametrize("group", ["contact", "material"])
def test_group_files_are_one_value_at_a_schema_field(group: str) -> None:
    """Each file is a ``# @package`` header and one key: the schema field it writes."""
    package, key = {"contact": ("train_teacher", "contact_model"), "material": ("train_teacher.material", "preset")}[
        group
    ]
    for option in group_options(group):
        text = (CONF_DIR / group / f"{option}.yaml").read_text()
        assert text.splitlines()[0] == f"# @package {package}"
        assert OmegaConf.to_container(OmegaConf.create(text)) == {key: option}


def test_absent_groups_add_nothing(compose: Callable[..., DictConfig]) -> None:
    """Without ``contact=`` or ``material=`` the fields hold the experiment's or the schema's values."""
    cfg = compose("+exp=ppo_heuristic_rft")
    assert cfg.train_teacher.contact_model == ContactModelName.heuristic_rft
    assert cfg.train_teacher.material.preset is None


@pytest.mark.parametrize("exp", EXPS)
@pytest.mark.parametrize("contact", CONTACTS)
def test_contact_group_is_the_field_override(compose: Callable[..., DictConfig], exp: str, contact: str) -> None:
    """``contact=<model>`` resolves exactly as ``train_teacher.contact_model=<model>``, over the experiment's model."""
    by_group = _resolved(compose, f"+exp={exp}", f"contact={contact}")
    assert by_group == _resolved(compose, f"+exp={exp}", f"train_teacher.contact_model={contact}")
    if isinstance(by_group, dict):
        assert by_group["train_teacher"]["contact_model"] == ContactModelName(contact)


@pytest.mark.parametrize("exp", EXPS)
@pytest.mark.parametrize("material", MATERIALS)
def test_material_group_is_the_field_override(compose: Callable[..., DictConfig], exp: str, material: str) -> None:
    """``material=<preset>`` resolves exactly as ``train_teacher.material.preset=<preset>``."""
    by_group = _resolved(compose, f"+exp={exp}", f"material={material}")
    assert by_group == _resolved(compose, f"+exp={exp}", f"train_teacher.material.preset={material}")
    assert by_group["train_teacher"]["material"]["preset"] == material


def test_both_groups_together(compose: Callable[..., DictConfig]) -> None:
    """``contact=`` and ``material=`` on one command line set both fields; an explicit field override still wins."""
    both = ("+exp=gm_loco", "contact=cone_multi", "material=poppy_seed")
    explicit = ("+exp=gm_loco", "train_teacher.contact_model=cone_multi", "train_teacher.material.preset=poppy_seed")
    assert _resolved(compose, *both) == _resolved(compose, *explicit)
    cfg = compose(*both, "train_teacher.contact_model=rigid", "train_teacher.material.preset=basalt")
    assert (cfg.train_teacher.contact_model, cfg.train_teacher.material.preset) == (ContactModelName.rigid, "basalt")


@pytest.mark.parametrize(("group", "package"), [("ppo", "train_teacher.ppo"), ("eval", "eval_mpm")])
def test_preset_group_is_its_field_overrides(compose: Callable[..., DictConfig], group: str, package: str) -> None:
    """Each ``ppo=`` / ``eval=`` preset resolves exactly as its field overrides; without one, the schema's defaults.

    A preset is a ``# @package <section>`` file of fields of that section's schema; the defaults are written nowhere
    else (no experiment repeats them).
    """
    schema = {"ppo": "PpoCfg", "eval": "G1EvalCfg"}[group]
    module = {"ppo": "gmloco.train.teacher_student.config", "eval": "gmloco.eval.g1.config"}[group]
    fields = set(getattr(__import__(module, fromlist=[schema]), schema).__dataclass_fields__)
    assert group_options(group)
    for preset in group_options(group):
        text = (CONF_DIR / group / f"{preset}.yaml").read_text()
        assert text.splitlines()[0] == f"# @package {package}"
        values = OmegaConf.to_container(OmegaConf.create(text))
        assert isinstance(values, dict) and values and set(values) <= fields
        for exp in EXPS:
            explicit = [f"{package}.{k}={_override_value(v)}" for k, v in values.items()]
            assert _resolved(compose, f"+exp={exp}", f"{group}={preset}") == _resolved(
                compose, f"+exp={exp}", *explicit
            )


def _override_value(value: Any) -> str:
    """A YAML value as a Hydra override value (lists as ``[a,b]``)."""
    return f"[{','.join(map(str, value))}]" if isinstance(value, list) else str(value)


def test_presets_by_hand(compose: Callable[..., DictConfig]) -> None:
    """No preset: PpoCfg's entropy bonus and G1EvalCfg's terrains; ``ppo=low_entropy``, ``eval=speed_table``."""
    from gmloco.eval.g1.config import G1EvalCfg
    from gmloco.train.teacher_student.config import PpoCfg

    plain = compose("+exp=gm_loco")
    assert plain.train_teacher.ppo.entropy_coef == PpoCfg().entropy_coef == 0.005
    assert plain.eval_mpm.num_episodes == G1EvalCfg().num_episodes == 100
    chosen = compose("+exp=gm_loco", "ppo=low_entropy", "eval=speed_table")
    assert chosen.train_teacher.ppo.entropy_coef == 0.001
    assert list(chosen.eval_mpm.terrains) == ["basalt", "dry_sand", "poppy_seed"]
    assert [s.value for s in chosen.eval_mpm.scenarios] == ["straight"]


def _leaves(node: Any, prefix: str = "") -> dict[str, Any]:
    """Dotted paths and values of the leaves of a plain container (an empty mapping is a leaf)."""
    if isinstance(node, dict) and node:
        return {k: v for key, sub in node.items() for k, v in _leaves(sub, f"{prefix}{key}.").items()}
    return {prefix.rstrip("."): node}


@pytest.mark.parametrize("exp", sorted(EXP_CONTACT_MODELS))
def test_exp_writes_no_default(exp: str) -> None:
    """Every value an experiment file sets differs from the schema's default there (each value written once)."""
    text = OmegaConf.create((CONF_DIR / "exp" / f"{exp}.yaml").read_text())
    written = _leaves({k: v for k, v in OmegaConf.to_container(text).items() if k not in ("defaults", "exp_name")})  # type: ignore[union-attr]
    base = OmegaConf.to_container(OmegaConf.structured(PipelineCfg))  # the schema's defaults, unresolved
    repeated = []
    for path, value in written.items():
        node: Any = base
        for key in path.split("."):
            node = node.get(key) if isinstance(node, dict) else None
        if value == node or (hasattr(node, "value") and value == node.value):
            repeated.append(path)
    assert not repeated, f"{exp} repeats the schema's defaults at {repeated}"


def test_every_exp_is_listed() -> None:
    """Each ``conf/exp`` file has its contact model written out in ``EXP_CONTACT_MODELS``."""
    assert sorted(EXP_CONTACT_MODELS) == group_options("exp")


@pytest.mark.parametrize(("exp", "contact"), sorted(EXP_CONTACT_MODELS.items()))
def test_exp_resolves_as_with_the_plain_field(compose: Callable[..., DictConfig], exp: str, contact: str) -> None:
    """An experiment choosing its model through the ``contact`` group resolves as the plain field value did.

    The explicit form drops the group (``~contact``) and sets ``train_teacher.contact_model`` itself, as the
    experiment file did; both are composed at full and at smoke scale.
    """
    for scale in ("+scale=full", "+scale=smoke"):
        by_group = _resolved(compose, f"+exp={exp}", scale)
        explicit = _resolved(compose, f"+exp={exp}", "~contact", f"train_teacher.contact_model={contact}", scale)
        assert by_group == explicit


@pytest.mark.parametrize(
    ("override", "group", "words"),
    [
        ("contact=rft4d", "contact", ["unknown contact 'rft4d'", "rft3d_calibrated", "did you mean 'rft3d'"]),
        ("material=popy_seed", "material", ["unknown material 'popy_seed'", "basalt", "did you mean 'poppy_seed'"]),
        ("+contact=rigid", "contact", ["chosen more than once", "contact=<option>", "cone_multi"]),
        ("material=null", "material", ["cannot unset", "material=<option>", "dry_sand"]),
    ],
)
def test_bad_group_value_names_the_group_and_its_choices(
    compose: Callable[..., DictConfig], override: str, group: str, words: list[str]
) -> None:
    """An unknown or misused group value is bad input naming the group and listing its options."""
    with pytest.raises(ConfigInputError) as info:
        compose("+exp=gm_loco", override)
    assert info.value.key == group
    for word in words:
        assert word in str(info.value)
