# SPDX-License-Identifier: Apache-2.0
"""The passive-callback coupling against MuJoCo C (oracle) and against Newton's second law.

A constant-wrench source stands in for a contact model (it is a test double for the coupling, not a
granular model): whatever wrench it writes must reach the feet exactly as ``xfrc_applied`` does in MuJoCo C.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
import torch
import warp as wp

from gmloco.deploy.g1 import G1_FOOT_BODIES, g1_mjcf_path
from gmloco.train.contact_coupling import ContactCoupling

FEET = G1_FOOT_BODIES
DT = 0.005
"""Physics step [s]."""


@wp.kernel
def _constant_wrench(wrench_in: wp.array[wp.spatial_vector], wrench_out: wp.array2d[wp.spatial_vector]) -> None:
    """wrench_out[w, f] = wrench_in[f]."""
    world, foot = wp.tid()
    wrench_out[world, foot] = wrench_in[foot]


class ConstantWrench:
    """Test double of a contact model: a fixed (force, torque about CoM) per foot; counts state updates."""

    def __init__(self, wrenches: np.ndarray) -> None:
        self.wrench = wp.array(wrenches.astype(np.float32), dtype=wp.spatial_vector, device="cpu")
        self.updates = 0

    def compute(self, pos: wp.array, mat: wp.array, lin: wp.array, ang: wp.array, com: wp.array, out: wp.array) -> None:
        """Write the fixed wrenches."""
        wp.launch(_constant_wrench, dim=out.shape, inputs=[self.wrench], outputs=[out], device=out.device)

    def update_state(self, *inputs: wp.array) -> None:
        """Count substeps."""
        self.updates += 1


def _g1_model(gravity: float) -> mujoco.MjModel:
    """Return mjlab's G1 MJCF (free-floating, no floor) with rigid contact off."""
    model = mujoco.MjModel.from_xml_path(str(g1_mjcf_path()))
    model.opt.gravity[:] = (0.0, 0.0, -gravity)
    model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT
    return model


def _simulation(model: mujoco.MjModel, num_envs: int, device: str) -> object:
    """An mjlab ``Simulation`` of the bare G1 (MujocoCfg keeps the model's gravity and flags)."""
    from mjlab.sim import MujocoCfg, SimulationCfg
    from mjlab.sim.sim import Simulation

    g = tuple(float(x) for x in model.opt.gravity)
    cfg = SimulationCfg(mujoco=MujocoCfg(timestep=DT, gravity=g, disableflags=("contact",)))  # type: ignore[arg-type]
    return Simulation(num_envs=num_envs, cfg=cfg, model=model, device=device)


