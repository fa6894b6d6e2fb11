# SPDX-License-Identifier: Apache-2.0
"""DAgger + PPO distillation of the GM-Loco student (Kamohara et al., arXiv 2603.13707, Sec. IV-B).

L = w_PPO * L_PPO + w_dist * ||a - a_hat||^2 + ||z - z_hat||^2 + (psi(z) - psi(z_hat))^2, teacher and psi frozen.

DAgger (Ross et al., AISTATS 2011): the student acts in the environment (its stochastic PPO action is what the
env receives), and the frozen teacher labels the states the student visits. The labels are computed at update
time on the stored observations; the teacher is frozen and deterministic (latent mean), so that equals labelling
at collection time without widening rsl-rl's rollout storage. w_PPO and w_dist follow a
:class:`~gmloco.train.teacher_student.curriculum.LinearRamp` over learning updates.

Selected in rsl-rl with ``class_name="gmloco.train.teacher_student.student_ppo:StudentPPO"`` and run by
:class:`~gmloco.train.teacher_student.runner.StudentRunner`, which loads the teacher checkpoint.
"""

from __future__ import annotations

import torch
from rsl_rl.env import VecEnv
from rsl_rl.models import MLPModel
from rsl_rl.storage import RolloutStorage
from rsl_rl.utils import resolve_callable, resolve_obs_groups
from tensordict import TensorDict

from gmloco.train.teacher_student.aux_ppo import AuxLossPPO
from gmloco.train.teacher_student.checkpoint_teacher import attach_teacher
from gmloco.train.teacher_student.curriculum import LinearRamp
from gmloco.train.teacher_student.losses import distill_terms, squared_error
from gmloco.train.teacher_student.student import StudentActor
from gmloco.train.teacher_student.teacher import TeacherActor
from gmloco.train.teacher_student.teacher_ppo import batch_r2, eta_target

__all__ = ["StudentPPO"]


