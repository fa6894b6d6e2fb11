# SPDX-License-Identifier: Apache-2.0
"""Couple a granular foot-contact model to MuJoCo Warp through the passive-force callback.

Every physics substep, inside ``mjwarp.fwd_velocity`` (after kinematics and ``cvel``, before
``xfrc_applied`` is mapped to joint space), :meth:`ContactCoupling.passive` runs three launches:

1. gather the pose, origin velocity and CoM of each foot body into preallocated ``[W, F]`` arrays;
2. ``model.compute(...)`` writes one ``(force, torque about CoM)`` wrench per foot;
3. scatter the wrenches into ``d.xfrc_applied`` of the foot bodies.

The callback also runs in ``sim.forward()``, where it must leave the model state alone. Stateful models
advance their state once per substep, in one of two ways:

- one launch (default where the model has ``compute_and_update_state``): inside ``sim.step`` the callback
  calls ``model.compute_and_update_state(...)`` instead of ``compute``, which evaluates the forces from the old
  state and then advances it, with the same inputs; ``sim.forward()`` keeps calling ``compute``. With CUDA
  graphs the step graph is re-captured with the one-launch pass after every ``sim.create_graph()``;
- two launches: ``compute`` in the callback, then ``model.update_state(...)`` after ``sim.step``
  (:meth:`ContactCoupling.after_substep`), from the foot state gathered in that substep.

Both give the same trajectory and state (CPU test). Nothing is allocated after construction, so CUDA-graph
capture holds.
"""

from __future__ import annotations

import gc
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
        stateful: Whether the model state must advance once per substep.
        one_launch: Advance it inside the step's callback with ``model.compute_and_update_state`` (where the model
            has it and the integrator calls the callback once per step, i.e. not RK4); else ``update_state`` after
            the step.
    """

    def __init__(
        self,
        model: FootWrenchModel,
        sim: Simulation,
        foot_body_ids: Sequence[int],
        stateful: bool = True,
        one_launch: bool = True,
    ) -> None:
        import mujoco

        self.model = model
        self.sim = sim
        self.stateful = stateful
        rk4 = int(sim.mj_model.opt.integrator) == int(mujoco.mjtIntegrator.mjINT_RK4)
        self.one_launch = stateful and one_launch and not rk4 and hasattr(model, "compute_and_update_state")
        """Whether the state advances inside the step's callback (one launch) rather than after the step."""
        self._advance = False
        """True while ``sim.step`` runs (or its graph is captured) on the one-launch path."""
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
        self._sim_create_graph: Callable[[], None] | None = None
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
        """MuJoCo Warp passive callback: gather, compute (and advance the state inside a step), scatter."""
        launch_gather_foot_state(m, d, self.foot_bodyid, self.foot_state)
        if self._advance:
            self.model.compute_and_update_state(*self.foot_state, self.wrench)  # pyright: ignore[reportAttributeAccessIssue]
        else:
            self.model.compute(*self.foot_state, self.wrench)
        launch_scatter_foot_wrench(d, self.foot_bodyid, self.wrench)

    def after_substep(self) -> None:
        """Advance the model state from the foot state the last substep's force was computed at."""
        if self._state_graph is not None:
            wp.capture_launch(self._state_graph)
        else:
            self.model.update_state(*self.foot_state)

    def install(self) -> None:
        """Set the passive callback, wrap ``sim.step`` (and ``sim.create_graph``) for the state update, capture."""
        sim = self.sim
        sim.wp_model.callback.passive = self.passive
        if self.stateful and self._sim_step is None:
            self._sim_step = sim.step
            sim.step = self._step  # type: ignore[method-assign]
            if self.one_launch:
                self._sim_create_graph = sim.create_graph
                sim.create_graph = self._create_graph  # type: ignore[method-assign]
            elif sim.use_cuda_graph:
                with wp.ScopedDevice(sim.wp_device), wp.ScopedCapture() as capture:
                    self.model.update_state(*self.foot_state)
                self._state_graph = capture.graph
        sim.create_graph()

    def _create_graph(self) -> None:
        """``sim.create_graph()``, then the step graph re-captured with the one-launch contact pass.

        The simulation's own capture records ``compute`` in the step graph (the callback cannot tell a step from
        a forward pass); the forward and reset graphs keep it. The garbage collector is held off during the
        capture, as the simulation does, so no stale graph is finalised into the new one.
        """
        import mujoco_warp as mjwarp

        assert self._sim_create_graph is not None
        self._sim_create_graph()
        sim = self.sim
        if not sim.use_cuda_graph:
            return
        enabled = gc.isenabled()
        gc.disable()
        self._advance = True
        try:
            with wp.ScopedDevice(sim.wp_device), wp.ScopedCapture() as capture:
                mjwarp.step(sim.wp_model, sim.wp_data)
            sim.step_graph = capture.graph
        finally:
            self._advance = False
            if enabled:
                gc.enable()

    def _step(self) -> None:
        """One physics substep with the model-state update (inside it on the one-launch path, else after it)."""
        assert self._sim_step is not None
        if self.one_launch:
            self._advance = True  # read by the callback without a graph; the captured step graph has it built in
            try:
                self._sim_step()
            finally:
                self._advance = False
            return
        self._sim_step()
        with wp.ScopedDevice(self.sim.wp_device):
            self.after_substep()
