# SPDX-License-Identifier: Apache-2.0
"""Configs of the training gate: which policy, which cells, and the thresholds each metric must meet."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

from gmloco.train.config import ContactModelName
from gmloco.train.evaluation import RolloutCriteriaCfg
from gmloco.train.teacher_student.heldout import DEFAULT_HELD_OUT, HeldOutRegionCfg

__all__ = ["GATE_PARTS", "GateCfg", "GatePart", "GateThresholdsCfg"]

GatePart = Literal["success", "yaw", "circle", "apex", "eta"]
"""A measured part of the gate: forward cells (``success_pct``, ``vel_error_mps``, ``heading_drift_deg``), yaw
cells (``yaw_rate_ratio``), the circle (``circle_dtw_m``), the swing apex (``swing_apex_cm``), the held-out eta
(``eta_r2_heldout``)."""
GATE_PARTS: tuple[GatePart, ...] = ("success", "yaw", "circle", "apex", "eta")
"""Every part, in the order of the summary's keys."""


@dataclass
class GateThresholdsCfg:
    """What a policy must reach to pass the gate (issue 34's numbers)."""

    success_pct: float = 100.0
    """Least success of every (material, forward speed) cell [%]."""
    vel_error_mps: float = 0.15
    """Largest mean velocity error of a forward cell [m/s]."""
    yaw_rate_tolerance: float = 0.10
    """Largest |achieved / commanded yaw rate - 1| of a yaw cell [-]."""
    heading_drift_deg: float = 5.0
    """Largest mean heading drift of a straight cell over the episode [deg]."""
    circle_dtw_m: float = 0.10
    """Largest DTW path error of the circle, per material [m]."""
    swing_apex_rise_cm: float = 5.0
    """Least rise of the swing apex from the first material (stiffest) to the last (softest) [cm]."""
    eta_r2_heldout: float = 0.9
    """Least R^2 of the decoded eta on the held-out materials [-]."""
    gpu_minutes: float = 180.0
    """Most GPU time of the whole training (teacher + student) [min]."""


@dataclass
class GateCfg(RolloutCriteriaCfg):
    """The training gate of one delivered policy in the granular training simulator.

    Every episode is one env and counts from its start to its first failure or ``duration_s``; ``repeats``
    (inherited) is the number of episodes per cell. Failure rules and the eval floor: :class:`RolloutCriteriaCfg`.
    """

    policy_dir: str = "artifacts/gm_loco_student_td"
    """Run folder: ``checkpoint.pt`` (student / teacher) or ``policy.onnx`` (PPO), with ``train_cfg.json`` or a
    ``summary.json`` holding ``train_cfg``; ``manifest.json`` / ``summary.json`` give the GPU minutes."""
    materials: tuple[str, ...] = ("basalt", "dry_sand", "poppy_seed")
    """Material presets, stiffest first (``gmloco.contact.MATERIAL_PRESETS``)."""
    speeds: tuple[float, ...] = field(default=(0.5, 1.0, 1.5, 2.0, 2.5), metadata={"gt": 0})
    """Commanded forward speeds of the straight cells [m/s]."""
    repeats: int = field(default=20, metadata={"ge": 1})
    """Episodes per cell."""
    yaw_rates: tuple[float, ...] = (-1.0, -0.5, 0.5, 1.0)
    """Commanded yaw rates of the turning cells [rad/s], none zero (0 has no achieved/commanded ratio; straight
    walking is in ``speeds``)."""
    yaw_forward_speed: float = 0.5
    """Forward speed commanded with each yaw rate [m/s]."""
    circle_radius_m: float = 2.0
    """Radius of the circle cell [m]; its yaw rate is ``circle_speed / circle_radius_m``."""
    circle_speed: float = 1.0
    """Forward speed of the circle cell [m/s]."""
    apex_speed: float = 1.0
    """Forward cells whose swings give the swing apex per material [m/s]."""
    course_slack: float = field(default=0.2, metadata={"ge": 0, "lt": 1})
    """Fraction of the commanded path a straight walk may leave unwalked and still finish its course [-]: MPM's
    rule (``G1EvalCfg.course_slack``), applied for ``success_course_pct``."""
    settle_s: float = 1.0
    """Start of each episode left out of the velocity and yaw-rate metrics (acceleration from rest) [s]."""
    dtw_hz: float = 10.0
    """Sampling rate of the paths compared by DTW [Hz]."""
    held_out: HeldOutRegionCfg = field(default_factory=lambda: DEFAULT_HELD_OUT)
    """The (rho_c, mu_int) rectangle the training DR never draws."""
    held_out_grid: tuple[int, int] = field(default=(3, 3), metadata={"ge": 1})
    """Held-out materials along rho_c and mu_int, at least two in all (the R^2 of the decoded eta needs more than
    one material)."""
    held_out_mu_surf: float = 0.45
    """Surface friction of the held-out materials [-]."""
    held_out_speed: float = 1.0
    """Forward speed commanded on the held-out materials [m/s]."""
    eta_warmup_s: float = 1.0
    """Start of each episode left out of the eta R^2 (the history fills) [s]."""
    contact_model: ContactModelName = "rft3d"
    """Granular contact model of the simulator (PPO-Rigid is gated on sand too)."""
    rft_extensions_file: str = "results/sand_calibration/rft3d_calibrated.json"
    """Fitted ``RftExtensionsCfg`` file that ``contact_model="rft3d_calibrated"`` reads (other models ignore it)."""
    parts: tuple[GatePart, ...] = GATE_PARTS
    """Parts measured; the cells of the others are not run and their keys are null (e.g. ``("success",)`` for a
    success-by-speed table)."""
    num_envs: int = field(default=1024, metadata={"ge": 1})
    """Envs stepped at once; the cells run in batches of this size."""
    device: str = "cpu"
    """Torch / Warp device, e.g. ``cuda:0``."""
    seed: int = 0
    """Env seed."""
    thresholds: GateThresholdsCfg = field(default_factory=GateThresholdsCfg)
    """Pass thresholds."""
    out_path: str | None = None
    """If set, the summary JSON is written here (atomically)."""
