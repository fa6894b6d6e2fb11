# SPDX-License-Identifier: Apache-2.0
"""Typed configs: rsl-rl dicts resolve to our classes, observation sets, paper network sizes."""

from __future__ import annotations

from rsl_rl.utils import resolve_callable

from gmloco.train.teacher_student import (
    DistillCfg,
    ObsGroupsCfg,
    PpoCfg,
    PpoSchedule,
    StudentActor,
    StudentCfg,
    StudentPPO,
    StudentRunner,
    TeacherActor,
    TeacherCfg,
    TeacherPPO,
)


def test_teacher_dict_resolves_to_our_plugins_with_paper_sizes() -> None:
    """class_name strings resolve through rsl-rl; sizes are the paper's (512, 256, 128 / 256, 128, 64 / 64, 128, 256)."""
    d = TeacherCfg().to_rsl_rl(ObsGroupsCfg())
    assert resolve_callable(d["actor"]["class_name"]) is TeacherActor
    assert resolve_callable(d["algorithm"]["class_name"]) is TeacherPPO
    assert d["actor"]["hidden_dims"] == d["critic"]["hidden_dims"] == (512, 256, 128)
    assert d["actor"]["encoder_hidden_dims"] == (256, 128, 64)
    assert d["actor"]["decoder_hidden_dims"] == (64, 128, 256)
    assert d["actor"]["activation"] == "elu"
    assert d["algorithm"]["eta_group"] == "critic" and d["algorithm"]["eta_index"] == -1


def test_observation_sets_follow_the_group_names() -> None:
    """Renamed env groups flow into every rsl-rl observation set."""
    g = ObsGroupsCfg(policy=("policy",), critic=("critic",), privileged=("privileged",), history="proprio_hist")
    assert g.to_rsl_rl() == {
        "actor": ["policy"],
        "critic": ["critic"],
        "teacher": ["policy"],
        "encoder": ["privileged", "proprio_hist"],
        "history": ["proprio_hist"],
    }


def test_distill_dict_shares_latent_and_decoder_sizes_with_the_teacher() -> None:
    """The student's latent and decoder copy match the teacher's; runner and algorithm resolve to ours."""
    teacher, student = TeacherCfg(latent_dim=8), StudentCfg()
    d = DistillCfg(teacher_checkpoint="t.pt").to_rsl_rl(teacher, student, ObsGroupsCfg())
    assert resolve_callable(d["class_name"]) is StudentRunner
    assert resolve_callable(d["algorithm"]["class_name"]) is StudentPPO
    assert resolve_callable(d["actor"]["class_name"]) is StudentActor
    assert resolve_callable(d["teacher"]["class_name"]) is TeacherActor
    assert d["actor"]["latent_dim"] == d["teacher"]["latent_dim"] == 8
    assert d["actor"]["decoder_hidden_dims"] == d["teacher"]["decoder_hidden_dims"]
    assert d["actor"]["history_length"] == 50 and d["teacher_checkpoint"] == "t.pt"


def test_ppo_kwargs_carry_plain_strings() -> None:
    """The enum fields reach rsl-rl as the plain strings it compares against (and that YAML can write)."""
    kwargs = PpoCfg(schedule=PpoSchedule.fixed).to_rsl_rl()
    assert type(kwargs["schedule"]) is str and kwargs["schedule"] == "fixed"
    assert type(kwargs["optimizer"]) is str and kwargs["optimizer"] == "adam"
    algorithm = DistillCfg().to_rsl_rl(TeacherCfg(), StudentCfg(), ObsGroupsCfg())["algorithm"]
    assert type(algorithm["schedule"]) is str and algorithm["schedule"] == "fixed"
