# SPDX-License-Identifier: Apache-2.0
"""What the mismatch benchmark's scorers share (``v3/score_v3.py``, ``v4/score_v4.py``).

Row loading with its status bookkeeping, the in-library and out-of-library metrics, one-sided Clopper-Pearson
bounds, the protocols' pass rules, provenance (manifest source hashes against a code commit, tool-code diff
against the protocol commit) and the markdown tables. Each scorer keeps what its protocol fixes: the episode
lists, the null sets and the false-positive headline, the protocol commit, and the summary's layout; where the
shared code differs between protocols, a ``ScoringCfg`` says how.
"""

from __future__ import annotations

import hashlib
import json
import subprocess
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from scipy.stats import beta

from gmloco.deploy.mismatch.benchmark.scorer import EXCITED_GAIN, _param_err, score
from gmloco.deploy.mismatch.benchmark.sweep import in_source_hash
from gmloco.deploy.mismatch.effects import EFFECT_IDS

RESULTS_HOME = Path(__file__).resolve().parents[2] / "results/mismatch_benchmark"
"""The results folder this script reads and writes (its data lives under ``results/``, the code here)."""

BENCH = RESULTS_HOME
REPO = BENCH.parent.parent
PKGS = {"mismatch": "packages/deploy/src/gmloco/deploy/mismatch", "contact": "packages/contact/src/gmloco/contact"}
"""The packages whose sources the sweep hashes, by the name ``sweep.source_sha256`` gives them."""


@dataclass(frozen=True)
class ScoringCfg:
    """How one protocol's scoring differs where the scorers share code."""

    label: str
    """Column header of the scores table (the benchmark version)."""
    checks: tuple[str, ...]
    """Row fields that must equal the protocol episode's; a row that differs is excluded (``<field>_mismatch``)."""
    bookkeeping: tuple[str, ...]
    """Files of the mismatch package allowed to change after the protocol (paths below the package)."""
    null_rows: tuple[tuple[str, str], ...]
    """False-positive rows of the table: (key in the summary's ``nulls``, label); the first is the headline."""
    no_data: str
    """Verdict of a target with no episode to read."""
    strength_table: str | None = None
    """Strength table every invocation must have used (recorded in the provenance), None: not checked."""
    report_partial: bool = False
    """Say how many episodes each suite misses, count the missing ones and list rows failing ``checks``."""


def git(*a: str) -> str:
    """Stdout of ``git`` run in the repository."""
    return subprocess.run(["git", *a], capture_output=True, text=True, check=True, cwd=REPO).stdout


def commit_adding(path: str) -> str | None:
    """The commit that added ``path`` (repository-relative), None before it is committed."""
    added = git("log", "--diff-filter=A", "--format=%H", "--", path).split()
    return added[-1] if added else None


def hash_at_commit(commit: str) -> dict[str, str]:
    """``sweep.source_sha256`` computed from the tracked files of ``commit`` (same byte layout)."""
    out = {}
    for name, root in PKGS.items():
        h = hashlib.sha256()
        files = git("ls-tree", "-r", "--name-only", commit, root).split()
        files = [f for f in files if in_source_hash(name, Path(f).relative_to(root).as_posix())]
        for f in sorted(files, key=lambda p: Path(p).relative_to(root).parts):  # the order of sorted Paths
            data = subprocess.run(["git", "show", f"{commit}:{f}"], capture_output=True, check=True, cwd=REPO).stdout
            h.update(Path(f).relative_to(root).as_posix().encode() + b"\0" + data + b"\0")
        out[name] = h.hexdigest()
    return out


def tool_diff(protocol: str, commit: str, bookkeeping: tuple[str, ...]) -> list[str]:
    """Files of the tool and the sand laws (as hashed) that differ between ``protocol`` and ``commit``."""
    excl = [f":(exclude){PKGS['mismatch']}/{b}" for b in bookkeeping]
    changed = git("diff", "--name-only", protocol, commit, "--", *PKGS.values(), *excl).split()
    return [
        f for f in changed if any(f.startswith(r + "/") and in_source_hash(n, f[len(r) + 1 :]) for n, r in PKGS.items())
    ]


