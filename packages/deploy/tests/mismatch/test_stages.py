# SPDX-License-Identifier: Apache-2.0
"""The identification protocol: every effect has stages, untested effects name one, make_recording records each."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from gmloco.deploy.mismatch.attribution import Hypothesis
from gmloco.deploy.mismatch.benchmark.make_recording import main as make_recording
from gmloco.deploy.mismatch.effects import EFFECTS, effect
from gmloco.deploy.mismatch.io import read_recording
from gmloco.deploy.mismatch.report import _untested
from gmloco.deploy.mismatch.stages import STAGES, effect_stages, recording_stage, stage_to_record


def test_every_library_effect_has_protocol_stages() -> None:
    """Each effect maps to at least one known stage, and ground effects never to the in-air chirp."""
    for e in EFFECTS:
        stages = effect_stages(e.id)
        assert stages and set(stages) <= set(STAGES), e.id
        assert not (e.ground and "chirp" in stages), e.id


def test_stage_to_record_skips_stages_already_recorded() -> None:
    """Armature: chirp first; after a chirp recording, stepping; after both, the chirp again (record more)."""
    assert stage_to_record("joint.armature") == "chirp"
    assert stage_to_record("joint.armature", {"chirp"}) == "step"
    assert stage_to_record("joint.armature", {"chirp", "step"}) == "chirp"
    assert stage_to_record("actuator.torque_speed", {"chirp", "step"}) == "walk"


def test_untested_ground_effect_on_a_gantry_names_a_ground_stage() -> None:
    """A held pelvis cannot excite sand cohesion: the report asks for the stepping stage and gives the command."""
    h = Hypothesis(spec=effect("terrain.cohesion"), sens=np.zeros((1, 1, 1, 1)), testable=False)
    u = _untested(h, fixed=True, done_stages={"chirp"})
    assert u["stage"] == "step"
    assert u["reason"].startswith("untestable here: record stage step")
    assert u["record"].endswith("make_recording --stage step")


@pytest.mark.parametrize("stage", ["stand", "turn"])
def test_make_recording_records_the_stage_it_is_asked_for(tmp_path: Path, stage: str) -> None:
    """The recording's metadata names its stage, so the tool knows which stages a set of recordings covers."""
    out = tmp_path / f"{stage}.mcap"
    make_recording(["--stage", stage, "--duration", "1.2", "--seed", "4", "--out", str(out), "--key",
                    str(tmp_path / "key" / "key.json")])  # fmt: skip
    rec = read_recording(out)
    assert recording_stage(rec) == stage
    assert rec.has_odometry == (stage == "turn")
    assert json.loads((tmp_path / "key" / "key.json").read_text())["effect"] == "none"


def test_make_recording_refuses_a_scripted_stage_on_sand(tmp_path: Path) -> None:
    """Stand and step are scripted on the plane: asking for them on sand is a usage error (exit 2)."""
    with pytest.raises(SystemExit) as exc:
        make_recording(["--stage", "step", "--sand", "--out", str(tmp_path / "a.mcap"), "--key", str(tmp_path / "k")])
    assert exc.value.code == 2
