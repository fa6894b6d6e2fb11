# SPDX-License-Identifier: Apache-2.0
"""Which rheology solver reaches a given residual in the fewest sweeps, on the G1's own sand (issue 9).

The G1 walks ``warm_s`` on the evaluation's setting (CUDA graph, the configured solver and cap). Then every probe
frame solves the coupled rheology eagerly with one solver variant (``SolverImplicitMPM.Config.solver`` names,
e.g. ``gs``, ``jacobi``, ``jacobi,gs``, ``cr,gs``) up to ``probe_iterations`` sweeps at a tolerance no frame
reaches, and Newton's verbose loop reports the residual every 25-50 sweeps (L2 scaled by sqrt(1 + size), and
L-inf). The variants take turns frame after frame for ``cycles`` rounds, so each sees several mid-walk states.

Outputs under ``out``: ``probes.jsonl`` (one line per probe frame: variant, frame, residual curve, eager wall
time), ``summary.json`` (per variant: median residual at fixed sweep counts and the sweeps it needs to reach the
first variant's residual at ``reference_iterations``) and ``fig_residuals.png``. The eager wall time includes a
host read-back per residual check; the per-sweep cost under a CUDA graph is measured with ``g1.cli``
(``--rheology-solver``) instead.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import math
import re
import time
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from gmloco.deploy.config_cli import Flag, add_flags, cfg_from_flags, check_flags

__all__ = [
    "FLAGS",
    "SolverStudyCfg",
    "eval_cfg_of",
    "finite_residuals",
    "main",
    "parse_residual_log",
    "run_study",
    "summarize_probes",
    "sweeps_to_reach",
]

_ITER = re.compile(r"iteration #(\d+)\s+res\(l2\)=([0-9.eE+\-naif]+), res\(linf\)=([0-9.eE+\-naif]+)")
_LINEAR = re.compile(r"(\w+) terminated after (\d+) iterations with residual (\S+)")


@dataclass(frozen=True)
class SolverStudyCfg:
    """The probe schedule and the walk it probes."""

    variants: tuple[str, ...] = ("gs", "jacobi", "jacobi,gs", "gs-soa")
    """Solver names as ``MpmSolverCfg.rheology_solver``; the first is the reference."""
    warm_s: float = field(default=1.0, metadata={"ge": 0})
    """Walk before the first probe [s] (the evaluation's own solver, CUDA graph)."""
    probe_iterations: int = field(default=2000, metadata={"ge": 50})
    """Sweep cap of a probe frame, at least 50 (Newton reports the residual every 25-50 sweeps) [-]."""
    probe_tolerance: float = 1.0e-7
    """Tolerance of a probe frame (below any residual reached, so every curve runs to the cap)."""
    cycles: int = field(default=3, metadata={"ge": 1})
    """Rounds of probes (each variant once per round) [-]."""
    reference_iterations: int = 500
    """The reference variant's residual at this sweep count is the target the others must reach [-]."""
    robots: int = field(default=8, metadata={"ge": 1})
    """Robots (lanes) walking in the solver, one batch [-]."""
    speed: float = field(default=1.0, metadata={"gt": 0})
    """Commanded forward speed of the straight walk [m/s]."""
    terrain: str = "dry_sand"
    """Terrain of the walk (``G1EvalCfg.terrains``)."""
    voxel_size: float | None = field(default=None, metadata={"gt": 0})
    """Grid voxel size [m]; None: the evaluation's (``G1EvalCfg().solver.voxel_size``)."""
    cell_capacity_factor: float | None = field(default=None, metadata={"ge": 1, "also": (0.0,)})
    """Grid capacity factor (``G1EvalCfg.cell_capacity_factor``, 0 = unbounded); None: the evaluation's."""
    device: str | None = None
    """Warp device, e.g. ``cuda:0``; None: Warp's default."""


FLAGS: tuple[Flag, ...] = (
    Flag("--variants", "variants"),
    Flag("--robots", "robots"),
    Flag("--speed", "speed"),
    Flag("--terrain", "terrain"),
    Flag("--voxel", "voxel_size"),
    Flag("--warm-s", "warm_s"),
    Flag("--probe-iterations", "probe_iterations"),
    Flag("--cycles", "cycles"),
    Flag("--cell-capacity-factor", "cell_capacity_factor"),
    Flag("--device", "device"),
)
"""Every ``SolverStudyCfg`` field the command line sets; ``--policy`` and ``--out`` are the command line's own."""


def parse_residual_log(text: str) -> dict[str, Any]:
    """Residual curve of one verbose solve: ``{"iters": [...], "l2": [...], "linf": [...], "linear": [...]}``.

    ``linear`` holds (solver, iterations, residual) of a Krylov warm start, if the variant has one.
    """
    iters, l2, linf = [], [], []
    for m in _ITER.finditer(text):
        iters.append(int(m.group(1)))
        l2.append(float(m.group(2)))
        linf.append(float(m.group(3)))
    linear = [(m.group(1), int(m.group(2)), m.group(3)) for m in _LINEAR.finditer(text)]
    return {"iters": iters, "l2": l2, "linf": linf, "linear": linear}


def sweeps_to_reach(iters: list[int], residual: list[float], target: float) -> float:
    """First sweep count at which ``residual`` is at or below ``target`` (linear in log residual between reports).

    ``inf`` when the curve never gets there; ``nan`` for an empty curve or no target (``target`` nan).
    """
    if not iters or math.isnan(target):
        return math.nan
    if residual[0] <= target:
        return float(iters[0])
    for k in range(1, len(iters)):
        if residual[k] <= target:
            a, b = math.log(max(residual[k - 1], 1e-30)), math.log(max(residual[k], 1e-30))
            f = 0.0 if a == b else (a - math.log(target)) / (a - b)
            return float(iters[k - 1] + f * (iters[k] - iters[k - 1]))
    return math.inf


def _residual_at(iters: list[int], residual: list[float], n: int) -> float:
    """Residual reported at the last check at or before sweep ``n`` (nan if none)."""
    vals = [r for i, r in zip(iters, residual, strict=True) if i <= n]
    return vals[-1] if vals else math.nan


@contextlib.contextmanager
def finite_residuals(counts: list[tuple[int, int]]) -> Any:
    """Within: Newton's residual norm over the finite entries only; (finite, all) entry counts go to ``counts``.

    Newton 1.5.2 sizes the rheology arrays by the grid's reserved capacity, and the per-node residual of the
    reserved-but-inactive nodes is read from uninitialised temporaries (often NaN, on the CPU and the GPU), so the
    reported L2 norm is NaN and its half of the tolerance test cannot pass (the L-inf half ignores NaN). Here both
    norms skip them (eager solves only: it reads back).
    """
    import warp as wp
    from newton._src.solvers.implicit_mpm import solve_rheology as sr

    original = sr._RheologySolver.eval_residual

    def patched(self: Any) -> Any:
        original(self)
        r = self.strain_residual.numpy()
        ok = np.isfinite(r)
        counts.append((int(ok.sum()), int(r.size)))
        vals = np.array([[float(r[ok].sum())], [float(r[ok].max(initial=0.0))]], dtype=np.float32)
        return wp.array(vals, dtype=float, device=self.device)

    sr._RheologySolver.eval_residual = patched
    try:
        yield counts
    finally:
        sr._RheologySolver.eval_residual = original


def _probe(scene: Any, variant: str, cfg: SolverStudyCfg) -> dict[str, Any]:
    """One eager frame of ``scene`` solved by ``variant``; its residual curve and wall time."""
    import warp as wp

    from gmloco.eval.mpm.coupled_setup import rheology_solver_arg

    mpm = scene.mpm
    keep = (mpm.solver, mpm.max_iterations, mpm.tolerance, mpm._use_cuda_graph, mpm.verbose, scene.graph)
    arg = rheology_solver_arg(variant)
    mpm.solver = (arg,) if isinstance(arg, str) else tuple(arg)
    mpm.max_iterations, mpm.tolerance = cfg.probe_iterations, cfg.probe_tolerance
    mpm._use_cuda_graph, mpm.verbose, scene.graph = False, True, None
    buf = io.StringIO()
    error = None
    counts: list[tuple[int, int]] = []
    wp.synchronize()
    t0 = time.perf_counter()
    try:
        with contextlib.redirect_stdout(buf), finite_residuals(counts):
            scene.step()
        wp.synchronize()
    except Exception as exc:  # a variant Newton refuses here is reported, not fatal to the study
        error = repr(exc)
    wall = time.perf_counter() - t0
    mpm.solver, mpm.max_iterations, mpm.tolerance, mpm._use_cuda_graph, mpm.verbose, _ = keep
    row = {"variant": variant, "frame": scene.frame, "wall_s": wall, "error": error,
           "finite_nodes_min": min(c[0] for c in counts) if counts else None,
           "nodes": counts[-1][1] if counts else None}  # fmt: skip
    row.update(parse_residual_log(buf.getvalue()))
    return row


def summarize_probes(rows: list[dict[str, Any]], cfg: SolverStudyCfg) -> dict[str, Any]:
    """Per variant: median L2 and L-inf residuals at fixed sweep counts, and the sweeps to the reference's L2."""
    marks = [n for n in (100, 250, 500, 1000, 2000, 4000) if n <= cfg.probe_iterations]
    ref = [r for r in rows if r["variant"] == cfg.variants[0] and r["iters"]]
    target = (
        float(np.median([_residual_at(r["iters"], r["l2"], cfg.reference_iterations) for r in ref]))
        if ref
        else math.nan
    )
    out: dict[str, Any] = {"reference": cfg.variants[0], "reference_iterations": cfg.reference_iterations,
                           "target_l2": target, "variants": {}}  # fmt: skip
    for v in cfg.variants:
        mine = [r for r in rows if r["variant"] == v]
        ok = [r for r in mine if r["iters"]]
        entry: dict[str, Any] = {"probes": len(mine), "errors": [r["error"] for r in mine if r["error"]]}
        for n in marks:
            for norm in ("l2", "linf"):
                at_n = [_residual_at(r["iters"], r[norm], n) for r in ok]
                entry[f"{norm}_at_{n}"] = float(np.median(at_n)) if ok else math.nan
        reach = [sweeps_to_reach(r["iters"], r["l2"], target) for r in ok]
        entry["sweeps_to_target_median"] = float(np.median(reach)) if reach else math.nan
        entry["eager_ms_per_sweep_median"] = (
            float(np.median([1e3 * r["wall_s"] / r["iters"][-1] for r in ok])) if ok else math.nan
        )
        out["variants"][v] = entry
    return out


def _figure(rows: list[dict[str, Any]], cfg: SolverStudyCfg, path: Path) -> None:
    """Residual (L2) against sweeps, every probe, one colour per variant."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    for k, v in enumerate(cfg.variants):
        for j, r in enumerate(r for r in rows if r["variant"] == v and r["iters"]):
            ax.semilogy(r["iters"], r["l2"], color=f"C{k}", alpha=0.8, label=v if j == 0 else None)
    ax.axvline(cfg.reference_iterations, color="0.6", lw=0.8, ls="--")
    ax.set_xlabel("rheology sweeps in the frame")
    ax.set_ylabel("residual, L2 (scaled) [-]")
    ax.set_title("G1 on MPM sand: rheology solvers from mid-walk states")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def run_study(eval_cfg: Any, cfg: SolverStudyCfg, out: Path) -> dict[str, Any]:
    """Walk, probe, write ``probes.jsonl``, ``summary.json`` and the figure; return the summary."""
    import sys

    from gmloco.eval.g1.cell import build_cell_scene
    from gmloco.eval.g1.config import episode_specs
    from gmloco.eval.g1.policy import load_policy

    out.mkdir(parents=True, exist_ok=True)
    specs = episode_specs(eval_cfg)
    policy = load_policy(eval_cfg.policy_path, min(eval_cfg.robots_per_batch, len(specs)))
    t0 = time.perf_counter()
    scene, _, _ = build_cell_scene(specs, eval_cfg, policy)
    warm = round(cfg.warm_s / scene.frame_dt)
    for i in range(warm):
        scene.step()
        if i % 50 == 0:
            print(f"warm-up frame {i}/{warm}", file=sys.stderr, flush=True)
    rows: list[dict[str, Any]] = []
    with (out / "probes.jsonl").open("w") as f:
        for c in range(cfg.cycles):
            for v in cfg.variants:
                row = _probe(scene, v, cfg)
                row["cycle"] = c
                rows.append(row)
                f.write(json.dumps(row) + "\n")
                f.flush()
                last = f"{row['l2'][-1]:.3g}" if row["l2"] else "none"
                print(f"cycle {c + 1}/{cfg.cycles} {v}: {len(row['iters'])} reports, last l2 {last}, "
                      f"{row['wall_s']:.2f} s{' ERROR ' + row['error'] if row['error'] else ''}",
                      file=sys.stderr, flush=True)  # fmt: skip
    summary = summarize_probes(rows, cfg)
    summary["setting"] = {"voxel_size": eval_cfg.solver.voxel_size, "robots": scene.cfg.num_robots,
                          "window": [eval_cfg.window.length, eval_cfg.window.width], "bed": eval_cfg.bed_depth,
                          "eval_iterations": eval_cfg.solver.max_iterations, "study": cfg.__dict__,
                          "wall_s": time.perf_counter() - t0}  # fmt: skip
    tmp = out / "summary.json.tmp"
    tmp.write_text(json.dumps(summary, indent=1, default=str))
    tmp.replace(out / "summary.json")
    _figure(rows, cfg, out / "fig_residuals.png")
    return summary


def eval_cfg_of(cfg: SolverStudyCfg, policy: str, out: str) -> Any:
    """The evaluation setting the study walks: ``G1EvalCfg()`` with the study's robots, speed, terrain and grid."""
    from gmloco.eval.g1.config import G1EvalCfg

    base = G1EvalCfg()
    solver = base.solver if cfg.voxel_size is None else replace(base.solver, voxel_size=cfg.voxel_size)
    eval_cfg = replace(base, policy_path=policy, terrains=(cfg.terrain,), speeds=(cfg.speed,), scenarios=("straight",),
                       num_episodes=cfg.robots, robots_per_batch=cfg.robots, solver=solver, device=cfg.device,
                       record_mcap=False, out_dir=out)  # fmt: skip
    if cfg.cell_capacity_factor is not None:
        eval_cfg = replace(eval_cfg, cell_capacity_factor=cfg.cell_capacity_factor)
    return eval_cfg


def main(argv: list[str] | None = None) -> None:
    """CLI: ``python -m gmloco.eval.studies.solver_study --policy P --out DIR [--variants gs jacobi ...]``."""
    p = argparse.ArgumentParser(description=(__doc__ or "").split("\n")[0])
    p.add_argument("--policy", required=True, help="exported policy (ONNX with its metadata)")
    p.add_argument("--out", required=True, help="output folder")
    add_flags(p, SolverStudyCfg(), FLAGS)
    a = p.parse_args(argv)
    check_flags(p, a, SolverStudyCfg, FLAGS)
    cfg: SolverStudyCfg = cfg_from_flags(a, SolverStudyCfg(), FLAGS)
    summary = run_study(eval_cfg_of(cfg, a.policy, a.out), cfg, Path(a.out))
    print(json.dumps(summary["variants"], indent=1, default=str))


if __name__ == "__main__":
    main()
