# SPDX-License-Identifier: Apache-2.0
"""The sand bed of an env: contact model + coupling, per-env materials, floor curriculum state.

:class:`SandContact` is a class-based mjlab event term (mode ``"reset"``), so a task that lists it
runs unchanged under mjlab's own ``train``/``play`` scripts. Its constructor runs inside the event
manager's construction, before the rest of the managers and before mjlab re-captures CUDA graphs:
it builds the contact model, installs the passive callback and creates the
:class:`~gmloco.train.foot_contact.FootContactTracker`. On every reset it draws the materials of
the reset envs, places their hard floor at the depth of their curriculum level and clears the
model and tracker state. Other terms reach it as ``env.sand`` (see :func:`get_sand`).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import mujoco
import torch

from gmloco.deploy.g1 import G1_FOOT_BODIES, G1_FOOT_SITES
from gmloco.train.config import GranularTaskCfg, SandFloorCfg, SandTerrainCfg, contact_force_threshold
from gmloco.train.foot_contact import FootContactTracker, SurfaceHeightFn

if TYPE_CHECKING:
    from mjlab.envs import ManagerBasedRlEnv
    from mjlab.managers.event_manager import EventTermCfg

    from gmloco.train.contact_coupling import ContactCoupling
    from gmloco.train.contact_models import MaterialWriter

__all__ = [
    "FEET_FLOOR_SENSOR",
    "FOOT_BODIES",
    "FOOT_SITES",
    "SAND_FLOOR_BODY",
    "SandContact",
    "add_sand_floor",
    "floor_levels_for_depths",
    "get_sand",
    "make_surface_height",
]

SAND_FLOOR_BODY = "sand_floor"
"""Mocap body carrying the hard-floor plane; its per-env height is the terrain curriculum."""
FOOT_BODIES = G1_FOOT_BODIES
"""Robot bodies that receive the granular wrench (spec section 4)."""
FOOT_SITES = G1_FOOT_SITES
"""Sole sites of the G1 (3.7 cm below the ankle-roll origin)."""
FEET_FLOOR_SENSOR = "feet_floor_contact"
"""mjlab contact sensor between the foot bodies and the hard floor."""


def floor_levels_for_depths(depths: torch.Tensor, floor: SandFloorCfg) -> torch.Tensor:
    """The curriculum level of ``floor`` nearest to each floor depth [m] (clamped to the levels it has).

    A checkpoint keeps each env's floor depth beside its level, so a run resumed with another depth range or level
    count puts every env back at (nearly) the depth it had reached.
    """
    lo, hi = floor.depth_range
    top = max(floor.num_levels - 1, 0)
    if hi <= lo or top == 0:
        return torch.zeros_like(depths, dtype=torch.long)
    return torch.round((depths - lo) / (hi - lo) * top).long().clamp(0, top)


def add_sand_floor(spec: mujoco.MjSpec, feet_collide: bool) -> None:
    """Add the mocap hard-floor plane to a scene spec (a ``SceneCfg.spec_fn``).

    Args:
        spec: Scene spec after the robot was attached (bodies are prefixed ``robot/``).
        feet_collide: If False, the foot bodies are excluded from floor contact (pure granular
            support); other robot geoms still land on the floor.
    """
    body = spec.worldbody.add_body(name=SAND_FLOOR_BODY, mocap=True)
    body.add_geom(
        name=f"{SAND_FLOOR_BODY}_plane",
        type=mujoco.mjtGeom.mjGEOM_PLANE,
        size=[0.0, 0.0, 0.05],
        contype=1,
        conaffinity=1,
        rgba=[0.76, 0.70, 0.50, 1.0],
    )
    if not feet_collide:
        for foot in FOOT_BODIES:
            spec.add_exclude(bodyname1=SAND_FLOOR_BODY, bodyname2=f"robot/{foot}")


def make_surface_height(terrain: SandTerrainCfg) -> SurfaceHeightFn:
    """Return the free-surface height ``z_s(x, y) = a sin(k x) + a sin(k y)`` [m] (gmloco.contact sinusoid)."""
    amp, k = terrain.amplitude, 2.0 * math.pi / terrain.wavelength
    if amp == 0.0:
        return lambda x, y: torch.zeros_like(x)
    return lambda x, y: amp * (torch.sin(k * x) + torch.sin(k * y))


def get_sand(env: ManagerBasedRlEnv) -> SandContact:
    """Return the env's :class:`SandContact` (set when the event manager is built)."""
    return env.sand  # type: ignore[attr-defined]


