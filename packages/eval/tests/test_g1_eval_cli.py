# SPDX-License-Identifier: Apache-2.0
"""The MPM evaluation's command line: the coupling frame must divide the policy step."""

from __future__ import annotations

import pytest

from gmloco.eval.g1_eval_cli import _parse


def test_frame_dt_and_substeps_reach_the_parsed_arguments() -> None:
    """A 5 ms frame with one rigid step (the setting the G1 probes walk longest on) is accepted."""
    a = _parse(["--out", "x", "--frame-dt", "0.005", "--substeps", "1"])
    assert a.frame_dt == 0.005 and a.substeps == 1


@pytest.mark.parametrize("argv", [["--frame-dt", "0.003"], ["--frame-dt", "0.04"], ["--substeps", "0"]])
def test_a_frame_that_does_not_divide_the_policy_step_is_refused(
    argv: list[str], capsys: pytest.CaptureFixture[str]
) -> None:
    """3 ms and 40 ms frames do not fit 50 Hz policy steps, 0 substeps no physics: a usage error naming the value."""
    with pytest.raises(SystemExit):
        _parse(["--out", "x", *argv])
    assert argv[1] in capsys.readouterr().err
