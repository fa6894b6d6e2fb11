# SPDX-License-Identifier: Apache-2.0
"""The config of :class:`gmloco.eval.g1.scene.G1MpmScene` and the logs it keeps at the policy rate."""

from __future__ import annotations

from dataclasses import dataclass, field

from gmloco.eval.g1.soles import SoleCfg
from gmloco.eval.mpm.box_scene import MpmSolverCfg
from gmloco.eval.mpm.window import SandWindowCfg
from gmloco.eval.mpm.window_terrain import MpmTerrainCfg

__all__ = ["LOG_FIELDS", "G1MpmSceneCfg"]

LOG_FIELDS = ("base_q", "base_qd", "foot_force", "sinkage", "foot_sinkage", "joint_q", "joint_qd", "target", "action",
              "eta", "sole_out", "sole_reach")  # fmt: skip
"""The per-robot logs :class:`G1MpmScene` appends at the policy rate (one ``[R, ...]`` array per sample each)."""


@dataclass(frozen=True)
class G1MpmSceneCfg:
    """G1s-on-sand scene."""

    terrain: MpmTerrainCfg = field(default_factory=lambda: MpmTerrainCfg(name="dry_sand", materials=("dry_sand",)))
    """Terrain (media along x, surface, depth)."""
    window: SandWindowCfg = field(default_factory=lambda: SandWindowCfg(moving=False, length=0.6, width=0.5))
    """Each robot's sand patch (default: a static 0.6 x 0.5 m bed under the feet)."""
    num_robots: int = 1
    """Robots (lanes) in the scene."""
    lane_spacing: float = 2.0
    """Distance between lanes along y [m]; larger than the window width (and the walked path)."""
    solver: MpmSolverCfg = field(default_factory=lambda: MpmSolverCfg(frame_dt=0.01, rigid_substeps=2))
    """MPM numerics; frame_dt / rigid_substeps is the 200 Hz physics step."""
    sole: SoleCfg = field(default_factory=SoleCfg)
    """Foot sole colliders."""
    floor_contact: bool = True
    """Soles collide with the rigid floor at z = -depth through MuJoCo contacts (False: the floor holds sand only)."""
    wall_colliders: bool = True
    """Window walls as kinematic MPM colliders (False: only the particle clamp after each MPM step)."""
    wall_thickness: float = 0.05
    """Half thickness of the wall boxes [m]."""
    drop_height: float = 0.005
    """Initial gap between the lowest sole point and the sand surface [m]."""
    commands: tuple[tuple[float, float, float], ...] = ((0.0, 0.0, 0.0),)
    """Velocity command (v_x, v_y, w_z) [m/s, m/s, rad/s] of each robot (cycled over robots)."""
    wrench_frames: int = 1
    """Frames of coupled sand wrench the robots receive as one: 1, the last frame's (the lagged coupling); 2, the
    mean of the last two, which cancels the force's alternation from one frame to the next
    (``results/mpm_eval/coupling_chatter/``)."""
    natural_frequency_hz: float = 10.0
    """mjlab's actuator natural frequency: joint armature = kp / (2 pi f)^2 [Hz]."""
    seed: int = 0
    """Seed of the sand jitter."""
    robots_as_worlds: bool | None = None
    """One MuJoCo world per robot through mujoco_warp (else all robots in one MuJoCo C world); None = on CUDA."""
    use_cuda_graph: bool = True
    """Capture one frame in a CUDA graph (CUDA, fixed-capacity grid and an even substep count only)."""
    device: str | None = None
    """Warp device; None = Warp's default."""
