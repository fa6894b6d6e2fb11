# SPDX-License-Identifier: Apache-2.0
"""Analyze many logs and write the summary table (markdown, CSV, JSON) and figures: ``analyze(paths, out_dir)``."""

from __future__ import annotations

import csv
import json
import math
import warnings
from pathlib import Path
from typing import Any

from gmloco.deploy.logs.analysis.run_analysis import AnalysisCfg, RunAnalysis, analyze_log
from gmloco.deploy.logs.errors import LogFormatError

__all__ = ["analyze", "expand_paths"]

_COLUMNS = (
    "file", "source", "controller", "policy", "material", "support", "duration_s", "damaged", "velocity_source",
    "tracking_rmse_mps", "leg_odometry_rmse_mps", "n_stances", "stance_duration_s", "ankle_pitch_peak_Nm",
    "ankle_pitch_impulse_Nms", "n_swings", "clearance_mean_m", "clearance_std_m", "segmentation_agreement",
    "eta_mean",
)  # fmt: skip
_OUTPUTS = ("summary.md", "summary.csv", "summary.json", "tracking.csv")


def expand_paths(paths: list[str | Path]) -> list[Path]:
    """Expand directories to their ``*.mcap`` files (sorted); keep files as given.

    Raises:
        ValueError: No path given, a path that does not exist, or a directory without ``*.mcap`` files; the
            message is one paragraph saying what to pass instead.
    """
    if not paths:
        raise ValueError("no recording given: pass MCAP files (gmloco.g1_log/1 schema) or directories holding them.")
    out: list[Path] = []
    for p in map(Path, paths):
        if not p.exists():
            raise ValueError(f"'{p}' does not exist: pass MCAP files or directories holding them.")
        found = sorted(p.glob("*.mcap")) if p.is_dir() else [p]
        if not found:
            kinds = sorted({f.suffix or f.name for f in p.iterdir()})[:5]
            held = f"it holds {', '.join(kinds)}" if kinds else "it is empty"
            raise ValueError(
                f"directory '{p}' holds no *.mcap recording ({held}; subdirectories are not searched): pass MCAP "
                "files or the directory that holds them, e.g. packages/deploy/data/sample_logs."
            )
        out += found
    return out


def _fmt(v: Any) -> str:
    """Format a table cell."""
    if isinstance(v, float):
        return "" if math.isnan(v) else f"{v:.3g}"
    if isinstance(v, list):
        return " ".join(f"{x:.3g}" for x in v)
    return "" if v is None else str(v)


def _tracking_rows(runs: list[RunAnalysis]) -> list[dict]:
    """Velocity tracking per (controller, material, commanded speed, file)."""
    return [
        {"file": r.summary["file"], "controller": r.summary["controller"], "material": r.summary["material"],
         "velocity_source": r.summary["velocity_source"], **row}
        for r in runs
        for row in r.tracking
    ]  # fmt: skip


