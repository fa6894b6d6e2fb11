# SPDX-License-Identifier: Apache-2.0
"""MPM box scene: a rigid box (Newton + MuJoCo) coupled two-way with an implicit-MPM sand bed.

Coupling (semi-implicit, one MPM step per frame): the rigid solver integrates the box over ``rigid_substeps``
with the sand wrench of the previous frame; MPM then sees the box with that wrench's velocity change removed
and solves the frictional contact implicitly against the box's mass and inertia (the body is a *dynamic*
collider, ``SolverImplicitMPM.setup_collider(model=..)``); the collider-node impulses of that step divided by
the frame time are the new sand wrench. Pattern learnt from Newton's ``example_mpm_twoway_coupling``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from gmloco.eval.box import BoxCfg
from gmloco.eval.mpm.bed import SandBedCfg, add_bed_container
from gmloco.eval.mpm.coupled_setup import build_sand_model, make_coupled_states, make_mpm_solver
from gmloco.eval.mpm.materials import GranularMaterial, MpmMaterialCfg, mpm_material

__all__ = ["MIN_RHEOLOGY_ITERATIONS", "MpmBoxScene", "MpmBoxSceneCfg", "MpmSolverCfg"]

MIN_RHEOLOGY_ITERATIONS = 25
"""Newton 1.5.2's Gauss-Seidel ``solve_granularity``: the eager solver loop runs ``max_iterations // 25`` batches."""


@dataclass(frozen=True)
class MpmSolverCfg:
    """Numerics of ``SolverImplicitMPM`` (names as in ``SolverImplicitMPM.Config``)."""

    voxel_size: float = 0.05
    """Grid voxel size [m]; choose it by the convergence check (README)."""
    frame_dt: float = 0.01
    """MPM step = frame time [s] (100 Hz as Newton's coupled example)."""
    rigid_substeps: int = 4
    """Rigid-solver substeps per frame."""
    max_iterations: int = 50
    """Rheology solver iterations per step. Without a CUDA graph Newton runs ``max_iterations // 25`` batches of 25
    Gauss-Seidel sweeps, so fewer than 25 means *no* solve at all: no collider acts (issue 5's zero plate force)."""
    tolerance: float = 1.0e-4
    """Rheology solver tolerance."""
    grid_type: Literal["sparse", "dense", "fixed"] = "sparse"
    """Grid type; ``"fixed"`` allows CUDA graph capture (set ``max_active_cell_count``)."""
    grid_padding: int = 0
    """Empty cells around the particles (fixed grids only)."""
    max_active_cell_count: int = -1
    """Active-cell capacity; raise it at fine voxels or the fixed grid overflows (issue 5 timings)."""
    strain_basis: str = "P0"
    """Strain basis (Newton's coupled example: P0)."""

    def __post_init__(self) -> None:
        """Refuse settings under which Newton's eager (CPU / no-graph) rheology loop would not iterate."""
        if self.max_iterations < MIN_RHEOLOGY_ITERATIONS:
            raise ValueError(
                f"max_iterations={self.max_iterations}: SolverImplicitMPM runs max_iterations // "
                f"{MIN_RHEOLOGY_ITERATIONS} Gauss-Seidel batches without a CUDA graph, so below "
                f"{MIN_RHEOLOGY_ITERATIONS} no contact or rheology solve happens (sand falls through every collider)"
            )


@dataclass(frozen=True)
class MpmBoxSceneCfg:
    """Box-on-sand MPM scene."""

    box: BoxCfg = field(default_factory=BoxCfg)
    """The intruder."""
    bed: SandBedCfg = field(default_factory=SandBedCfg)
    """The sand bed (surface at z = 0)."""
    solver: MpmSolverCfg = field(default_factory=MpmSolverCfg)
    """MPM numerics."""
    device: str | None = None
    """Warp device; None = Warp's default."""
    use_cuda_graph: bool = True
    """Capture one frame in a CUDA graph when the device is CUDA and the grid is fixed."""
    rigid_solver: Literal["mujoco", "semi_implicit"] = "mujoco"
    """Integrator of the free box: ``"mujoco"`` (SolverMuJoCo: MuJoCo C on CPU, mujoco_warp on CUDA) or
    ``"semi_implicit"`` (Newton's SolverSemiImplicit, no angular damping): the box has no joints or rigid
    contacts, so both integrate the same Newton-Euler equations; the latter builds in milliseconds on a GPU."""


