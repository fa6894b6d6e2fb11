# SPDX-License-Identifier: Apache-2.0
"""Couple a granular foot-contact model to MuJoCo Warp through the passive-force callback.

Every physics substep, inside ``mjwarp.fwd_velocity`` (after kinematics and ``cvel``, before
``xfrc_applied`` is mapped to joint space), :meth:`ContactCoupling.passive` runs three launches:

1. gather the pose, origin velocity and CoM of each foot body into preallocated ``[W, F]`` arrays;
2. ``model.compute(...)`` writes one ``(force, torque about CoM)`` wrench per foot;
3. scatter the wrenches into ``d.xfrc_applied`` of the foot bodies.

The callback also runs in ``sim.forward()``, so it is stateless; stateful models advance their
state once per substep in :meth:`ContactCoupling.after_substep`, wrapped around ``sim.step``.
Nothing is allocated after construction, so CUDA-graph capture (``sim.create_graph()``) holds.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Protocol

import torch
import warp as wp

from gmloco.train.kernels_coupling import launch_gather_foot_state, launch_scatter_foot_wrench

if TYPE_CHECKING:
    from mjlab.sim.sim import Simulation

__all__ = ["ContactCoupling", "FootWrenchModel"]


class FootWrenchModel(Protocol):
    """What the coupling needs from a contact model (``gmloco.contact.ContactModel`` satisfies it)."""

    def compute(
        self,
        foot_pos_w: wp.array,
        foot_mat_w: wp.array,
        foot_lin_vel_w: wp.array,
        foot_ang_vel_w: wp.array,
        foot_com_w: wp.array,
        wrench_out: wp.array,
    ) -> None:
        """Write the wrench on each foot, ``[W, F]`` spatial vectors (force, torque about CoM)."""
        ...

    def update_state(
        self,
        foot_pos_w: wp.array,
        foot_mat_w: wp.array,
        foot_lin_vel_w: wp.array,
        foot_ang_vel_w: wp.array,
        foot_com_w: wp.array,
    ) -> None:
        """Advance internal state once per physics substep."""
        ...


class ContactCoupling:
    """Owns the foot-state and wrench buffers and installs the passive callback on a simulation.

    Args:
        model: Contact model computing foot wrenches from foot state.
        sim: mjlab simulation (its ``wp_model`` / ``wp_data`` are MuJoCo Warp objects).
        foot_body_ids: Global MuJoCo body ids of the feet, length ``F``.
        stateful: Whether ``model.update_state`` must run after every substep.
    """

    def __init__(
        self, model: FootWrenchModel, sim: Simulation, foot_body_ids: Sequence[int], stateful: bool = True
    ) -> None:
        self.model = model
        self.sim = sim
        self.stateful = stateful
        device = sim.wp_device
        shape = (sim.num_envs, len(foot_body_ids))
        self.foot_bodyid = wp.array(list(foot_body_ids), dtype=int, device=device)
        self.foot_pos_w = wp.zeros(shape, dtype=wp.vec3, device=device)
        """Foot body origin position [m], world frame, shape [W, F]."""
        self.foot_mat_w = wp.zeros(shape, dtype=wp.mat33, device=device)
        """Foot body-to-world rotation, shape [W, F]."""
        self.foot_lin_vel_w = wp.zeros(shape, dtype=wp.vec3, device=device)
        """Linear velocity of the foot body origin [m/s], world frame, shape [W, F]."""
        self.foot_ang_vel_w = wp.zeros(shape, dtype=wp.vec3, device=device)
        """Foot angular velocity [rad/s], world frame, shape [W, F]."""
        self.foot_com_w = wp.zeros(shape, dtype=wp.vec3, device=device)
        """Foot body CoM position [m], world frame, shape [W, F]."""
        self.wrench = wp.zeros(shape, dtype=wp.spatial_vectorf, device=device)  # = wp.spatial_vector, typed as a class
        """Granular wrench (force [N], torque about CoM [N m]), world frame, shape [W, F]."""
        self.wrench_torch = wp.to_torch(self.wrench).view(*shape, 6)
        """Zero-copy torch view of :attr:`wrench`, shape [W, F, 6]."""
        self._sim_step: Callable[[], None] | None = None
        self._state_graph: wp.Graph | None = None

    @property
    def foot_state(self) -> tuple[wp.array, wp.array, wp.array, wp.array, wp.array]:
        """The five gathered foot-state arrays in ``model.compute`` order."""
        return (self.foot_pos_w, self.foot_mat_w, self.foot_lin_vel_w, self.foot_ang_vel_w, self.foot_com_w)

    @property
    def foot_force_w(self) -> torch.Tensor:
        """Granular force on each foot [N], world frame, shape [W, F, 3] (torch view)."""
        return self.wrench_torch[..., :3]

    def passive(self, m: object, d: object) -> None:
        """MuJoCo Warp passive callback: gather, compute, scatter (three launches)."""
        launch_gather_foot_state(m, d, self.foot_bodyid, self.foot_state)
        self.model.compute(*self.foot_state, self.wrench)
        launch_scatter_foot_wrench(d, self.foot_bodyid, self.wrench)

    def after_substep(self) -> None:
        """Advance the model state from the foot state the last substep's force was computed at."""
        if self._state_graph is not None:
            wp.capture_launch(self._state_graph)
        else:
            self.model.update_state(*self.foot_state)

    def install(self) -> None:
        """Set the passive callback, wrap ``sim.step`` for the state update, re-capture graphs."""
        sim = self.sim
        sim.wp_model.callback.passive = self.passive
        if self.stateful and self._sim_step is None:
            self._sim_step = sim.step
            sim.step = self._step  # type: ignore[method-assign]
            if sim.use_cuda_graph:
                with wp.ScopedDevice(sim.wp_device), wp.ScopedCapture() as capture:
                    self.model.update_state(*self.foot_state)
                self._state_graph = capture.graph
        sim.create_graph()

    def _step(self) -> None:
        """One physics substep followed by the model-state update."""
        assert self._sim_step is not None
        self._sim_step()
        with wp.ScopedDevice(self.sim.wp_device):
            self.after_substep()
