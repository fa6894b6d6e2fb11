# SPDX-License-Identifier: Apache-2.0
"""Figures keep their text inside the saved image: MPM evaluation figures (which name the policy) and log figures."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

pytest.importorskip("matplotlib")

import matplotlib

matplotlib.use("Agg")
from matplotlib.figure import Figure
from matplotlib.text import Text

LONG_POLICY = "gm_loco_student_clr50 (distilled, yaw target)"
"""A long policy name: the longest title and legend entries the figures draw."""
TERRAINS = ("dry_sand", "poppy_seed_deep", "basalt_rough")
"""Three terrains with long names."""
TOLERANCE_PX = 1.0
"""Rounding slack of the renderer's extents [px]."""


def _rows() -> list[dict[str, Any]]:
    """Episode rows over 3 terrains x 2 scenarios x 2 speeds with the fields the figures read."""
    rng = np.random.default_rng(0)
    layers = [{"medium": m, "steps": 10, "eta_mean": 0.3, "swing_apex": 0.04, "swing_lift": 0.05} for m in TERRAINS]
    rows = []
    for terrain in TERRAINS:
        for scenario in ("straight", "circle"):
            for speed in (1.0, 2.0):
                for _ in range(3):
                    rows.append({"terrain": terrain, "scenario": scenario, "speed": speed,
                                 "success": bool(rng.random() > 0.5), "vel_error": float(rng.random()),
                                 "alive_s": float(10 * rng.random()), "mean_sinkage": float(0.05 * rng.random()),
                                 "layers": layers})  # fmt: skip
    return rows


def _drawn_texts(fig: Figure) -> list[Text]:
    """Visible, non-empty texts that are drawn: tick labels only for ticks inside their axis' view interval."""
    ticks, drawn = set(), []
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            lo, hi = sorted(axis.get_view_interval())
            for tick in [*axis.get_major_ticks(), *axis.get_minor_ticks()]:
                ticks.update((id(tick.label1), id(tick.label2)))
                if lo - 1e-9 * (hi - lo) <= tick.get_loc() <= hi + 1e-9 * (hi - lo):
                    drawn += [label for label in (tick.label1, tick.label2) if label.get_visible()]
    drawn += [t for t in fig.findobj(Text) if id(t) not in ticks and t.get_visible()]
    return [t for t in drawn if t.get_text().strip()]


def _text_outside(fig: Figure, bbox_inches: Any) -> list[str]:
    """Drawn texts whose extent leaves the saved area (the figure, or its tight box)."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()  # type: ignore[attr-defined]
    tight = bbox_inches == "tight"
    box = fig.get_tightbbox(renderer).transformed(fig.dpi_scale_trans) if tight else fig.bbox
    bad = []
    for text in _drawn_texts(fig):
        ext = text.get_window_extent(renderer)
        inside = (ext.x0 >= box.x0 - TOLERANCE_PX and ext.y0 >= box.y0 - TOLERANCE_PX
                  and ext.x1 <= box.x1 + TOLERANCE_PX and ext.y1 <= box.y1 + TOLERANCE_PX)  # fmt: skip
        if not inside:
            bad.append(f"{text.get_text()!r} at {tuple(round(float(v)) for v in ext.bounds)} outside {box.bounds}")
    return bad


@pytest.fixture
def saved(monkeypatch: pytest.MonkeyPatch) -> Iterator[list[tuple[list[str], list[str]]]]:
    """Check each figure as it is saved; yields (clipped texts, all texts) per saved figure."""
    original = Figure.savefig
    seen: list[tuple[list[str], list[str]]] = []

    def check(self: Figure, *args: Any, **kwargs: Any) -> None:
        seen.append((_text_outside(self, kwargs.get("bbox_inches")), [t.get_text() for t in _drawn_texts(self)]))
        original(self, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", check)
    yield seen


def _speed_sweep(rows: list[dict[str, Any]], path: Path) -> None:
    from gmloco.eval.report.figures_mpm import fig_mpm_speed_sweep

    fig_mpm_speed_sweep(rows, path, LONG_POLICY)


def _transition(rows: list[dict[str, Any]], path: Path) -> None:
    from gmloco.eval.report.figures_mpm import fig_mpm_transition

    fig_mpm_transition(rows, path, LONG_POLICY)


def _by_speed(rows: list[dict[str, Any]], path: Path) -> None:
    from gmloco.eval.report.figures_mpm import fig_policies_by_speed

    fig_policies_by_speed([(LONG_POLICY, rows), ("ppo_rft3d", rows)], path, "dry_sand / straight")


def _per_terrain(rows: list[dict[str, Any]], path: Path) -> None:
    from gmloco.eval.report.figures_mpm import fig_per_terrain

    fig_per_terrain([(LONG_POLICY, rows), ("ppo_rft3d", rows), ("ppo_rigid", rows)], path)


FIGURES: dict[str, Callable[[list[dict[str, Any]], Path], None]] = {
    "speed_sweep": _speed_sweep,
    "transition": _transition,
    "policies_by_speed": _by_speed,
    "per_terrain": _per_terrain,
}
"""Each figure function of ``figures_mpm`` drawn with long names."""


@pytest.mark.parametrize("name", list(FIGURES))
def test_figure_text_stays_inside_and_names_the_policy(
    name: str, tmp_path: Path, saved: list[tuple[list[str], list[str]]]
) -> None:
    """Titles, labels, ticks and legend entries lie inside the saved image; the policy's name is shown."""
    FIGURES[name](_rows(), tmp_path / f"{name}.png")
    assert len(saved) == 1 and (tmp_path / f"{name}.png").is_file()
    clipped, texts = saved[0]
    assert not clipped, clipped
    assert any(LONG_POLICY in t for t in texts)
    assert not any(t.strip() == "export" or " export " in f" {t} " for t in texts), texts


def test_log_analysis_figures_keep_long_run_labels_inside(
    tmp_path: Path, saved: list[tuple[list[str], list[str]]]
) -> None:
    """The committed sample recordings (long file names in every legend entry) give figures with no clipped text."""
    from gmloco.deploy.logs.analysis.report import analyze

    folder = Path(__file__).resolve().parents[1] / "packages/deploy/data/sample_logs"
    samples: list[str | Path] = sorted(folder.glob("*.mcap"))
    assert samples
    analyze(samples, tmp_path / "logs", progress=False)
    assert len(saved) >= 5
    clipped = [entry for bad, _ in saved for entry in bad]
    assert not clipped, clipped


def test_checker_finds_a_legend_outside_the_figure(tmp_path: Path, saved: list[tuple[list[str], list[str]]]) -> None:
    """A legend pushed right of the axes without a tight box is reported as clipped (the check can fail)."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(3, 2))
    ax.plot([0, 1], [0, 1], label="a rather long legend entry")
    ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0))
    fig.savefig(tmp_path / "clipped.png")
    plt.close(fig)
    assert any("legend entry" in entry for entry in saved[0][0]), saved[0][0]
