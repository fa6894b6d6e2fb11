# SPDX-License-Identifier: Apache-2.0
"""Post-hoc re-score of the stored benchmark rows under the residual-floor rule (PROTOCOL.md).

The winner's held-out residual per element is ``nominal_energy_ratio * (1 - heldout_gain)``, exactly what
``attribution.decide`` compares with ``mismatch_ratio``; a stored ``explained`` row whose winner leaves more
becomes ``unexplained``.

    uv run python benchmarks/mismatch_benchmark/ool/rescore.py   # writes rescore.json next to this file
"""

from __future__ import annotations

import json
from pathlib import Path

from gmloco.deploy.mismatch.attribution import AttributionCfg
from gmloco.deploy.mismatch.benchmark.scorer import score

RESULTS_HOME = Path(__file__).resolve().parents[3] / "results/mismatch_benchmark/ool"
"""The results folder this script reads and writes (its data lives under ``results/``, the code here)."""

HERE = RESULTS_HOME
BENCH = HERE.parent


def rescore(row: dict, bound: float) -> dict:
    """Return the row with the verdict the new rule gives, and the residual its winner leaves."""
    ratio = row.get("nominal_energy_ratio")
    win = next((c for c in row.get("confirmed", []) if c["id"] == row.get("winner")), None)
    if row.get("verdict") != "explained" or win is None or ratio is None:
        return {**row, "residual_ratio": ratio if row.get("verdict") != "explained" else None}
    left = ratio * (1.0 - win["heldout_gain"])
    if ratio >= AttributionCfg().mismatch_ratio and left > bound:
        return {**row, "verdict": "unexplained", "winner": None, "nearest": row["winner"], "residual_ratio": left}
    return {**row, "residual_ratio": left}


def load(sub: str) -> list[dict]:
    """Stored rows of one suite directory."""
    return [json.loads(f.read_text()) for f in sorted((BENCH / sub / "rows").glob("*.json"))]


def main() -> None:
    """Score plane, sand (pre-registered rows) and pooled, before and after the rule."""
    cfg = AttributionCfg()
    bound = cfg.mismatch_ratio if cfg.residual_ratio_max is None else cfg.residual_ratio_max
    plane, sand = [json.loads(f.read_text()) for f in sorted((BENCH / "rows").glob("*.json"))], load("sand")
    sand_post = {r["name"]: r for r in load("sand_posthoc")}
    # The post-hoc sand suite: the grid-start torque-speed row and 16 nulls replace the pre-registered ones.
    sand_ph = [sand_post.get(r["name"], r) for r in sand] + [
        r for n, r in sand_post.items() if n not in {x["name"] for x in sand}
    ]
    out: dict = {"bound": bound}
    for name, rows in (
        ("plane", plane),
        ("sand", sand),
        ("sand_posthoc", sand_ph),
        ("pooled", plane + sand),
        ("pooled_posthoc", plane + sand_ph),
    ):
        new = [rescore(r, bound) for r in rows]
        changed = [
            {
                "name": r["name"],
                "from": f"{r['verdict']}/{r.get('winner')}",
                "to": f"{n['verdict']}/{n.get('nearest')}",
                "residual_ratio": n["residual_ratio"],
            }
            for r, n in zip(rows, new, strict=True)
            if r["verdict"] != n["verdict"]
        ]
        keep = (
            "top1_mid_macro",
            "top1_mid_macro_excited",
            "top3_mid_macro",
            "false_positive_rate_null",
            "null_episodes",
            "false_positive_upper95_null",
        )
        before, after = score(rows), score(new)
        ool = lambda rs: [r["verdict"] == "unexplained" for r in rs if r["effect"].startswith("ool.")]  # noqa: E731
        out[name] = {
            "before": {k: before["overall"][k] for k in keep}
            | {"ool_unexplained": f"{sum(ool(rows))}/{len(ool(rows))}"},
            "after": {k: after["overall"][k] for k in keep} | {"ool_unexplained": f"{sum(ool(new))}/{len(ool(new))}"},
            "changed": changed,
            "in_library_residual_max": max(
                (
                    n["residual_ratio"]
                    for n in new
                    if n["verdict"] == "explained"
                    and n["effect"] not in ("none",)
                    and not n["effect"].startswith("ool.")
                    and n["residual_ratio"] is not None
                ),
                default=None,
            ),
        }
    (HERE / "rescore.json").write_text(json.dumps(out, indent=2, default=float))
    print(json.dumps(out, indent=1, default=float))


if __name__ == "__main__":
    main()
