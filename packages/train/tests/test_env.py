# SPDX-License-Identifier: Apache-2.0
"""The G1 task builds and steps for every contact model; observation layout; standing on 3D-RFT sand."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
import torch
import warp as wp

from gmloco.train import g1_granular_task
from gmloco.train.tasks.g1_granular.observations_cfg import ACTOR_TERMS, CRITIC_EXTRA_TERMS

NUM_JOINTS = 29
ACTOR_FRAME = 3 + 3 + 3 + 3 * NUM_JOINTS  # ang vel, gravity, command, q, dq, last action = 96
CRITIC_DIM = ACTOR_FRAME + 3 + 2 + 2 + 6 + 2 + 1  # + lin vel, heights, contact, forces, air time, eta = 112


@pytest.mark.parametrize("contact_model", ["rigid", "rft3d", "heuristic_rft", "cone_single", "cone_multi"])
def test_env_builds_and_steps(make_env, contact_model: str) -> None:  # noqa: ANN001
    """Two envs build, reset and take three steps; observations and rewards are finite, groups as documented."""
    task = g1_granular_task(contact_model)  # type: ignore[arg-type]
    env = make_env(task, num_envs=2)
    obs, _ = env.reset()
    for _ in range(3):
        obs, reward, *_ = env.step(torch.zeros(2, NUM_JOINTS))
    om = env.observation_manager
    assert tuple(om.active_terms["actor"]) == ACTOR_TERMS
    assert tuple(om.active_terms["critic"]) == ACTOR_TERMS + CRITIC_EXTRA_TERMS
    assert obs["actor"].shape == (2, ACTOR_FRAME * task.policy_history_length)
    assert obs["critic"].shape == (2, CRITIC_DIM)
    assert env.action_manager.total_action_dim == NUM_JOINTS
    assert env.step_dt == pytest.approx(0.02) and env.physics_dt == pytest.approx(0.005)
    assert torch.isfinite(obs["actor"]).all() and torch.isfinite(obs["critic"]).all() and torch.isfinite(reward).all()
    sand = env.sand
    assert (sand.coupling is None) == (contact_model == "rigid")
    if sand.coupling is not None:
        eta = sand.eta.cpu().numpy()
        assert np.all((eta > 0.0) & (eta <= 1.0)), eta
        # Floor under each env sits at -depth(level) after the reset (mocap plane).
        floor_z = env.sim.data.mocap_pos[:, sand.floor_mocap_id, 2].cpu().numpy()
        np.testing.assert_allclose(floor_z, -sand.floor_depth.cpu().numpy(), atol=1e-6)


def test_standing_robot_sinks_as_rft_predicts(make_env) -> None:  # noqa: ANN001
    """A PD-held G1 on 3D-RFT dry sand carries its weight on the granular force and sinks to the static depth.

    Zero actions, no DR, no floor under the feet.

    Static prediction (spec 5.3): each flat sole carries W/2 = G_z xi A d, G_z = 0.8757 (spec 5.1 case A),
    xi = rho_c g f(mu_int) of dry sand, A = 0.206 x 0.0736 m^2 -> d ~ 7.8 mm for the 33 kg G1. The model's
    default collider also has side faces, so the tolerance is 20 %; the force check averages 0.2 s.
    """
    from gmloco.contact import MATERIAL_PRESETS, ContactRFT3DCfg
    from gmloco.contact.reference import rft3d_generic

    task = g1_granular_task("rft3d", play=True)
    task = replace(task, material=replace(task.material, preset="dry_sand"))
    task.terrain.floor.enabled = False
    env = make_env(task, num_envs=1)
    env.sand.model.point_outputs = True  # the per-point depths are read below (CPU: no captured graph to redo)
    env.reset()
    weight = float(env.sim.mj_model.body_subtreemass[env.scene["robot"].indexing.root_body_id] * 9.81)
    fz, depth = [], []
    sole = torch.as_tensor(env.sand.model.collider.normals[:, 2] < -0.5)  # the static prediction is for the sole
    for step in range(25):
        env.step(torch.zeros(1, NUM_JOINTS))
        if step >= 15:
            fz.append(env.sand.coupling.wrench_torch[0, :, 2].sum().item())
            depth.append(wp.to_torch(env.sand.model.point_depth)[0][:, sole].mean().item())  # mean sole depth
    cfg = ContactRFT3DCfg()
    g_z = rft3d_generic(np.array([[0.0, 0.0, -1.0]]), np.zeros((1, 3)), cfg.coeffs)[0, 2]
    area = np.diff(cfg.collider.x_range)[0] * np.diff(cfg.collider.y_range)[0]
    static = 0.5 * weight / (g_z * MATERIAL_PRESETS["dry_sand"].xi * area)
    np.testing.assert_allclose(np.mean(fz), weight, rtol=0.10)
    np.testing.assert_allclose(np.mean(depth), static, rtol=0.20)
    assert env.sand.feet.in_contact.all()


@pytest.mark.parametrize("terrain", ["rough", "deep"])
def test_rough_and_deep_terrains_step(make_env, terrain: str) -> None:  # noqa: ANN001
    """3D-RFT on the sinusoidal and the 30 cm deep bed: builds, steps, floors sit at the configured depth."""
    env = make_env(g1_granular_task("rft3d", terrain), num_envs=2)  # type: ignore[arg-type]
    env.reset()
    for _ in range(3):
        obs, reward, *_ = env.step(torch.zeros(2, NUM_JOINTS))
    assert torch.isfinite(obs["critic"]).all() and torch.isfinite(reward).all()
    floor_z = env.sim.data.mocap_pos[:, env.sand.floor_mocap_id, 2].cpu().numpy()
    if terrain == "deep":
        np.testing.assert_allclose(floor_z, -0.30, atol=1e-6)
    assert env.sand.task.terrain.kind == terrain


def test_diverged_world_is_reset_before_its_nans_reach_the_policy(make_env) -> None:  # noqa: ANN001
    """A world whose physics state turns NaN ends by ``physics_diverged`` and restarts finite; its neighbour runs on."""
    env = make_env(g1_granular_task("rft3d"), num_envs=2)
    env.reset()
    env.step(torch.zeros(2, NUM_JOINTS))
    env.sim.data.qvel[1] = float("nan")
    obs, _, terminated, truncated, _ = env.step(torch.zeros(2, NUM_JOINTS))
    assert env.termination_manager.get_term("physics_diverged").tolist() == [False, True]
    assert terminated.tolist() == [False, True] and not truncated.any()
    assert torch.isfinite(obs["actor"]).all() and torch.isfinite(obs["critic"]).all()
    assert torch.isfinite(env.sim.data.qpos[:]).all() and torch.isfinite(env.sim.data.qvel[:]).all()
    for _ in range(3):
        obs, reward, terminated, *_ = env.step(torch.zeros(2, NUM_JOINTS))
        assert torch.isfinite(obs["critic"]).all() and torch.isfinite(reward).all() and not terminated.any()


def test_world_that_blows_up_without_nans_is_reset(make_env) -> None:  # noqa: ANN001
    """A world moving faster than any G1 motion (a finite blow-up) ends by ``physics_diverged`` as a NaN one does."""
    env = make_env(g1_granular_task("rft3d"), num_envs=2)
    env.reset()
    env.step(torch.zeros(2, NUM_JOINTS))
    env.sim.data.qvel[0, 8] = 1e6
    *_, terminated, _, _ = env.step(torch.zeros(2, NUM_JOINTS))
    assert env.termination_manager.get_term("physics_diverged").tolist() == [True, False]
    assert terminated.tolist() == [True, False]
