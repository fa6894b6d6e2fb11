# SPDX-License-Identifier: Apache-2.0
"""The paper's MPM tables across policies: several evaluation runs, one table (issue 9).

GM-Loco's contact-model ablation and per-terrain tables put several policies side by side. Each policy is scored
by its own evaluation run (often over several machines: a run folder resumes from its ``episodes.jsonl``); this
tool labels each run's episodes with the policy's name and writes the combined tables:

    python -m gmloco.eval.report.paper_tables --run td=RUN_DIR --run clr50=RUN_DIR [...] --out DIR [--episodes 100]
    python -m gmloco.eval.report.paper_tables --runs-file results/mpm_eval/tables/runs.txt --out DIR   # LABEL=DIR lines

* ``table_terrains.{md,csv}``: one row per (policy, terrain, scenario) with the success rate and its 95 % Wilson
  interval, tracking errors, DTW path error, sinkage and swing (``gmloco.eval.report.tables_mpm``);
* ``table_speeds.{md,csv}``: success rate per commanded speed, one row per (policy, terrain, scenario);
* ``table_transition.{md,csv}`` and ``fig_transition_<label>.png`` (per medium and speed) when a run walked the
  layered course;
* ``table_ablation.{md,csv}`` (the contact-model ablation's layout: per terrain and policy, the straight walk's
  success beside the circular walk's success and DTW path error) and ``table_per_terrain.{md,csv}`` (one row per
  terrain, each policy's success rate and velocity / yaw tracking errors on the straight walk);
* ``fig_per_terrain.png``: the per-terrain table as bars (success rate with its interval and episode count, mean
  sinkage; straight walks);
* ``fig_speeds_<terrain>_<scenario>.png``: per cell, the policies' success rate (95 % interval) and median time alive
  against the commanded speed;
* ``fig_table_<table>.png`` for every table above (``gmloco.eval.report.figures_tables``) and, where a run walked the
  transition course, ``fig_adaptation_<label>.png``: GM-Loco's adaptation figure (decoded eta and swing clearance
  over the course, per-medium means of every walk and the recorded walks);
* ``tables.json``: the runs, their common MPM setting, which rows are partial, the paper's metrics per (policy,
  terrain, scenario) (``paper_metrics``: ``success_pct``, ``vel_error_mps``, ``heading_error_deg``,
  ``path_error_m``, ``episodes``; ``tables_mpm.paper_metrics``), and the rows as records
  (``--summary FILE`` writes the same to FILE, e.g. ``results/mpm_eval/summary.json``).

A table mixes like with like only: runs whose MPM setting (voxel, iterations, frame, bed, window, episode length,
failure rules) differs are refused, naming the differing fields, unless ``--allow-mixed-settings`` (then each
markdown table ends with a note naming the rows and fields that differ). A row with
fewer than ``--episodes`` episodes says ``no`` in the ``complete`` column (and is listed in ``tables.json``): such a
row is a measurement, not the paper's 100-episode row.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path
from typing import Any

__all__ = ["SETTING_KEYS", "WINDOW_EXIT_NOTE_PCT", "combine", "main", "runs_file", "setting_of"]

SETTING_KEYS = ("solver", "window", "bed_depth", "episode_s", "failure", "course_slack", "circle_radius")
"""Fields of a run's ``summary.json`` ``cfg`` that define the experiment; runs in one table must agree on them."""

WINDOW_EXIT_NOTE_PCT = 5.0
"""Rows with more than this % of early sand-window exits are named under the tables [%]."""


def _summary(run_dir: Path) -> dict[str, Any]:
    """An evaluation run's ``summary.json``."""
    path = run_dir / "summary.json"
    if not path.is_file():
        raise FileNotFoundError(f"{run_dir}: no summary.json; pass a g1_eval output folder (python -m "
                                "gmloco.eval.g1.cli --out DIR writes it)")  # fmt: skip
    return json.loads(path.read_text())


def setting_of(summary: dict[str, Any]) -> dict[str, Any]:
    """The MPM setting of an evaluation run: ``SETTING_KEYS`` of its ``summary.json`` cfg."""
    return {k: summary["cfg"].get(k) for k in SETTING_KEYS}


def _differences(a: dict[str, Any], b: dict[str, Any], prefix: str = "") -> list[str]:
    """Dotted names of the fields where two nested settings differ."""
    out = []
    for k in sorted(set(a) | set(b)):
        va, vb = a.get(k), b.get(k)
        if isinstance(va, dict) and isinstance(vb, dict):
            out += _differences(va, vb, f"{prefix}{k}.")
        elif va != vb:
            out.append(f"{prefix}{k} ({va!r} vs {vb!r})")
    return out