class MpmBoxScene:
    """Example-shaped scene (``__init__``, ``capture``, ``step``, ``test_final``) with per-frame logging.

    Attributes:
        body_q: Box pose (p, q_xyzw) after each frame, list of [7].
        body_qd: Box (linear, angular) velocity after each frame [m/s, rad/s], list of [6].
        sand_force: Sand force on the box of each frame [N], list of [3].
        particle_count: Number of MPM particles.
    """

    def __init__(self, cfg: MpmBoxSceneCfg, material: GranularMaterial | MpmMaterialCfg) -> None:
        """Build the rigid model, the sand model, both solvers and the coupling buffers."""
        import newton
        import warp as wp

        self.cfg = cfg
        self.mat = material if isinstance(material, MpmMaterialCfg) else mpm_material(material)
        self.device = wp.get_device(cfg.device)
        s = cfg.solver
        self.frame_dt, self.sim_dt = s.frame_dt, s.frame_dt / s.rigid_substeps
        with wp.ScopedDevice(self.device):
            self.model = self._build_rigid_model(newton, wp)
            self.sand_model, self.particle_count = build_sand_model(
                newton, self.cfg.bed, self.cfg.solver.voxel_size, self.mat
            )
            self._build_solvers(newton)
            self._allocate_states(newton, wp)
        self.frame = 0
        self.wall_time = 0.0
        self.body_q: list[np.ndarray] = []
        self.body_qd: list[np.ndarray] = []
        self.sand_force: list[np.ndarray] = []
        self.graph = None
        self.capture()

    # -- construction ---------------------------------------------------------------------------------------

    def _build_rigid_model(self, newton: Any, wp: Any) -> Any:
        """Box body (uniform density, mu = mu_surf) plus the static bed container."""
        box = self.cfg.box
        hx, hy, hz = (float(v) for v in box.half_extents)
        builder = newton.ModelBuilder()
        q = box.initial_quat_wxyz
        body = builder.add_body(
            xform=wp.transform(wp.vec3(*box.initial_pos), wp.quat(q[1], q[2], q[3], q[0])), label="box"
        )
        density = float(box.mass / (8.0 * hx * hy * hz))
        shape_cfg = newton.ModelBuilder.ShapeConfig(density=density, mu=float(self.mat.collider_friction))
        builder.add_shape_box(body, hx=float(hx), hy=float(hy), hz=float(hz), cfg=shape_cfg)
        add_bed_container(builder, self.cfg.bed, friction=self.mat.friction)
        model = builder.finalize()
        # initial velocity through the free joint (linear part first), then forward kinematics
        qd = model.joint_qd.numpy()
        qd[0:3] = box.initial_velocity
        model.joint_qd.assign(qd)
        self.box_body = body
        return model

    def _build_solvers(self, newton: Any) -> None:
        """Implicit MPM reading its colliders (box + container) from the rigid model; MuJoCo for the box."""
        self.mpm = make_mpm_solver(newton, self.sand_model, self.cfg.solver, self.mat)
        self.mpm.setup_collider(model=self.model)
        if self.cfg.rigid_solver == "semi_implicit":
            # no rigid contacts in the model's collision pipeline: step() gets contacts=None
            self.rigid = newton.solvers.SolverSemiImplicit(self.model, angular_damping=0.0)
            return
        # no rigid contacts: the box touches only sand (MuJoCo C on CPU, mujoco_warp on CUDA)
        self.rigid = newton.solvers.SolverMuJoCo(
            self.model, use_mujoco_cpu=not self.device.is_cuda, use_mujoco_contacts=False, njmax=16, nconmax=16
        )

    def _allocate_states(self, newton: Any, wp: Any) -> None:
        """Rigid states, the sand state (sharing body arrays) and the wrench buffers."""
        st = make_coupled_states(newton, wp, self.model, self.sand_model)
        self.state_0, self.state_1, self.control = st.state_0, st.state_1, st.control
        self.sand_state, self.sand_wrench = st.sand_state, st.sand_wrench

    # -- stepping -------------------------------------------------------------------------------------------

    def capture(self) -> None:
        """Capture one frame as a CUDA graph (fixed grid on CUDA only; CPU runs eagerly)."""
        import warp as wp

        if not (self.cfg.use_cuda_graph and self.device.is_cuda and self.cfg.solver.grid_type == "fixed"):
            return
        self.simulate()  # warm-up: lazily built inner graphs and kernels
        with wp.ScopedDevice(self.device), wp.ScopedCapture() as capture:
            self.simulate()
        self.graph = capture.graph

    def simulate(self) -> None:
        """Advance one frame: rigid substeps with the lagged sand wrench, then one coupled MPM step."""
        import warp as wp

        from gmloco.eval.mpm.kernels_coupling import eval_body_sand_wrench, eval_rewind_body_velocity

        for _ in range(self.cfg.solver.rigid_substeps):
            self.state_0.clear_forces()
            wp.copy(self.state_0.body_f, self.sand_wrench)
            self.rigid.step(self.state_0, self.state_1, self.control, None, self.sim_dt)
            self.state_0, self.state_1 = self.state_1, self.state_0
        # MPM sees the box pose and its velocity without the lagged wrench, and re-solves the contact
        wp.copy(self.sand_state.body_q, self.state_0.body_q)
        eval_rewind_body_velocity(
            self.model.body_inv_mass, self.model.body_inv_inertia, self.frame_dt, self.state_0.body_q,
            self.state_0.body_qd, self.sand_wrench, self.sand_state.body_qd,
        )  # fmt: skip
        self.mpm.step(self.sand_state, self.sand_state, None, None, self.frame_dt)
        eval_body_sand_wrench(
            self.mpm.collider_body_index, self.model.body_com, self.frame_dt,
            self.mpm.collect_collider_impulses(self.sand_state), self.sand_state.body_q, self.sand_wrench,
        )  # fmt: skip

    def step(self) -> None:
        """Advance one frame (graph replay when captured) and log the box state and sand force."""
        import warp as wp

        t0 = time.perf_counter()
        if self.graph is not None:
            wp.capture_launch(self.graph)
        else:
            self.simulate()
        wrench = self.sand_wrench.numpy()[self.box_body]
        self.wall_time += time.perf_counter() - t0
        self.frame += 1
        self.body_q.append(self.state_0.body_q.numpy()[self.box_body].copy())
        self.body_qd.append(self.state_0.body_qd.numpy()[self.box_body].copy())
        self.sand_force.append(np.asarray(wrench[:3], dtype=np.float64))

    def run(self, num_frames: int | None = None) -> None:
        """Step ``num_frames`` frames (default: the box's ``duration``)."""
        n = num_frames if num_frames is not None else round(self.cfg.box.duration / self.frame_dt)
        for _ in range(n):
            self.step()

    @property
    def frames_per_second(self) -> float:
        """Simulated frames per wall-clock second [1/s] (graph capture and construction excluded)."""
        return self.frame / max(self.wall_time, 1e-9)

    def test_final(self) -> None:
        """Assert physical sanity: finite state, box above the floor, sand inside the container."""
        q = np.asarray(self.body_q[-1])
        assert np.all(np.isfinite(q)), "box state is not finite"
        assert q[2] > -self.cfg.bed.depth, f"box fell through the bed (z = {q[2]:.3f} m)"
        z = self.sand_state.particle_q.numpy()[:, 2]
        assert np.all(z > -self.cfg.bed.depth - 2 * self.cfg.solver.voxel_size), "sand leaked through the floor"
