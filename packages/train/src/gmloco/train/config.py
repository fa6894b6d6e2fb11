# SPDX-License-Identifier: Apache-2.0
"""Typed configuration of the G1 granular velocity task (pure data; built by ``tasks.g1_granular``)."""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import StrEnum
from typing import Literal

__all__ = [
    "ContactModelName",
    "FloorPromotion",
    "FootClearanceName",
    "GranularTaskCfg",
    "MaterialRangeCfg",
    "RobotDrCfg",
    "SandFloorCfg",
    "SandTerrainCfg",
    "TerrainName",
    "contact_force_threshold",
    "deep_sand_terrain",
    "flat_sand_terrain",
    "rough_sand_terrain",
]

ContactModelName = Literal["rft3d", "heuristic_rft", "cone_multi", "cone_single", "rigid", "rft3d_calibrated"]
"""Foot-ground contact model: the four granular models of GM-Loco, plain rigid contact, or 3D-RFT with the terms
fitted to MPM sand (``GranularTaskCfg.rft_extensions_file``)."""

TerrainName = Literal["flat", "rough", "deep"]
"""Sand bed: flat soft sand, sinusoidal (rough) free surface, or a 30 cm deep loose bed."""

FootClearanceName = Literal["penalty", "reward", "touchdown", "sinkage"]


class FloorPromotion(StrEnum):
    """Rules of the floor-depth curriculum (``SandFloorCfg.promotion``; an Enum, so Hydra configs can hold it)."""

    distance = "distance"
    survival = "survival"


"""Form of the swing-height term (``GranularTaskCfg.foot_clearance``)."""


@dataclass
class MaterialRangeCfg:
    """Per-env granular material, drawn on every reset (GM-Loco code DR, spec section 4)."""

    bulk_density: tuple[float, float] = (1000.0, 3000.0)
    """Uniform range of the grain bulk density [kg/m^3]; rho_c = packing * bulk_density."""
    packing: tuple[float, float] = (0.5, 1.0)
    """Uniform range of the packing fraction [-]."""
    mu_int: tuple[float, float] = (0.2, 0.9)
    """Uniform range of the internal friction coefficient [-]."""
    mu_surf: tuple[float, float] = (0.1, 1.0)
    """Uniform range of the intruder-grain surface friction coefficient [-]."""
    sigma_flat: tuple[float, float] = (1.0e6, 1.0e7)
    """Uniform range of the cone models' flat-area stress per depth [N/m^3] (cone models only)."""
    sigma_cone: tuple[float, float] = (1.5e5, 6.0e5)
    """Uniform range of the cone models' flank stress per depth [N/m^3] (cone models only)."""
    preset: str | None = None
    """Name in ``gmloco.contact.MATERIAL_PRESETS``; when set every env uses it and nothing is drawn."""
    soft_share: float = 0.0
    """Share of the draws [0, 1] whose rho_c comes from U[``soft_rho_c``] instead of packing x bulk density (the
    rest unchanged). The product of the two uniforms puts ~8 % of the draws below 800 kg/m^3, where poppy seed
    (638 kg/m^3) lies; 0 keeps GM-Loco's draw."""
    soft_rho_c: tuple[float, float] = (500.0, 800.0)
    """rho_c range [kg/m^3] of the soft share."""
    held_out_rho_c: tuple[float, float] | None = None
    """rho_c range [kg/m^3] of a (rho_c, mu_int) rectangle the DR never draws: materials held out for evaluation
    (``gmloco.train.teacher_student.heldout``); None (or ``held_out_mu_int`` None): no hole."""
    held_out_mu_int: tuple[float, float] | None = None
    """mu_int range [-] of the held-out rectangle; must lie inside ``mu_int``."""


@dataclass
class SandFloorCfg:
    """Hard floor (bedrock) under the sand; its depth is the terrain curriculum (spec 1.5 and 4)."""

    enabled: bool = True
    """Whether the feet collide with the floor. Other robot geoms always collide with it."""
    depth_range: tuple[float, float] = (0.0, 0.12)
    """Floor depth below the sand free surface [m] at curriculum level 0 and at the top level."""
    num_levels: int = 10
    """Number of curriculum levels between the two depths."""
    max_init_level: int = 0
    """Highest level an env may start at (uniform in [0, max_init_level])."""
    curriculum: bool = True
    """Move envs between levels at each reset, by the ``promotion`` rule."""
    promotion: FloorPromotion = FloorPromotion.distance
    """``"distance"`` (GM-Loco's and mjlab's terrain rule): deeper after walking farther than 4 m from the env
    origin, shallower after covering less than half the commanded distance; under turning commands the straight
    distance falls short of the path, so turning envs are sent back. ``"survival"``: deeper after an episode that
    ran to its time limit, shallower after a failure (fall, base too low)."""