def combine(
    runs: list[tuple[str, Path]], out_dir: Path, episodes: int = 100, allow_mixed: bool = False
) -> dict[str, Any]:
    """Write the combined tables of ``runs`` (label, run folder) under ``out_dir``; return ``tables.json``'s content.

    Folders given the same label are pooled (one policy's cells scored in several folders, e.g. one per GPU by
    ``gmloco.eval.g1.queue``); they must hold the same policy.

    Raises:
        ValueError: Two runs differ in their MPM setting (and ``allow_mixed`` is False), one label names runs of
            different policies, or a run holds no episodes.
    """
    from gmloco.eval.metrics.episodes import load_episodes
    from gmloco.eval.report.tables_mpm import (
        ABLATION_COLUMNS,
        TERRAIN_COLUMNS,
        TRANSITION_COLUMNS,
        paper_metrics,
        table_ablation,
        table_per_terrain,
        table_speeds,
        table_terrains,
        table_transition,
        write_table,
    )

    grouped: dict[str, list[Path]] = {}
    for label, d in runs:
        grouped.setdefault(label, []).append(Path(d))
    labels = list(grouped)
    summaries = {label: [_summary(d) for d in ds] for label, ds in grouped.items()}
    for label, sms in summaries.items():
        policies = sorted({str(sm.get("policy")) for sm in sms})
        if len(policies) > 1:
            raise ValueError(f"the runs labelled {label!r} scored different policies ({policies}); give each "
                             "policy its own label")  # fmt: skip
    first = labels[0]
    base = setting_of(summaries[first][0])
    mixed = _mixed_settings(base, grouped, summaries)
    if mixed and not allow_mixed:
        lines = "; ".join(f"{label}: {', '.join(diff)}" for label, diff in mixed.items())
        raise ValueError(f"runs were scored at different MPM settings than {first!r} ({lines}); rerun them at one "
                         "setting, or pass --allow-mixed-settings to tabulate them anyway")  # fmt: skip
    loaded = [(label, [r for d in ds for r in load_episodes(d)]) for label, ds in grouped.items()]
    all_speeds = sorted({float(r["speed"]) for _, rows in loaded for r in rows})
    terrains, speeds, transition, partial = [], [], [], []
    for label, rows in loaded:
        for row in table_terrains(rows, label):
            complete = row[3] >= episodes
            terrains.append([*row, "yes" if complete else "no"])
            if not complete:
                partial.append(f"{label}/{row[1]}/{row[2]}: {row[3]} of {episodes} episodes")
        speeds += [[label, *r] for r in table_speeds(rows, all_speeds)[1]]
        transition += [[label, *r] for r in table_transition(rows)]
    out_dir.mkdir(parents=True, exist_ok=True)
    exits = _window_exit_rows(terrains)
    turns = _window_share_rows(terrains, exits, "window_exit_turn_pct")
    falls = _window_share_rows(terrains, exits, "window_exit_fall_pct")
    note = _mixed_note(first, mixed) + _window_exit_note(exits, turns, falls)
    write_table(out_dir / "table_terrains", (*TERRAIN_COLUMNS, "complete"), terrains, note)
    write_table(out_dir / "table_speeds", ["policy", *table_speeds([], all_speeds)[0]], speeds, note)
    if transition:
        write_table(out_dir / "table_transition", ("policy", *TRANSITION_COLUMNS), transition, note)
    write_table(out_dir / "table_ablation", ABLATION_COLUMNS, table_ablation(terrains), note)
    write_table(out_dir / "table_per_terrain", *table_per_terrain(terrains), note)
    figures = _figures_by_cell(loaded, out_dir) + _path_figures(grouped, summaries, out_dir)
    figures += _transition_figures(loaded, out_dir)
    figures += _table_figures(out_dir, terrains, speeds, transition, all_speeds)
    figures += _adaptation_figures(loaded, grouped, out_dir)
    if any(r["scenario"] == "straight" for _, rows in loaded for r in rows):
        from gmloco.eval.report.figures_mpm import fig_per_terrain

        figures.append(fig_per_terrain(loaded, out_dir / "fig_per_terrain.png"))
    summary = {
        "runs": {
            label: {"dirs": [str(d) for d in ds], "policy": summaries[label][0].get("policy")}
            for label, ds in grouped.items()
        },
        "setting": base,
        "mixed_settings": mixed,
        "episodes_expected": episodes,
        "partial_rows": partial,
        "window_exit_rows": exits,
        "window_exit_turn_rows": turns,
        "figures": [p.name for p in figures],
        "paper_metrics": paper_metrics(terrains),
        "rows": [dict(zip((*TERRAIN_COLUMNS, "complete"), row, strict=True)) for row in terrains],
        "speed_rows": [dict(zip(["policy", *table_speeds([], all_speeds)[0]], row, strict=True)) for row in speeds],
    }
    (out_dir / "tables.json").write_text(json.dumps(summary, indent=1) + "\n")
    return summary


