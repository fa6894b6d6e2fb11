# SPDX-License-Identifier: Apache-2.0
"""The Unitree G1 on implicit-MPM sand, coupled two-way, driven by an exported ONNX policy (issue 9).

* Robot: mjlab's G1 MJCF loaded into Newton (``ModelBuilder.add_mjcf``) and stepped by ``SolverMuJoCo``
  (MuJoCo C on CPU, mujoco_warp on CUDA) with MuJoCo contacts off: the robot touches nothing but sand.
* Feet: every MJCF geom is hidden from the particles; each ankle-roll link gets a sole box (``SoleCfg``,
  no mass, no rigid contact) that only the particles resolve (thin foot capsules fall through a coarse bed).
* Coupling: exactly the box scene's semi-implicit scheme (:mod:`gmloco.eval.mpm.box_scene`): rigid substeps
  with the lagged sand wrench, MPM sees the feet with that wrench's velocity change removed and solves the
  contact implicitly against each foot's *effective* mass (``SoleCfg.effective_mass``: a foot alone weighs
  ~0.6 kg, but in stance it carries the robot, so MPM is told so), the collider impulses / dt are the new wrench.
* Joint armature: kp / (2 pi 10 Hz)^2, mjlab's rotor inertia (the MJCF has none; without it the explicit PD
  on the light ankle links is unstable at 200 Hz).
* Control: PD torques tau = kp (q* - q) - kd qd computed every 200 Hz physics step from the policy's 50 Hz
  joint targets q* = q_0 + action_scale a (the gains, q_0, scale and joint order from the ONNX metadata).
* Observation: the mjlab export layout (per-term history, term-major, oldest first): base angular velocity
  (pelvis, body frame), projected gravity, command (v_x, v_y, w_z), joint_pos - q_0, joint_vel, last action.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from gmloco.eval.mpm.bed import SandBedCfg, add_bed_container
from gmloco.eval.mpm.box_scene import MpmSolverCfg
from gmloco.eval.mpm.coupled_setup import build_sand_model, make_coupled_states, make_mpm_solver
from gmloco.eval.mpm.materials import GranularMaterial, MpmMaterialCfg, mpm_material

__all__ = [
    "G1MpmScene",
    "G1MpmSceneCfg",
    "MjlabOnnxPolicy",
    "PolicySpec",
    "SoleCfg",
    "StudentOnnxPolicy",
    "g1_mjcf_path",
]

FOOT_BODIES = ("left_ankle_roll_link", "right_ankle_roll_link")


def g1_mjcf_path() -> Path:
    """Path of mjlab's G1 MJCF (29 DoF)."""
    import mjlab

    return Path(mjlab.__file__).parent / "asset_zoo/robots/unitree_g1/xmls/g1.xml"


@dataclass(frozen=True)
class SoleCfg:
    """Sole box of each foot, in the ankle-roll-link frame (covers the MJCF foot capsules)."""

    center: tuple[float, float, float] = (0.039, 0.0, -0.03)
    """Box centre in the ankle-roll frame [m] (capsules span x in [-0.054, 0.132], sit at z = -0.025)."""
    half_extents: tuple[float, float, float] = (0.095, 0.035, 0.01)
    """Half sizes [m]."""
    effective_mass: float | None = None
    """Mass MPM solves each foot's contact against [kg]; None = half the robot's mass (double stance)."""


@dataclass(frozen=True)
class PolicySpec:
    """What the scene needs from a policy (read from ONNX metadata, or the default pose for PD-only runs)."""

    joint_names: list[str]
    kp: np.ndarray
    kd: np.ndarray
    default_joint_pos: np.ndarray
    action_scale: np.ndarray
    policy_dt: float = 0.02


@dataclass(frozen=True)
class G1MpmSceneCfg:
    """G1-on-sand scene."""

    bed: SandBedCfg = field(
        default_factory=lambda: SandBedCfg(size_x=0.6, size_y=0.5, depth=0.15, center_x=0.03, center_y=0.0)
    )
    """Sand bed, surface at z = 0."""
    solver: MpmSolverCfg = field(default_factory=lambda: MpmSolverCfg(frame_dt=0.01, rigid_substeps=2))
    """MPM numerics; frame_dt / rigid_substeps is the 200 Hz physics step."""
    sole: SoleCfg = field(default_factory=SoleCfg)
    """Foot sole colliders."""
    drop_height: float = 0.005
    """Initial gap between the lowest sole point and the sand surface [m]."""
    command: tuple[float, float, float] = (0.0, 0.0, 0.0)
    """Velocity command (v_x, v_y, w_z) [m/s, m/s, rad/s]."""
    natural_frequency_hz: float = 10.0
    """mjlab's actuator natural frequency: joint armature = kp / (2 pi f)^2 [Hz]."""
    device: str | None = None
    """Warp device; None = Warp's default."""


