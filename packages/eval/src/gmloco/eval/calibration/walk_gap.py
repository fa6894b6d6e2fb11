# SPDX-License-Identifier: Apache-2.0
"""How a policy's straight walks differ between MPM and the training simulator, per material and speed.

Success alone does not say why a prediction misses. Per (material, speed) cell this reads, on the MPM side, the
episodes of the policy's MPM runs (``runs.<policy>.dirs`` of ``results/mpm_eval/summary.json``) and, on the
simulator side, the gate summary, and reports the same four things for both: the share of episodes that fell, the
share that survived but did not walk their course (MPM's ``timeout``, the gate's ``course_unfinished``), the
velocity-tracking error and the heading change.

The heading measures differ: MPM's ``heading_turn_deg`` is the largest turn from the start over the episode, the
gate's ``heading_drift_deg`` the turn at its end, survivors only; a turn that comes back counts on MPM's side alone.
"""

from __future__ import annotations

import statistics
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from gmloco.eval.calibration.predict import _speed_key
from gmloco.eval.metrics.episodes import load_episodes

__all__ = ["gate_walk", "mpm_walks"]

_FALLS = ("tilt", "base_height")
"""MPM failure reasons that are falls (``gmloco.eval.metrics.locomotion``); ``timeout`` is an unfinished course."""


def _median(values: Iterable[float | None]) -> float | None:
    """Median of the finite values; None when there are none."""
    finite = [float(v) for v in values if v is not None and v == v]
    return statistics.median(finite) if finite else None


def _pct(count: int, total: int) -> float | None:
    """``count`` of ``total`` in percent; None for no episodes."""
    return 100.0 * count / total if total else None


def mpm_walks(dirs: list[str], scenario: str = "straight") -> dict[str, dict[str, dict[str, Any]]]:
    """Return ``{material: {speed key: walk}}`` over the episodes of the MPM run folders ``dirs``.

    A walk: ``episodes``, ``fell_pct``, ``course_unfinished_pct`` (survived, course not walked), ``success_pct``,
    ``vel_error_mps`` and ``heading_turn_deg`` (medians over the episodes; the turn is the largest from the start).

    Raises:
        FileNotFoundError: If a folder holds no ``episodes.jsonl``.
    """
    cells: dict[tuple[str, str], list[dict[str, Any]]] = {}
    for d in dirs:
        for row in load_episodes(Path(d)):
            if row.get("scenario") == scenario and row.get("speed") is not None:
                cells.setdefault((str(row["terrain"]), _speed_key(float(row["speed"]))), []).append(row)
    out: dict[str, dict[str, dict[str, Any]]] = {}
    for (material, speed), rows in sorted(cells.items()):
        n = len(rows)
        out.setdefault(material, {})[speed] = {
            "episodes": n,
            "fell_pct": _pct(sum(r.get("reason") in _FALLS for r in rows), n),
            "course_unfinished_pct": _pct(sum(r.get("reason") == "timeout" for r in rows), n),
            "success_pct": _pct(sum(bool(r.get("success")) for r in rows), n),
            "vel_error_mps": _median(r.get("vel_error") for r in rows),
            "heading_turn_deg": _median(r.get("heading_turn_deg") for r in rows),
        }
    return out


def gate_walk(body: dict[str, Any], material: str, speed: str) -> dict[str, Any] | None:
    """The same walk from a gate summary's cell (None when the gate lacks it).

    ``fell_pct`` and ``course_unfinished_pct`` come from the cell's ``failures`` list and ``setup.episodes_per_cell``
    (``course_unfinished_pct`` is None for a summary written before the course rule); ``vel_error_mps`` is the
    gate's mean over the episodes, ``heading_drift_deg`` the survivors' mean turn at the end.
    """
    failures = (body.get("failures") or {}).get(material, {}).get(speed)
    n = (body.get("setup") or {}).get("episodes_per_cell")
    if failures is None or not n:
        return None
    course = "success_course_pct" in body
    unfinished = sum(f == "course_unfinished" for f in failures)
    return {
        "episodes": int(n),
        "fell_pct": _pct(len(failures) - unfinished, int(n)),
        "course_unfinished_pct": _pct(unfinished, int(n)) if course else None,
        "vel_error_mps": (body.get("vel_error_mps") or {}).get(material, {}).get(speed),
        "heading_drift_deg": (body.get("heading_drift_deg") or {}).get(material, {}).get(speed),
    }