@dataclass
class SandTerrainCfg:
    """Shape of the sand free surface and of the floor under it."""

    kind: TerrainName = "flat"
    """Terrain name, used in task ids and logs."""
    amplitude: float = 0.0
    """Amplitude a of the free surface z_s = a sin(2 pi x / L) + a sin(2 pi y / L) [m]; 0 is flat at z = 0."""
    wavelength: float = 2.0
    """Wavelength L of the sinusoidal free surface along x and y [m]."""
    floor: SandFloorCfg = field(default_factory=SandFloorCfg)
    """Hard floor under the sand."""


def flat_sand_terrain() -> SandTerrainCfg:
    """Flat soft sand over a floor lowered from 0 to 12 cm by the curriculum."""
    return SandTerrainCfg(kind="flat")


def rough_sand_terrain(amplitude: float = 0.04, wavelength: float = 1.5) -> SandTerrainCfg:
    """Sand whose free surface is ``a sin(2 pi x / L) + a sin(2 pi y / L)`` [m] (gmloco.contact sinusoid)."""
    return SandTerrainCfg(kind="rough", amplitude=amplitude, wavelength=wavelength)


def deep_sand_terrain(depth: float = 0.30) -> SandTerrainCfg:
    """A deep bed: the floor sits ``depth`` [m] below the surface, no floor curriculum."""
    floor = SandFloorCfg(depth_range=(depth, depth), num_levels=1, curriculum=False)
    return SandTerrainCfg(kind="deep", floor=floor)


@dataclass
class RobotDrCfg:
    """Robot domain randomization (GM-Loco code and project page, spec section 4)."""

    enabled: bool = True
    """Master switch; False disables every term below (evaluation)."""
    added_mass: tuple[float, float] = (-1.0, 3.0)
    """Mass added to the torso at startup [kg]."""
    com_offset: float = 0.03
    """Half-width of the uniform torso CoM offset along x, y, z at startup [m]."""
    actuator_gain: tuple[float, float] = (0.9, 1.1)
    """Scale of the PD gains kp and kd at startup [-]."""
    foot_friction: tuple[float, float] = (0.6, 1.0)
    """Friction of the foot geoms against the hard floor at startup [-]."""
    push_velocity: float = 1.0
    """Half-width of the uniform xy root-velocity kick [m/s]."""
    push_interval_s: tuple[float, float] = (10.0, 15.0)
    """Range of the time between pushes [s]."""
    joint_pos_offset: float = 0.1
    """Half-width of the uniform joint-position offset on reset [rad]."""


