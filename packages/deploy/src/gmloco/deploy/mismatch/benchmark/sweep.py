# SPDX-License-Identifier: Apache-2.0
"""Run benchmark episodes in parallel processes and score them.

Usage: ``python -m gmloco.deploy.mismatch.benchmark.sweep --out DIR [--workers N] [--seeds 2] [--nulls 8]``
(``--seed-offset K`` for fresh seeds, ``--part I/N`` for one of N interleaved parts of the list,
``--deadline-s S`` to start no episode after S seconds; ``--resume`` runs what is left; ``--strength-table v4``
for benchmark v4's mid strengths).
Each worker generates the "real" recording, writes the truth key under ``DIR/keys/`` (never passed to the
tool), analyses the recording with the tool, and then computes the oracle held-out energy with the true
parameters for the scorer.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from multiprocessing import Pool
from pathlib import Path
from typing import Any

import numpy as np

from gmloco.deploy.config_cli import Flag, add_flags, cfg_from_flags, check_flags
from gmloco.deploy.mismatch.benchmark.sweep_cfg import SweepCfg

__all__ = ["FLAGS", "HASH_SKIP", "in_source_hash", "main", "run_episode", "source_sha256"]


def _episode_cfg(ep: dict, duration: float, keep_before_fall: float | None) -> Any:
    """The generator's ``EpisodeCfg`` of one recording of an episode (the episode's fields, or a stage's)."""
    from gmloco.deploy.mismatch.benchmark.chirp import ChirpCfg
    from gmloco.deploy.mismatch.benchmark.generator import EpisodeCfg
    from gmloco.deploy.mismatch.benchmark.policy_motion import motion_cfg
    from gmloco.deploy.mismatch.benchmark.truth import TruthEffect

    return EpisodeCfg(
        effect=TruthEffect(ep["effect"], ep["params"]),
        duration=duration,
        seed=ep["seed"],
        keep_before_fall=keep_before_fall,
        ground="sand" if ep.get("ground", "plane") == "sand" else "plane",
        material=ep.get("material", "dry_sand"),
        policy=motion_cfg(ep.get("motion", "walk")) if ep.get("policy") else None,
        odometry=bool(ep.get("odometry", False)),
        support=ep.get("support", "free"),
        chirp=ChirpCfg() if ep.get("chirp") else None,
    )


