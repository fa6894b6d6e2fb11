# SPDX-License-Identifier: Apache-2.0
"""The MPM evaluation of one policy (:class:`G1EvalCfg`) and its episodes: terrain, scenario, speed and command.

:class:`G1EvalCfg` is also the pipeline's ``eval_mpm`` section (``workflows/schemas.py``): closed choices are
``str`` enums, and a numeric field's valid range sits in its ``metadata`` (``ge`` / ``gt`` / ``le`` / ``lt``),
checked when a config is composed.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import StrEnum

from gmloco.eval.metrics.locomotion import FailureCfg
from gmloco.eval.mpm.box_scene import MpmSolverCfg
from gmloco.eval.mpm.window import SandWindowCfg

__all__ = ["EpisodeSpec", "G1EvalCfg", "Scenario", "command", "episode_batches", "episode_specs"]


class Scenario(StrEnum):
    """Command scenario of an episode."""

    straight = "straight"
    """Walk straight ahead at the commanded speed."""
    circle = "circle"
    """Walk a circle of ``G1EvalCfg.circle_radius`` (yaw rate = v / R)."""


@dataclass(frozen=True)
class G1EvalCfg:
    """The MPM evaluation of one policy."""

    policy_path: str = "artifacts/ppo_rft3d/policy.onnx"
    """Exported policy: gmloco student format (``obs`` + ``history``) or mjlab's actor export (``obs`` only)."""
    out_dir: str = "results/mpm_eval"
    """Output folder."""
    policy_name: str = ""
    """The policy's name in tables and figures; empty: the name of the policy file's folder."""
    terrains: tuple[str, ...] = ("dry_sand",)
    """Terrains (``gmloco.eval.mpm.window_terrain.terrain_cfg`` names: a preset medium, ``<medium>_rough``,
    ``<medium>_deep``, ``transition``)."""
    scenarios: tuple[Scenario, ...] = (Scenario.straight,)
    """Command scenarios."""
    speeds: tuple[float, ...] = field(default=(1.0, 1.5, 2.0, 2.5), metadata={"gt": 0})
    """Forward-speed commands [m/s]; episode k of a cell uses ``speeds[k % len(speeds)]``."""
    num_episodes: int = field(default=100, metadata={"ge": 1})
    """Episodes per (terrain, scenario)."""
    shard: int = field(default=0, metadata={"ge": 0})
    """Which share of each cell's episodes this run scores: those whose index k has ``k % shards == shard``."""
    shards: int = field(default=1, metadata={"ge": 1})
    """Shares a cell's episodes are split into (one run folder, e.g. one GPU, each; ``paper_tables`` pools the
    folders). With as many shares as speeds, each share walks one speed."""
    episode_s: float = field(default=10.0, metadata={"gt": 0})
    """Episode length = course time limit [s]."""
    circle_radius: float = field(default=2.0, metadata={"gt": 0})
    """Radius of the circular walk [m] (yaw rate = v / R)."""
    course_slack: float = field(default=0.2, metadata={"ge": 0, "lt": 1})
    """Fraction of the commanded path that may be left when time runs out and still count as finished [-]."""
    bed_depth: float = field(default=0.30, metadata={"gt": 0})
    """Sand depth of the flat and rough terrains [m] (the deep terrain has its own 0.30 m); a loaded sole of a
    walking G1 reaches 20-30 cm on MPM sand (``results/mpm_eval/convergence/batched_cuts``)."""
    window: SandWindowCfg = field(default_factory=lambda: SandWindowCfg(length=1.4, width=0.6))
    """Sand window of each robot (``moving=False``: a static bed covering the course, the naive baseline). 1.4 m
    walks as 1.8 m does, 0.6 m wide as 1.0 m does (``docs/mpm_eval.md``); a 1.0 x 0.5 m window was rejected. The
    window turns with the robot's heading (within ``turn_step``), so straight walks, circles and drifting headings
    share one setting; ``turn_with_robot=False`` gives the box of the grid's axes the earlier tables used."""
    bed_margin: float = field(default=0.6, metadata={"ge": 0})
    """Static beds: margin around the commanded path [m]."""
    robots_per_batch: int = field(default=32, metadata={"ge": 1})
    """Robots (lanes) simulated together in one MPM solver."""
    refill: bool = True
    """Start a lane's next episode as soon as its robot falls or its episode ends (one solver per cell, episodes
    of any length share it); False: one solver per batch of ``robots_per_batch`` episodes, lanes idle after."""
    retire_idle_lanes: bool = True
    """Take a lane's sand out of the MPM solve once its robot has no episode left (``G1MpmScene.retire_robots``):
    the cell's tail, while its last robots walk, costs only their sand. False: idle lanes keep their sand in the
    solve (the runs up to the ablation-circle runs)."""
    lane_gap: float = field(default=2.0, metadata={"ge": 0})
    """Free space between neighbouring lanes' windows or paths [m] (robots may drift)."""
    cell_capacity_factor: float = field(default=1.5, metadata={"ge": 1, "also": (0.0,)})
    """Grid capacity = factor x particles / particles-per-cell (fixed capacity: CUDA graph); 0 = unbounded.
    The rheology solver sweeps the whole capacity, so its cost grows with the factor: 1.5 gave 1.46x the
    robot-frames/s of 3.0 (H200, 32 robots, results/mpm_eval/convergence/grid_capacity_solvers); an overflow stops the cell with an error."""
    solver: MpmSolverCfg = field(
        default_factory=lambda: MpmSolverCfg(voxel_size=0.03, frame_dt=0.005, rigid_substeps=1, max_iterations=500)
    )
    """MPM numerics: 3 cm voxels, 5 ms frames (200 Hz coupling), 500 rheology iterations per frame, the setting the
    convergence check accepted (the accepted-setting runs, ``docs/mpm_eval.md``): 500 against 1000 iterations and a 1.4 m window
    against 1.8 m are accepted; 350 iterations, 4 or 5 cm voxels, a 20 cm bed and 10 ms frames are rejected. A 3 cm
    frame of a G1 walk does not reach the 1e-4 tolerance within 1000 iterations, so the cap is the cost. The
    pipeline's smoke scale uses fast, unconverged numerics (``conf/scale/smoke.yaml``)."""
    wrench_frames: int = field(default=1, metadata={"ge": 1, "le": 2})
    """Frames of coupled sand wrench the robots receive as one (``G1MpmSceneCfg.wrench_frames``): 1, the last
    frame's (the lagged coupling, every table so far); 2, the mean of the last two, which stops the force's
    alternation from frame to frame (``results/mpm_eval/coupling_chatter/``)."""
    failure: FailureCfg = field(default_factory=FailureCfg)
    """Failure rules."""
    record_mcap: bool = True
    """Write the best walk of every (terrain, scenario, speed) group as an MCAP recording (``recordings/``): a success
    if any, else the longest time alive; a sidecar JSON names the episode. Runs before the square-window runs recorded the
    group's first episode to end."""
    seed: int = field(default=0, metadata={"ge": 0, "le": 2**32 - 1})
    """Seed of the sand."""
    device: str | None = None
    """Warp device."""
    max_minutes: float | None = field(default=None, metadata={"gt": 0})
    """Stop (resumable) after this much wall time [min]."""
    fit_time_box: bool = True
    """With ``max_minutes``: start only walks that can end before it (``g1_eval_fit``): a cell whose running walks
    would not end in the time left if no robot fell is stopped after ~30 s of stepping and rebuilt with the lanes that
    fit, a later cell of the same (terrain, scenario) gets those lanes before it is built, the first cell of a
    (terrain, scenario) is sized before its build by an H200's frame-cost line (``g1_eval_fit.prior_cost``: none
    when not one walk would end), and a freed lane takes the next episode only if a whole walk still fits. False:
    cells run until the time box drops them."""
    resume: bool = True
    """Keep finished episodes in ``episodes.jsonl``; else start fresh."""