class SandContact:
    """Class-based reset event owning the granular contact of one env batch.

    Args:
        cfg: The event term config; ``cfg.params["task"]`` is the :class:`GranularTaskCfg`.
        env: The environment under construction.
    """

    def __init__(self, cfg: EventTermCfg, env: ManagerBasedRlEnv) -> None:
        task: GranularTaskCfg = cfg.params["task"]
        self.task = task
        self.env = env
        self.num_envs, self.device = env.num_envs, env.device
        self.surface_height = make_surface_height(task.terrain)
        self.coupling: ContactCoupling | None = None
        self.model: Any = None
        self.materials: MaterialWriter | None = None
        self._eta = torch.ones(self.num_envs, device=self.device)
        if task.contact_model != "rigid":
            from gmloco.train.contact_models import MaterialWriter

            self.coupling = self._install_granular(env, task)
            self.model = self.coupling.model
            self.materials = MaterialWriter(self.model, task.material, self.device, task.rft_extension_ranges)
            self._eta = self.materials.eta
        threshold = contact_force_threshold(task)
        self.feet = FootContactTracker(
            env, self.coupling, FEET_FLOOR_SENSOR, FOOT_SITES, FOOT_BODIES, threshold, self.surface_height
        )
        self._init_floor(env, task)
        env.sand = self  # type: ignore[attr-defined]

    # Public signals.

    @property
    def eta(self) -> torch.Tensor:
        """Normalized granular stiffness eta per env [-], shape [W] (ones for rigid contact)."""
        return self._eta

    @property
    def floor_depth(self) -> torch.Tensor:
        """Depth of the hard floor below the free surface per env [m], shape [W]."""
        floor = self.task.terrain.floor
        lo, hi = floor.depth_range
        frac = self.floor_level.float() / max(floor.num_levels - 1, 1)
        return lo + (hi - lo) * frac

    # Checkpoint state.

    def state_dict(self) -> dict[str, torch.Tensor]:
        """What a checkpoint keeps of the sand: each env's floor-depth curriculum level and floor depth [m]."""
        return {"floor_level": self.floor_level.cpu(), "floor_depth": self.floor_depth.cpu()}

    def load_state_dict(self, state: dict[str, torch.Tensor]) -> None:
        """Restore :meth:`state_dict`'s floors; a checkpoint of another env count leaves the drawn levels.

        With the depths saved, each env gets the level of its own floor range nearest to the saved depth (the range
        or level count may have changed between chunks); an older checkpoint's bare levels are taken as they are.
        """
        depths = state.get("floor_depth")
        levels = state["floor_level"] if depths is None else floor_levels_for_depths(depths, self.task.terrain.floor)
        if levels.shape[0] == self.num_envs:
            self.floor_level.copy_(levels.to(self.device))

    # Event interface.

    def __call__(self, env: ManagerBasedRlEnv, env_ids: torch.Tensor | None, task: GranularTaskCfg) -> None:
        """Draw materials, place floors and clear contact state of the reset envs."""
        del task
        if env_ids is None:
            env_ids = torch.arange(self.num_envs, device=self.device)
        if self.materials is not None:
            from gmloco.train.contact_models import reset_model_state

            self.materials.draw(env_ids)
            reset_model_state(self.model, env_ids)
        self._place_floor(env_ids)
        self.feet.reset(env_ids)

    def reset(self, env_ids: torch.Tensor | None = None) -> None:
        """Event-manager reset hook (state is already cleared in ``__call__``)."""
        del env_ids

    # Construction helpers.

    def _install_granular(self, env: ManagerBasedRlEnv, task: GranularTaskCfg) -> ContactCoupling:
        """Build the granular contact model and hook it into the simulation."""
        from gmloco.train.contact_coupling import ContactCoupling
        from gmloco.train.contact_models import build_contact_model

        model, stateful = build_contact_model(task, env.num_envs, env.sim.wp_device)
        robot = env.scene["robot"]
        local_ids = robot.find_bodies(FOOT_BODIES, preserve_order=True)[0]
        body_ids = [int(robot.indexing.body_ids[i]) for i in local_ids]
        coupling = ContactCoupling(model, env.sim, body_ids, stateful=stateful)
        coupling.install()
        return coupling

    def _init_floor(self, env: ManagerBasedRlEnv, task: GranularTaskCfg) -> None:
        """Resolve the floor mocap id and draw initial curriculum levels."""
        body_id = mujoco.mj_name2id(env.sim.mj_model, mujoco.mjtObj.mjOBJ_BODY, SAND_FLOOR_BODY)
        self.floor_mocap_id = int(env.sim.mj_model.body_mocapid[body_id])
        floor = task.terrain.floor
        high = min(floor.max_init_level, floor.num_levels - 1) + 1
        self.floor_level = torch.randint(0, high, (self.num_envs,), device=self.device)
        if task.contact_model == "rigid":
            self.floor_level.zero_()

    # Reset helpers.

    def _place_floor(self, env_ids: torch.Tensor) -> None:
        """Write the floor height of ``env_ids`` into the mocap pose (after ``sim.reset``)."""
        depth = self.floor_depth[env_ids]
        mocap_pos = self.env.sim.data.mocap_pos
        mocap_pos[env_ids, self.floor_mocap_id, 2] = -depth