def _figures_by_cell(loaded: list[tuple[str, list[dict[str, Any]]]], out_dir: Path) -> list[Path]:
    """``fig_speeds_<terrain>_<scenario>.png``: the policies side by side on each (terrain, scenario) cell."""
    from gmloco.eval.report.figures_mpm import fig_policies_by_speed

    cells = dict.fromkeys((r["terrain"], r["scenario"]) for _, rows in loaded for r in rows)
    paths = []
    for terrain, scenario in cells:
        runs = [
            (label, [r for r in rows if (r["terrain"], r["scenario"]) == (terrain, scenario)]) for label, rows in loaded
        ]
        runs = [(label, rs) for label, rs in runs if rs]
        paths.append(
            fig_policies_by_speed(runs, out_dir / f"fig_speeds_{terrain}_{scenario}.png", f"{terrain} / {scenario}")
        )
    return paths


def _transition_figures(loaded: list[tuple[str, list[dict[str, Any]]]], out_dir: Path) -> list[Path]:
    """``fig_transition_<label>.png``: each policy's transition-course walks per medium and speed."""
    from gmloco.eval.report.figures_mpm import fig_mpm_transition

    return [fig_mpm_transition(rows, out_dir / f"fig_transition_{label}.png", label)
            for label, rows in loaded if any(r.get("layers") for r in rows)]  # fmt: skip


def _table_figures(
    out_dir: Path,
    terrains: list[list[Any]],
    speeds: list[list[Any]],
    transition: list[list[Any]],
    all_speeds: list[float],
) -> list[Path]:
    """``fig_table_<table>.png``: one figure per table, drawn from the table's own rows."""
    from gmloco.eval.report import figures_tables as ft
    from gmloco.eval.report.tables_mpm import TERRAIN_COLUMNS, table_ablation, table_per_terrain, table_speeds

    columns: list[str] = [*TERRAIN_COLUMNS, "complete"]
    records: list[dict[str, Any]] = [{c: v for c, v in zip(columns, row, strict=True)} for row in terrains]
    out = [ft.fig_table_terrains(records, out_dir / "fig_table_terrains.png"),
           ft.fig_table_speeds(["policy", *table_speeds([], all_speeds)[0]], speeds, out_dir / "fig_table_speeds.png"),
           ft.fig_table_ablation(table_ablation(terrains), out_dir / "fig_table_ablation.png"),
           ft.fig_table_per_terrain(*table_per_terrain(terrains), out_dir / "fig_table_per_terrain.png")]  # fmt: skip
    if transition:
        out.append(ft.fig_table_transition(transition, out_dir / "fig_table_transition.png"))
    return out


def _adaptation_figures(
    loaded: list[tuple[str, list[dict[str, Any]]]], grouped: dict[str, list[Path]], out_dir: Path
) -> list[Path]:
    """``fig_adaptation_<label>.png`` for each policy that walked the transition course (with its recordings)."""
    from gmloco.eval.report.figures_tables import fig_adaptation

    out = []
    for label, rows in loaded:
        layered = [r for r in rows if r.get("layers")]
        if not layered:
            continue
        recs = sorted(p for d in grouped[label] for p in (d / "recordings").glob("transition__*.mcap"))
        try:
            out.append(fig_adaptation(layered, recs, out_dir / f"fig_adaptation_{label}.png", label))
        except (KeyError, ValueError, OSError) as exc:
            print(f"fig_adaptation_{label}.png skipped: a recording could not be read ({type(exc).__name__}: {exc})",
                  file=sys.stderr)  # fmt: skip
    return out