def load_suite(d: Path, expected: list[dict], checks: tuple[str, ...]) -> tuple[list[dict], dict[str, Any]]:
    """Rows of one suite directory, in the protocol's order, with the status of every expected episode.

    A row under ``errors/`` whose truth key exists is a tool error (kept, ``tool_error``); without a key it is a
    generation error (excluded). An unreadable row file counts as missing. An ``errors/`` file of an episode that
    also has a good row under ``rows/`` (same seed) is a failed earlier attempt that a later invocation re-ran:
    the good row is scored and the file is listed under ``superseded_error`` (not counted). A row whose field in
    ``checks`` (e.g. seed, parameters, motion) differs from the protocol's episode is excluded and listed
    (``<field>_mismatch``, checked in the order of ``checks``).
    """
    rows: list[dict] = []
    status: dict[str, list[str]] = {"generation_error": [], "tool_error": [], "missing": []}
    status |= {f"{c}_mismatch": [] for c in checks}
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
        bad = next((c for c in checks if row.get(c) != ep.get(c)), None)
        if bad is not None:
            status[f"{bad}_mismatch"].append(n)
            continue
        if "error" in row:
            if not (d / "keys" / f"{n}.json").exists():
                status["generation_error"].append(n)
                continue
            status["tool_error"].append(n)
            row = {**row, "tool_error": True, "verdict": "tool_error", "winner": None, "ranked": []}
        rows.append(row)
    return rows, status


def mean(v: list) -> float | None:
    """Mean, None for no values."""
    return float(np.mean(v)) if v else None


def median(v: list) -> float | None:
    """Median, None for no values."""
    return float(np.median(v)) if v else None


def cp(k: int, n: int, conf: float = 0.95) -> dict[str, Any]:
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
            g = median([e["oracle_gain"] for e in se if e["oracle_gain"] is not None])
            cells[s] = {
                "n": len(se),
                "top1": mean([e["correct"] for e in se]),
                "median_oracle_gain": g,
                "excited": g is not None and g >= EXCITED_GAIN,
                "winners": [e["winner"] or e["verdict"] for e in se],
            }
        exc = [e for e in ce if cells[e["suite"]]["excited"]]
        per[c] = {
            "n": len(ce),
            "top1": mean([e["correct"] for e in ce]),
            "top1_excited_cells": mean([e["correct"] for e in exc]),
            "top3": mean([e["top3"] for e in ce]),
            "median_param_err": median([e["param_err"] for e in ce if e["param_err"] is not None]),
            "median_oracle_frac": median([e["oracle_frac"] for e in ce if e["oracle_frac"] is not None]),
            "cells": cells,
        }
    with_eps = [v for v in per.values() if v["n"]]
    h2 = [v["top1_excited_cells"] for v in with_eps if v["top1_excited_cells"] is not None]
    fitted = [e["covered"] for e in eps if e["covered"] is not None]
    return {
        "H1_top1_macro_all_classes": mean([v["top1"] for v in with_eps]),
        "classes_with_episodes": len(with_eps),
        "classes_without_episodes": [c for c, v in per.items() if not v["n"]],
        "H2_top1_macro_excited_cells": mean(h2),
        "H2_classes": len(h2),
        "top1_micro": cp(sum(e["correct"] for e in eps), len(eps)),
        "top3_macro": mean([v["top3"] for v in with_eps]),
        "median_param_err": median([v["median_param_err"] for v in with_eps if v["median_param_err"] is not None]),
        "classes_with_param_err": sum(v["median_param_err"] is not None for v in with_eps),
        "median_oracle_fraction": median(
            [v["median_oracle_frac"] for v in with_eps if v["median_oracle_frac"] is not None]
        ),
        "ci_coverage": mean(fitted),
        "ci_coverage_n": len(fitted),
        "per_class": per,
    }


def false_positives(rows: list[dict]) -> list[bool]:
    """Per null row, whether it is a false positive (verdict not ``no_mismatch``; a tool error counts as one)."""
    return [r.get("verdict") != "no_mismatch" for r in rows if r["effect"] == "none"]


def false_positive_names(fresh: dict[str, list[dict]]) -> list[str]:
    """Names of the false-positive null rows over all suites."""
    return [r["name"] for s in fresh.values() for r in s if r["effect"] == "none" and r.get("verdict") != "no_mismatch"]