def _write_tables(runs: list[RunAnalysis], failures: list[dict], out_dir: Path) -> dict[str, Any]:
    """Write summary.md / summary.csv / tracking.csv / summary.json; return the JSON content."""
    rows = [r.summary for r in runs]
    with open(out_dir / "summary.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=_COLUMNS, extrasaction="ignore")
        w.writeheader()
        w.writerows([{c: _fmt(row.get(c)) for c in _COLUMNS} for row in rows])
    tracking = _tracking_rows(runs)
    with open(out_dir / "tracking.csv", "w", newline="") as f:
        cols = ["file", "controller", "material", "velocity_source", "cmd", "v_mean", "v_std", "error_mean", "rmse",
                "t_start", "t_end", "duration"]  # fmt: skip
        w = csv.DictWriter(f, fieldnames=cols)
        w.writeheader()
        w.writerows(tracking)
    lines = ["# G1 log summary", "", "| " + " | ".join(_COLUMNS) + " |", "|" + "---|" * len(_COLUMNS)]
    lines += ["| " + " | ".join(_fmt(row.get(c)) for c in _COLUMNS) + " |" for row in rows]
    lines += [
        "",
        "## Velocity tracking per commanded speed",
        "",
        "| file | controller | material | source | cmd [m/s] | v mean [m/s] | v std | rmse |",
        "|---" * 8 + "|",
    ]
    lines += [f"| {t['file']} | {t['controller']} | {t['material']} | {t['velocity_source']} | {t['cmd']:.2f} | "
              f"{t['v_mean']:.3f} | {t['v_std']:.3f} | {t['rmse']:.3f} |" for t in tracking]  # fmt: skip
    if failures:
        lines += ["", "## Files not analyzed", ""] + [f"- {f['file']}: {f['error']}" for f in failures]
    (out_dir / "summary.md").write_text("\n".join(lines) + "\n")
    content = {"runs": rows, "tracking": tracking, "failures": failures,
               "stances": {r.summary["file"]: r.stances for r in runs},
               "swings": {r.summary["file"]: r.swings for r in runs}}  # fmt: skip
    (out_dir / "summary.json").write_text(json.dumps(_nan_to_none(content), indent=1))
    return content


def _nan_to_none(x: Any) -> Any:
    """Replace NaN floats by ``None`` recursively (strict JSON)."""
    if isinstance(x, float) and math.isnan(x):
        return None
    if isinstance(x, dict):
        return {k: _nan_to_none(v) for k, v in x.items()}
    if isinstance(x, list):
        return [_nan_to_none(v) for v in x]
    return x


def _guard_inputs(paths: list[Path], out_dir: Path) -> None:
    """Refuse an output directory whose outputs would overwrite an input file."""
    inputs = {p.resolve() for p in paths}
    clash = [o for o in _OUTPUTS if (out_dir / o).resolve() in inputs]
    if clash:
        raise ValueError(f"output {clash} would overwrite an input file; choose another --out directory")


def analyze(
    paths: list[str | Path], out_dir: str | Path, cfg: AnalysisCfg | None = None, figures: bool = True,
    progress: bool = True,
) -> dict[str, Any]:  # fmt: skip
    """Analyze recordings and write the summary table and figures.

    Args:
        paths: MCAP files or directories of them.
        out_dir: Output directory (created); inputs are never overwritten.
        cfg: Analysis settings.
        figures: Also write the PNG figures.
        progress: Show a rich progress bar over files.

    Returns:
        ``summary.json``'s content plus ``"figures"`` (paths) and ``"warnings"`` (per file).

    Raises:
        ValueError: Bad ``paths`` (:func:`expand_paths`) or an ``out_dir`` whose outputs would overwrite an input.
    """
    files = expand_paths(paths)
    out = Path(out_dir)
    _guard_inputs(files, out)
    out.mkdir(parents=True, exist_ok=True)
    runs, failures, caught = [], [], {}
    for path in _progress(files, progress):
        with warnings.catch_warnings(record=True) as ws:
            warnings.simplefilter("always")
            try:
                runs.append(analyze_log(path, cfg))
            except (LogFormatError, OSError, KeyError) as exc:
                failures.append({"file": str(path), "error": f"{type(exc).__name__}: {exc}"})
        for w in ws:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        caught[str(path)] = [f"{w.category.__name__}: {w.message}" for w in ws]
    content = _write_tables(runs, failures, out)
    content["figures"] = [str(p) for p in (write_figures_lazy(runs, out / "figures") if figures and runs else [])]
    content["warnings"] = caught
    return content


def write_figures_lazy(runs: list[RunAnalysis], out_dir: Path) -> list[Path]:
    """Write the figures (matplotlib is imported only here)."""
    from gmloco.deploy.logs.analysis.figures import write_figures

    return write_figures(runs, out_dir)


def _progress(files: list[Path], enabled: bool) -> Any:
    """Iterate over files with a rich progress bar (plain iteration if rich is missing or disabled)."""
    if not enabled:
        yield from files
        return
    try:
        from rich.progress import track
    except ImportError:
        yield from files
        return
    yield from track(files, description="analyzing logs", transient=True)