def _path_figures(
    grouped: dict[str, list[Path]], summaries: dict[str, list[dict[str, Any]]], out_dir: Path
) -> list[Path]:
    """``fig_paths_<terrain>_<scenario>.png``: each policy's recorded walks of a cell against the commanded paths.

    A policy's panel holds one recording per speed (its runs' first episodes; the first run that recorded a speed).
    """
    from gmloco.eval.report.figures_paths import fig_paths, recordings_by_cell

    cells: dict[tuple[str, str], list[tuple[str, list[Path]]]] = {}
    for label, dirs in grouped.items():
        for cell, recs in recordings_by_cell(list(dirs)).items():
            cells.setdefault(cell, []).append((label, recs))
    episode_s = float(summaries[next(iter(summaries))][0].get("cfg", {}).get("episode_s", 10.0))
    figures = []
    for (terrain, scenario), panels in cells.items():
        try:
            figures.append(fig_paths(panels, out_dir / f"fig_paths_{terrain}_{scenario}.png", episode_s,
                                     f"{terrain} / {scenario}"))  # fmt: skip
        except (KeyError, ValueError, OSError) as exc:
            print(f"fig_paths_{terrain}_{scenario}.png skipped: a recording could not be read "
                  f"({type(exc).__name__}: {exc})", file=sys.stderr)  # fmt: skip
    return figures


def _mixed_settings(
    base: dict[str, Any], grouped: dict[str, list[Path]], summaries: dict[str, list[dict[str, Any]]]
) -> dict[str, list[str]]:
    """Each label's setting differences from ``base``, one entry per distinct difference.

    The entry is keyed by the label when every folder of it differs so (a row's shares), else by the label and the
    folders that do.
    """
    mixed: dict[str, list[str]] = {}
    for label, ds in grouped.items():
        by_diff: dict[tuple[str, ...], list[Path]] = {}
        for d, sm in zip(ds, summaries[label], strict=True):
            if diff := _differences(base, setting_of(sm)):
                by_diff.setdefault(tuple(diff), []).append(d)
        for diff, dirs in by_diff.items():
            more = f" and {len(dirs) - 1} more folders" if len(dirs) > 1 else ""
            mixed[label if len(dirs) == len(ds) else f"{label} ({dirs[0]}{more})"] = list(diff)
    return mixed


def _mixed_note(first: str, mixed: dict[str, list[str]]) -> str:
    """Markdown note naming the rows scored at another setting than ``first``'s, and how ("" when none)."""
    if not mixed:
        return ""
    lines = [f"- `{label}`: {', '.join(diff)}" for label, diff in mixed.items()]
    return (
        f"\nScored at settings other than `{first}`'s (tabulated with `--allow-mixed-settings`):\n\n"
        + "\n".join(lines)
        + "\n"
    )


def _window_exit_rows(rows: list[list[Any]]) -> dict[str, float]:
    """``policy/terrain/scenario`` -> % of episodes whose soles left their sand window early, above the threshold.

    Rows above ``WINDOW_EXIT_NOTE_PCT`` only; NaN (runs older than the check) is never listed.
    """
    from gmloco.eval.report.tables_mpm import TERRAIN_COLUMNS

    k = TERRAIN_COLUMNS.index("window_exit_pct")
    return {f"{r[0]}/{r[1]}/{r[2]}": round(float(r[k]), 1) for r in rows if float(r[k]) > WINDOW_EXIT_NOTE_PCT}


def _window_share_rows(rows: list[list[Any]], exits: dict[str, float], column: str) -> dict[str, float]:
    """Key -> a ``column`` of the ``exits`` rows that recorded it (runs from the per-terrain runs on).

    ``window_exit_turn_pct``: % of episodes that left the window early because the robot turned;
    ``window_exit_fall_pct``: % whose early exit came within ``metrics.episodes.FALL_EXIT_S`` before their fall.
    """
    from gmloco.eval.report.tables_mpm import TERRAIN_COLUMNS

    k = TERRAIN_COLUMNS.index(column)
    return {key: round(float(r[k]), 1) for r in rows
            if (key := f"{r[0]}/{r[1]}/{r[2]}") in exits and math.isfinite(float(r[k]))}  # fmt: skip