class MjlabOnnxPolicy:
    """An mjlab-exported actor (single ``obs`` input; per-term history flattened term-major) on onnxruntime."""

    def __init__(self, path: str | Path, num_threads: int = 1) -> None:
        """Load the model and parse its comma-joined metadata."""
        import onnxruntime as ort

        options = ort.SessionOptions()
        options.intra_op_num_threads = num_threads
        self.session = ort.InferenceSession(str(path), options, providers=["CPUExecutionProvider"])
        meta = self.session.get_modelmeta().custom_metadata_map
        floats = lambda key: np.array([float(v) for v in meta[key].split(",")])  # noqa: E731
        self.joint_names = meta["joint_names"].split(",")
        self.action_joint_names = meta.get("action_joint_names", meta["joint_names"]).split(",")
        self.term_names = meta["observation_names"].split(",")
        self.term_dims = [round(v) for v in floats("observation_dims")]
        self.term_history = [round(v) for v in floats("observation_terms_history_length")]
        self.term_scale = floats("observation_terms_scale")
        self.obs_dim = int(meta["observation_dim"])
        if sum(d * h for d, h in zip(self.term_dims, self.term_history, strict=True)) != self.obs_dim:
            raise ValueError("observation layout in the metadata does not add up to observation_dim")
        scale = floats("action_scale")
        by_name = dict(zip(self.joint_names, range(len(self.joint_names)), strict=True))
        idx = [by_name[n] for n in self.action_joint_names]
        self.spec = PolicySpec(
            joint_names=self.action_joint_names,
            kp=floats("joint_stiffness")[idx],
            kd=floats("joint_damping")[idx],
            default_joint_pos=floats("default_joint_pos")[idx],
            action_scale=np.broadcast_to(scale, (len(idx),)).copy(),
            policy_dt=float(meta.get("policy_dt", 0.02)),
        )
        self.input_name = self.session.get_inputs()[0].name
        self._hist: list[np.ndarray] | None = None

    def reset(self) -> None:
        """Forget the history (the next frame is back-filled, as mjlab does after a reset)."""
        self._hist = None

    def act(self, terms: dict[str, np.ndarray]) -> np.ndarray:
        """Push one frame of observation terms and return the action [num_actions]."""
        frames = [
            np.asarray(terms[n], dtype=np.float32) * s for n, s in zip(self.term_names, self.term_scale, strict=True)
        ]
        if self._hist is None:
            self._hist = [np.repeat(f[None], h, axis=0) for f, h in zip(frames, self.term_history, strict=True)]
        else:
            self._hist = [np.concatenate([b[1:], f[None]]) for b, f in zip(self._hist, frames, strict=True)]
        obs = np.concatenate([b.reshape(-1) for b in self._hist])[None].astype(np.float32)
        return np.asarray(self.session.run(None, {self.input_name: obs})[0])[0]


class StudentOnnxPolicy:
    """A gmloco student export (``obs`` + ``history``) run by ``OnnxPolicyRunner``; o_t built from the metadata."""

    def __init__(self, path: str | Path) -> None:
        """Load the runner; check that the observation terms are ones the scene provides."""
        from gmloco.deploy.export import OnnxPolicyRunner

        self.runner = OnnxPolicyRunner(path)
        meta = self.runner.metadata
        known = {"base_ang_vel", "projected_gravity", "command", "joint_pos", "joint_vel", "actions"}
        if not set(meta.observation_names) <= known:
            raise ValueError(f"unsupported observation terms {sorted(set(meta.observation_names) - known)}")
        self.meta = meta
        self.spec = PolicySpec(
            joint_names=list(meta.joint_names),
            kp=np.asarray(meta.joint_stiffness, dtype=np.float64),
            kd=np.asarray(meta.joint_damping, dtype=np.float64),
            default_joint_pos=np.asarray(meta.default_joint_pos, dtype=np.float64),
            action_scale=np.asarray(meta.action_scale, dtype=np.float64),
            policy_dt=float(meta.policy_dt),
        )

    def reset(self) -> None:
        """Forget the history."""
        self.runner.reset()

    def act(self, terms: dict[str, np.ndarray]) -> np.ndarray:
        """Clip, scale and concatenate the terms into o_t; return the action [num_actions]."""
        parts = []
        for name, clip, scale in zip(
            self.meta.observation_names, self.meta.observation_clip, self.meta.observation_scale, strict=True
        ):
            x = np.asarray(terms[name], dtype=np.float64)
            if clip is not None:
                x = np.clip(x, clip[0], clip[1])
            parts.append(x * np.asarray(scale, dtype=np.float64))
        return np.asarray(self.runner.step(np.concatenate(parts).astype(np.float32)))