def _random_state(model: mujoco.MjModel, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """A random but valid (qpos, qvel): pelvis 1 m up, unit quaternion, joints within +-0.3 rad."""
    rng = np.random.default_rng(seed)
    qpos = model.qpos0.copy()
    qpos[:3] = (0.1, -0.2, 1.0)
    quat = rng.normal(size=4)
    qpos[3:7] = quat / np.linalg.norm(quat)
    qpos[7:] += rng.uniform(-0.3, 0.3, model.nq - 7)
    return qpos, rng.uniform(-1.0, 1.0, model.nv)


@pytest.fixture(scope="module")
def g1() -> mujoco.MjModel:
    """The G1 with gravity."""
    return _g1_model(9.81)


def test_gather_matches_mujoco_c(g1: mujoco.MjModel, device: str) -> None:
    """Gathered foot pose, origin velocity and CoM equal MuJoCo C's to float32 precision.

    References: ``xpos``/``xmat``/``xipos`` and ``mj_objectVelocity(mjOBJ_XBODY)`` (velocity of the body frame
    origin, world axes).
    """
    qpos, qvel = _random_state(g1, 0)
    sim = _simulation(g1, 1, device)
    feet = [g1.body(n).id for n in FEET]
    coupling = ContactCoupling(ConstantWrench(np.zeros((2, 6))), sim, feet)
    coupling.install()
    sim.data.qpos[0] = torch.tensor(qpos, dtype=torch.float32)
    sim.data.qvel[0] = torch.tensor(qvel, dtype=torch.float32)
    sim.forward()
    data = mujoco.MjData(g1)
    data.qpos[:], data.qvel[:] = qpos, qvel
    mujoco.mj_forward(g1, data)
    vel = np.zeros((2, 6))
    for i, b in enumerate(feet):
        mujoco.mj_objectVelocity(g1, data, mujoco.mjtObj.mjOBJ_XBODY, b, vel[i], 0)  # (ang, lin)
    np.testing.assert_allclose(coupling.foot_pos_w.numpy()[0], data.xpos[feet], atol=2e-5)
    np.testing.assert_allclose(coupling.foot_mat_w.numpy()[0], data.xmat[feet].reshape(2, 3, 3), atol=2e-5)
    np.testing.assert_allclose(coupling.foot_com_w.numpy()[0], data.xipos[feet], atol=2e-5)
    np.testing.assert_allclose(coupling.foot_ang_vel_w.numpy()[0], vel[:, :3], atol=1e-4)
    np.testing.assert_allclose(coupling.foot_lin_vel_w.numpy()[0], vel[:, 3:], atol=1e-4)


def test_wrench_response_matches_mujoco_c(g1: mujoco.MjModel, device: str) -> None:
    """The change of qacc caused by the foot wrenches equals MuJoCo C with the same ``xfrc_applied``.

    Wrenches: left (30, -20, 150) N with torque (2, -1, 3) N m about its CoM, right (-10, 40, 90) N with
    (-4, 0.5, 1) N m. Tolerance: 1e-3 of the largest response (float32 vs float64 dynamics).
    """
    wrenches = np.array([[30.0, -20.0, 150.0, 2.0, -1.0, 3.0], [-10.0, 40.0, 90.0, -4.0, 0.5, 1.0]])
    qpos, qvel = _random_state(g1, 1)
    feet = [g1.body(n).id for n in FEET]
    responses = []
    for wrench in (np.zeros_like(wrenches), wrenches):
        sim = _simulation(g1, 1, device)
        ContactCoupling(ConstantWrench(wrench), sim, feet).install()
        sim.data.qpos[0] = torch.tensor(qpos, dtype=torch.float32)
        sim.data.qvel[0] = torch.tensor(qvel, dtype=torch.float32)
        sim.forward()
        responses.append(sim.data.qacc[0].cpu().numpy().astype(np.float64))
    warp_delta = responses[1] - responses[0]
    data = mujoco.MjData(g1)
    data.qpos[:], data.qvel[:] = qpos, qvel
    mujoco.mj_forward(g1, data)
    base = data.qacc.copy()
    data.xfrc_applied[feet] = wrenches
    mujoco.mj_forward(g1, data)
    c_delta = data.qacc - base
    assert np.abs(c_delta).max() > 1.0  # the wrench matters
    np.testing.assert_allclose(warp_delta, c_delta, atol=1e-3 * np.abs(c_delta).max())


def _linear_momentum(sim: object, model: mujoco.MjModel) -> np.ndarray:
    """Total linear momentum sum_i m_i v_i [kg m/s] per world, v_i the velocity of body i's CoM."""
    cvel = sim.data.cvel.cpu().numpy().astype(np.float64)  # (ang, lin) at the root subtree CoM
    xipos = sim.data.xipos.cpu().numpy().astype(np.float64)
    com = sim.data.subtree_com.cpu().numpy().astype(np.float64)[:, model.body_rootid]
    v = cvel[..., 3:] + np.cross(cvel[..., :3], xipos - com)
    return np.einsum("b,wbk->wk", model.body_mass, v)


def _c_momentum(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    """MuJoCo C linear momentum of the whole robot [kg m/s]."""
    mujoco.mj_forward(model, data)
    mujoco.mj_subtreeVel(model, data)
    root = model.body("pelvis").id
    return data.subtree_linvel[root] * model.body_subtreemass[root]


def test_foot_wrenches_push_the_robot_as_in_mujoco_c(device: str) -> None:
    """Constant foot wrenches move the robot as in MuJoCo C and change its momentum by their impulse.

    Zero gravity, no contact, 40 substeps with forces 50 N up plus small side forces and torques about the
    feet CoMs: the trajectory equals MuJoCo C stepping with the same ``xfrc_applied``, and the robot's
    linear momentum is the impulse n dt (F_L + F_R) = (1.0, -0.6, 20) kg m/s.

    Newton's law holds only to O(dt) in MuJoCo's discrete dynamics (MuJoCo C itself is off by 0.10 kg m/s
    in z after 40 steps), hence 1 % on the impulse; the oracle comparison is at float32 precision.
    The model's state update runs once per substep, never in forward().
    """
    model = _g1_model(0.0)
    sim = _simulation(model, 2, device)  # applies mjlab's MujocoCfg (integrator, timestep) to ``model``
    feet = [model.body(n).id for n in FEET]
    wrenches = np.array([[5.0, 0.0, 50.0, 0.0, 1.0, 0.0], [0.0, -3.0, 50.0, 0.5, 0.0, 0.0]])
    source = ConstantWrench(wrenches)
    ContactCoupling(source, sim, feet).install()
    data = mujoco.MjData(model)
    n = 40
    for _ in range(n):
        sim.step()
        data.xfrc_applied[feet] = wrenches
        mujoco.mj_step(model, data)
    sim.forward()
    np.testing.assert_allclose(sim.data.qpos.cpu().numpy(), np.broadcast_to(data.qpos, (2, model.nq)), atol=1e-4)
    momentum = _linear_momentum(sim, model)
    np.testing.assert_allclose(momentum, np.broadcast_to(_c_momentum(model, data), (2, 3)), atol=2e-3)
    impulse = n * DT * wrenches[:, :3].sum(axis=0)
    np.testing.assert_allclose(momentum, np.broadcast_to(impulse, (2, 3)), atol=0.01 * np.linalg.norm(impulse))
    assert source.updates == n


def _sand_run(one_launch: bool, device: str, steps: int) -> tuple[np.ndarray, list[np.ndarray]]:
    """Step the G1 dropped 3 cm into 3D-RFT dry sand; return qpos and the model's state arrays after ``steps``."""
    from gmloco.contact import MATERIAL_PRESETS, ContactRFT3DCfg, make_contact_model

    model = _g1_model(9.81)
    sim = _simulation(model, 2, device)
    feet = [model.body(n).id for n in FEET]
    contact = make_contact_model(ContactRFT3DCfg(), 2, len(feet), device)
    sand = MATERIAL_PRESETS["dry_sand"]
    contact.set_materials(np.full(2, sand.rho_c), np.full(2, sand.mu_int), np.full(2, sand.mu_surf))
    contact.point_outputs = False
    coupling = ContactCoupling(contact, sim, feet, stateful=True, one_launch=one_launch)
    assert coupling.one_launch == one_launch
    coupling.install()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    sole_z = min(data.xpos[f][2] for f in feet)  # foot origins; the soles sit a few cm below them
    qpos = np.broadcast_to(model.qpos0, (2, model.nq)).copy()
    qpos[:, 2] = model.qpos0[2] - sole_z - 0.01  # origins 1 cm above the surface: sole elements submerged
    qpos[1, 0] = 0.05  # the second world differs, so per-world bookkeeping shows
    sim.data.qpos[:] = torch.as_tensor(qpos, dtype=torch.float32, device=sim.data.qpos.device)
    sim.forward()
    for _ in range(steps):
        sim.step()
        sim.forward()  # forward passes in between must not advance the state
    state = [a.numpy().copy() for a in (contact.depth_max, contact.ema_tau, contact.vel_prev, contact.anchor)]
    return sim.data.qpos.cpu().numpy(), state


def test_one_launch_step_equals_compute_then_update_state(device: str) -> None:
    """The one-launch path (state advanced inside the step's callback) gives the two-launch trajectory and state.

    30 substeps of a G1 sinking into 3D-RFT dry sand (elements in both branches, sticking anchors), with a
    ``sim.forward()`` after every step: qpos and every state array agree to float32 round-off, and the state is
    not trivially zero (the comparison would otherwise prove nothing).
    """
    q1, s1 = _sand_run(True, device, 30)
    q2, s2 = _sand_run(False, device, 30)
    np.testing.assert_allclose(q1, q2, atol=1e-6)
    for a, b in zip(s1, s2, strict=True):
        np.testing.assert_allclose(a, b, atol=1e-6)
    assert s1[0].max() > 1e-3  # some element reached more than 1 mm depth


def test_one_launch_is_off_for_models_without_it(device: str) -> None:
    """A model without compute_and_update_state keeps the two-launch path (update_state after each step)."""
    model = _g1_model(0.0)
    sim = _simulation(model, 1, device)
    source = ConstantWrench(np.zeros((2, 6)))
    coupling = ContactCoupling(source, sim, [model.body(n).id for n in FEET])
    assert not coupling.one_launch
    coupling.install()
    for _ in range(3):
        sim.step()
    assert source.updates == 3