@dataclass(frozen=True)
class EpisodeSpec:
    """One episode."""

    terrain: str
    scenario: Scenario
    speed: float
    index: int

    @property
    def key(self) -> str:
        """Unique id in ``episodes.jsonl``."""
        return f"{self.terrain}/{self.scenario}/{self.index}"

    @property
    def group(self) -> str:
        """(terrain, scenario, speed) group id."""
        return f"{self.terrain}/{self.scenario}/v{self.speed:g}"


def episode_specs(cfg: G1EvalCfg) -> list[EpisodeSpec]:
    """The run's episodes (its share of each cell: ``shard`` of ``shards``), cell-major.

    Raises:
        ValueError: ``shard`` is not one of ``0 .. shards - 1``.
    """
    if not 0 <= cfg.shard < cfg.shards:
        raise ValueError(f"shard {cfg.shard} of {cfg.shards}: the share must be 0 .. {cfg.shards - 1} (--shard I/N)")
    return [
        EpisodeSpec(t, s, float(cfg.speeds[k % len(cfg.speeds)]), k)
        for t in cfg.terrains
        for s in cfg.scenarios
        for k in range(cfg.num_episodes)
        if k % cfg.shards == cfg.shard
    ]


def episode_batches(specs: list[EpisodeSpec], size: int) -> list[list[EpisodeSpec]]:
    """Split episodes into batches of at most ``size`` that share a (terrain, scenario) cell."""
    out: list[list[EpisodeSpec]] = []
    for s in specs:
        if out and len(out[-1]) < size and (out[-1][0].terrain, out[-1][0].scenario) == (s.terrain, s.scenario):
            out[-1].append(s)
        else:
            out.append([s])
    return out


def command(spec: EpisodeSpec, cfg: G1EvalCfg) -> tuple[float, float, float]:
    """(v_x, v_y, w_z) of an episode [m/s, m/s, rad/s]."""
    wz = spec.speed / cfg.circle_radius if spec.scenario == "circle" else 0.0
    return (spec.speed, 0.0, wz)
