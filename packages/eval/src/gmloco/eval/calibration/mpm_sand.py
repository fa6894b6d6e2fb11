# SPDX-License-Identifier: Apache-2.0
"""Newton implicit-MPM sand for the sole experiments: a kinematic G1 sole box on a walled bed.

The sole is a *kinematic* collider body (zero effective mass: its motion is prescribed), as the plate intrusions of
:mod:`gmloco.eval.rft_fit.plate`; the force of the sand on it is the sum of its collider-node impulses divided by the
frame time (``kernels_coupling.eval_body_sand_wrench``). The bed, material mapping and solver are the evaluation's
(:mod:`gmloco.eval.mpm`), so the calibration measures the same sand the policies are judged on.

Torque: the MPM coupling exposes per-node impulses and their grid-node positions, and ``eval_body_sand_wrench`` sums
them into the body wrench (force, torque about the body's CoM, world axes). The sand reports that torque moved to the
sole-box centre, tau_c = tau_com + (x_com - x_c) x F; the sole's CoM is its body origin (the box centre), so the
shift is zero in practice. The lever arms are those of the collider's grid nodes, so the torque carries the grid's
resolution (one voxel) in its arm. The twist experiment's yaw torque on MPM sand is a GPU run::

    python -m gmloco.eval.calibration --material basalt --experiments twist --device cuda:0 --out <folder>
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from gmloco.eval.calibration.protocol import SoleProtocolCfg
from gmloco.eval.mpm.bed import SandBedCfg, add_bed_container
from gmloco.eval.mpm.box_scene import MpmSolverCfg, emit_bed_particles
from gmloco.eval.mpm.coupled_setup import make_mpm_solver
from gmloco.eval.mpm.materials import GranularMaterial, apply_mpm_material, mpm_material

__all__ = ["MpmSoleSand", "MpmSoleSandCfg", "mpm_sole_smoke_cfg"]


@dataclass(frozen=True)
class MpmSoleSandCfg:
    """Bed and numerics of the MPM sole experiments."""

    bed: SandBedCfg = field(default_factory=lambda: SandBedCfg(size_x=0.6, size_y=0.4, depth=0.3, center_x=0.0))
    """Sand bed (surface z = 0), centred under the sole; 0.6 x 0.4 m leaves > 0.15 m of sand around a 0.1 m drag."""
    solver: MpmSolverCfg = field(default_factory=lambda: MpmSolverCfg(voxel_size=0.02, max_iterations=250))
    """MPM numerics (``frame_dt`` is overridden by the protocol's frame time)."""
    device: str | None = None
    """Warp device; None = Warp's default."""


def mpm_sole_smoke_cfg() -> MpmSoleSandCfg:
    """Return a tiny CPU configuration (a 0.3 x 0.2 x 0.08 m bed at 4 cm voxels): runs end to end, not physics."""
    return MpmSoleSandCfg(
        bed=SandBedCfg(size_x=0.3, size_y=0.2, depth=0.08, center_x=0.0),
        solver=MpmSolverCfg(voxel_size=0.04, max_iterations=25),
        device="cpu",
    )


class MpmSoleSand:
    """A fresh MPM bed with one kinematic sole; call it once per frame (:data:`~.protocol.SoleSand`).

    Attributes:
        particle_count: MPM particles.
        build_s: Construction wall time [s].
        step_s: Accumulated stepping wall time [s].
    """

    def __init__(self, cfg: MpmSoleSandCfg, protocol: SoleProtocolCfg, material: GranularMaterial) -> None:
        """Build the collider model (sole + container), the bed and the solver."""
        import newton
        import warp as wp

        t0 = time.perf_counter()
        self.cfg, self.protocol = cfg, protocol
        self.mat = mpm_material(material)
        self.dt = protocol.frame_dt
        self.wp = wp
        with wp.ScopedDevice(wp.get_device(cfg.device)):
            builder = newton.ModelBuilder()
            half = [0.5 * s for s in protocol.sole_size]
            shape = newton.ModelBuilder.ShapeConfig(density=0.0, mu=float(self.mat.collider_friction))
            start = wp.transform(wp.vec3(0.0, 0.0, half[2] + protocol.start_gap), wp.quat_identity())
            self.body = builder.add_body(xform=start, is_kinematic=True, label="sole")
            builder.add_shape_box(self.body, hx=half[0], hy=half[1], hz=half[2], cfg=shape)
            add_bed_container(builder, cfg.bed, friction=self.mat.friction)
            self.colliders = builder.finalize()
            sand = newton.ModelBuilder()
            newton.solvers.SolverImplicitMPM.register_custom_attributes(sand)
            self.particle_count = emit_bed_particles(sand, cfg.bed, cfg.solver.voxel_size, self.mat.density)
            model = sand.finalize()
            apply_mpm_material(model, self.mat)
            self.mpm = make_mpm_solver(newton, model, cfg.solver, self.mat)
            self.mpm.setup_collider(model=self.colliders)
            self.state = model.state()
            self.body_q = wp.clone(self.colliders.body_q)  # pyright: ignore[reportArgumentType]
            """Collider poses (p, q_xyzw), the MPM state's ``body_q``."""
            self.body_qd = wp.zeros(self.colliders.body_count, dtype=wp.spatial_vectorf)
            """Collider velocities (linear, angular), the MPM state's ``body_qd``."""
            self.state.body_q, self.state.body_qd = self.body_q, self.body_qd
            self.wrench = wp.zeros(self.colliders.body_count, dtype=wp.spatial_vectorf)
            self.body_com = np.asarray(self.colliders.body_com.numpy()[self.body], dtype=np.float64)  # pyright: ignore[reportOptionalMemberAccess]
            """The sole's CoM in its body frame [m], [3] (the wrench's torque is about it)."""
        self.build_s = time.perf_counter() - t0
        self.step_s = 0.0

    def __call__(self, pos: np.ndarray, rot: np.ndarray, lin_vel: np.ndarray, ang_vel: np.ndarray) -> np.ndarray:
        """Step one frame with the sole at (pos, rot) moving at (lin_vel, ang_vel); return the sand wrench [6].

        The wrench is the force [N] and the torque about the sole-box centre ``pos`` [N m], world axes.
        """
        from gmloco.eval.mpm.kernels_coupling import eval_body_sand_wrench
        from gmloco.eval.rft_fit.plate import _quat_xyzw

        wp = self.wp
        t0 = time.perf_counter()
        q = self.body_q.numpy()
        qd = self.body_qd.numpy()
        q[self.body, :3], q[self.body, 3:] = pos, _quat_xyzw(rot)
        qd[self.body, :3], qd[self.body, 3:] = lin_vel, ang_vel
        with wp.ScopedDevice(wp.get_device(self.cfg.device)):
            self.body_q.assign(q)
            self.body_qd.assign(qd)
            # Newton annotates control/contacts as required; SolverImplicitMPM.step documents both as unused
            self.mpm.step(self.state, self.state, None, None, self.dt)  # pyright: ignore[reportArgumentType]
            eval_body_sand_wrench(self.mpm.collider_body_index, self.colliders.body_com, self.dt,  # pyright: ignore[reportArgumentType]
                                  self.mpm.collect_collider_impulses(self.state), self.body_q,
                                  self.wrench)  # fmt: skip
        wrench = np.asarray(self.wrench.numpy()[self.body], dtype=np.float64)
        force = wrench[:3]
        torque = wrench[3:] + np.cross(np.asarray(rot) @ self.body_com, force)  # about the CoM -> about the centre
        self.step_s += time.perf_counter() - t0
        return np.concatenate([force, torque])

    def check(self) -> None:
        """Raise if Newton's sparse grid ran out of capacity during the run."""
        self.mpm.check_sparse_grid_rebuild_status()