def out_of_library(fresh: dict[str, list[dict]]) -> dict[str, Any]:
    """Fraction of out-of-library episodes with verdict ``unexplained``."""
    res: dict[str, Any] = {}
    allv = []
    for s, rows in fresh.items():
        v = [r.get("verdict") == "unexplained" for r in rows if r["effect"].startswith("ool.")]
        res[s] = cp(sum(v), len(v))
        res[f"{s}_verdicts"] = {r["name"]: r.get("verdict") for r in rows if r["effect"].startswith("ool.")}
        allv += v
    res["pooled"] = cp(sum(allv), len(allv))
    return res


def invocations(d: Path) -> list[dict]:
    """The manifest's invocations (none when the folder has no manifest yet)."""
    f = d / "manifest.json"
    return json.loads(f.read_text())["invocations"] if f.exists() else []


def provenance(dirs: dict[str, Path], code_commit: str | None, protocol: str | None, cfg: ScoringCfg) -> dict[str, Any]:
    """Source hashes (and strength tables) of every invocation; tool-code diff against the commit ``protocol``."""
    invs = {s: invocations(d) for s, d in dirs.items()}
    out: dict[str, Any] = {"protocol_commit": protocol, "code_commit": code_commit}

    def table(i: dict) -> str | None:
        return (i.get("strength_table") or {}).get("name")

    if cfg.strength_table is not None:
        key = f"all_invocations_strength_table_{cfg.strength_table}"
        out[key] = all(table(i) == cfg.strength_table for v in invs.values() for i in v)
    out["invocations"] = {
        s: [
            {k: i.get(k) for k in ("command", "git", "source_sha256", "mujoco", "wall_s_this_invocation", "cpus")}
            | ({"strength_table": table(i)} if cfg.strength_table is not None else {})
            | {
                "n_run": len(i["episodes_run_by_this_invocation"]),
                "cpu_s_children": i["cpu_s_children_this_invocation"],
            }
            for i in v
        ]
        for s, v in invs.items()
    }
    if code_commit:
        ref = hash_at_commit(code_commit)
        out["hash_at_code_commit"] = ref
        out["tool_files_changed_since_protocol"] = (
            tool_diff(protocol, code_commit, cfg.bookkeeping) if protocol else "no protocol commit"
        )
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


def sections(
    fresh: dict[str, list[dict]],
    nu: dict[str, Any],
    dirs: dict[str, Path],
    code_commit: str | None,
    protocol: str | None,
    cfg: ScoringCfg,
) -> dict[str, Any]:
    """The summary's scored sections, after the scorer's own bookkeeping (episodes, completeness, status).

    In order: targets, in-library metrics, the nulls ``nu`` (the protocol's false-positive counts; the first of
    ``cfg.null_rows`` is the headline), out of library, the benchmark scorer per suite (tool errors left out),
    provenance.
    """
    il = in_library(fresh)
    return {
        "targets": verdicts(il, nu[cfg.null_rows[0][0]], cfg),
        "in_library": il,
        "nulls": nu,
        "out_of_library": out_of_library(fresh),
        "per_suite_scorer": {s: score([r for r in rows if not r.get("tool_error")]) for s, rows in fresh.items()},
        "provenance": provenance(dirs, code_commit, protocol, cfg),
    }


def fmt(x: float | None, nd: int = 2) -> str:
    """``x`` with ``nd`` decimals, ``n/a`` for None."""
    return "n/a" if x is None else f"{x:.{nd}f}"


