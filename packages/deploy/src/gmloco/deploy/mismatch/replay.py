# SPDX-License-Identifier: Apache-2.0
"""Multiple-shooting replay of a recording in the nominal (or hypothesis-modified) MuJoCo G1 simulator.

For every segment start ``k0`` the simulator is reset to the *real* state at ``k0`` (joints from the log, base
from odometry or leg odometry, :mod:`gmloco.deploy.mismatch.baseest`), the *logged* LowCmd is applied through
the motor PD law for ``horizon`` samples, and the simulated measurements are compared with the logged ones
(R1 short-horizon output error, ``shared/reference/mismatch-discovery.md`` section 3.2). Short horizons keep a
closed-loop policy or a fall from hiding the local signature. A recording whose pelvis is held (``support`` gantry
or fixed) is replayed with the pelvis welded to its logged orientation: only the joints move, and the simulated
gyro and accelerometer are those of a pelvis at rest. Every candidate effect is applied here (actuator,
sensor, model edits) or in :mod:`gmloco.deploy.mismatch.terrain`, and all are exactly nominal at zero.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from gmloco.deploy.mismatch.baseest import BaseEstCfg, BaseTrajectory, estimate_base, odometry_base, welded_base
from gmloco.deploy.mismatch.effects import BACKLASH_GROUPS, EFFECTS, LIMB_LINKS, effect
from gmloco.deploy.mismatch.frames import quat_conj, quat_from_roll_pitch, quat_mul, quat_to_mat
from gmloco.deploy.mismatch.g1model import G1_ARMATURE, G1_EFFORT_LIMIT, SOLE_POINTS, G1SimCfg, build_model
from gmloco.deploy.mismatch.memo import SegmentMemo, params_key
from gmloco.deploy.mismatch.recording import Recording
from gmloco.deploy.mismatch.sand import SandCfg, SoleRFT
from gmloco.deploy.mismatch.terrain import TerrainEffectCfg, TerrainParams, sand_effect_forces, sole_forces

__all__ = [
    "CHANNEL_GROUPS",
    "N_CHANNELS",
    "ReplayCfg",
    "Replayer",
    "attitude_rate_residual",
    "channel_names",
    "parse_ground",
    "replay_cfg_for_rate",
    "sand_replay_cfg",
]

CHANNEL_GROUPS: tuple[tuple[str, int], ...] = (
    ("q", 29),
    ("dq", 29),
    ("tau_est", 29),
    ("gyro", 3),
    ("acc", 3),
    ("gyro_att", 3),
)
"""Compared signals and their widths, in output-column order. ``gyro_att`` is the gyro minus the attitude rate
(the angular velocity implied by the logged IMU quaternion), a sensor-consistency signal: zero for a consistent
IMU, whatever the dynamics (:func:`attitude_rate_residual`)."""

N_CHANNELS: int = sum(w for _, w in CHANNEL_GROUPS)
"""Number of output columns."""

_REF_EFFORT = 88.0  # N*m: friction/damping parameters are quoted for an 88 N*m joint (7520-14 motor)


def attitude_rate_residual(quat: np.ndarray, gyro: np.ndarray, dt: float, half: int) -> np.ndarray:
    """Gyro minus the attitude rate of the logged quaternion, per sample [rad/s], shape [N, 3].

    Over a window of ``2 half`` samples, the rotation ``q(k - half)^-1 q(k + half)`` (IMU frame) has the
    rotation vector ``integral(omega) dt``; its mean rate is compared with the mean gyro over the same window, so
    the difference is zero for any motion when the gyro and the quaternion agree (no curvature error), and equals
    an additive gyro bias otherwise. A constant IMU mounting rotation cancels (both signals live in the IMU frame).
    The quaternion noise sets the floor: ``sqrt(2) sigma_quat / (2 half dt)``. Edges use the nearest full window.

    Args:
        quat: IMU orientation (w, x, y, z), shape [N, 4].
        gyro: IMU angular velocity [rad/s], shape [N, 3].
        dt: Sample period [s].
        half: Half window [samples].
    """
    n = len(quat)
    k = np.clip(np.arange(n), half, max(n - 1 - half, half))
    rel = quat_mul(quat_conj(quat[k - half]), quat[np.minimum(k + half, n - 1)])
    rel = rel * np.where(rel[:, :1] < 0.0, -1.0, 1.0)
    vec = rel[:, 1:]
    sn = np.linalg.norm(vec, axis=1, keepdims=True)
    ang = 2.0 * np.arctan2(sn[:, 0], rel[:, 0])[:, None]
    rotvec = np.where(sn > 1e-12, vec / np.maximum(sn, 1e-300) * ang, 2.0 * vec)
    csum = np.concatenate([np.zeros((1, 3)), np.cumsum(gyro, axis=0)])
    lo, hi = k - half, np.minimum(k + half, n - 1)
    mean_gyro = (csum[hi] - csum[lo]) / np.maximum(hi - lo, 1)[:, None]
    return mean_gyro - rotvec / ((hi - lo)[:, None] * dt)


def channel_names(joint_names: tuple[str, ...]) -> list[str]:
    """Return ``signal:joint`` (or ``signal:axis``) names of the output columns."""
    out = []
    for sig, width in CHANNEL_GROUPS:
        out += [f"{sig}:{j}" for j in joint_names] if width == 29 else [f"{sig}:{a}" for a in "xyz"]
    return out


@dataclass
class ReplayCfg:
    """Settings of the multiple-shooting replay."""

    horizon: int = 30
    """Samples simulated after each reset (60 ms at 500 Hz)."""
    stride: int = 3
    """Compare every ``stride``-th sample of the horizon."""
    substeps: int = 1
    """Physics steps per log sample."""
    sim: G1SimCfg = field(default_factory=G1SimCfg)
    """Nominal simulator."""
    base: BaseEstCfg = field(default_factory=BaseEstCfg)
    """Leg-odometry settings (used when the log has no odometry)."""
    terrain: TerrainEffectCfg = field(default_factory=TerrainEffectCfg)
    """Terrain effect constants."""
    attitude_half_window: int = 8
    """Half window of the gyro-vs-attitude-rate channel [samples] (16 ms at 500 Hz)."""
    memo_bytes: int = 64 * 2**20
    """Simulated segments kept for reuse on the plane and for a welded pelvis [bytes] (:mod:`.memo`; the same
    bits as a new replay); 0 keeps none."""


PLANE_STEP_S = 0.002
"""Physics step of the rigid-plane replay [s] (one step per sample at 500 Hz)."""
SAND_STEP_S = 0.001
"""Physics step of the 3D-RFT sand replay [s]: on a walking null, 1 kHz removes a third of the 500 Hz residual
energy (the sand's elastic branch is stiff) for 1.3x the cost."""
HORIZON_S = 0.06
"""Default shooting horizon [s] (30 samples at 500 Hz)."""
ATTITUDE_HALF_WINDOW_S = 0.016
"""Half window of the gyro-vs-attitude-rate channel [s] (8 samples at 500 Hz)."""


def replay_cfg_for_rate(
    rate_hz: float, ground: str = "plane", material: str = "dry_sand", horizon: int | None = None
) -> ReplayCfg:
    """Replay settings for a recording sampled at ``rate_hz``: the 500 Hz defaults' times, in its samples.

    The physics step stays ``PLANE_STEP_S`` / ``SAND_STEP_S`` (``substeps`` per sample), the horizon
    ``HORIZON_S`` (at least 3 samples) unless given [samples], the compare stride a tenth of the horizon and the
    attitude window ``ATTITUDE_HALF_WINDOW_S``. At 500 Hz this is ``ReplayCfg()`` (plane) and the sand replay of
    the benchmark; at 50 Hz (the MPM evaluation's recordings) 10 or 20 steps per sample and a 3-sample horizon.

    Raises:
        ValueError: a non-positive rate, an unknown ground or a horizon below 1.
    """
    if not rate_hz > 0:
        raise ValueError(f"rate_hz={rate_hz}: a recording's sample rate must be positive")
    if ground not in ("plane", "sand"):
        raise ValueError(f"ground={ground!r}: use 'plane' or 'sand'")
    if horizon is not None and horizon < 1:
        raise ValueError(f"horizon={horizon}: at least 1 sample")
    step = SAND_STEP_S if ground == "sand" else PLANE_STEP_S
    substeps = max(1, round(1.0 / (rate_hz * step)))
    h = horizon if horizon is not None else max(3, round(HORIZON_S * rate_hz))
    timestep = 1.0 / (rate_hz * substeps)
    sim = G1SimCfg(timestep=timestep, ground="sand", sand=SandCfg(material=material)) if ground == "sand" else \
        G1SimCfg(timestep=timestep)  # fmt: skip
    return ReplayCfg(horizon=h, stride=max(1, round(h / 10)), substeps=substeps, sim=sim,
                     attitude_half_window=max(1, round(ATTITUDE_HALF_WINDOW_S * rate_hz)))  # fmt: skip


def parse_ground(spec: str) -> tuple[str, str]:
    """``"plane"`` / ``"sand"`` / ``"sand:MATERIAL"`` -> (ground, material; ``dry_sand`` by default).

    Raises:
        ValueError: any other spelling (a typo must not fall back to the rigid plane), or a material on the plane.
    """
    ground, _, material = spec.partition(":")
    if ground not in ("plane", "sand") or (ground == "plane" and material):
        raise ValueError(f"ground {spec!r}: use 'plane', 'sand' or 'sand:<material preset>'")
    return ground, material or "dry_sand"


def sand_replay_cfg(material: str = "dry_sand", rate_hz: float = 500.0, horizon: int = 30) -> ReplayCfg:
    """Return the replay settings for the project's 3D-RFT sand as nominal ground (``replay_cfg_for_rate``).

    Two physics steps per log sample at 500 Hz: on a walking null, 1 kHz removes a third of the 500 Hz residual
    energy (the sand's elastic branch is stiff) for 1.3x the cost.
    """
    return replay_cfg_for_rate(rate_hz, "sand", material, horizon)


@dataclass
class _Hyp:
    """All effect parameters, unpacked for the inner loop."""

    delay: float
    gain: float
    droop: float
    limit: float
    tau_c: float
    b: float
    tau_c_leg: np.ndarray
    b_leg: np.ndarray
    backlash: np.ndarray
    limb_mass: np.ndarray
    arm_scale: float
    offset: np.ndarray
    gyro_bias: np.ndarray
    mis: np.ndarray
    dmass: float
    terrain: TerrainParams
    rmis_t: np.ndarray
    has_backlash: bool
    """Whether any backlash width is non-zero."""
    lim: np.ndarray
    """Static torque limit of each joint [N*m], shape [29]."""
    neg_lim: np.ndarray
    """``-lim`` [N*m], shape [29]."""
    half_backlash: np.ndarray
    """Half the backlash width of each joint [rad], shape [29]."""


_BACKLASH_INDEX = np.array(
    [next(i for i, g in enumerate(BACKLASH_GROUPS) if g in n) for n in ("hip_pitch", "hip_roll", "hip_yaw", "knee",
     "ankle_pitch", "ankle_roll") * 2]
)  # fmt: skip
"""Backlash group of each leg joint (``G1_JOINT_NAMES[:12]`` order: six joints per leg)."""


def _leg(x: np.ndarray) -> np.ndarray:
    """Pad 12 leg-joint values to the 29 joints (zeros for waist and arms)."""
    out = np.zeros(29)
    out[:12] = x
    return out


def _unpack(params: dict[str, np.ndarray]) -> _Hyp:
    """Turn ``{effect_id: flat theta}`` into :class:`_Hyp` (missing ids are nominal)."""
    p = {e.id: e.split(np.asarray(params.get(e.id, np.zeros(e.size)), float)) for e in EFFECTS}
    off = np.zeros(29)
    off[:12] = p["sensor.encoder_offset"]["offset"]
    limit = 1.0 - float(p["actuator.torque_limit"]["limit_loss"][0])
    lim = G1_EFFORT_LIMIT if limit == 1.0 else limit * G1_EFFORT_LIMIT
    backlash = _leg(p["actuator.backlash"]["width"][_BACKLASH_INDEX])
    return _Hyp(
        delay=float(p["actuator.delay"]["delay"][0]),
        gain=1.0 + float(p["actuator.gain_scale"]["kp_scale"][0]),
        droop=float(p["actuator.torque_speed"]["droop"][0]),
        limit=limit,
        tau_c=float(p["joint.coulomb_friction"]["tau_c"][0]),
        b=float(p["joint.viscous_damping"]["b"][0]),
        tau_c_leg=_leg(p["joint.coulomb_friction_leg"]["tau_c"]),
        b_leg=_leg(p["joint.viscous_damping_leg"]["b"]),
        backlash=backlash,
        limb_mass=p["body.limb_mass"]["delta_mass"],
        arm_scale=float(p["joint.armature"]["scale"][0]),
        offset=off,
        gyro_bias=p["imu.gyro_bias"]["bias"],
        mis=p["imu.misalignment"]["angle"],
        dmass=float(p["body.mass_error"]["delta_mass"][0]),
        terrain=TerrainParams(
            zeta=float(p["terrain.stiffness_scale"]["zeta"][0]),
            kappa=float(p["terrain.depth_hardening"]["kappa"][0]),
            rho_drag=float(p["terrain.rate_drag"]["rho_drag"][0]),
            cohesion=float(p["terrain.cohesion"]["cohesion"][0]),
        ),
        rmis_t=quat_to_mat(quat_from_roll_pitch(*(float(a) for a in p["imu.misalignment"]["angle"]))).T,
        has_backlash=bool(p["actuator.backlash"]["width"].any()),
        lim=lim,
        neg_lim=-lim,
        half_backlash=0.5 * backlash,
    )


@dataclass
class _Seg:
    """State of one shooting segment while the segments are stepped side by side."""

    d: Any
    """Its ``mujoco.MjData``."""
    k0: int
    """Start sample."""
    damping: np.ndarray
    """Joint damping of each step (realised kd plus viscous friction) [N*m*s/rad], shape [H+1, 29]."""
    qc: np.ndarray
    """Delayed position commands [rad], shape [H+1, 29]."""
    dqc: np.ndarray
    """Delayed velocity commands [rad/s], shape [H+1, 29]."""
    tff: np.ndarray
    """Delayed feed-forward torques [N*m], shape [H+1, 29]."""
    kp: np.ndarray
    """Logged position gains of each step [N*m/rad], shape [H+1, 29]."""
    kd: np.ndarray
    """Logged velocity gains of each step [N*m*s/rad], shape [H+1, 29]."""
    gkd: np.ndarray
    """Realised velocity gains (gain scale times ``kd``) [N*m*s/rad], shape [H+1, 29]."""
    qpos: np.ndarray
    """View of the joint coordinates in ``d.qpos`` [rad], shape [29]."""
    qvel: np.ndarray
    """View of the joint velocities in ``d.qvel`` [rad/s], shape [29]."""
    qfrc: np.ndarray
    """View of the joint entries of ``d.qfrc_applied`` [N*m], shape [29]."""
    qm: np.ndarray = field(default_factory=lambda: np.zeros(29))
    """Encoder reading of the current step [rad]."""
    tau: np.ndarray = field(default_factory=lambda: np.zeros(29))
    """Motor torque of the current step [N*m]."""
    w_imu: np.ndarray = field(default_factory=lambda: np.zeros(3))
    """Pelvis angular velocity at the last compare point [rad/s]."""
    pelvis_quat: np.ndarray | None = None
    """Orientation (w, x, y, z) of a welded pelvis; ``None`` for a floating base."""


class Replayer:
    """Replay a :class:`Recording` over shooting segments with given effect parameters."""

    def __init__(self, rec: Recording, cfg: ReplayCfg | None = None) -> None:
        """Build the nominal model and cache what every replay needs."""
        import mujoco

        cfg = cfg or ReplayCfg()
        self.fixed = rec.fixed_base
        """Whether the pelvis is welded (the recording's ``support`` is gantry or fixed)."""
        if self.fixed:  # a held robot touches nothing: the ground, plane or sand, plays no part
            cfg = replace(cfg, sim=replace(cfg.sim, fixed_base=True, ground="plane"))
        self.cfg = cfg
        self.rec = rec
        # Visual meshes never collide, but their BVH costs mj_collision more than the rest of a step.
        self.model = build_model(replace(self.cfg.sim, visual_meshes=False))
        self._jq = slice(0 if self.fixed else 7, None)  # joint coordinates in qpos
        self._jv = slice(0 if self.fixed else 6, None)  # joint dofs in qvel and the dof_* arrays
        self.data = mujoco.MjData(self.model)
        m = self.model
        self._torso = m.body("torso_link").id
        self._pelvis = m.body("pelvis").id
        self._mass0 = float(m.body_mass[self._torso])
        self._inertia0 = m.body_inertia[self._torso].copy()
        self._limbs = np.array([m.body(n).id for n in LIMB_LINKS])
        self._limb_mass0 = m.body_mass[self._limbs].copy()
        self._limb_inertia0 = m.body_inertia[self._limbs].copy()
        self._feet = [m.body(f"{s}_ankle_roll_link").id for s in ("left", "right")]
        self._w = G1_EFFORT_LIMIT / _REF_EFFORT
        self.offsets = np.arange(self.cfg.stride, self.cfg.horizon + 1, self.cfg.stride)
        self._dt = rec.dt  # a median over the log: taken once, not per segment
        self._base_cache: dict[tuple, BaseTrajectory] = {}
        self._sink_cache: dict[tuple, float] = {}
        self._crater_cache: dict[tuple, np.ndarray] = {}
        self._zmax0: np.ndarray | None = None
        self._pool: list = []
        self._memo = SegmentMemo(self.cfg.memo_bytes)
        self.sand = SoleRFT(self.cfg.sim.sand) if self.cfg.sim.ground == "sand" else None
        """Nominal 3D-RFT sand on the soles (None on the plane ground)."""
        self.gyro_att = attitude_rate_residual(rec.imu_quat, rec.imu_gyro, rec.dt, self.cfg.attitude_half_window)

    # ----------------------------------------------------------------------------------------------- data
    def segment_starts(self, spacing: int | None = None) -> np.ndarray:
        """Return valid segment starts (no gap inside a segment), every ``spacing`` samples (default: horizon)."""
        h = self.cfg.horizon
        spacing = spacing or h
        ok = self.rec.valid_mask()
        bad = np.concatenate([[0], np.cumsum(~ok)])
        starts = np.arange(0, self.rec.n - h - 1, spacing)
        return starts[bad[starts + h + 1] - bad[starts] == 0]

    def measured(self, starts: np.ndarray) -> np.ndarray:
        """Logged measurements at the compare points, shape [S, P, N_CHANNELS]."""
        r = self.rec
        idx = starts[:, None] + self.offsets[None, :]
        return np.concatenate(
            [r.q[idx], r.dq[idx], r.tau_est[idx], r.imu_gyro[idx], r.imu_acc[idx], self.gyro_att[idx]], axis=-1
        )

    def _base_key(self, h: _Hyp) -> tuple:
        """Hypothesis parameters the base estimate depends on (sensor effects and the static load)."""
        return (
            tuple(np.round(h.offset[:12], 9)),
            tuple(np.round(h.mis, 9)),
            tuple(np.round(h.gyro_bias, 9)),
            self._load_key(h),
        )

    def base(self, params: dict[str, np.ndarray], starts: np.ndarray) -> BaseTrajectory:
        """Base state at the segment starts under the sensor hypotheses of ``params`` (cached)."""
        h = _unpack(params)
        key = (*self._base_key(h), starts.tobytes())
        if key not in self._base_cache:
            self._base_cache[key] = self._estimate(h, starts)
            if len(self._base_cache) > 64:
                self._base_cache.pop(next(iter(self._base_cache)))
        return self._base_cache[key]

    def crater_memory(self, params: dict[str, np.ndarray]) -> np.ndarray:
        """Each sole cell's deepest depth since it last entered the sand, per sample [m], shape [N, 2M] (cached).

        The nominal sand remembers, per cell, the maximum depth ``z_max`` of its current contact (the elastic
        unloading branch of :mod:`gmloco.deploy.mismatch.sand`); a segment that starts with ``z_max`` = present
        depth misplaces every foot that has rebounded. The memory is rebuilt kinematically: the sole cells follow
        the logged joints on the estimated base over the whole recording.
        """
        import mujoco

        h = _unpack(params)
        key = self._base_key(h)
        if key not in self._crater_cache:
            r, m, sand = self.rec, self.model, self.sand
            assert sand is not None
            base = self.base(params, np.arange(r.n))
            d = mujoco.MjData(m)
            depth = np.empty((r.n, 2 * sand.m))
            for k in range(r.n):
                d.qpos[2], d.qpos[3:7], d.qpos[7:] = base.pos[k, 2], base.quat[k], r.q[k] - h.offset
                mujoco.mj_kinematics(m, d)
                pts = np.einsum("fij,mj->fmi", d.xmat[self._feet].reshape(2, 3, 3), sand.points_body)
                depth[k] = sand.cfg.surface_z - (pts[..., 2] + d.xpos[self._feet][:, None, 2]).ravel()
            zm, out = np.zeros(2 * sand.m), np.empty_like(depth)
            for k in range(r.n):
                zm = np.where(depth[k] > 0.0, np.maximum(zm, depth[k]), 0.0)
                out[k] = zm
            self._crater_cache[key] = out
            if len(self._crater_cache) > 16:
                self._crater_cache.pop(next(iter(self._crater_cache)))
        return self._crater_cache[key]

    def _estimate(self, h: _Hyp, starts: np.ndarray) -> BaseTrajectory:
        """Run the base estimator (or wrap odometry) at ``starts``."""
        r = self.rec
        if self.fixed:
            qm = quat_from_roll_pitch(float(h.mis[0]), float(h.mis[1]))
            src = r.base_quat if r.base_quat is not None else quat_mul(r.imu_quat, quat_conj(qm))
            win = np.clip(starts[:, None] + np.arange(self.cfg.horizon + 1)[None, :], 0, r.n - 1)
            return welded_base(src[win])
        q_true = r.q[starts] - h.offset
        odom = r.odometry()
        if odom is not None:
            base_pos, base_quat, base_linvel, base_angvel = odom
            return odometry_base(
                self.model,
                q_true,
                base_pos[starts],
                base_quat[starts],
                base_linvel[starts],
                base_angvel[starts],
            )
        qm = quat_from_roll_pitch(float(h.mis[0]), float(h.mis[1]))
        quat = quat_mul(r.imu_quat[starts], quat_conj(qm))
        omega = (r.imu_gyro[starts] - h.gyro_bias) @ quat_to_mat(qm).T
        # Sinkage is not observable from proprioception: the assumed support-foot penetration follows the
        # static sinkage of the hypothesis (terrain laws and body mass change it), relative to the nominal one.
        # On sand the nominal sinkage itself (millimetres to centimetres) replaces the plane's fixed penetration.
        sink = self._static_sinkage(h) - (0.0 if self.sand is not None else self._static_sinkage(_unpack({})))
        pen0 = 0.0 if self.sand is not None else self.cfg.base.penetration
        base_cfg = replace(self.cfg.base, penetration=pen0 + sink)
        return estimate_base(self.model, q_true, r.dq[starts], quat, omega, base_cfg)

    @staticmethod
    def _load_key(h: _Hyp) -> tuple[float, ...]:
        """Parameters that change the static sinkage (terrain laws, body and limb masses)."""
        t = h.terrain
        return tuple(round(float(v), 9) for v in (t.zeta, t.kappa, t.cohesion, h.dmass, *h.limb_mass))

    def _static_sinkage(self, h: _Hyp) -> float:
        """Sinkage of the lowest sole points of the G1 standing straight under hypothesis ``h`` [m] (cached).

        A settle simulation: zero joint pose held by stiff PD, 0.5 s on the ground with the hypothesis's terrain
        law and body mass, averaged over the last 0.1 s.
        """
        import mujoco

        key = self._load_key(h)
        if key in self._sink_cache:
            return self._sink_cache[key]
        m, d = self.model, self.data
        saved = m.body_mass[self._torso], m.body_inertia[self._torso].copy()
        m.body_mass[self._torso] = self._mass0 + h.dmass
        m.body_inertia[self._torso] = self._inertia0 * (self._mass0 + h.dmass) / self._mass0
        mujoco.mj_resetData(m, d)
        d.qpos[3] = 1.0
        mujoco.mj_kinematics(m, d)
        d.qpos[2] -= min(float((d.xpos[b] + SOLE_POINTS @ d.xmat[b].reshape(3, 3).T)[:, 2].min()) for b in self._feet)
        m.dof_damping[6:] = 20.0
        n, depth = round(0.5 / m.opt.timestep), []
        for k in range(n):
            mujoco.mj_step1(m, d)
            d.qfrc_applied[6:] = -500.0 * d.qpos[7:]
            self._zmax0 = None
            self._ground(h, [d], reset=k == 0)
            mujoco.mj_step2(m, d)
            if k >= n - round(0.1 / m.opt.timestep):
                soles = [d.xpos[b] + SOLE_POINTS @ d.xmat[b].reshape(3, 3).T for b in self._feet]
                depth.append(-min(float(p[:, 2].min()) for p in soles))
        m.body_mass[self._torso], m.body_inertia[self._torso] = saved
        d.xfrc_applied[:] = 0.0
        self._sink_cache[key] = float(np.mean(depth))
        return self._sink_cache[key]

    # ----------------------------------------------------------------------------------------- simulate
    def _set_model(self, h: _Hyp) -> None:
        """Apply the model-edit effects (armature, friction, mass) to the shared model."""
        import mujoco

        m = self.model
        m.dof_armature[self._jv] = G1_ARMATURE * (1.0 + h.arm_scale)
        m.dof_frictionloss[self._jv] = h.tau_c * self._w + h.tau_c_leg
        m.body_mass[self._torso] = self._mass0 + h.dmass
        m.body_inertia[self._torso] = self._inertia0 * (self._mass0 + h.dmass) / self._mass0
        limb = self._limb_mass0 + h.limb_mass
        m.body_mass[self._limbs] = limb
        m.body_inertia[self._limbs] = self._limb_inertia0 * (limb / self._limb_mass0)[:, None]
        mujoco.mj_setConst(m, self.data)

    def _commands(self, k0: int, delay: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Commands applied at samples ``k0..k0+H``, delayed by linear interpolation, shapes [H+1, 29]."""
        r = self.rec
        s = np.arange(k0, k0 + self.cfg.horizon + 1) - delay / self._dt
        i0 = np.clip(np.floor(s).astype(int), 0, r.n - 1)
        i1 = np.clip(i0 + 1, 0, r.n - 1)
        w = np.clip(s - np.floor(s), 0.0, 1.0)[:, None]
        lerp = lambda a: (1 - w) * a[i0] + w * a[i1]  # noqa: E731
        return lerp(r.q_cmd), lerp(r.dq_cmd), lerp(r.tau_ff)

    def _datas(self, n: int) -> list:
        """A pool of ``n`` MjData, one per shooting segment (segments are stepped side by side)."""
        import mujoco

        while len(self._pool) < n:
            self._pool.append(mujoco.MjData(self.model))
        return self._pool[:n]

    def simulate(self, params: dict[str, np.ndarray], starts: np.ndarray) -> np.ndarray:
        """Simulated measurements at the compare points, shape [S, P, N_CHANNELS].

        On sand all segments are stepped side by side (one MjData each), so the sand forces of every segment are
        computed in one vectorised call per physics step; on the plane, and for a welded pelvis, the segments run
        one after the other in one MjData. Either way each segment's arithmetic is that of a lone replay.

        Args:
            params: ``{effect_id: flat parameter vector}``; missing ids are nominal.
            starts: Segment start samples, shape [S].
        """
        if self.sand is None:
            return self._simulate_remembered(params, starts)
        h = _unpack(params)
        self._set_model(h)
        base = self.base(params, starts)
        out = np.zeros((len(starts), len(self.offsets), N_CHANNELS))
        self._zmax0 = self.crater_memory(params)[starts].reshape(-1)
        return self._simulate_side_by_side(h, base, starts, out)

    def _simulate_remembered(self, params: dict[str, np.ndarray], starts: np.ndarray) -> np.ndarray:
        """Serial replay of the segments the memory does not hold; the others come from it."""
        key = params_key(params)
        out = np.zeros((len(starts), len(self.offsets), N_CHANNELS))
        new = np.ones(len(starts), bool)
        for i, k0 in enumerate(starts):
            y = self._memo.get(key, int(k0))
            if y is not None:
                out[i], new[i] = y, False
        if new.any():
            h = _unpack(params)
            self._set_model(h)
            todo = starts[new]
            out[new] = self._simulate_serial(h, self.base(params, todo), todo, out[new])
            for k0, y in zip(todo, out[new], strict=True):
                self._memo.put(key, int(k0), y)
        return out

    def _simulate_side_by_side(self, h: _Hyp, base: BaseTrajectory, starts: np.ndarray, out: np.ndarray) -> np.ndarray:
        """Step all segments together, one ``MjData`` each, so the ground forces take one call per step."""
        datas = self._datas(len(starts))
        segs = [self._seg_start(h, base, s, int(k0), datas[s]) for s, k0 in enumerate(starts)]
        p = 0
        for j in range(self.cfg.horizon + 1):
            for sub in range(self.cfg.substeps):
                at_compare = sub == 0 and p < len(self.offsets) and j == self.offsets[p]
                for seg in segs:
                    self._seg_pre(h, seg, j, at_compare)
                self._ground(h, datas[: len(segs)], reset=j == 0 and sub == 0)
                for seg, o in zip(segs, out, strict=True):
                    self._seg_post(h, seg, j, o[p] if at_compare else None)
                p += int(at_compare)
        return out

    def _simulate_serial(self, h: _Hyp, base: BaseTrajectory, starts: np.ndarray, out: np.ndarray) -> np.ndarray:
        """Replay the segments one after the other in one ``MjData`` (plane or welded pelvis); fills ``out``.

        Without sand no force couples the segments, so each one runs its whole horizon before the next starts.
        The arithmetic is that of the side-by-side loop (:meth:`_seg_pre`, :meth:`_seg_post`), bit for bit, but
        one ``MjData`` stays in the CPU cache (stepping hundreds of them in turn made ``mj_step1`` cost 2-4x its
        lone cost), and it sets the per-step damping once per step and the welded pelvis once per segment.
        """
        import mujoco

        m, d = self.model, self._datas(1)[0]
        step1, step2, terrain = mujoco.mj_step1, mujoco.mj_step2, not self.fixed and h.terrain.active()
        horizon, substeps, n_cmp = self.cfg.horizon, self.cfg.substeps, len(self.offsets)
        damping = m.dof_damping[self._jv]  # a view: mj_setConst and the effects keep the buffer in place
        for s, k0 in enumerate(starts):
            seg = self._seg_start(h, base, s, int(k0), d)
            if seg.pelvis_quat is not None:
                m.body_quat[self._pelvis] = seg.pelvis_quat
            p = 0
            for j in range(horizon + 1):
                for sub in range(substeps):
                    at_compare = sub == 0 and p < n_cmp and j == self.offsets[p]
                    damping[:] = seg.damping[j]
                    step1(m, d)
                    if at_compare and not self.fixed:
                        seg.w_imu = d.qvel[3:6].copy()
                    self._torque(h, seg, j)
                    if terrain:
                        self._terrain(h.terrain, d)
                    step2(m, d)
                    if at_compare:
                        self._observe(h, seg, out[s, p])
                    p += int(at_compare)
        return out

    def _seg_start(self, h: _Hyp, base: BaseTrajectory, s: int, k0: int, d: Any) -> _Seg:
        """Reset ``d`` to the real state at ``k0`` (segment ``s`` of ``base``)."""
        import mujoco

        m, r = self.model, self.rec
        mujoco.mj_resetData(m, d)
        if not self.fixed:
            d.qpos[2] = base.pos[s, 2]
            d.qpos[3:7] = base.quat[s]
            d.qvel[:3] = base.linvel[s]
            d.qvel[3:6] = base.angvel[s]
        d.qpos[self._jq] = r.q[k0] - h.offset
        d.qvel[self._jv] = r.dq[k0]
        qc, dqc, tff = self._commands(k0, h.delay)
        rows = slice(k0, k0 + self.cfg.horizon + 1)
        kp, kd = r.kp[rows], r.kd[rows]
        damping = h.gain * kd + h.b * self._w + h.b_leg
        views = d.qpos[self._jq], d.qvel[self._jv], d.qfrc_applied[self._jv]
        pelvis = base.quat[s] if self.fixed else None
        return _Seg(d, k0, damping, qc, dqc, tff, kp, kd, h.gain * kd, *views, pelvis_quat=pelvis)

    def _seg_pre(self, h: _Hyp, seg: _Seg, j: int, at_compare: bool) -> None:
        """First half of a physics step of one segment: kinematics, motor torques (PD on the encoders)."""
        import mujoco

        m, d = self.model, seg.d
        # Damping enters qfrc_passive in mj_step1 and the implicit Euler update in mj_step2: set it first.
        m.dof_damping[self._jv] = seg.damping[j]
        if seg.pelvis_quat is not None:  # segments share the model: put this segment's welded pelvis in place
            m.body_quat[self._pelvis] = seg.pelvis_quat
        mujoco.mj_step1(m, d)
        if at_compare and not self.fixed:
            seg.w_imu = d.qvel[3:6].copy()  # angular velocity the gyro sensor saw
        self._torque(h, seg, j)

    @staticmethod
    def _torque(h: _Hyp, seg: _Seg, j: int) -> None:
        """Motor torques of step ``j`` (PD on the encoders) into ``seg.tau``, and the applied joint forces."""
        seg.qm = seg.qpos + h.offset
        v = seg.qvel
        err = seg.qc[j] - seg.qm
        if h.has_backlash:  # dead band of the position loop; at zero width the error passes unchanged
            err = err - np.minimum(np.maximum(err, -h.half_backlash), h.half_backlash)  # np.clip, no dispatch
        tau = h.gain * (seg.kp[j] * err + seg.kd[j] * (seg.dqc[j] - v)) + seg.tff[j]
        if h.droop == 0.0:
            seg.tau = np.minimum(np.maximum(tau, h.neg_lim), h.lim)
        else:
            lim = h.lim * np.clip(1.0 - h.droop * np.abs(v), 0.0, None)
            seg.tau = np.minimum(np.maximum(tau, -lim), lim)
        # The -kd*dq part is integrated implicitly through dof_damping (Euler integrator), so add it back.
        seg.qfrc[:] = seg.tau + seg.gkd[j] * v

    def _seg_post(self, h: _Hyp, seg: _Seg, j: int, out: np.ndarray | None) -> None:
        """Second half of the physics step; write the simulated measurements into ``out`` [N_CHANNELS] if given."""
        import mujoco

        m, d = self.model, seg.d
        m.dof_damping[self._jv] = seg.damping[j]
        mujoco.mj_step2(m, d)
        if out is not None:
            self._observe(h, seg, out)

    def _observe(self, h: _Hyp, seg: _Seg, out: np.ndarray) -> None:
        """Write the simulated measurements of a segment after its physics step into ``out`` [N_CHANNELS]."""
        m, d = self.model, seg.d
        rmis_t = h.rmis_t
        out[:29] = seg.qm
        out[29:58] = d.qvel[self._jv]
        out[58:87] = seg.tau
        if seg.pelvis_quat is None:
            gyro, acc = d.sensordata[0:3], d.sensordata[6:9]
        else:  # MuJoCo computes no sensor on a world-welded body: a pelvis at rest senses -gravity, no rotation
            gyro, acc = np.zeros(3), d.xmat[self._pelvis].reshape(3, 3).T @ -m.opt.gravity
        out[87:90] = rmis_t @ gyro + h.gyro_bias
        out[90:93] = rmis_t @ acc
        # simulated gyro output minus the simulated IMU frame's own angular velocity
        out[93:96] = out[87:90] - rmis_t @ seg.w_imu

    def _ground(self, h: _Hyp, datas: list, reset: bool) -> None:
        """Write the ground wrench (sand forces, or terrain effects on the plane) into each ``xfrc_applied``."""
        if self.fixed:  # a held robot touches nothing
            return
        if self.sand is not None:
            self._sand_wrench(h.terrain, datas, reset)
        elif h.terrain.active():
            for d in datas:
                self._terrain(h.terrain, d)

    def _sand_wrench(self, tp: TerrainParams, datas: list, reset: bool) -> None:
        """3D-RFT sand (and its terrain effects) on both soles of every segment, vectorised over segments."""
        import mujoco

        sand, feet, m = self.sand, self._feet, self.model
        assert sand is not None
        ns, mc = len(datas), sand.m
        pos, rot, xi = np.empty((ns, 2, 3)), np.empty((ns, 2, 3, 3)), np.empty((ns, 2, 3))
        vel6 = np.empty((ns, 2, 6))
        for s, d in enumerate(datas):
            pos[s], rot[s], xi[s] = d.xpos[feet], d.xmat[feet].reshape(2, 3, 3), d.xipos[feet]
            for f, b in enumerate(feet):
                mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_BODY, b, vel6[s, f], 0)
        rel = np.einsum("sfij,mj->sfmi", rot, sand.points_body)  # cell offsets in the world frame [S, 2, M, 3]
        pts = pos[:, :, None, :] + rel
        vel = vel6[:, :, None, 3:] + np.cross(vel6[:, :, None, :3], rel)
        normals = -rot[:, :, :, 2].reshape(-1, 3)  # outward sole normal = -z of the ankle-roll frame
        if reset or sand.zmax.shape[0] != ns * 2 * mc:
            zm = self._zmax0 if self._zmax0 is not None and len(self._zmax0) == ns * 2 * mc else None
            sand.reset(pts.reshape(-1, 3), zm)
        f, depth = sand.forces(pts.reshape(-1, 3), vel.reshape(-1, 3), normals)
        f = sand_effect_forces(f, depth, vel.reshape(-1, 3)[:, 2], sand.area(2 * ns), tp, self.cfg.terrain)
        f = f.reshape(ns, 2, mc, 3)
        wrench = np.concatenate([f.sum(2), np.cross(pts - xi[:, :, None, :], f).sum(2)], axis=-1)  # [S, 2, 6]
        for s, d in enumerate(datas):
            d.xfrc_applied[feet] = wrench[s]

    def _terrain(self, tp: TerrainParams, d: Any) -> None:
        """Write the terrain-effect wrench of both feet into ``xfrc_applied`` (plane ground)."""
        import mujoco

        m = self.model
        vel6 = np.zeros(6)
        for b in self._feet:
            rot = d.xmat[b].reshape(3, 3)
            rel = SOLE_POINTS @ rot.T
            pts = d.xpos[b] + rel
            mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_BODY, b, vel6, 0)
            vz = vel6[5] + vel6[0] * rel[:, 1] - vel6[1] * rel[:, 0]
            fz = sole_forces(pts[:, 2], vz, tp, self.cfg.terrain)
            arm = pts - d.xipos[b]
            d.xfrc_applied[b, :] = [0.0, 0.0, fz.sum(), (arm[:, 1] * fz).sum(), -(arm[:, 0] * fz).sum(), 0.0]

    def effect_ids(self) -> tuple[str, ...]:
        """Effect ids this replayer realises."""
        return tuple(e.id for e in EFFECTS if effect(e.id))
