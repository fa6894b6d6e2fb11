# SPDX-License-Identifier: Apache-2.0
"""The noise-cost study's reduction and command line (the rollout itself runs in the slow G1 test)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from gmloco.train.studies.noise_cost import main, noise_rates


def test_rates_average_alive_steps_only_and_return_sums_them() -> None:
    """Two envs, two terms; env 1 dies after its first step: its later (garbage) rewards count nowhere."""
    rewards = np.zeros((3, 2, 2))
    rewards[:, 0] = [[2.0, -1.0]] * 3  # env 0: +2 tracking, -1 penalty every step
    rewards[0, 1] = [4.0, 0.0]
    rewards[1:, 1] = [1.0e9, -1.0e9]
    alive = np.array([[1, 1], [1, 0], [1, 0]], dtype=bool)
    out = noise_rates(rewards, alive, ["track", "penalty"], dt=0.02)
    assert out["rate"]["track"] == pytest.approx((2.0 * 3 + 4.0) / 4)
    assert out["rate"]["penalty"] == pytest.approx(-3.0 / 4)
    assert out["total_rate"] == pytest.approx(out["rate"]["track"] + out["rate"]["penalty"])
    assert out["survival"] == pytest.approx(0.5)
    assert out["return"] == pytest.approx(((2.0 - 1.0) * 3 * 0.02 + 4.0 * 0.02) / 2)


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["--noise-stds", "0,-1"], "--noise-stds"),
        (["--noise-stds", "a"], "--noise-stds"),
        (["--num-envs", "0"], "--num-envs"),
        (["--contact-model", "rft4d"], "--contact-model"),
        (["--material", "mud"], "--material"),
    ],
)
def test_bad_input_exits_2_naming_the_flag(argv: list[str], needle: str, capsys: pytest.CaptureFixture[str]) -> None:
    """Malformed flags are refused before any simulator is built."""
    with pytest.raises(SystemExit) as exc:
        main([*argv, "--out", "unused.json"])
    assert exc.value.code == 2 and needle in capsys.readouterr().err


def test_a_missing_run_folder_exits_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A folder without a training config is named, with what to pass."""
    assert main(["--policy", str(tmp_path), "--out", str(tmp_path / "out.json")]) == 2
    assert str(tmp_path) in capsys.readouterr().err


def test_replot_draws_the_figure_from_a_written_study(tmp_path: Path) -> None:
    """--replot redraws the PNG from the JSON alone (no simulator)."""
    import json

    doc = {
        "policy": "artifacts/x",
        "terms": ["track", "penalty"],
        "levels": {
            "0": {"rate": {"track": 2.0, "penalty": -0.1}, "total_rate": 1.9},
            "1": {"rate": {"track": 1.5, "penalty": -1.1}, "total_rate": 0.4},
        },
        "setup": {"cfg": {"floor_depth": 0.025, "material": "dry_sand", "contact_model": "rft3d", "speed": 1.0}},
    }
    (tmp_path / "s.json").write_text(json.dumps(doc))
    png = tmp_path / "s.png"
    assert main(["--out", str(tmp_path / "s.json"), "--figure", str(png), "--mark", "0.5", "--replot"]) == 0
    assert png.stat().st_size > 1000
    assert main(["--out", str(tmp_path / "missing.json"), "--figure", str(png), "--replot"]) == 2