class G1MpmScene:
    """G1 standing / walking on a coupled MPM sand bed (Example-shaped: ``step``, ``run``, ``test_final``).

    Attributes:
        base_q: Pelvis pose (p, q_xyzw) after each frame, list of [7].
        base_qd: Pelvis (linear, angular) world velocity after each frame, list of [6].
        foot_force: Sand force on each foot of each frame [N], list of [2, 3].
        sole_z: Lowest sole-centre height of each frame [m] (sinkage = -sole_z).
    """

    def __init__(
        self,
        cfg: G1MpmSceneCfg,
        material: GranularMaterial | MpmMaterialCfg,
        policy: MjlabOnnxPolicy | StudentOnnxPolicy | PolicySpec,
    ) -> None:
        """Build robot + sand models, both solvers and the coupling buffers."""
        import newton
        import warp as wp

        self.cfg = cfg
        self.mat = material if isinstance(material, MpmMaterialCfg) else mpm_material(material)
        self.policy = None if isinstance(policy, PolicySpec) else policy
        self.spec = policy if isinstance(policy, PolicySpec) else policy.spec
        self.device = wp.get_device(cfg.device)
        s = cfg.solver
        self.frame_dt, self.sim_dt = s.frame_dt, s.frame_dt / s.rigid_substeps
        self.frames_per_policy = max(1, round(self.spec.policy_dt / self.frame_dt))
        with wp.ScopedDevice(self.device):
            self.model = self._build_robot(newton, wp)
            self.sand_model, self.particle_count = build_sand_model(
                newton, self.cfg.bed, self.cfg.solver.voxel_size, self.mat
            )
            self._build_solvers(newton, wp)
            self._allocate(newton, wp)
        self.frame = 0
        self.wall_time = 0.0
        self.action = np.zeros(len(self.spec.joint_names))
        self.target = self.spec.default_joint_pos.copy()
        self.base_q: list[np.ndarray] = []
        self.base_qd: list[np.ndarray] = []
        self.foot_force: list[np.ndarray] = []
        self.sole_z: list[float] = []

    # -- construction ---------------------------------------------------------------------------------------

    def _build_robot(self, newton: Any, wp: Any) -> Any:
        """G1 from the MJCF (particles see only the sole boxes) plus the static bed container."""
        builder = newton.ModelBuilder()
        builder.add_mjcf(str(g1_mjcf_path()), floating=True, parse_visuals=False)
        particle_bit = int(newton.ShapeFlags.COLLIDE_PARTICLES)
        builder.shape_flags = [int(f) & ~particle_bit for f in builder.shape_flags]
        labels = [label.rsplit("/", 1)[-1] for label in builder.body_label]
        self.foot_bodies = [labels.index(n) for n in FOOT_BODIES]
        sole = self.cfg.sole
        sole_cfg = newton.ModelBuilder.ShapeConfig(
            density=0.0, mu=float(self.mat.collider_friction), has_shape_collision=False
        )
        for b in self.foot_bodies:
            builder.add_shape_box(b, xform=wp.transform(wp.vec3(*sole.center), wp.quat_identity()),
                                  hx=sole.half_extents[0], hy=sole.half_extents[1], hz=sole.half_extents[2],
                                  cfg=sole_cfg)  # fmt: skip
        add_bed_container(builder, self.cfg.bed, friction=self.mat.friction)
        # actuated joints in policy order -> coordinate / dof indices
        jlabels = [label.rsplit("/", 1)[-1] for label in builder.joint_label]
        model = builder.finalize()
        q_start, qd_start = model.joint_q_start.numpy(), model.joint_qd_start.numpy()
        joints = [jlabels.index(n) for n in self.spec.joint_names]
        self.q_idx = np.array([q_start[j] for j in joints])
        self.qd_idx = np.array([qd_start[j] for j in joints])
        self.robot_mass = float(model.body_mass.numpy().sum())
        # the MJCF has no rotor inertia; mjlab adds it with its actuators and derives the gains from it
        # (kp = I_a w^2, kd = 2 zeta I_a w, w = 2 pi 10 Hz, zeta = 2), so I_a = kp / w^2 recovers it
        armature = model.joint_armature.numpy()
        armature[self.qd_idx] = self.spec.kp / (2.0 * np.pi * self.cfg.natural_frequency_hz) ** 2
        model.joint_armature.assign(armature)
        # default pose, feet drop_height above the sand
        q = model.joint_q.numpy()
        q[self.q_idx] = self.spec.default_joint_pos
        model.joint_q.assign(q)
        state = model.state()
        newton.eval_fk(model, model.joint_q, model.joint_qd, state)
        q[2] += self.cfg.drop_height - float(self._sole_bottom(state.body_q.numpy()).min())
        model.joint_q.assign(q)
        return model

    def _sole_bottom(self, body_q: np.ndarray) -> np.ndarray:
        """Lowest corner height of each sole box [m], [2]."""
        from scipy.spatial.transform import Rotation

        c, h = np.array(self.cfg.sole.center), np.array(self.cfg.sole.half_extents)
        corners = c + h * np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
        out = []
        for b in self.foot_bodies:
            p, rot = body_q[b, :3], Rotation.from_quat(body_q[b, 3:7])
            out.append(float((rot.apply(corners) + p)[:, 2].min()))
        return np.array(out)

    def _build_solvers(self, newton: Any, wp: Any) -> None:
        """Implicit MPM with the sole boxes as dynamic colliders of effective mass; MuJoCo for the robot."""
        self.mpm = make_mpm_solver(newton, self.sand_model, self.cfg.solver, self.mat)
        m_eff = self.cfg.sole.effective_mass or 0.5 * self.robot_mass
        mass = self.model.body_mass.numpy().copy()
        inv_inertia = self.model.body_inv_inertia.numpy().copy()
        for b in self.foot_bodies:
            inv_inertia[b] *= mass[b] / m_eff
            mass[b] = m_eff
        inv_mass = np.where(mass > 0, 1.0 / np.maximum(mass, 1e-12), 0.0)
        self.eff_inv_mass = wp.array(inv_mass.astype(np.float32), dtype=float)
        self.eff_inv_inertia = wp.array(inv_inertia.astype(np.float32), dtype=wp.mat33)
        self.mpm.setup_collider(
            model=self.model, body_mass=wp.array(mass.astype(np.float32), dtype=float),
            body_inv_inertia=self.eff_inv_inertia,
        )  # fmt: skip
        self.rigid = newton.solvers.SolverMuJoCo(
            self.model, use_mujoco_cpu=not self.device.is_cuda, use_mujoco_contacts=False, njmax=64, nconmax=64
        )

    def _allocate(self, newton: Any, wp: Any) -> None:
        """Rigid states, the sand state (sharing body arrays) and the wrench buffers."""
        st = make_coupled_states(newton, wp, self.model, self.sand_model)
        self.state_0, self.state_1, self.control = st.state_0, st.state_1, st.control
        self.sand_state, self.sand_wrench = st.sand_state, st.sand_wrench
        self.joint_f = np.zeros(self.model.joint_dof_count, dtype=np.float32)

    # -- control --------------------------------------------------------------------------------------------

    def _joint_state(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Return (root pose [7], root qd [6], joint pos [A], joint vel [A]) in policy joint order."""
        q, qd = self.state_0.joint_q.numpy(), self.state_0.joint_qd.numpy()
        return q[:7], qd[:6], q[self.q_idx], qd[self.qd_idx]

    def observation_terms(self) -> dict[str, np.ndarray]:
        """One frame of the mjlab velocity-task observation terms (no noise, scale 1)."""
        from scipy.spatial.transform import Rotation

        root_q, _, jq, jqd = self._joint_state()
        body_qd = self.state_0.body_qd.numpy()[0]
        rot = Rotation.from_quat(root_q[3:7])
        return {
            "base_ang_vel": rot.inv().apply(body_qd[3:6]),
            "projected_gravity": rot.inv().apply([0.0, 0.0, -1.0]),
            "command": np.asarray(self.cfg.command, dtype=np.float64),
            "joint_pos": jq - self.spec.default_joint_pos,
            "joint_vel": jqd,
            "actions": self.action,
        }

    def _apply_pd(self) -> None:
        """Write PD torques tau = kp (q* - q) - kd qd into ``control.joint_f`` (200 Hz, explicit)."""
        _, _, jq, jqd = self._joint_state()
        self.joint_f[:] = 0.0
        self.joint_f[self.qd_idx] = self.spec.kp * (self.target - jq) - self.spec.kd * jqd
        self.control.joint_f.assign(self.joint_f)

    # -- stepping -------------------------------------------------------------------------------------------

    def simulate(self) -> None:
        """One frame: PD + rigid substeps with the lagged sand wrench, then one coupled MPM step."""
        import warp as wp

        from gmloco.eval.mpm.kernels_coupling import eval_body_sand_wrench, eval_rewind_body_velocity

        for _ in range(self.cfg.solver.rigid_substeps):
            self._apply_pd()
            self.state_0.clear_forces()
            wp.copy(self.state_0.body_f, self.sand_wrench)
            self.rigid.step(self.state_0, self.state_1, self.control, None, self.sim_dt)
            self.state_0, self.state_1 = self.state_1, self.state_0
        wp.copy(self.sand_state.body_q, self.state_0.body_q)
        eval_rewind_body_velocity(
            self.eff_inv_mass, self.eff_inv_inertia, self.frame_dt, self.state_0.body_q,
            self.state_0.body_qd, self.sand_wrench, self.sand_state.body_qd,
        )  # fmt: skip
        self.mpm.step(self.sand_state, self.sand_state, None, None, self.frame_dt)
        eval_body_sand_wrench(
            self.mpm.collider_body_index, self.model.body_com, self.frame_dt,
            self.mpm.collect_collider_impulses(self.sand_state), self.sand_state.body_q, self.sand_wrench,
        )  # fmt: skip

    def step(self) -> None:
        """Advance one frame (policy at its own rate) and log base state, foot forces and sole height."""
        t0 = time.perf_counter()
        if self.frame % self.frames_per_policy == 0 and self.policy is not None:
            self.action = self.policy.act(self.observation_terms()).astype(np.float64)
            self.target = self.spec.default_joint_pos + self.spec.action_scale * self.action
        self.simulate()
        wrench = self.sand_wrench.numpy()
        body_q = self.state_0.body_q.numpy()
        self.wall_time += time.perf_counter() - t0
        self.frame += 1
        self.base_q.append(body_q[0].copy())
        self.base_qd.append(self.state_0.body_qd.numpy()[0].copy())
        self.foot_force.append(np.asarray(wrench[self.foot_bodies, :3], dtype=np.float64))
        self.sole_z.append(float(self._sole_bottom(body_q).min()))

    def run(self, num_frames: int) -> None:
        """Step ``num_frames`` frames."""
        for _ in range(num_frames):
            self.step()

    @property
    def frames_per_second(self) -> float:
        """Simulated frames per wall-clock second (construction excluded)."""
        return self.frame / max(self.wall_time, 1e-9)

    def support_ratio(self, skip: float = 0.5) -> float:
        """Mean vertical sand force on both feet over the frames after the first ``skip`` fraction, over m g."""
        f = np.asarray(self.foot_force)[:, :, 2].sum(axis=1)
        k = int(len(f) * skip)
        return float(f[k:].mean() / (self.robot_mass * 9.81))

    def test_final(self) -> None:
        """Finite state, pelvis up, soles not through the bed, sand inside the container."""
        q = np.asarray(self.base_q[-1])
        assert np.all(np.isfinite(q)), "robot state is not finite"
        assert q[2] > 0.3, f"pelvis fell (z = {q[2]:.3f} m)"
        assert self.sole_z[-1] > -self.cfg.bed.depth, "foot went through the bed"
        z = self.sand_state.particle_q.numpy()[:, 2]
        assert np.all(np.isfinite(z)) and np.all(z > -self.cfg.bed.depth - 2 * self.cfg.solver.voxel_size)
