# SPDX-License-Identifier: Apache-2.0
"""Executed against commanded paths of the MPM evaluation's recorded episodes (what the DTW path error scores).

Each evaluation run records the best walk of every (terrain, scenario, speed) group (a success if any, else the
longest time alive; runs before the square-window runs: the first episode to end, often an early fall) as
``recordings/<terrain>__<scenario>__v<speed>.mcap``: one episode, not the group's typical one. :func:`recorded_path` reads one back as the pelvis path in its
start frame (start at the origin, heading +x) with the command it walked; :func:`fig_paths` draws a panel per policy
(or run), each speed's executed path solid over its commanded path dashed, marked where it ended: a cross where the
robot fell, a star where it finished the course (an episode ends there), nothing where the 10 s ran out.
"""

from __future__ import annotations

import re
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gmloco.deploy.logs import read_log

__all__ = ["RecordedPath", "fig_paths", "recorded_path", "recordings_by_cell"]

_END_MARKERS: dict[str, str | None] = {"completed": "*", "timeout": None}
"""Marker at a walk's end by its ``end_reason``; any other reason is a fall (``x``)."""
_NAME = re.compile(r"^(?P<terrain>.+?)__(?P<scenario>[a-z]+)__v(?P<speed>[0-9.]+)$")


@dataclass(frozen=True)
class RecordedPath:
    """One recorded episode's pelvis path and command."""

    xy: np.ndarray
    """Pelvis position in the start frame [T, 2] (origin at the start, +x along the start heading) [m]."""
    dt: float
    """Sample period [s]."""
    speed: float
    """Commanded forward speed [m/s]."""
    yaw_rate: float
    """Commanded yaw rate [rad/s] (0 on a straight walk)."""
    end_reason: str
    """How the episode ended: ``completed`` (course finished), ``timeout``, or the failure (``tilt``, ``height``)."""


def recorded_path(recording: str | Path) -> RecordedPath:
    """Read one episode recording (``g1.record`` schema) as its path in the start frame and its command.

    Raises:
        KeyError: The recording holds no odometry or no velocity command (not an evaluation episode).
    """
    from gmloco.eval.metrics.locomotion import quat_wxyz_to_roll_pitch_yaw

    with warnings.catch_warnings():  # a recording has no run_end record by design; the reader warns about it
        warnings.simplefilter("ignore")
        lg = read_log(recording)
    t, pos = lg.signal("odom.position")
    _, quat = lg.signal("odom.orientation")  # w x y z
    _, vx = lg.signal("command.lin_vel_x")
    _, wz = lg.signal("command.ang_vel_z")
    yaw0 = float(quat_wxyz_to_roll_pitch_yaw(np.asarray(quat[:1], dtype=float))[0, 2])
    c, s = np.cos(yaw0), np.sin(yaw0)
    d = np.asarray(pos, dtype=float)[:, :2] - np.asarray(pos, dtype=float)[0, :2]
    xy = np.stack([c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1]], axis=1)
    dt = float(np.median(np.diff(t))) if len(t) > 1 else 0.02
    end = (lg.run_end or {}).get("end_reason", "unknown")
    return RecordedPath(xy=xy, dt=dt, speed=float(vx[0]), yaw_rate=float(wz[0]), end_reason=end)


def recordings_by_cell(run_dirs: list[str | Path]) -> dict[tuple[str, str], list[Path]]:
    """One recording per speed of each (terrain, scenario) in run folders, ordered by speed.

    Where several folders recorded a speed (shares of one row), the first folder's is taken; file names that do
    not parse are skipped.
    """
    cells: dict[tuple[str, str], dict[float, Path]] = {}
    for d in run_dirs:
        for f in sorted((Path(d) / "recordings").glob("*.mcap")):
            if (m := _NAME.match(f.stem)) is not None:
                cells.setdefault((m["terrain"], m["scenario"]), {}).setdefault(float(m["speed"]), f)
    return {cell: [by_speed[v] for v in sorted(by_speed)] for cell, by_speed in cells.items()}


def fig_paths(panels: list[tuple[str, list[Path]]], path: str | Path, episode_s: float, title: str) -> Path:
    """One panel per (label, recordings): executed paths solid, commanded dashed, in each walk's start frame.

    Raises:
        KeyError, ValueError, OSError: A recording cannot be read (:func:`recorded_path`); nothing is written.

    Args:
        panels: (panel title, its recordings), e.g. one policy's recordings of one cell at each speed.
        path: Output ``.png``.
        episode_s: Episode length [s]: the commanded path is drawn over it.
        title: Figure title.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from gmloco.eval.metrics.locomotion import circular_path

    walks = [(label, [recorded_path(r) for r in recordings]) for label, recordings in panels]  # read all first
    width = max(6.0, 3.6 * len(panels))  # room for the title over a single panel
    fig, axes = plt.subplots(1, len(panels), figsize=(width, 3.8), squeeze=False, constrained_layout=True)
    for ax, (label, recorded) in zip(axes[0], walks, strict=True):
        for k, p in enumerate(recorded):
            cmd, _ = circular_path(p.speed, p.yaw_rate, episode_s, p.dt)
            color = f"C{k}"
            ax.plot(cmd[:, 0], cmd[:, 1], "--", color=color, lw=1.0, alpha=0.6)
            ax.plot(p.xy[:, 0], p.xy[:, 1], "-", color=color, lw=1.4, label=f"{p.speed:g} m/s")
            if (marker := _END_MARKERS.get(p.end_reason, "x")) is not None:
                ax.plot(*p.xy[-1], marker, color=color, ms=8, mew=2)
        ax.set_aspect("equal", adjustable="datalim")
        ax.set(xlabel="x along the start heading [m]", ylabel="y [m]", title=label)
        ax.title.set_fontsize(8)
        ax.legend(fontsize=7)
    fig.suptitle(f"{title}\nexecuted (solid) vs commanded (dashed), x = fell, * = course finished", fontsize=9)
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)
    return Path(path)
