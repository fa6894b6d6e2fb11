# SPDX-License-Identifier: Apache-2.0
"""Score benchmark v4 exactly as PROTOCOL.md defines (H1, H2, false positives, parameter error, ...).

A copy of ``../v3/score_v3.py`` adapted to v4: the episode lists are the composite-motion sand suite with the
``v4`` strength table and 64 nulls, and the plane suite with 20 nulls, both at seed offset 20 000. The
false-positive headline is over the fresh composite sand nulls alone (no stored nulls). Every row must carry
its episode's seed, parameters and motion.

Reads ``V4/sand`` and ``V4/plane``: each holds ``rows/``, ``errors/``, ``keys/`` and ``manifest.json``, as the
device sweep left them. A folder that is absent, empty or partial is scored on what it holds, and every episode
without a row is listed as missing (``scores.md`` and ``summary.json`` → ``status``). It writes
``V4/summary.json`` and ``V4/scores.md``.

    uv run python results/mismatch_benchmark/v4/score_v4.py --code-commit COMMIT

``--code-commit`` is the commit whose tree the device ran. The script checks that the tool code there equals
the protocol commit's (the sweep's bookkeeping aside), that each manifest's source hash equals the hash of that
tree, and that each invocation used the ``v4`` strength table.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import subprocess
from collections import defaultdict
from pathlib import Path
from typing import Any

import numpy as np
from scipy.stats import beta

from gmloco.deploy.mismatch.benchmark.episodes import episode_list, sand_episode_list
from gmloco.deploy.mismatch.benchmark.scorer import EXCITED_GAIN, _param_err, score
from gmloco.deploy.mismatch.benchmark.sweep import in_source_hash
from gmloco.deploy.mismatch.effects import EFFECT_IDS

HERE = Path(__file__).parent
BENCH = HERE.parent
REPO = BENCH.parent.parent
PROTOCOL = "results/mismatch_benchmark/v4/PROTOCOL.md"
SEED_OFFSET, SEEDS, SAND_NULLS, PLANE_NULLS, TABLE, MOTION = 20000, 2, 64, 20, "v4", "composite"
"""The protocol's episode lists: ``sweep --seeds 2 --seed-offset 20000 --strength-table v4``, sand with
``--motion composite --nulls 64``, plane with ``--nulls 20``."""
BOOKKEEPING = ("benchmark/sweep.py",)
"""Files of the mismatch package allowed to change after the protocol (the sweep's bookkeeping). The strength
tables (``benchmark/episodes.py``) are not among them; every row's parameters are checked as well."""
PKGS = {"mismatch": "packages/deploy/src/gmloco/deploy/mismatch", "contact": "packages/contact/src/gmloco/contact"}


def _git(*a: str) -> str:
    return subprocess.run(["git", *a], capture_output=True, text=True, check=True, cwd=REPO).stdout


def protocol_commit() -> str | None:
    """The commit that added ``PROTOCOL.md`` (the tool code under test), None before it is committed."""
    added = _git("log", "--diff-filter=A", "--format=%H", "--", PROTOCOL).split()
    return added[-1] if added else None


def expected_lists() -> dict[str, list[dict]]:
    """The protocol's episodes per suite: 96 composite sand episodes and 48 plane episodes."""
    return {
        "sand": sand_episode_list(SEEDS, SAND_NULLS, seed_offset=SEED_OFFSET, motion=MOTION, table=TABLE),
        "plane": episode_list(SEEDS, PLANE_NULLS, seed_offset=SEED_OFFSET, table=TABLE),
    }


def hash_at_commit(commit: str) -> dict[str, str]:
    """``sweep.source_sha256`` computed from the tracked files of ``commit`` (same byte layout)."""
    out = {}
    for name, root in PKGS.items():
        h = hashlib.sha256()
        files = _git("ls-tree", "-r", "--name-only", commit, root).split()
        files = [f for f in files if in_source_hash(name, Path(f).relative_to(root).as_posix())]
        for f in sorted(files, key=lambda p: Path(p).relative_to(root).parts):  # the order of sorted Paths
            data = subprocess.run(["git", "show", f"{commit}:{f}"], capture_output=True, check=True, cwd=REPO).stdout
            h.update(Path(f).relative_to(root).as_posix().encode() + b"\0" + data + b"\0")
        out[name] = h.hexdigest()
    return out


def tool_diff(protocol: str, commit: str) -> list[str]:
    """Files of the tool and the sand laws (as hashed) that differ between ``protocol`` and ``commit``."""
    excl = [f":(exclude){PKGS['mismatch']}/{b}" for b in BOOKKEEPING]
    changed = _git("diff", "--name-only", protocol, commit, "--", *PKGS.values(), *excl).split()
    return [
        f for f in changed if any(f.startswith(r + "/") and in_source_hash(n, f[len(r) + 1 :]) for n, r in PKGS.items())
    ]


def load_suite(d: Path, expected: list[dict]) -> tuple[list[dict], dict[str, Any]]:
    """Rows of one suite directory, in the protocol's order, with the status of every expected episode.

    A row under ``errors/`` whose truth key exists is a tool error (kept, ``tool_error``); without a key it is a
    generation error (excluded). An unreadable row file counts as missing. An ``errors/`` file of an episode that
    also has a good row under ``rows/`` (same seed) is a failed earlier attempt that a later invocation re-ran:
    the good row is scored and the file is listed under ``superseded_error`` (not counted). A row whose seed,
    parameters or motion differ from the protocol's episode is excluded and listed (``seed_mismatch``,
    ``params_mismatch``, ``motion_mismatch``).
    """
    rows: list[dict] = []
    status: dict[str, list[str]] = {"generation_error": [], "tool_error": [], "missing": [], "seed_mismatch": []}
    status["params_mismatch"], status["motion_mismatch"] = [], []
    status["superseded_error"] = []
    for ep in expected:
        n = ep["name"]
        good, err = d / "rows" / f"{n}.json", d / "errors" / f"{n}.json"
        if good.exists() and err.exists():
            try:
                same_seed = json.loads(err.read_text()).get("seed") == json.loads(good.read_text()).get("seed")
            except json.JSONDecodeError:
                same_seed = False
            if same_seed:
                status["superseded_error"].append(n)
        row = None
        for sub in ("rows", "errors"):
            f = d / sub / f"{n}.json"
            if row is None and f.exists():
                try:
                    row = json.loads(f.read_text())
                except json.JSONDecodeError:
                    row = None
        if row is None:
            status["missing"].append(n)
            continue
        if row.get("seed") != ep["seed"]:
            status["seed_mismatch"].append(n)
            continue
        if row.get("params") != ep["params"]:
            status["params_mismatch"].append(n)
            continue
        if row.get("motion") != ep.get("motion"):
            status["motion_mismatch"].append(n)
            continue
        if "error" in row:
            if not (d / "keys" / f"{n}.json").exists():
                status["generation_error"].append(n)
                continue
            status["tool_error"].append(n)
            row = {**row, "tool_error": True, "verdict": "tool_error", "winner": None, "ranked": []}
        rows.append(row)
    return rows, status


def _mean(v: list) -> float | None:
    return float(np.mean(v)) if v else None


def _median(v: list) -> float | None:
    return float(np.median(v)) if v else None


def _cp(k: int, n: int, conf: float = 0.95) -> dict[str, Any]:
    """Rate with one-sided Clopper-Pearson bounds."""
    if n == 0:
        return {"k": 0, "n": 0, "rate": None, "upper95": None, "lower95": None}
    up = 1.0 if k >= n else float(beta.ppf(conf, k + 1, n - k))
    lo = 0.0 if k == 0 else float(beta.ppf(1 - conf, k, n - k + 1))
    return {"k": k, "n": n, "rate": k / n, "upper95": up, "lower95": lo}


def in_library(rows_by_suite: dict[str, list[dict]]) -> dict[str, Any]:
    """H1, H2, micro top-1, top-3, parameter error, oracle fraction and coverage over fresh mid episodes."""
    eps = []
    for suite, rows in rows_by_suite.items():
        for r in rows:
            if r["effect"] not in EFFECT_IDS or r.get("strength") != "mid":
                continue
            en = r.get("energy") or {}
            e = {
                "suite": suite,
                "name": r["name"],
                "effect": r["effect"],
                "correct": r.get("winner") == r["effect"],
                "top3": r["effect"] in (r.get("ranked") or [])[:3],
                "verdict": r.get("verdict"),
                "winner": r.get("winner"),
                "oracle_gain": 1.0 - en["oracle"] / max(en["nominal"], 1e-300) if en else None,
                "oracle_frac": (en["nominal"] - en["fitted"]) / (en["nominal"] - en["oracle"])
                if en and en["nominal"] - en["oracle"] > 0
                else None,
            }
            e["param_err"], e["covered"] = _param_err(r)
            eps.append(e)
    per: dict[str, dict[str, Any]] = {}
    for c in EFFECT_IDS:
        ce = [e for e in eps if e["effect"] == c]
        cells = {}
        for s in sorted({e["suite"] for e in ce}):
            se = [e for e in ce if e["suite"] == s]
            g = _median([e["oracle_gain"] for e in se if e["oracle_gain"] is not None])
            cells[s] = {
                "n": len(se),
                "top1": _mean([e["correct"] for e in se]),
                "median_oracle_gain": g,
                "excited": g is not None and g >= EXCITED_GAIN,
                "winners": [e["winner"] or e["verdict"] for e in se],
            }
        exc = [e for e in ce if cells[e["suite"]]["excited"]]
        per[c] = {
            "n": len(ce),
            "top1": _mean([e["correct"] for e in ce]),
            "top1_excited_cells": _mean([e["correct"] for e in exc]),
            "top3": _mean([e["top3"] for e in ce]),
            "median_param_err": _median([e["param_err"] for e in ce if e["param_err"] is not None]),
            "median_oracle_frac": _median([e["oracle_frac"] for e in ce if e["oracle_frac"] is not None]),
            "cells": cells,
        }
    with_eps = [v for v in per.values() if v["n"]]
    h2 = [v["top1_excited_cells"] for v in with_eps if v["top1_excited_cells"] is not None]
    fitted = [e["covered"] for e in eps if e["covered"] is not None]
    return {
        "H1_top1_macro_all_classes": _mean([v["top1"] for v in with_eps]),
        "classes_with_episodes": len(with_eps),
        "classes_without_episodes": [c for c, v in per.items() if not v["n"]],
        "H2_top1_macro_excited_cells": _mean(h2),
        "H2_classes": len(h2),
        "top1_micro": _cp(sum(e["correct"] for e in eps), len(eps)),
        "top3_macro": _mean([v["top3"] for v in with_eps]),
        "median_param_err": _median([v["median_param_err"] for v in with_eps if v["median_param_err"] is not None]),
        "classes_with_param_err": sum(v["median_param_err"] is not None for v in with_eps),
        "median_oracle_fraction": _median(
            [v["median_oracle_frac"] for v in with_eps if v["median_oracle_frac"] is not None]
        ),
        "ci_coverage": _mean(fitted),
        "ci_coverage_n": len(fitted),
        "per_class": per,
    }


def nulls(fresh: dict[str, list[dict]]) -> dict[str, Any]:
    """False positives (verdict not ``no_mismatch``; a tool error counts as one) on the fresh nulls.

    The headline is the fresh composite sand nulls alone (the protocol's decision 2): no stored null enters.
    """

    def fp(rows: list[dict]) -> list[bool]:
        return [r.get("verdict") != "no_mismatch" for r in rows if r["effect"] == "none"]

    fs, fp_ = fp(fresh.get("sand", [])), fp(fresh.get("plane", []))
    fpn = [r["name"] for s in fresh.values() for r in s if r["effect"] == "none" and r.get("verdict") != "no_mismatch"]
    return {
        "headline_sand_composite_fresh": _cp(sum(fs), len(fs)),
        "plane_fresh": _cp(sum(fp_), len(fp_)),
        "fresh_all": _cp(sum(fs + fp_), len(fs + fp_)),
        "fresh_false_positives": fpn,
    }


def out_of_library(fresh: dict[str, list[dict]]) -> dict[str, Any]:
    """Fraction of out-of-library episodes with verdict ``unexplained``."""
    res: dict[str, Any] = {}
    allv = []
    for s, rows in fresh.items():
        v = [r.get("verdict") == "unexplained" for r in rows if r["effect"].startswith("ool.")]
        res[s] = _cp(sum(v), len(v))
        res[f"{s}_verdicts"] = {r["name"]: r.get("verdict") for r in rows if r["effect"].startswith("ool.")}
        allv += v
    res["pooled"] = _cp(sum(allv), len(allv))
    return res


def _invocations(d: Path) -> list[dict]:
    """The manifest's invocations (none when the folder has no manifest yet)."""
    f = d / "manifest.json"
    return json.loads(f.read_text())["invocations"] if f.exists() else []


def provenance(dirs: dict[str, Path], code_commit: str | None) -> dict[str, Any]:
    """Source hashes and strength table of every invocation; tool-code diff against the protocol commit."""
    invs = {s: _invocations(d) for s, d in dirs.items()}
    proto = protocol_commit()
    out: dict[str, Any] = {
        "protocol_commit": proto,
        "code_commit": code_commit,
        "all_invocations_strength_table_v4": all(
            (i.get("strength_table") or {}).get("name") == TABLE for v in invs.values() for i in v
        ),
        "invocations": {
            s: [
                {k: i.get(k) for k in ("command", "git", "source_sha256", "mujoco", "wall_s_this_invocation", "cpus")}
                | {"strength_table": (i.get("strength_table") or {}).get("name")}
                | {
                    "n_run": len(i["episodes_run_by_this_invocation"]),
                    "cpu_s_children": i["cpu_s_children_this_invocation"],
                }
                for i in v
            ]
            for s, v in invs.items()
        },
    }
    if code_commit:
        ref = hash_at_commit(code_commit)
        out["hash_at_code_commit"] = ref
        out["tool_files_changed_since_protocol"] = tool_diff(proto, code_commit) if proto else "no protocol commit"
        out["all_invocations_match_code_commit"] = all(i.get("source_sha256") == ref for v in invs.values() for i in v)
    # An invocation killed by its timeout appends no manifest entry, though the rows it finished are complete.
    out["rows_without_manifest_invocation"] = {
        s: sorted(
            {f.stem for f in (d / "rows").glob("*.json") if not f.name.startswith(".")}
            - {n for i in invs[s] for n in i["episodes_run_by_this_invocation"]}
        )
        for s, d in dirs.items()
    }
    return out


def _f(x: float | None, nd: int = 2) -> str:
    return "n/a" if x is None else f"{x:.{nd}f}"


def markdown(s: dict[str, Any]) -> str:
    """Tables of the pre-registered scores."""
    il, nu, ool = s["in_library"], s["nulls"], s["out_of_library"]
    t = s["targets"]
    h = nu["headline_sand_composite_fresh"]
    head = (
        []
        if s["complete"]
        else [
            f"**Incomplete run:** {s['episodes_scored']} of {s['episodes_expected']} episodes scored; the verdicts "
            "below read only what ran. Missing per suite: "
            + ", ".join(
                f"{k} {len(v)} of {s['episodes_expected_per_suite'][k]}" for k, v in s["missing_per_suite"].items()
            )
            + " (names at the end).",
            "",
        ]
    )
    lines = [
        *head,
        "| metric (target) | v4 | verdict |",
        "|---|---|---|",
        f"| H1 top-1 at mid, macro over {il['classes_with_episodes']} classes, pooled (≥ 0.8) | "
        f"**{_f(il['H1_top1_macro_all_classes'])}** | {t['top1_H1']} |",
        f"| H2 top-1 at mid, excited (class, suite) cells, {il['H2_classes']} classes (≥ 0.8 over ≥ 8) | "
        f"{_f(il['H2_top1_macro_excited_cells'])} | {t['top1_H2']} |",
        f"| top-1 micro, {il['top1_micro']['k']}/{il['top1_micro']['n']} episodes (95 % lower bound) | "
        f"{_f(il['top1_micro']['rate'])} ({_f(il['top1_micro']['lower95'])}) | |",
        f"| top-3 at mid, macro | {_f(il['top3_macro'])} | |",
        f"| false positives, fresh composite sand nulls {h['k']}/{h['n']} (≤ 0.05; 95 % upper bound) | "
        f"**{_f(h['rate'], 3)}** ({_f(h['upper95'], 3)}) | {t['false_positive']} |",
        f"| false positives, fresh plane nulls {nu['plane_fresh']['k']}/{nu['plane_fresh']['n']} | "
        f"{_f(nu['plane_fresh']['rate'], 3)} ({_f(nu['plane_fresh']['upper95'], 3)}) | |",
        f"| false positives, all fresh nulls {nu['fresh_all']['k']}/{nu['fresh_all']['n']} | "
        f"{_f(nu['fresh_all']['rate'], 3)} ({_f(nu['fresh_all']['upper95'], 3)}) | |",
        f"| median parameter error at mid, {il['classes_with_param_err']} classes (≤ 0.2) | "
        f"**{_f(il['median_param_err'], 3)}** | {t['param_err']} |",
        f"| median fraction of the oracle held-out gain (≥ 0.5) | **{_f(il['median_oracle_fraction'])}** | "
        f"{t['oracle_fraction']} |",
        f"| 95 % interval coverage, {il['ci_coverage_n']} fits | {_f(il['ci_coverage'])} | |",
        f"| out of library → `unexplained` {ool['pooled']['k']}/{ool['pooled']['n']} (≥ 0.6) | "
        f"{_f(ool['pooled']['rate'])} | |",
        "",
        "| class | top-1 | per suite: winners (median oracle gain, excited) | median param err | oracle frac |",
        "|---|---|---|---|---|",
    ]
    for c, v in il["per_class"].items():
        cells = "; ".join(
            f"{su}: {', '.join(x if x else 'none' for x in cv['winners'])} ({_f(cv['median_oracle_gain'])}"
            f"{', excited' if cv['excited'] else ''})"
            for su, cv in v["cells"].items()
        )
        lines.append(
            f"| `{c}` | {_f(v['top1'])} | {cells} | {_f(v['median_param_err'], 3)} | {_f(v['median_oracle_frac'])} |"
        )
    st = s["status"]
    lines += ["", f"Missing ({len(st['missing'])}): {st['missing'] or 'none'}. "]
    lines[-1] += f"Generation errors: {st['generation_error'] or 'none'}. "
    bad = {k: st[k] for k in ("seed_mismatch", "params_mismatch", "motion_mismatch") if st.get(k)}
    if bad:
        lines[-1] += f"Excluded, not the protocol's episode: {bad}. "
    lines[-1] += f"Tool errors: {st['tool_error'] or 'none'}. Fresh false positives: {nu['fresh_false_positives']}."
    if st.get("superseded_error"):
        lines[-1] += (
            f" Not counted: {len(st['superseded_error'])} `errors/` files of a failed earlier attempt at episodes "
            "that a later invocation re-ran with the same seed (the good row is scored)."
        )
    orphans = {k: len(v) for k, v in s["provenance"].get("rows_without_manifest_invocation", {}).items() if v}
    if orphans:
        lines[-1] += (
            f" Rows that no manifest entry lists (an invocation killed by its timeout writes none), per suite: "
            f"{orphans}; names in `summary.json` → `provenance`."
        )
    return "\n".join(lines) + "\n"


def verdicts(il: dict[str, Any], h: dict[str, Any]) -> dict[str, str]:
    """The protocol's pass rules (``no episodes`` where a metric has nothing to read yet)."""
    h1, h2 = il["H1_top1_macro_all_classes"], il["H2_top1_macro_excited_cells"]
    if h1 is None:
        top1_h1 = top1_h2 = "no episodes"
    else:
        top1_h1 = "established" if h1 >= 0.8 else "not met"
        if h1 >= 0.8:
            top1_h2 = "met"
        elif h2 is not None and h2 >= 0.8 and il["H2_classes"] >= 8:
            top1_h2 = "met on the excited cells only"
        else:
            top1_h2 = "not met"
    if not h["n"]:
        fpv = "no episodes"
    elif h["upper95"] <= 0.05:
        fpv = "established"
    elif h["rate"] <= 0.05:
        fpv = "met as a point estimate"
    else:
        fpv = "not met"
    pe, of = il["median_param_err"], il["median_oracle_fraction"]
    return {
        "top1_H1": top1_h1,
        "top1_H2": top1_h2,
        "false_positive": fpv,
        "param_err": "no episodes" if pe is None else "met" if pe <= 0.2 else "not met",
        "oracle_fraction": "no episodes" if of is None else "met" if of >= 0.5 else "not met",
    }


def main(argv: list[str] | None = None) -> None:
    """Score and write ``summary.json`` and ``scores.md`` into ``--v4``."""
    p = argparse.ArgumentParser()
    p.add_argument("--v4", type=Path, default=HERE, help="folder holding sand/ and plane/ as the device left them")
    p.add_argument("--code-commit", default=None, help="the commit the device ran (provenance check)")
    a = p.parse_args(argv)
    expected = expected_lists()
    dirs = {s: a.v4 / s for s in expected if (a.v4 / s).exists()}
    fresh: dict[str, list[dict]] = {s: [] for s in expected}
    status: dict[str, list[str]] = defaultdict(list)
    for k in ("missing", "generation_error", "tool_error", "seed_mismatch", "params_mismatch", "motion_mismatch"):
        status[k] = []
    status["superseded_error"] = []
    missing_per_suite: dict[str, list[str]] = {}
    for s in expected:
        if s in dirs:
            fresh[s], st = load_suite(dirs[s], expected[s])
        else:
            st = {"missing": [e["name"] for e in expected[s]]}
        missing_per_suite[s] = st["missing"]
        for k, v in st.items():
            status[k] += v
    il, nu = in_library(fresh), nulls(fresh)
    bad = ("missing", "generation_error", "seed_mismatch", "params_mismatch", "motion_mismatch")
    summary = {
        "protocol": PROTOCOL,
        "episodes_expected": sum(len(v) for v in expected.values()),
        "episodes_expected_per_suite": {s: len(v) for s, v in expected.items()},
        "episodes_scored": sum(len(v) for v in fresh.values()),
        "complete": not any(status[k] for k in bad),
        "missing_per_suite": missing_per_suite,
        "status": dict(status),
        "targets": verdicts(il, nu["headline_sand_composite_fresh"]),
        "in_library": il,
        "nulls": nu,
        "out_of_library": out_of_library(fresh),
        "per_suite_scorer": {s: score([r for r in rows if not r.get("tool_error")]) for s, rows in fresh.items()},
        "provenance": provenance(dirs, a.code_commit),
    }
    (a.v4 / "summary.json").write_text(json.dumps(summary, indent=2, default=float))
    (a.v4 / "scores.md").write_text(markdown(summary))
    print(markdown(summary))
    keys = ("episodes_expected", "episodes_scored", "complete", "targets")
    print(json.dumps({k: summary[k] for k in keys} | {"missing": {k: len(v) for k, v in missing_per_suite.items()}}))


if __name__ == "__main__":
    main()