def run_episode(
    ep: dict,
    out: str,
    duration: float = 8.0,
    keep_before_fall: float | None = None,
    effects: tuple[str, ...] | None = None,
) -> dict:
    """Generate, analyse and score-prepare one episode; returns a JSON-ready row.

    ``effects`` limits the tool's screening to a subset of the library (quick checks); None screens all. An
    episode with ``support`` gantry or fixed and ``chirp`` true is the in-air chirp stage (pelvis held). An
    episode with ``stages`` (a list of field dicts, e.g. ``[{"support": "gantry", "chirp": True}, {}]``) records
    one robot (one seed: the same effect, nuisances and noise draw) once per stage and diagnoses the recordings
    together (:func:`gmloco.deploy.mismatch.multi.analyze_many`).
    """
    from gmloco.deploy.mismatch.benchmark.generator import generate
    from gmloco.deploy.mismatch.effects import EFFECT_IDS
    from gmloco.deploy.mismatch.multi import analyze_many
    from gmloco.deploy.mismatch.pipeline import AnalysisCfg
    from gmloco.deploy.mismatch.replay import sand_replay_cfg

    t0 = time.time()
    sand = ep.get("ground", "plane") == "sand"
    recs, stage_keys = [], []
    try:
        for stage in ep.get("stages") or [{}]:
            rec, stage_key = generate(_episode_cfg({**ep, **stage}, duration, keep_before_fall))
            recs.append(rec)
            stage_keys.append(stage_key)
    except RuntimeError as exc:
        return {**ep, "error": str(exc)}
    keys = Path(out) / "keys"
    keys.mkdir(parents=True, exist_ok=True)
    key = stage_keys[0] if len(stage_keys) == 1 else {"stages": stage_keys}
    (keys / f"{ep['name']}.json").write_text(json.dumps(key))
    # The ground is what the user tells the tool (the robot walked on sand), not part of the hidden truth.
    cfg = AnalysisCfg(replay=sand_replay_cfg(ep.get("material", "dry_sand"))) if sand else AnalysisCfg()
    cfg.attribution.effects = effects
    res = analyze_many(recs, cfg)
    rep = res.report
    row = {
        **ep,
        "verdict": rep["verdict"],
        "winner": rep.get("winner"),
        "ranked": [h["id"] for h in rep["hypotheses"] if "rank" in h],
        "runtime_s": time.time() - t0,
    }
    trimmed = [{"fell_at_s": k["fell_at_s"], "kept_s": k["kept_s"]} for k in stage_keys if "kept_s" in k]
    if trimmed:
        row["trimmed"] = trimmed[0] if len(stage_keys) == 1 else trimmed
    row["untested"] = [u["id"] for u in rep["untested"]]
    row["nominal_energy_ratio"] = rep.get("mismatch", {}).get("nominal_energy_ratio")
    row["residual_ratio"] = rep.get("mismatch", {}).get("residual_ratio")
    row["nearest"] = rep.get("nearest")
    keys_h = ("passed", "dbic", "heldout_gain", "heldout_gain_lo", "heldout_gain_lo_signals", "p_boot")
    row["confirmed"] = [
        {"id": h["id"], **{k: h.get(k) for k in keys_h}} for h in rep["hypotheses"] if h.get("confirmed")
    ]
    hyp = next((h for h in rep["hypotheses"] if h["id"] == ep["effect"] and h.get("confirmed")), None)
    if hyp is not None:
        row["fit"] = {k: [v["value"], *v["ci95"]] for k, v in hyp["params"].items()}
    if ep["effect"] in EFFECT_IDS and "problem" in res.arrays:
        pb, r0 = res.arrays["problem"], res.arrays["r0"]
        from gmloco.deploy.mismatch.effects import effect

        theta = np.concatenate([np.asarray(ep["params"][p.name], float).ravel() for p in effect(ep["effect"]).params])
        e0 = float(np.sum(r0[pb.held] ** 2))
        eo = float(np.sum(pb.resid({ep["effect"]: theta}, pb.held) ** 2))
        w = res.arrays.get("winner")
        ef = float(np.sum(pb.resid({w.spec.id: w.theta}, pb.held) ** 2)) if w is not None else e0
        row["energy"] = {"nominal": e0, "oracle": eo, "fitted": ef}
    (Path(out) / "rows").mkdir(parents=True, exist_ok=True)
    # Write then rename: a sweep killed mid-write (a wall-clock limit) leaves no truncated row for --resume.
    tmp = Path(out) / "rows" / f".{ep['name']}.json.tmp"
    tmp.write_text(json.dumps(row, default=float))
    tmp.replace(Path(out) / "rows" / f"{ep['name']}.json")
    return row


def _star(args: tuple) -> dict:
    """Pool adapter: skips an episode not started by the deadline; a failed episode's row goes to ``OUT/errors``.

    ``args`` is ``run_episode``'s arguments followed by the deadline (``time.time()`` value, or None).
    """
    *ep_args, deadline = args
    ep, out = ep_args[0], ep_args[1]
    if deadline is not None and time.time() > deadline:
        return {**ep, "skipped": "not started before the deadline"}
    try:
        row = run_episode(*ep_args)
    except Exception as exc:  # keep the sweep alive; the row records the failure
        row = {**ep, "error": repr(exc)}
    if "error" in row:
        (Path(out) / "errors").mkdir(parents=True, exist_ok=True)
        (Path(out) / "errors" / f"{ep['name']}.json").write_text(json.dumps(row, default=float))
    return row


HASH_SKIP: dict[str, tuple[str, ...]] = {"contact": ("kernels_", "models.py", "model_base.py")}
"""Per package, file-name prefixes left out of the source hash: the Warp (GPU) implementation of the contact
models, which the benchmark's CPU truth and replay never call (they use ``gmloco.contact.reference``, the
materials, colliders, coefficients and configs)."""


def in_source_hash(package: str, rel: str) -> bool:
    """Whether the file at ``rel`` (a path relative to the package root) enters ``package``'s source hash."""
    return rel.endswith(".py") and not Path(rel).name.startswith(HASH_SKIP.get(package, ()))


def source_sha256() -> dict[str, str]:
    """SHA-256 over the Python sources the benchmark's results depend on (provenance).

    Keys: ``mismatch`` (the tool and the benchmark generator) and ``contact`` (the sand laws; without the Warp
    kernels, ``HASH_SKIP``). Each hash covers the sorted relative paths and bytes of the package's ``*.py``
    files found on the path (located, not imported: ``gmloco.contact`` would import Warp).
    """
    import hashlib
    from importlib.util import find_spec

    out = {}
    for name, mod in (("mismatch", "gmloco.deploy.mismatch"), ("contact", "gmloco.contact")):
        spec = find_spec(mod)
        if spec is None or spec.origin is None:
            out[name] = "not found"
            continue
        root = Path(spec.origin).parent
        h = hashlib.sha256()
        for f in sorted(root.rglob("*.py")):
            rel = f.relative_to(root).as_posix()
            if in_source_hash(name, rel):
                h.update(rel.encode() + b"\0" + f.read_bytes() + b"\0")
        out[name] = h.hexdigest()
    return out