class StudentPPO(AuxLossPPO):
    """PPO on a :class:`StudentActor` plus DAgger supervision from a frozen :class:`TeacherActor`."""

    actor: StudentActor
    teacher: TeacherActor
    teacher_loaded: bool = False
    """Whether teacher parameters were loaded (distillation refuses to start otherwise)."""

    def __init__(
        self,
        actor: StudentActor,
        critic: MLPModel,
        storage: RolloutStorage,
        teacher: TeacherActor,
        w_ppo_start: float = 0.0,
        w_ppo_end: float = 1.0,
        w_dist_start: float = 1.0,
        w_dist_end: float = 0.1,
        curriculum_begin: int = 0,
        curriculum_finish: int = 1000,
        latent_loss_weight: float = 1.0,
        decoder_loss_weight: float = 1.0,
        init_from_teacher: bool = True,
        eta_group: str | None = "critic",
        eta_index: int = -1,
        **kwargs: object,
    ) -> None:
        """Initialise PPO on the student and freeze the teacher.

        Args:
            actor: Student actor (acts in the environment).
            critic: Critic for the PPO term (starts from the teacher's critic when ``init_from_teacher``).
            storage: Rollout storage.
            teacher: Teacher actor; frozen here (``requires_grad=False``, eval mode, normalizers not updated).
            w_ppo_start: w_PPO at the start of the curriculum.
            w_ppo_end: w_PPO at its end.
            w_dist_start: w_dist at the start of the curriculum.
            w_dist_end: w_dist at its end.
            curriculum_begin: Learning update at which the ramps start.
            curriculum_finish: Learning update at which the ramps end.
            latent_loss_weight: Weight of ||z - z_hat||^2 (1 in the paper).
            decoder_loss_weight: Weight of (psi(z) - psi(z_hat))^2 (1 in the paper).
            init_from_teacher: Copy the teacher's actor MLP, o_t normalizer, action std and critic into the
                student when the teacher is loaded.
            eta_group: Group holding the true eta, only for logging ``eta_error`` (None: not logged).
            eta_index: Column of eta in that group.
            **kwargs: rsl-rl PPO arguments.
        """
        if not isinstance(actor, StudentActor) or not isinstance(teacher, TeacherActor):
            raise TypeError("StudentPPO needs a StudentActor student and a TeacherActor teacher.")
        super().__init__(actor, critic, storage, **kwargs)
        self.teacher = teacher.to(self.device).eval().requires_grad_(False)
        self.w_ppo = LinearRamp(w_ppo_start, w_ppo_end, curriculum_begin, curriculum_finish)
        self.w_dist = LinearRamp(w_dist_start, w_dist_end, curriculum_begin, curriculum_finish)
        self.latent_loss_weight = latent_loss_weight
        self.decoder_loss_weight = decoder_loss_weight
        self.init_from_teacher = init_from_teacher
        self.eta_group = eta_group
        self.eta_index = eta_index
        self.num_updates = 0

    # -- losses ---------------------------------------------------------------------------------------------------

    def policy_loss_weight(self) -> float:
        """Return w_PPO at the current learning update."""
        return self.w_ppo(self.num_updates)

    def auxiliary_loss(self, batch: RolloutStorage.Batch) -> tuple[torch.Tensor, dict[str, float]]:
        """Return the DAgger terms on the student's visited states, labelled now by the frozen teacher."""
        obs: TensorDict = batch.observations  # type: ignore[assignment]
        with torch.no_grad():
            teacher_action = self.teacher(obs)
            z_teacher = self.teacher.latent_mu
        assert self.actor.latent is not None and z_teacher is not None
        terms = distill_terms(
            self.actor.output_mean, teacher_action, z_teacher, self.actor.latent, self.teacher.decoder
        )
        w_dist = self.w_dist(self.num_updates)
        loss = w_dist * terms.action + self.latent_loss_weight * terms.latent + self.decoder_loss_weight * terms.decoded
        logs = {"distill_action": terms.action.item(), "distill_latent": terms.latent.item()}
        logs |= {"distill_decoded": terms.decoded.item(), "w_dist": w_dist}
        if self.eta_group is not None:
            with torch.no_grad():
                eta_hat = self.teacher.decoder(self.actor.latent)
                eta = eta_target(obs, self.eta_group, self.eta_index)
                logs["eta_error"] = squared_error(eta_hat, eta).item()
                logs["eta_r2"] = batch_r2(eta_hat, eta)
        return loss, logs

    def update(self) -> dict[str, float]:
        """Run one PPO + DAgger update and advance the curriculum."""
        logs = super().update()
        self.num_updates += 1
        return logs

    # -- modes, teacher loading, checkpoints ----------------------------------------------------------------------

    def train_mode(self) -> None:
        """Train the student and critic; the teacher stays in eval mode."""
        super().train_mode()
        self.teacher.eval()

    def eval_mode(self) -> None:
        """Set every model to eval mode."""
        super().eval_mode()
        self.teacher.eval()

    def load_teacher(self, loaded_dict: dict, strict: bool = True) -> None:
        """Load a TeacherPPO checkpoint (``actor_state_dict``, ``critic_state_dict``) into the frozen teacher.

        Also copies the decoder psi into the student (for export) and, with ``init_from_teacher``, the actor MLP,
        the o_t normalizer, the action distribution and the critic.
        """
        self.teacher.load_state_dict(loaded_dict["actor_state_dict"], strict=strict)
        self.teacher.requires_grad_(False).eval()
        self.actor.decoder.load_state_dict(self.teacher.decoder.state_dict())
        if self.init_from_teacher:
            self.actor.mlp.load_state_dict(self.teacher.mlp.state_dict())
            self.actor.obs_normalizer.load_state_dict(self.teacher.obs_normalizer.state_dict())
            if self.actor.distribution is not None and self.teacher.distribution is not None:
                self.actor.distribution.load_state_dict(self.teacher.distribution.state_dict())
            self.critic.load_state_dict(loaded_dict["critic_state_dict"], strict=strict)
        self.teacher_loaded = True

    def save(self) -> dict:
        """Return the student checkpoint: PPO state plus the frozen teacher and the curriculum position."""
        saved = super().save()
        saved["teacher_state_dict"] = self.teacher.state_dict()
        saved["distill_updates"] = self.num_updates
        return saved

    def load(self, loaded_dict: dict, load_cfg: dict | None, strict: bool) -> bool:
        """Load a student checkpoint, or a teacher checkpoint (no ``teacher_state_dict``) via :meth:`load_teacher`.

        A student checkpoint whose teacher was detached (``checkpoint_teacher.detach_teacher``) gets it back from the
        teacher file it names first.
        """
        loaded_dict = dict(attach_teacher(loaded_dict))
        if "teacher_state_dict" not in loaded_dict:
            self.load_teacher(loaded_dict, strict)
            return False
        load_cfg = load_cfg or {"actor": True, "critic": True, "optimizer": True, "iteration": True, "teacher": True}
        if load_cfg.get("teacher", True):
            self.teacher.load_state_dict(loaded_dict["teacher_state_dict"], strict=strict)
            self.teacher_loaded = True
        if load_cfg.get("iteration"):
            self.num_updates = int(loaded_dict.get("distill_updates", 0))
        return super().load(loaded_dict, load_cfg, strict)

    @staticmethod
    def construct_algorithm(obs: TensorDict, env: VecEnv, cfg: dict, device: str) -> StudentPPO:
        """Build student, critic, teacher, storage and algorithm from an rsl-rl train cfg.

        ``cfg`` has rsl-rl's keys plus ``"teacher"`` (the teacher model cfg); observation sets ``"actor"``,
        ``"critic"``, ``"teacher"`` (defaults to the actor's), ``"history"`` and ``"encoder"``.
        """
        alg_class: type[StudentPPO] = resolve_callable(cfg["algorithm"].pop("class_name"))  # type: ignore[assignment]
        models = {key: resolve_callable(cfg[key].pop("class_name")) for key in ("actor", "critic", "teacher")}
        if "actor" in cfg["obs_groups"]:
            cfg["obs_groups"].setdefault("teacher", list(cfg["obs_groups"]["actor"]))
        cfg["obs_groups"] = resolve_obs_groups(obs, cfg["obs_groups"], ["actor", "critic", "teacher"])
        for key in ("rnd_cfg", "symmetry_cfg"):
            if cfg["algorithm"].get(key) is not None:
                raise ValueError(f"StudentPPO does not support '{key}'.")
            cfg["algorithm"][key] = None
        groups, n_act = cfg["obs_groups"], env.num_actions
        actor = models["actor"](obs, groups, "actor", n_act, **cfg["actor"]).to(device)
        critic = models["critic"](obs, groups, "critic", 1, **cfg["critic"]).to(device)
        teacher = models["teacher"](obs, groups, "teacher", n_act, **cfg["teacher"]).to(device)
        storage = RolloutStorage("rl", env.num_envs, cfg["num_steps_per_env"], obs, [n_act], device)
        alg = alg_class(
            actor, critic, storage, teacher=teacher, device=device, **cfg["algorithm"], multi_gpu_cfg=cfg["multi_gpu"]
        )
        alg.compile(cfg.get("torch_compile_mode"))
        return alg