@dataclass
class GranularTaskCfg:
    """Everything that selects one G1 velocity task on sand; ``make_g1_granular_env_cfg`` builds it."""

    contact_model: ContactModelName = "rft3d"
    """Foot-ground contact model."""
    foot_faces: Literal["sole", "box"] = "sole"
    """Faces of the foot box the RFT models sample: ``"sole"`` (GM-Loco's collider, the -z face) or ``"box"`` (all
    six). With the sole alone a swinging foot that rises or points its toe down meets no sand at any depth; the
    whole box gives 30-80 N of drag at 4-8 cm, as MPM sand does (results/mpm_eval/probes/swing_trip/face_drag.md). Cone and
    rigid models ignore it."""
    rft_extensions_file: str = "results/sand_calibration/rft3d_calibrated.json"
    """Fitted ``gmloco.contact.RftExtensionsCfg`` that ``contact_model="rft3d_calibrated"`` reads (written by
    ``python -m gmloco.eval.calibration.fit_cli --write-default`` only when the held-out error improved)."""
    rft_extension_ranges: dict[str, tuple[float, float]] = field(default_factory=dict)
    """Per-env domain randomization of the fitted terms, U[lo, hi] on reset, keyed by the per-world
    ``RftExtensionsCfg`` fields (``gmloco.contact.kernels_rft3d_ext.EXT_COLUMNS``); empty = the fitted values."""
    terrain: SandTerrainCfg = field(default_factory=flat_sand_terrain)
    """Sand free surface and floor."""
    material: MaterialRangeCfg = field(default_factory=MaterialRangeCfg)
    """Per-env material randomization."""
    robot_dr: RobotDrCfg = field(default_factory=RobotDrCfg)
    """Robot domain randomization."""
    episode_length_s: float = 20.0
    """Episode length [s]."""
    action_scale: float = 0.25
    """Joint-position offset per unit action [rad]."""
    policy_history_length: int = 5
    """Frames of history stacked in the actor observation (GM-Loco uses 10)."""
    obs_noise_scale: float = 1.0
    """Multiplier on the actor observation noise ranges; 0 disables noise."""
    contact_force_threshold: float | None = None
    """|F| above which a foot is in contact [N]; None: 40 N granular (GM-Loco), 5 N rigid."""
    command_curriculum: bool = True
    """Widen the commanded-velocity ranges in stages (GM-Loco schedule)."""
    reward_ramp_steps: int = 15_000 * 24
    """Env steps over which tracking weights ramp 4 -> 8 and std sqrt(1.0) -> sqrt(0.1); 0 disables."""
    command_stage_steps: tuple[int, int] = (10_000 * 24, 15_000 * 24)
    """Env steps at which the command ranges widen to stage 2 (vx <= 1.7 m/s) and stage 3 (vx <= 2.5 m/s)."""
    curriculum_scale: float = 1.0
    """Multiplier on ``reward_ramp_steps`` and ``command_stage_steps``. 1.0 is GM-Loco's schedule, written for
    tens of thousands of iterations; 0.1 fits it into a ~2k-iteration budget (ramp over 1.5k iterations, stages
    at 1k and 1.5k). Below 1, the wide initial tracking kernel (std 1 m/s, where standing still already earns
    ~70 % of the tracking reward) is left before the policy settles on standing."""
    foot_clearance: FootClearanceName = "penalty"
    """Swing-height term. ``"penalty"``: the GM-Loco project page's ``foot_clearance_l2`` (weight -2, zero for
    still feet); ``"reward"``: the public code's exp form (weight +5), which pays its maximum to feet that do not
    move, so a policy that stands still earns it in full (measured: 62 % of the term's maximum at iteration 1,400
    while tracking earned 17 %, no walking; see artifacts/ppo_rft3d/manifest.json); ``"touchdown"``: the penalty
    plus ``swing_height_at_touchdown`` (weight +100, lift out of the footprint up to 0.12 m, paid per completed
    swing), which pays neither standing nor an early fall (the penalty alone at weight -300 taught a teacher to fall
    early, results/mpm_eval/probes/swing_trip/README.md). With ``foot_faces="box"`` it trained ``artifacts/gm_loco_teacher_td``,
    whose student is the first policy to walk 10 s on MPM sand (results/mpm_eval/probes/touchdown_lift/README.md); the weight
    is that run's, not tuned against others. ``"sinkage"``: the same two terms (same names and weights) with a
    terrain-aware target: 9 cm above the surface plus the depth of the foot's last footprint, at most 20 cm
    (``mdp.foot_clearance_sinkage_l2``, ``mdp.swing_apex_sinkage_at_touchdown``), so soft ground, where the feet sink
    deeper, asks for a higher apex, as the project page's swing (~9 cm stiff, ~16 cm soft); the touchdown mode's
    fixed 12 cm lift cap stops paying at a 5 cm apex out of a 7 cm footprint."""
    yaw_command: Literal["yaw_target", "heading_envs"] = "yaw_target"
    """Heading command. ``"yaw_target"`` (GM-Loco's code): every env holds a yaw target that integrates the
    commanded w_z (``mdp.commands.YawTargetVelocityCommand``), rewarded by ``track_yaw_target_exp`` (weight 4), and
    the observed w_z carries ``heading_stiffness`` times the heading error. ``"heading_envs"`` (mjlab's task, the
    committed policies up to ``gm_loco_teacher_td``): 30 % of envs steer toward a random heading, the rest get no
    heading feedback, and a straight command drifts (11-74 degrees in 10 s measured on MPM and in the training
    simulator)."""
    heading_stiffness: float = 1.0
    """k of the observed yaw-rate command w_z + k * e_psi under ``yaw_command="yaw_target"`` [1/s] (mjlab's heading
    envs use 0.5); part of a policy's deploy contract."""
    reward_weights: dict[str, float] = field(default_factory=dict)
    """Overrides of reward term weights by name (see ``mdp.rewards``)."""
    play: bool = False
    """Evaluation mode: no noise, no pushes, no curricula, no robot DR."""


def contact_force_threshold(task: GranularTaskCfg) -> float:
    """Return |F| above which a foot is in contact [N]: the task's, else 5 N rigid and 40 N granular (GM-Loco)."""
    if task.contact_force_threshold is not None:
        return task.contact_force_threshold
    return 5.0 if task.contact_model == "rigid" else 40.0