def _part_indices(spec: str) -> tuple[int, int]:
    """``(i, n)`` of ``spec`` = ``"i/n"``; ValueError says what a valid one looks like."""
    try:
        i, n = (int(x) for x in spec.split("/"))
    except ValueError:
        raise ValueError(f"--part {spec!r}: give I/N with whole numbers, e.g. --part 0/2") from None
    if not 0 <= i < n:
        raise ValueError(f"--part {spec}: need 0 <= i < n")
    return i, n


def _part_spec(text: str) -> str:
    """Check ``--part I/N`` at parse time (a usage error, exit code 2)."""
    try:
        _part_indices(text)
    except ValueError as err:
        raise argparse.ArgumentTypeError(str(err).removeprefix("--part ")) from None
    return text


def _part(eps: list[dict], spec: str | None) -> list[dict]:
    """Episodes at the positions ``i``, ``i + n``, ... of the list for ``spec`` = ``"i/n"`` (all for None)."""
    if spec is None:
        return eps
    i, n = _part_indices(spec)
    return eps[i::n]


def _git_commit() -> dict:
    """Commit and dirty flag of the checkout (best effort)."""
    import subprocess

    def git(*a: str) -> str:
        return subprocess.run(["git", *a], capture_output=True, text=True, check=False).stdout.strip()

    return {"commit": git("rev-parse", "HEAD"), "dirty_paths": git("status", "--porcelain", "--", ".").count("\n")}


def _manifest(
    out: Path,
    argv: list[str],
    eps: list[dict],
    todo: list[dict],
    wall: float,
    cpu: float,
    git: dict,
    policy_motion: str | None = None,
    strength_table: dict | None = None,
) -> None:
    """Append this invocation to ``manifest.json``: commit, command line, configuration and timing.

    ``policy_motion``: the sand suite's motion name (its command schedule is recorded), None for the plane.
    ``strength_table``: the name and the mid strengths of the suite's strength table.
    """
    import os
    import platform
    from dataclasses import asdict

    import mujoco

    from gmloco.deploy.mismatch.benchmark.controller import MotionCfg
    from gmloco.deploy.mismatch.benchmark.generator import EpisodeCfg
    from gmloco.deploy.mismatch.benchmark.policy_motion import motion_cfg
    from gmloco.deploy.mismatch.pipeline import AnalysisCfg

    ep_cfg = asdict(EpisodeCfg())
    ep_cfg.pop("effect")
    man = {
        "git": git,
        "source_sha256": source_sha256(),
        "mujoco": mujoco.__version__,
        "episodes_run_by_this_invocation": [e["name"] for e in todo],
        "command": "python -m gmloco.deploy.mismatch.benchmark.sweep " + " ".join(argv),
        "episode_cfg": ep_cfg,
        "motion": asdict(MotionCfg()),
        "policy_motion": None
        if policy_motion is None
        else {"name": policy_motion, **asdict(motion_cfg(policy_motion))},
        "strength_table": strength_table,
        "analysis_cfg": asdict(AnalysisCfg()),
        "episodes": [e["name"] for e in eps],
        "wall_s_this_invocation": wall,
        "cpu_s_children_this_invocation": cpu,
        "cpus": os.cpu_count(),
        "load_avg_at_end": os.getloadavg(),
        "python": platform.python_version(),
    }
    # Every invocation (a first run, --resume, a re-run of some episodes with --only) is kept in order.
    path = out / "manifest.json"
    old = json.loads(path.read_text()) if path.exists() else {"invocations": []}
    runs = old.get("invocations", [old])  # a single-invocation manifest of an older sweep becomes the first entry
    path.write_text(json.dumps({"invocations": [*runs, man]}, indent=2, default=str))


FLAGS: tuple[Flag, ...] = (
    Flag("--workers", "workers"),
    Flag("--seeds", "seeds"),
    Flag("--nulls", "nulls"),
    Flag("--duration", "duration"),
    Flag("--motion", "motion"),
    Flag("--strengths", "strengths", sep=","),
    Flag("--strength-table", "strength_table"),
    Flag("--suite", "suite"),
    Flag("--keep-before-fall", "keep_before_fall"),
    Flag("--only", "only", sep=","),
    Flag("--score-only", "score_only"),
    Flag("--pool", "pool"),
    Flag("--resume", "resume"),
    Flag("--effects", "effects", sep=","),
    Flag("--seed-offset", "seed_offset"),
    Flag("--part", "part", parse=_part_spec),
    Flag("--deadline-s", "deadline_s"),
)
"""Every ``SweepCfg`` field the command line sets (lists as one comma-separated word); ``--out`` is its own."""