def _window_exit_note(
    exits: dict[str, float], turns: dict[str, float] | None = None, falls: dict[str, float] | None = None
) -> str:
    """Markdown note naming the rows whose soles left the sand early ("" when none).

    With the share of each row's exits by the robot's turn and the share that came with the fall.
    """
    from gmloco.eval.metrics.episodes import FALL_EXIT_S

    if not exits:
        return ""
    turns, falls = turns or {}, falls or {}

    def why(key: str) -> str:
        if key not in turns:
            return ""
        return f" ({turns[key]:.0f} % by the robot's turn: give it a turning window)" if turns[key] > 0 else " (reach)"

    def fall(key: str) -> str:
        if key not in falls:
            return ""
        return f"; {falls[key]:.0f} % within {FALL_EXIT_S:g} s before their fall"

    lines = [f"- `{key}`: {pct:.0f} % of episodes{why(key)}{fall(key)}" for key, pct in exits.items()]
    return (
        "\nSoles left the sand window more than 0.25 s before the episode ended (the robot stepped where no sand "
        "was simulated), so these rows' times alive and falls may depend on the window; rerun them with a window "
        "that covers the reach printed by the run (`--window-length`, `--window-width`, `--window-lead`), or, where "
        "the robot turned out of a window on the grid's axes, with a window that turns with it (the default). Exits within "
        f"{FALL_EXIT_S:g} s before a fall came with it (a stumble's trailing sole): rerun at a window no sole left, "
        "the reach-window runs' poppy-seed and deep-sand rows did not change (`results/mpm_eval/table_rows/poppy_seed_deep_sand_reach/README.md`):\n\n"
        + "\n".join(lines)
        + "\n"
    )


def _run_arg(text: str) -> tuple[str, Path]:
    """``LABEL=DIR`` -> (label, folder)."""
    label, sep, d = text.partition("=")
    if not sep or not label or not d:
        raise argparse.ArgumentTypeError(f"{text!r}: expected LABEL=RUN_DIR, e.g. td=results/mpm_eval/my_run")
    return label, Path(d)


def runs_file(path: Path) -> list[tuple[str, Path]]:
    """The runs a file lists: one ``LABEL=RUN_DIR`` per line, ``#`` comments and blank lines skipped.

    ``RUN_DIR`` may be a glob pattern (e.g. the shares of one row, ``.../table_td_basalt_share*of4``), relative to
    the working directory; its matches are taken in sorted order.

    Raises:
        FileNotFoundError: No such file, or a line's folder or pattern matches nothing.
        ValueError: A line is not ``LABEL=RUN_DIR``.
    """
    import glob

    if not path.is_file():
        raise FileNotFoundError(f"--runs-file {path}: no such file")
    out: list[tuple[str, Path]] = []
    for n, raw in enumerate(path.read_text().splitlines(), 1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        try:
            label, pattern = _run_arg(line)
        except argparse.ArgumentTypeError as exc:
            raise ValueError(f"{path}:{n}: {exc}") from None
        matches = sorted(glob.glob(str(pattern))) if glob.has_magic(str(pattern)) else [str(pattern)]
        if not matches or not all(Path(m).is_dir() for m in matches):
            raise FileNotFoundError(f"{path}:{n}: {pattern} is no run folder (nothing matches); fix the line")
        out += [(label, Path(m)) for m in matches]
    if not out:
        raise ValueError(f"{path}: no run in it (one LABEL=RUN_DIR per line)")
    return out


def main(argv: list[str] | None = None) -> dict[str, Any]:
    """Command line: combine runs into the paper's tables."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument(
        "--run",
        type=_run_arg,
        action="append",
        default=[],
        help="LABEL=RUN_DIR (repeat per policy; folders with the same label are pooled)",
    )
    p.add_argument("--runs-file", type=Path, default=None,
                   help="a file of LABEL=RUN_DIR lines (RUN_DIR may be a glob, e.g. a row's shares), after --run")  # fmt: skip
    p.add_argument("--out", type=Path, required=True, help="folder for the tables")
    p.add_argument("--episodes", type=int, default=100, help="episodes a complete row has (the paper: 100)")
    p.add_argument("--allow-mixed-settings", action="store_true", help="tabulate runs scored at different settings")
    p.add_argument("--summary", type=Path, default=None, help="also write tables.json's content here (e.g. "
                   "results/mpm_eval/summary.json)")  # fmt: skip
    a = p.parse_args(argv)
    try:
        runs = list(a.run) + (runs_file(a.runs_file) if a.runs_file is not None else [])
        if not runs:
            p.error("give the runs: --run LABEL=RUN_DIR (repeat) and/or --runs-file FILE")
        summary = combine(runs, a.out, a.episodes, a.allow_mixed_settings)
    except (FileNotFoundError, ValueError) as exc:
        p.error(str(exc))
    if a.summary is not None:
        a.summary.parent.mkdir(parents=True, exist_ok=True)
        tmp = a.summary.with_name(a.summary.name + ".tmp")
        tmp.write_text(json.dumps({"tables": str(a.out), **summary}, indent=1) + "\n")
        tmp.replace(a.summary)
    print((a.out / "table_terrains.md").read_text(), end="")
    for row in summary["partial_rows"]:
        print(f"partial: {row}")
    return summary


if __name__ == "__main__":
    main()
