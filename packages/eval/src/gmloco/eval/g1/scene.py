# SPDX-License-Identifier: Apache-2.0
"""Unitree G1s on implicit-MPM sand, coupled two-way, driven by an exported ONNX policy (issue 9), batched.

* Robots: mjlab's G1 MJCF loaded into Newton (``ModelBuilder.add_mjcf``), ``num_robots`` copies, each in its own
  lane (y offset ``lane_spacing``), stepped by ``SolverMuJoCo`` (one MuJoCo world per robot on CUDA through
  mujoco_warp; all robots in one MuJoCo C world on CPU). MuJoCo's only contacts are the sole boxes against the
  rigid floor under the sand (``floor_contact``): a sole pressed through the bed stands on the floor, as a foot
  would on the bottom of a sandbox, instead of falling through a floor that holds only particles.
* Sand: one ``SolverImplicitMPM`` for all robots; each robot walks on its own window of sand
  (:mod:`gmloco.eval.mpm.window`): static (a full bed, the naive baseline) or moving with it (recycled columns).
  The window's four walls are kinematic MPM colliders (``wall_colliders``): one wall body per robot, in a
  collider-only copy of the robot model, moved with the window every frame. Clamping particles back into the
  window after the MPM step (``SandWindow.apply_walls``, kept as a safety net) is not enough on its own: the solve
  then sees free vertical faces of sand, the bed slumps towards them every step and never builds its
  confining stress, and a standing G1 sank ~23 cm instead of ~6 cm (``results/mpm_eval/G1_SINKAGE.md``).
* Feet: every MJCF geom is hidden from the particles; each ankle-roll link gets a sole box (``SoleCfg``,
  no mass, no rigid contact) that only the particles resolve (thin foot capsules fall through a coarse bed).
* Coupling: the box scene's semi-implicit scheme (:mod:`gmloco.eval.mpm.box_scene`): rigid substeps with the
  lagged sand wrench, MPM sees the feet at the scheme's velocity (``MpmSolverCfg.velocity_handover``; default
  the predicted one, velocity + g frame_dt) and solves the contact implicitly against each foot's *effective* mass (``SoleCfg.effective_mass``: in stance a foot carries the
  robot), the collider impulses / dt are the new wrench.
* Joint armature: kp / (2 pi 10 Hz)^2, mjlab's rotor inertia (the MJCF has none; without it the explicit PD
  on the light ankle links is unstable at 200 Hz).
* Control: PD torques tau = kp (q* - q) - kd qd every 200 Hz physics step, on the device
  (:func:`~gmloco.eval.mpm.kernels_coupling.eval_pd_joint_force`), from the policy's 50 Hz joint targets
  q* = q_0 + action_scale a. One frame (rigid substeps + window + MPM) is one CUDA graph when the grid has a
  fixed capacity (``max_active_cell_count > 0``).
* Observation: the mjlab velocity-task terms: base angular velocity (pelvis, body frame), projected gravity,
  command (v_x, v_y, w_z), joint_pos - q_0, joint_vel, last action. The policy gets the pelvis heading too, so
  a ``yaw_target`` policy observes w_z with the heading correction it was trained with (``g1.policy``).
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from gmloco.deploy.g1 import G1_FOOT_BODIES
from gmloco.eval.g1.policy import MjlabOnnxPolicy, PolicySpec, StudentOnnxPolicy
from gmloco.eval.g1.scene_cfg import G1MpmSceneCfg
from gmloco.eval.g1.soles import (
    NJMAX_PER_ROBOT,
    g1_mjcf_path,
    needs_sand,
    quat_conj,
    quat_rotate_inv,
    sole_box_corners,
    sole_reach,
    soles_outside,
)
from gmloco.eval.metrics.locomotion import quat_wxyz_to_roll_pitch_yaw
from gmloco.eval.mpm.box_scene import frame_dt_problem, model_gravity
from gmloco.eval.mpm.coupled_setup import make_coupled_states, make_mpm_solver
from gmloco.eval.mpm.window import SandWindow
from gmloco.eval.mpm.window_terrain import terrain_materials, terrain_surface_height

__all__ = ["G1MpmScene"]


class G1MpmScene:
    """G1s walking on coupled MPM sand (Example-shaped: ``step``, ``run``, ``test_final``), logged at 50 Hz.

    Attributes:
        base_q: Pelvis pose (p, q_xyzw) of every robot at each policy step, list of [R, 7].
        base_qd: Pelvis (linear, angular) world velocity at each policy step, list of [R, 6].
        foot_force: Sand force on each foot [N], list of [R, 2, 3]: the mean over the frames since the previous policy
            step (the coupling's force changes from frame to frame; one frame's sample of it need not carry the
            robot's weight on average).
        sinkage: Depth of each robot's lowest sole point below the local terrain surface [m], list of [R].
        foot_sinkage: The same per foot [m], list of [R, 2].
        joint_q, joint_qd, target: Actuated joints [rad], [rad/s] and PD targets [rad], lists of [R, A].
        action: Raw policy actions, list of [R, A].
        eta: The student's decoded normalized terrain stiffness, list of [R] (NaN for other policies).
    """

    def __init__(self, cfg: G1MpmSceneCfg, policy: MjlabOnnxPolicy | StudentOnnxPolicy | PolicySpec) -> None:
        """Build robots + sand models, both solvers, the windows and the coupling buffers."""
        import newton
        import warp as wp

        self.cfg = cfg
        self.mats = terrain_materials(cfg.terrain)
        self.policy = None if isinstance(policy, PolicySpec) else policy
        self.spec = policy if isinstance(policy, PolicySpec) else policy.spec
        self.device = wp.get_device(cfg.device)
        s = cfg.solver
        if (problem := frame_dt_problem(s.frame_dt, self.spec.policy_dt)) is not None:
            raise ValueError(f"MpmSolverCfg.{problem}")
        self.frame_dt, self.sim_dt = s.frame_dt, s.frame_dt / s.rigid_substeps
        self.frames_per_policy = round(self.spec.policy_dt / self.frame_dt)
        n = cfg.num_robots
        self.commands = np.array([cfg.commands[r % len(cfg.commands)] for r in range(n)], dtype=np.float64)
        self.lane_y = np.arange(n) * cfg.lane_spacing
        with wp.ScopedDevice(self.device):
            self.model = self._build_robots(newton, wp)
            self.gravity = model_gravity(self.model)
            self._build_sand(newton, wp)
            self._build_solvers(newton, wp)
        self.frame = 0
        self.wall_time = 0.0
        self.graph = None
        self.capture_error: str | None = None  # why a frame could not be captured as a CUDA graph
        self.last_action = np.zeros((n, len(self.spec.joint_names)))
        self.base_q: list[np.ndarray] = []
        self.base_qd: list[np.ndarray] = []
        self.foot_force: list[np.ndarray] = []
        self.sinkage: list[np.ndarray] = []
        self.foot_sinkage: list[np.ndarray] = []
        self.joint_q: list[np.ndarray] = []
        self.joint_qd: list[np.ndarray] = []
        self.target: list[np.ndarray] = []
        self.action: list[np.ndarray] = []
        self.eta: list[np.ndarray] = []
        self.sole_out: list[np.ndarray] = []
        """Per sample: sole corners per robot that need sand but lie outside the window (``soles_outside``)."""
        self.sole_reach: list[np.ndarray] = []
        """Per sample: reach of the soles that need sand behind / ahead of / beside the pelvis (``sole_reach``)."""

    @property
    def particle_count(self) -> int:
        """MPM particles of all windows."""
        return self.window.particle_count

    # -- construction ---------------------------------------------------------------------------------------

    def _robot_builder(self, newton: Any, wp: Any) -> Any:
        """One G1 from the MJCF; particles see only the two sole boxes."""
        b = newton.ModelBuilder()
        b.add_mjcf(str(g1_mjcf_path()), floating=True, parse_visuals=False)
        # MJCF geoms touch nothing: particles see the soles only, MuJoCo contacts are the soles' with the floor
        hidden = int(newton.ShapeFlags.COLLIDE_PARTICLES) | int(newton.ShapeFlags.COLLIDE_SHAPES)
        b.shape_flags = [int(f) & ~hidden for f in b.shape_flags]
        labels = [label.rsplit("/", 1)[-1] for label in b.body_label]
        self.foot_local = [labels.index(name) for name in G1_FOOT_BODIES]
        sole = self.cfg.sole
        mu = float(np.median([m.collider_friction for m in self.mats]))
        sole_cfg = newton.ModelBuilder.ShapeConfig(density=0.0, mu=mu, has_shape_collision=self.cfg.floor_contact)
        for body in self.foot_local:
            b.add_shape_box(body, xform=wp.transform(wp.vec3(*sole.center), wp.quat_identity()),
                            hx=sole.half_extents[0], hy=sole.half_extents[1], hz=sole.half_extents[2],
                            cfg=sole_cfg)  # fmt: skip
        jlabels = [label.rsplit("/", 1)[-1] for label in b.joint_label]
        self.joints_local = [jlabels.index(name) for name in self.spec.joint_names]
        return b

    def _build_robots(self, newton: Any, wp: Any) -> Any:
        """R robots (worlds on CUDA, one world on CPU) over a rigid floor at z = -depth, in the default pose."""
        rb = self._robot_builder(newton, wp)
        self.bodies_per_robot, self.coords_per_robot = rb.body_count, rb.joint_coord_count
        self.dofs_per_robot = rb.joint_dof_count
        as_worlds = self.cfg.robots_as_worlds
        self.as_worlds = self.device.is_cuda if as_worlds is None else as_worlds
        self._rb = rb
        model = self._assemble(newton, wp).finalize()
        q_start, qd_start = model.joint_q_start.numpy(), model.joint_qd_start.numpy()
        self.q_idx = np.array([q_start[j] for j in self.joints_local])
        self.qd_idx = np.array([qd_start[j] for j in self.joints_local])
        self.robot_mass = float(model.body_mass.numpy()[: self.bodies_per_robot].sum())
        self.foot_bodies = np.array([[r * self.bodies_per_robot + f for f in self.foot_local]
                                     for r in range(self.cfg.num_robots)])  # fmt: skip
        # the MJCF has no rotor inertia; mjlab adds it with its actuators and derives the gains from it
        # (kp = I_a w^2, kd = 2 zeta I_a w, w = 2 pi 10 Hz, zeta = 2), so I_a = kp / w^2 recovers it
        armature = model.joint_armature.numpy()
        q = model.joint_q.numpy()
        for r in range(self.cfg.num_robots):
            armature[r * self.dofs_per_robot + self.qd_idx] = (
                self.spec.kp / (2 * np.pi * self.cfg.natural_frequency_hz) ** 2
            )
            q[r * self.coords_per_robot + self.q_idx] = self.spec.default_joint_pos
            q[r * self.coords_per_robot + 1] = self.lane_y[r]
        model.joint_armature.assign(armature)
        model.joint_q.assign(q)
        self._drop_onto_surface(newton, model, q)
        self._q_init = q.copy()  # every robot's start: default pose, dropped onto the sand (reset_robots)
        return model

    def _assemble(self, newton: Any, wp: Any, walls: list[np.ndarray] | None = None) -> Any:
        """Builder of R robots (worlds or one world) and the floor; ``walls``: one wall body per robot after them.

        ``walls`` holds each wall body's first position (the window centre); ``place_walls`` turns it.
        """
        builder = newton.ModelBuilder()
        if self.as_worlds:
            for _ in range(self.cfg.num_robots):
                builder.add_world(self._rb)
        else:
            builder.begin_world()
            for _ in range(self.cfg.num_robots):
                builder.add_builder(self._rb)
            builder.end_world()
        if walls is not None:
            wall_cfg = newton.ModelBuilder.ShapeConfig(mu=0.0, density=0.0, has_shape_collision=False)
            for corner in walls:
                body = builder.add_body(xform=wp.transform(wp.vec3(*corner), wp.quat_identity()), mass=0.0)
                for c, h in self.window.wall_boxes(self.cfg.wall_thickness, height=0.3):
                    builder.add_shape_box(body, xform=wp.transform(wp.vec3(*c), wp.quat_identity()),
                                          hx=h[0], hy=h[1], hz=h[2], cfg=wall_cfg)  # fmt: skip
        floor = newton.ModelBuilder.ShapeConfig(mu=float(self.mats[0].friction), density=0.0)
        builder.add_ground_plane(height=-float(self.cfg.terrain.depth), cfg=floor)
        return builder

    def _drop_onto_surface(self, newton: Any, model: Any, q: np.ndarray) -> None:
        """Lift every robot so its lowest sole corner is ``drop_height`` above the terrain surface."""
        state = model.state()
        newton.eval_fk(model, model.joint_q, model.joint_qd, state)
        corners = self._sole_corners(state.body_q.numpy())  # [R, 2, 8, 3]
        surf = terrain_surface_height(self.cfg.terrain, corners[..., 0], corners[..., 1] - self.lane_y[:, None, None])
        gap = (corners[..., 2] - surf).reshape(self.cfg.num_robots, -1).min(axis=1)
        for r in range(self.cfg.num_robots):
            q[r * self.coords_per_robot + 2] += self.cfg.drop_height - gap[r]
        model.joint_q.assign(q)

    def _sole_corners(self, body_q: np.ndarray) -> np.ndarray:
        """World corners of every sole box [m], [R, 2, 8, 3]."""
        local = sole_box_corners(self.cfg.sole)
        pose = body_q[self.foot_bodies]  # [R, 2, 7]
        quat = np.broadcast_to(pose[:, :, None, 3:7], (*pose.shape[:2], 8, 4))
        return quat_rotate_inv(quat_conj(quat), np.broadcast_to(local, (*quat.shape[:-1], 3))) + pose[:, :, None, :3]

    def _build_sand(self, newton: Any, wp: Any) -> None:
        """Particles of every robot's window, placed around the initial poses and filled with the terrain."""
        builder = newton.ModelBuilder()
        newton.solvers.SolverImplicitMPM.register_custom_attributes(builder)
        self.window = SandWindow(self.cfg.window, self.cfg.terrain, self.cfg.solver.voxel_size, self.lane_y,
                                 self.bodies_per_robot, seed=self.cfg.seed)  # fmt: skip
        self.window.add_particles(builder)
        self.sand_model = builder.finalize()
        mat = self.mats[0]
        for name, value in mat.mpm_attributes().items():
            if name != "friction":
                getattr(self.sand_model.mpm, name).fill_(value)
        self.window.allocate(wp, self.device)
        state = self.model.state()
        newton.eval_fk(self.model, self.model.joint_q, self.model.joint_qd, state)
        self.window.seed_model(wp, self.sand_model, state.body_q)

    def _build_solvers(self, newton: Any, wp: Any) -> None:
        """Implicit MPM with the sole boxes as dynamic colliders of effective mass; MuJoCo for the robots."""
        self.mpm = make_mpm_solver(newton, self.sand_model, self.cfg.solver, self.mats[0])
        # colliders: the robots' soles (same body indices as the robot model), the floor and, with
        # wall_colliders, one kinematic (zero effective mass) wall body per robot after the robots' bodies
        self.wall_body_offset = self.model.body_count
        if self.cfg.wall_colliders:
            centres = self.window.frames()[0]
            walls = [np.array([x, y, 0.0]) for x, y in centres]
            self.collider_model = self._assemble(newton, wp, walls).finalize()
        else:
            self.collider_model = self.model
        m_eff = self.cfg.sole.effective_mass or 0.5 * self.robot_mass
        mass = self.collider_model.body_mass.numpy().copy()
        mass[self.wall_body_offset :] = 0.0
        inv_inertia = self.collider_model.body_inv_inertia.numpy().copy()
        for b in self.foot_bodies.ravel():
            inv_inertia[b] *= mass[b] / m_eff
            mass[b] = m_eff
        inv_mass = np.where(mass > 0, 1.0 / np.maximum(mass, 1e-12), 0.0)
        self.eff_inv_mass = wp.array(inv_mass.astype(np.float32), dtype=float)
        self.eff_inv_inertia = wp.array(inv_inertia.astype(np.float32), dtype=wp.mat33)
        self.mpm.setup_collider(model=self.collider_model, body_mass=wp.array(mass.astype(np.float32), dtype=float),
                                body_inv_inertia=self.eff_inv_inertia)  # fmt: skip
        per_world = 1 if self.as_worlds else self.cfg.num_robots
        self.rigid = newton.solvers.SolverMuJoCo(
            self.model, use_mujoco_cpu=not self.as_worlds, use_mujoco_contacts=self.cfg.floor_contact,
            njmax=NJMAX_PER_ROBOT * per_world, nconmax=64 * per_world,
        )  # fmt: skip
        # mujoco_warp without MuJoCo contacts still reads Newton contacts: an empty set (the robots touch only sand)
        no_contacts = self.cfg.floor_contact or not self.as_worlds
        self.contacts = None if no_contacts else newton.Contacts(0, 0, device=self.device)
        st = make_coupled_states(newton, wp, self.model, self.sand_model)
        self.state_0, self.state_1, self.control = st.state_0, st.state_1, st.control
        self.sand_state, self.sand_wrench = st.sand_state, st.sand_wrench
        if self.cfg.wrench_frames not in (1, 2):
            raise ValueError(
                f"wrench_frames={self.cfg.wrench_frames}: give 1 (the last frame's) or 2 (two frames' mean)"
            )
        self.sand_wrench_raw = wp.zeros_like(self.sand_wrench)
        """This frame's coupled wrench before the two-frame mean (``wrench_frames=2``)."""
        self.sand_wrench_last = wp.zeros_like(self.sand_wrench)
        """The previous frame's coupled wrench (``wrench_frames=2``)."""
        self.sand_wrench_sum = wp.zeros_like(self.sand_wrench)
        """Sum of the sand wrench over the frames since the last policy step's read (``foot_force`` is its mean)."""
        self.frames_summed = 0
        if self.cfg.wall_colliders:  # the sand state's bodies: the robots' then the wall bodies
            nb = self.collider_model.body_count
            self.sand_state.body_q = wp.clone(self.collider_model.body_q)
            self.sand_state.body_qd = wp.zeros(nb, dtype=wp.spatial_vector, device=self.device)
            wp.copy(self.sand_state.body_q, self.state_0.body_q, count=self.wall_body_offset)
            self.window.place_walls(self.wall_body_offset, self.sand_state.body_q, self.sand_state.body_qd)
        self.window.bind(self.sand_model, self.sand_state, self.mpm)
        a = len(self.spec.joint_names)
        self.pd = {
            "kp": wp.array(self.spec.kp.astype(np.float32), dtype=float),
            "kd": wp.array(self.spec.kd.astype(np.float32), dtype=float),
            "q_idx": wp.array(self.q_idx.astype(np.int32), dtype=int),
            "qd_idx": wp.array(self.qd_idx.astype(np.int32), dtype=int),
        }
        self.targets = wp.array(np.tile(self.spec.default_joint_pos, (self.cfg.num_robots, 1)).astype(np.float32),
                                dtype=float)  # fmt: skip
        assert self.targets.shape == (self.cfg.num_robots, a)

    # -- control --------------------------------------------------------------------------------------------

    def _read_state(self) -> dict[str, np.ndarray]:
        """Host copy of every robot's pelvis and actuated-joint state, and the sand wrench on the feet."""
        n = self.cfg.num_robots
        q = self.state_0.joint_q.numpy().reshape(n, self.coords_per_robot)
        qd = self.state_0.joint_qd.numpy().reshape(n, self.dofs_per_robot)
        body_q = self.state_0.body_q.numpy()
        body_qd = self.state_0.body_qd.numpy()
        pelvis = np.arange(n) * self.bodies_per_robot
        wrench = self.sand_wrench.numpy()
        if self.frames_summed > 0:  # the mean over the frames since the last read, else this frame's
            wrench = self.sand_wrench_sum.numpy() / self.frames_summed
        self.sand_wrench_sum.zero_()
        self.frames_summed = 0
        return {"body_q": body_q, "base_q": body_q[pelvis].astype(np.float64),
                "base_qd": body_qd[pelvis].astype(np.float64), "jq": q[:, self.q_idx].astype(np.float64),
                "jqd": qd[:, self.qd_idx].astype(np.float64),
                "foot_force": wrench[self.foot_bodies][..., :3].astype(np.float64)}  # fmt: skip

    def observation_terms(self, st: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        """One frame of the mjlab velocity-task observation terms of every robot (no noise, scale 1), [R, d]."""
        quat = st["base_q"][:, 3:7]
        gravity = np.broadcast_to([0.0, 0.0, -1.0], (len(quat), 3))
        return {
            "base_ang_vel": quat_rotate_inv(quat, st["base_qd"][:, 3:6]),
            "projected_gravity": quat_rotate_inv(quat, gravity),
            "command": self.commands,
            "joint_pos": st["jq"] - self.spec.default_joint_pos,
            "joint_vel": st["jqd"],
            "actions": self.last_action,
        }

    def _log(self, st: dict[str, np.ndarray], target: np.ndarray) -> None:
        """Append one policy-rate sample of every robot."""
        corners = self._sole_corners(st["body_q"])
        surf = terrain_surface_height(self.cfg.terrain, corners[..., 0], corners[..., 1] - self.lane_y[:, None, None])
        self.base_q.append(st["base_q"])
        self.base_qd.append(st["base_qd"])
        self.foot_force.append(st["foot_force"])
        depth = (surf - corners[..., 2]).max(axis=2)
        self.foot_sinkage.append(depth)
        self.sinkage.append(depth.max(axis=1))
        self.joint_q.append(st["jq"])
        self.joint_qd.append(st["jqd"])
        self.target.append(target)
        self.action.append(self.last_action.copy())
        self.eta.append(self._decoded_eta())
        low = needs_sand(corners, surf)
        self.sole_out.append(soles_outside(corners, low, self.window.frames()))
        self.sole_reach.append(sole_reach(corners, low, st["base_q"]))

    def _decoded_eta(self) -> np.ndarray:
        """The student's decoded terrain stiffness after its last step, [R] (NaN for policies without one)."""
        eta = getattr(getattr(self.policy, "runner", None), "eta", None)
        if eta is None:
            return np.full(len(self.lane_y), np.nan)
        return np.asarray(eta, dtype=np.float64).reshape(len(self.lane_y), -1)[:, 0]

    def reset_robots(self, robots: list[int], commands: list[tuple[float, float, float]], seeds: list[int]) -> None:
        """Start a new episode in each lane of ``robots``: start pose, at rest, new command, fresh sand.

        The robot goes back to its start pose at rest with its new command, its sand window is refilled with
        fresh sand (jitter seed offsets ``seeds``) and its policy history is forgotten. Call it between frames, right before a policy step (``frame % frames_per_policy == 0``): the next
        :meth:`step` logs the new episode's first sample. Other robots are untouched.
        """
        import newton
        import warp as wp

        if not robots:
            return
        if not (len(robots) == len(commands) == len(seeds)):
            raise ValueError(f"reset_robots: {len(robots)} robots, {len(commands)} commands, {len(seeds)} seeds")
        nq, nd = self.coords_per_robot, self.dofs_per_robot
        for st in (self.state_0, self.state_1):
            q, qd = st.joint_q.numpy(), st.joint_qd.numpy()
            for r in robots:
                q[r * nq : (r + 1) * nq] = self._q_init[r * nq : (r + 1) * nq]
                qd[r * nd : (r + 1) * nd] = 0.0
            st.joint_q.assign(q)
            st.joint_qd.assign(qd)
            newton.eval_fk(self.model, st.joint_q, st.joint_qd, st,
                           indices=wp.array(robots, dtype=int, device=self.device))  # fmt: skip
        nb = self.bodies_per_robot
        wrenches = (self.sand_wrench, self.sand_wrench_sum, self.sand_wrench_last)
        held = [w.numpy() for w in wrenches]  # the old episode's forces are not the new one's
        targets = self.targets.numpy()
        for r, cmd in zip(robots, commands, strict=True):
            for h in held:
                h[r * nb : (r + 1) * nb] = 0.0
            targets[r] = self.spec.default_joint_pos
            self.last_action[r] = 0.0
            self.commands[r] = cmd
        for w, h in zip(wrenches, held, strict=True):
            w.assign(h)
        self.targets.assign(targets)
        if self.policy is not None:
            self.policy.reset(robots)
        self.window.reseed_lanes(list(robots), list(seeds), self.state_0.body_q)

    def retire_robots(self, robots: list[int]) -> None:
        """Take the sand of ``robots``' lanes out of the MPM solve: lanes with no episode left stop costing.

        Their robots lose their support and keep stepping unscored; the other lanes are untouched (their sand never
        shares a grid cell with a retired lane's). :meth:`reset_robots` brings a lane back. Between frames only.
        """
        self.window.set_lanes_active(list(robots), False)

    # -- stepping -------------------------------------------------------------------------------------------

    def simulate(self) -> None:
        """One frame: PD + rigid substeps with the lagged sand wrench, window advance, one coupled MPM step."""
        import warp as wp

        from gmloco.eval.mpm.kernels_coupling import (
            accumulate_sand_wrench,
            eval_body_sand_wrench,
            eval_pd_joint_force,
            hand_over_velocity,
            mean_of_two_wrenches,
        )

        for _ in range(self.cfg.solver.rigid_substeps):
            eval_pd_joint_force(self.pd["kp"], self.pd["kd"], self.pd["q_idx"], self.pd["qd_idx"],
                                self.coords_per_robot, self.dofs_per_robot, self.state_0.joint_q,
                                self.state_0.joint_qd, self.targets, self.control.joint_f)  # fmt: skip
            self.state_0.clear_forces()
            wp.copy(self.state_0.body_f, self.sand_wrench)
            self.rigid.step(self.state_0, self.state_1, self.control, self.contacts, self.sim_dt)
            self.state_0, self.state_1 = self.state_1, self.state_0
        if self.cfg.solver.rigid_substeps % 2:
            self._restore_state_parity()
        self.window.advance(self.state_0.body_q)
        wp.copy(self.sand_state.body_q, self.state_0.body_q, count=self.wall_body_offset)
        if self.cfg.wall_colliders:
            self.window.place_walls(self.wall_body_offset, self.sand_state.body_q, self.sand_state.body_qd)
        hand_over_velocity(
            self.cfg.solver.velocity_handover, self.gravity, self.eff_inv_mass, self.eff_inv_inertia,
            self.frame_dt, self.state_0.body_q, self.state_0.body_qd, self.sand_wrench, self.sand_state.body_qd,
        )  # fmt: skip
        self.mpm.step(self.sand_state, self.sand_state, None, None, self.frame_dt)
        self.window.apply_walls()
        two = self.cfg.wrench_frames == 2
        eval_body_sand_wrench(
            self.mpm.collider_body_index, self.model.body_com, self.frame_dt,
            self.mpm.collect_collider_impulses(self.sand_state), self.sand_state.body_q,
            self.sand_wrench_raw if two else self.sand_wrench,
        )  # fmt: skip
        if two:  # the robots receive the mean of this frame's and the last frame's wrench
            mean_of_two_wrenches(self.sand_wrench_raw, self.sand_wrench_last, self.sand_wrench)
            wp.copy(self.sand_wrench_last, self.sand_wrench_raw)
        accumulate_sand_wrench(self.sand_wrench, self.sand_wrench_sum)

    def _restore_state_parity(self) -> None:
        """After an odd number of substeps, move the newest rigid state back into the frame's first State object.

        The substeps ping-pong between two States; an odd count would leave the newest one in the other object, so
        consecutive frames would swap buffers, which a captured CUDA graph (fixed buffers) cannot follow. Copying the
        integrated fields back makes every frame start and end on the same objects; the values are unchanged.
        """
        import warp as wp

        for name in ("joint_q", "joint_qd", "body_q", "body_qd"):
            src, dst = getattr(self.state_0, name), getattr(self.state_1, name)
            if src is not None and dst is not None:
                wp.copy(dst, src)
        self.state_0, self.state_1 = self.state_1, self.state_0

    def capture(self) -> None:
        """Capture one frame as a CUDA graph (fixed-capacity grid, CUDA only; else eager)."""
        import warp as wp

        s = self.cfg.solver
        fixed = s.grid_type == "fixed" or (s.grid_type == "sparse" and s.max_active_cell_count > 0)
        if not (self.cfg.use_cuda_graph and self.device.is_cuda and fixed):
            return
        self.simulate()  # warm-up: lazily built inner graphs and kernels
        try:
            with wp.ScopedDevice(self.device), wp.ScopedCapture() as cap:
                self.simulate()
            self.graph = cap.graph
        except Exception as exc:  # a step that cannot be captured still runs eagerly; the reason is kept
            self.graph, self.capture_error = None, repr(exc)
        self.sand_wrench_sum.zero_()  # the warm-up frame is not a logged frame

    def step(self) -> None:
        """Advance one frame; at the policy rate log every robot and set new PD targets first."""
        import warp as wp

        t0 = time.perf_counter()
        if self.frame % self.frames_per_policy == 0:
            st = self._read_state()
            target = self.targets.numpy().astype(np.float64)
            if self.policy is not None:
                heading = quat_wxyz_to_roll_pitch_yaw(st["base_q"][:, [6, 3, 4, 5]])[:, 2]
                self.last_action = self.policy.act(self.observation_terms(st), heading).astype(np.float64)
                target = self.spec.default_joint_pos + self.spec.action_scale * self.last_action
                self.targets.assign(target.astype(np.float32))
            self._log(st, target)
        if self.graph is not None:
            wp.capture_launch(self.graph)
        else:
            self.simulate()
        self.frames_summed += 1
        self.wall_time += time.perf_counter() - t0
        self.frame += 1

    def sync(self) -> None:
        """Wait for the frames in flight and count the wait as stepping time (``wall_time``).

        ``step`` returns once a frame is launched; the GPU runs it while the host goes on. A host call that waits
        for the device outside ``step`` (the grid-capacity check, reading a result) would otherwise take up to
        ``frames_per_policy`` frames of GPU time off the scene's clock (the square-window runs: ~8 % at 4.4M particles).
        """
        import warp as wp

        t0 = time.perf_counter()
        wp.synchronize_device(self.device)
        self.wall_time += time.perf_counter() - t0

    def run(self, num_frames: int) -> None:
        """Step ``num_frames`` frames (graph captured first when possible), then wait for the last ones."""
        if self.graph is None and self.frame == 0:
            self.capture()
        for _ in range(num_frames):
            self.step()
        self.sync()

    @property
    def frames_per_second(self) -> float:
        """Simulated frames per wall-clock second (construction and capture excluded)."""
        return self.frame / max(self.wall_time, 1e-9)

    def support_ratio(self, skip: float = 0.5) -> np.ndarray:
        """Mean vertical sand force on both feet after the first ``skip`` fraction of samples, over m g, [R]."""
        f = np.asarray(self.foot_force)[:, :, :, 2].sum(axis=2)
        return f[int(len(f) * skip) :].mean(axis=0) / (self.robot_mass * 9.81)

    def test_final(self) -> None:
        """Finite state, pelvises up, soles not through the bed, sand above the floor."""
        q = np.asarray(self.base_q[-1])
        assert np.all(np.isfinite(q)), "robot state is not finite"
        assert np.all(q[:, 2] > 0.3), f"a pelvis fell (z = {q[:, 2]})"
        # a sole resting on the rigid floor sits up to a few mm into it (MuJoCo's soft contact)
        assert np.all(self.sinkage[-1] < self.cfg.terrain.depth + 0.01), "a foot went through the floor"
        z = self.sand_state.particle_q.numpy()[:, 2]
        assert np.all(np.isfinite(z)) and np.all(z > -self.cfg.terrain.depth - 2 * self.cfg.solver.voxel_size)