def _parse(argv: list[str]) -> tuple[Path, SweepCfg]:
    """The sweep folder and config of the arguments (exit code 2 on a malformed or out-of-range one)."""
    p = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    p.add_argument("--out", type=Path, required=True, help="sweep folder: rows/, keys/, summary.json, manifest.json")
    add_flags(p, SweepCfg(), FLAGS)
    a = p.parse_args(argv)
    check_flags(p, a, SweepCfg, FLAGS)
    return a.out, cfg_from_flags(a, SweepCfg(), FLAGS)


def _score_only(out: Path, pool: str | None) -> None:
    """Score the rows under ``out/rows`` (and, pooled, ``pool/rows``) into the summaries."""
    from gmloco.deploy.mismatch.benchmark.scorer import score

    rows = [json.loads(f.read_text()) for f in sorted((out / "rows").glob("*.json"))]
    (out / "summary.json").write_text(
        json.dumps({**score(rows), "episodes_scored": len(rows)}, indent=2, default=float)
    )
    if pool is not None:
        rows += [json.loads(f.read_text()) for f in sorted((Path(pool) / "rows").glob("*.json"))]
        pooled = {**score(rows), "episodes_scored": len(rows), "pooled_with": pool}
        (out / "summary_pooled.json").write_text(json.dumps(pooled, indent=2, default=float))


def _episodes(cfg: SweepCfg) -> list[dict]:
    """The episodes of the config's suite, part and name prefixes."""
    from gmloco.deploy.mismatch.benchmark.episodes import episode_list, sand_episode_list

    if cfg.suite == "sand":
        eps = sand_episode_list(
            cfg.seeds, cfg.nulls, seed_offset=cfg.seed_offset, motion=cfg.motion, table=cfg.strength_table
        )
    else:
        eps = episode_list(cfg.seeds, cfg.nulls, cfg.strengths, seed_offset=cfg.seed_offset, table=cfg.strength_table)
    eps = _part(eps, cfg.part)
    if cfg.only:
        eps = [e for e in eps if any(e["name"].startswith(s) for s in cfg.only)]
    return eps


def main(argv: list[str] | None = None) -> None:
    """Run the sweep and write ``summary.json`` and ``manifest.json``."""
    from gmloco.deploy.mismatch.benchmark.episodes import STRENGTH_TABLES
    from gmloco.deploy.mismatch.benchmark.policy_motion import MOTIONS
    from gmloco.deploy.mismatch.benchmark.scorer import score

    argv = list(sys.argv[1:] if argv is None else argv)
    out, cfg = _parse(argv)
    if cfg.score_only:
        _score_only(out, cfg.pool)
        return
    eps = _episodes(cfg)
    out.mkdir(parents=True, exist_ok=True)
    todo = [e for e in eps if not (cfg.resume and (out / "rows" / f"{e['name']}.json").exists())]
    t0, git = time.time(), _git_commit()
    deadline = None if cfg.deadline_s is None else t0 + cfg.deadline_s
    duration = cfg.duration if cfg.duration is not None else MOTIONS[cfg.motion] if cfg.suite == "sand" else 8.0
    args = [(e, str(out), duration, cfg.keep_before_fall, cfg.effects, deadline) for e in todo]
    with Pool(cfg.workers) as pool:
        fresh = pool.map(_star, args, chunksize=1)
    cpu = sum(os.times()[2:4])
    by_name = {r["name"]: r for r in fresh if "skipped" not in r}
    rows, missing = [], []
    for n in sorted(e["name"] for e in eps):
        f = out / "rows" / f"{n}.json"
        row = by_name.get(n) or (json.loads(f.read_text()) if f.exists() else None)
        if row is None:
            missing.append(n)
        else:
            rows.append(row)
    (out / "rows.json").write_text(json.dumps(rows, indent=1, default=float))
    summary = {**score(rows), "episodes_scored": len(rows), "missing": missing, "wall_s": time.time() - t0}
    (out / "summary.json").write_text(json.dumps(summary, indent=2, default=float))
    table = {"name": cfg.strength_table, "mid": STRENGTH_TABLES[cfg.strength_table][cfg.suite]}
    motion = cfg.motion if cfg.suite == "sand" else None
    _manifest(out, argv, eps, todo, time.time() - t0, cpu, git, motion, table)


if __name__ == "__main__":
    main()
