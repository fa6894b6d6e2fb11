# SPDX-License-Identifier: Apache-2.0
"""The schema's closed choices name what the packages accept: one list of names, in the package."""

from __future__ import annotations

import typing
from enum import Enum

import pytest

from gmloco.train import config as train_config
from gmloco.train.tasks.g1_jump import config as jump_config
from workflows import schemas


@pytest.mark.parametrize(
    ("choice", "names"),
    [
        (schemas.ContactModelName, train_config.ContactModelName),
        (schemas.TerrainName, train_config.TerrainName),
        (schemas.FootClearanceForm, train_config.FootClearanceName),
        (schemas.JumpMotion, jump_config.JumpMotionName),
    ],
)
def test_schema_enum_names_are_the_package_literal(choice: type[Enum], names: object) -> None:
    """Each schema enum holds exactly the package ``Literal``'s names, each member named by its value."""
    assert [m.value for m in choice] == list(typing.get_args(names))
    assert all(m.name == m.value for m in choice)


def test_the_task_field_uses_the_named_literal() -> None:
    """``GranularTaskCfg.foot_clearance`` is typed by ``FootClearanceName``, the list the schema is checked against."""
    hints = typing.get_type_hints(train_config.GranularTaskCfg)
    assert hints["foot_clearance"] == train_config.FootClearanceName
