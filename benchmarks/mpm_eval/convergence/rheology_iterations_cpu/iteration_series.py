# SPDX-License-Identifier: Apache-2.0
"""The td student's walk at 5 cm against the rheology iteration count (CPU): table and figure.

    uv run python benchmarks/mpm_eval/convergence/rheology_iterations_cpu/iteration_series.py   ->  iteration_series.md, fig_iteration_series.png

The touchdown-lift study's CPU walks at 50 / 100 / 250 iterations (``../../probes/touchdown_lift/probe_td_cpu.jsonl``, 10 s) and this study's
at 500 and 1000 (``probe_iters_cpu_i*.jsonl``, 5 s), then 3 s at 1000 iterations commanded 1.5 m/s and with the
delivered clr50 student at 1.0 m/s; all ``policy_probe.py --window eval --vx 1.0 --voxel 0.05
--frame-dt 0.005 --substeps 1 --handover predict --depth 0.3`` (the it-672 td student unless named); the rows and the figure
come from ``../../probes/touchdown_lift/probe_table.py`` (same columns: fall, speed, stance depth, swing apex / lift).
"""

from __future__ import annotations

import contextlib
import importlib.util
import io
from pathlib import Path

RESULTS_HOME = Path(__file__).resolve().parents[4] / "results/mpm_eval/convergence/rheology_iterations_cpu"
"""The results folder this script reads and writes (its data lives under ``results/``, the code here)."""

HERE = RESULTS_HOME
TD, S10 = "td student, it 672, CPU", HERE.parents[1] / "probes/touchdown_lift/probe_td_cpu.jsonl"
SERIES = {  # label -> (record file, policy)
    "student_td_B_v5_i50_dt0.005_sub1_10s_cpu": (S10, TD),
    "student_td_B_v5_i100_dt0.005_sub1_10s_cpu": (S10, TD),
    "student_td_B_v5_i250_dt0.005_sub1_10s_cpu": (S10, TD),
    "student_td_B_v5_i500_dt0.005_sub1_5s_cpu": (HERE / "probe_iters_cpu_i500.jsonl", TD),
    "student_td_B_v5_i1000_dt0.005_sub1_5s_cpu": (HERE / "probe_iters_cpu_i1000.jsonl", TD),
    # converged at other commands / policies: 1.5 m/s, and the delivered clr50 student (iteration 1,081)
    "student_td_B_v5_i1000_dt0.005_sub1_3s_vx1.5_cpu": (HERE / "probe_iters_cpu_i1000_vx1.5.jsonl", TD),
    "student_clr50_v5_i1000_dt0.005_sub1_3s_cpu": (
        HERE / "probe_iters_cpu_i1000_clr50.jsonl",
        "delivered clr50 student, CPU",
    ),
}
FIGURE = tuple(list(SERIES)[:5])
"""The iteration series at 1.0 m/s (the figure)."""


def main() -> None:
    """Print and write the table, draw the figure (records that do not exist yet are left out)."""
    spec = importlib.util.spec_from_file_location(
        "probe_table_s10", Path(__file__).resolve().parents[2] / "probes/touchdown_lift/probe_table.py"
    )
    assert spec is not None and spec.loader is not None
    pt = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(pt)
    runs = {label: run for label, run in SERIES.items() if run[0].exists() and label in path_labels(run[0])}
    pt.RUNS.clear()
    pt.RUNS.update(runs)
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        pt.table()
    (HERE / "iteration_series.md").write_text(buf.getvalue())
    print(buf.getvalue())
    pt.figure(HERE / "fig_iteration_series.png", tuple(r for r in FIGURE if r in runs), numerics=True)


def path_labels(path: Path) -> set[str]:
    """Labels recorded in a probe file."""
    import json

    return {json.loads(line)["label"] for line in path.read_text().splitlines() if line.strip()}


if __name__ == "__main__":
    main()