def markdown(s: dict[str, Any], cfg: ScoringCfg) -> str:
    """Tables of the pre-registered scores."""
    il, nu, ool = s["in_library"], s["nulls"], s["out_of_library"]
    t = s["targets"]
    (hk, hl), *other_nulls = cfg.null_rows
    h = nu[hk]
    per_suite = (
        " Missing per suite: "
        + ", ".join(f"{k} {len(v)} of {s['episodes_expected_per_suite'][k]}" for k, v in s["missing_per_suite"].items())
        + " (names at the end)."
        if cfg.report_partial
        else ""
    )
    head = (
        []
        if s["complete"]
        else [
            f"**Incomplete run:** {s['episodes_scored']} of {s['episodes_expected']} episodes scored; the verdicts "
            "below read only what ran." + per_suite,
            "",
        ]
    )
    lines = [
        *head,
        f"| metric (target) | {cfg.label} | verdict |",
        "|---|---|---|",
        f"| H1 top-1 at mid, macro over {il['classes_with_episodes']} classes, pooled (≥ 0.8) | "
        f"**{fmt(il['H1_top1_macro_all_classes'])}** | {t['top1_H1']} |",
        f"| H2 top-1 at mid, excited (class, suite) cells, {il['H2_classes']} classes (≥ 0.8 over ≥ 8) | "
        f"{fmt(il['H2_top1_macro_excited_cells'])} | {t['top1_H2']} |",
        f"| top-1 micro, {il['top1_micro']['k']}/{il['top1_micro']['n']} episodes (95 % lower bound) | "
        f"{fmt(il['top1_micro']['rate'])} ({fmt(il['top1_micro']['lower95'])}) | |",
        f"| top-3 at mid, macro | {fmt(il['top3_macro'])} | |",
        f"| false positives, {hl} {h['k']}/{h['n']} (≤ 0.05; 95 % upper bound) | "
        f"**{fmt(h['rate'], 3)}** ({fmt(h['upper95'], 3)}) | {t['false_positive']} |",
        *(
            f"| false positives, {lab} {nu[k]['k']}/{nu[k]['n']} | "
            f"{fmt(nu[k]['rate'], 3)} ({fmt(nu[k]['upper95'], 3)}) | |"
            for k, lab in other_nulls
        ),
        f"| median parameter error at mid, {il['classes_with_param_err']} classes (≤ 0.2) | "
        f"**{fmt(il['median_param_err'], 3)}** | {t['param_err']} |",
        f"| median fraction of the oracle held-out gain (≥ 0.5) | **{fmt(il['median_oracle_fraction'])}** | "
        f"{t['oracle_fraction']} |",
        f"| 95 % interval coverage, {il['ci_coverage_n']} fits | {fmt(il['ci_coverage'])} | |",
        f"| out of library → `unexplained` {ool['pooled']['k']}/{ool['pooled']['n']} (≥ 0.6) | "
        f"{fmt(ool['pooled']['rate'])} | |",
        "",
        "| class | top-1 | per suite: winners (median oracle gain, excited) | median param err | oracle frac |",
        "|---|---|---|---|---|",
    ]
    for c, v in il["per_class"].items():
        cells = "; ".join(
            f"{su}: {', '.join(x if x else 'none' for x in cv['winners'])} ({fmt(cv['median_oracle_gain'])}"
            f"{', excited' if cv['excited'] else ''})"
            for su, cv in v["cells"].items()
        )
        lines.append(
            f"| `{c}` | {fmt(v['top1'])} | {cells} | {fmt(v['median_param_err'], 3)} | {fmt(v['median_oracle_frac'])} |"
        )
    st = s["status"]
    count = f" ({len(st['missing'])})" if cfg.report_partial else ""
    lines += ["", f"Missing{count}: {st['missing'] or 'none'}. Generation errors: {st['generation_error'] or 'none'}. "]
    bad = {k: st[k] for k in (f"{c}_mismatch" for c in cfg.checks) if st.get(k)} if cfg.report_partial else {}
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


def verdicts(il: dict[str, Any], h: dict[str, Any], cfg: ScoringCfg) -> dict[str, str]:
    """The protocols' pass rules on ``il`` and the false-positive headline ``h`` (``cfg.no_data``: nothing to read)."""
    h1, h2 = il["H1_top1_macro_all_classes"], il["H2_top1_macro_excited_cells"]
    if h1 is None:  # no in-library episode: H2 has none either
        top1_h1 = top1_h2 = cfg.no_data
    else:
        top1_h1 = "established" if h1 >= 0.8 else "not met"
        if h1 >= 0.8:
            top1_h2 = "met"
        elif h2 is not None and h2 >= 0.8 and il["H2_classes"] >= 8:
            top1_h2 = "met on the excited cells only"
        else:
            top1_h2 = "not met"
    if not h["n"]:
        fpv = cfg.no_data
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
        "param_err": cfg.no_data if pe is None else "met" if pe <= 0.2 else "not met",
        "oracle_fraction": cfg.no_data if of is None else "met" if of >= 0.5 else "not met",
    }


def write(folder: Path, summary: dict[str, Any], cfg: ScoringCfg, brief: dict[str, Any]) -> None:
    """Write ``summary.json`` and ``scores.md`` into ``folder``; print the tables and ``brief`` (one JSON line)."""
    (folder / "summary.json").write_text(json.dumps(summary, indent=2, default=float))
    md = markdown(summary, cfg)
    (folder / "scores.md").write_text(md)
    print(md)
    print(json.dumps(brief))
