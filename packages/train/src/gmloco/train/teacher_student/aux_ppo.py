# SPDX-License-Identifier: Apache-2.0
"""PPO with weighted auxiliary losses: the shared update loop of the GM-Loco teacher and student.

rsl-rl's ``PPO.update`` builds its loss inside one long loop with no hook, so this subclass re-states the
mini-batch loop (same rollout storage, same adaptive learning rate, same clipping) and adds two hooks:
:meth:`AuxLossPPO.policy_loss_weight` (w_PPO) and :meth:`AuxLossPPO.auxiliary_loss`. The actor's PPO terms are
scaled by w_PPO; the value loss is not, so the critic keeps tracking the acting policy while w_PPO is small.
Random network distillation, symmetry augmentation and recurrent models are not supported (refused at init).
"""

from __future__ import annotations

from collections import defaultdict

import torch
import torch.nn as nn
from rsl_rl.algorithms import PPO
from rsl_rl.models import MLPModel
from rsl_rl.storage import RolloutStorage

from gmloco.train.teacher_student.losses import surrogate_loss, value_loss

__all__ = ["AuxLossPPO"]


class AuxLossPPO(PPO):
    """PPO whose mini-batch loss is ``w_PPO * (surrogate - c_H * entropy) + c_V * value + auxiliary``."""

    def __init__(self, actor: MLPModel, critic: MLPModel, storage: RolloutStorage, **kwargs: object) -> None:
        """Initialise PPO; refuse the extensions this update loop does not implement.

        Raises:
            NotImplementedError: For RND, symmetry augmentation or recurrent actor/critic.
        """
        if kwargs.get("rnd_cfg") or kwargs.get("symmetry_cfg"):
            raise NotImplementedError(f"{type(self).__name__} does not support RND or symmetry augmentation.")
        if actor.is_recurrent or critic.is_recurrent:
            raise NotImplementedError(f"{type(self).__name__} supports feed-forward models only.")
        super().__init__(actor, critic, storage, **kwargs)  # type: ignore[arg-type]

    def save(self) -> dict:
        """Return rsl-rl's checkpoint dict plus the adaptive ``learning_rate``, so a resumed run continues from it."""
        return super().save() | {"learning_rate": self.learning_rate}

    def load(self, loaded_dict: dict, load_cfg: dict | None, strict: bool) -> bool:
        """Load a checkpoint and its adaptive learning rate.

        A checkpoint without ``optimizer_state_dict`` (a slim artifact), or whose optimizer groups no longer match
        this algorithm's (a checkpoint of an earlier parameter grouping), starts a fresh optimizer. The saved
        ``learning_rate`` is restored either way: a fresh Adam's first steps move every weight by about the rate,
        so resuming at the schedule's initial rate would jolt a trained policy.
        """
        if "optimizer_state_dict" in loaded_dict and not self._optimizer_matches(loaded_dict["optimizer_state_dict"]):
            print(f"[{type(self).__name__}] checkpoint optimizer groups differ from this run's: fresh optimizer")
            loaded_dict = {k: v for k, v in loaded_dict.items() if k != "optimizer_state_dict"}
        if "optimizer_state_dict" not in loaded_dict:
            load_cfg = {"actor": True, "critic": True, "iteration": True} | (load_cfg or {}) | {"optimizer": False}
        out = super().load(loaded_dict, load_cfg, strict)
        if "learning_rate" in loaded_dict:
            self.learning_rate = float(loaded_dict["learning_rate"])
            for group in self.optimizer.param_groups:
                if not group.get("fixed_lr", False):
                    group["lr"] = self.learning_rate
        return out

    def _optimizer_matches(self, state: dict) -> bool:
        """Whether a saved optimizer state has this optimizer's number of groups and of parameters per group."""
        saved = [len(g["params"]) for g in state.get("param_groups", [])]
        return saved == [len(g["params"]) for g in self.optimizer.param_groups]

    def policy_loss_weight(self) -> float:
        """Return w_PPO, the weight of the actor's PPO terms (1 for plain PPO)."""
        return 1.0

    def auxiliary_loss(self, batch: RolloutStorage.Batch) -> tuple[torch.Tensor, dict[str, float]]:
        """Return the auxiliary loss of a mini-batch (called right after the actor/critic forward) and its logs."""
        return torch.zeros((), device=self.device), {}

    def update(self) -> dict[str, float]:
        """Run the PPO epochs with the auxiliary loss added; return the mean of every logged term."""
        sums: dict[str, float] = defaultdict(float)
        num_updates = 0
        w_ppo = self.policy_loss_weight()
        for batch in self.storage.mini_batch_generator(self.num_mini_batches, self.num_learning_epochs):
            if self.normalize_advantage_per_mini_batch:
                with torch.no_grad():
                    batch.advantages = (batch.advantages - batch.advantages.mean()) / (batch.advantages.std() + 1e-8)  # type: ignore[operator]
            surrogate, value, entropy = self._ppo_terms(batch)
            aux, aux_logs = self.auxiliary_loss(batch)
            loss = w_ppo * (surrogate - self.entropy_coef * entropy) + self.value_loss_coef * value + aux
            # Gradient step on actor + critic (a frozen teacher has no parameters in the optimizer)
            self.optimizer.zero_grad()
            loss.backward()
            if self.is_multi_gpu:
                self.reduce_parameters()
            nn.utils.clip_grad_norm_(self.actor.parameters(), self.max_grad_norm)
            nn.utils.clip_grad_norm_(self.critic.parameters(), self.max_grad_norm)
            self.optimizer.step()
            # Book-keeping
            for key, val in {"surrogate": surrogate.item(), "value": value.item(), "entropy": entropy.item()}.items():
                sums[key] += val
            for key, val in aux_logs.items():
                sums[key] += val
            num_updates += 1
        self.storage.clear()
        return {key: val / max(num_updates, 1) for key, val in sums.items()} | {"w_ppo": w_ppo}

    def _ppo_terms(self, batch: RolloutStorage.Batch) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """Forward actor and critic on the batch, adapt the learning rate, return (surrogate, value, entropy)."""
        self.actor(batch.observations, stochastic_output=True)
        log_prob = self.actor.get_output_log_prob(batch.actions)  # type: ignore[arg-type]
        values = self.critic(batch.observations)
        self._adapt_learning_rate(batch)
        surrogate = surrogate_loss(log_prob, batch.old_actions_log_prob, batch.advantages, self.clip_param)  # type: ignore[arg-type]
        value = value_loss(values, batch.values, batch.returns, self.clip_param, self.use_clipped_value_loss)  # type: ignore[arg-type]
        return surrogate, value, self.actor.output_entropy.mean()

    def _adapt_learning_rate(self, batch: RolloutStorage.Batch) -> None:
        """KL-adaptive learning rate, the rule of rsl-rl's PPO (no-op unless ``schedule == "adaptive"``)."""
        if self.desired_kl is None or self.schedule != "adaptive":
            return
        with torch.inference_mode():
            kl = self.actor.get_kl_divergence(batch.old_distribution_params, self.actor.output_distribution_params)  # type: ignore[arg-type]
            kl_mean = kl.mean()
            if self.is_multi_gpu:
                torch.distributed.all_reduce(kl_mean, op=torch.distributed.ReduceOp.SUM)
                kl_mean /= self.gpu_world_size
            if self.gpu_global_rank == 0:
                if kl_mean > self.desired_kl * 2.0:
                    self.learning_rate = max(1e-5, self.learning_rate / 1.5)
                elif 0.0 < kl_mean < self.desired_kl / 2.0:
                    self.learning_rate = min(1e-2, self.learning_rate * 1.5)
            if self.is_multi_gpu:
                lr = torch.tensor(self.learning_rate, device=self.device)
                torch.distributed.broadcast(lr, src=0)
                self.learning_rate = lr.item()
        for group in self.optimizer.param_groups:
            if not group.get("fixed_lr", False):
                group["lr"] = self.learning_rate

    def split_fixed_lr_group(self, modules: list[nn.Module], learning_rate: float) -> None:
        """Give ``modules``' parameters their own Adam group at a fixed ``learning_rate`` [1/step].

        The KL-adaptive schedule then leaves that group alone: it drives the policy's step size, and when the policy
        moves fast (e.g. after a warm start) it falls to 1e-5..1e-4, which would all but stop a supervised head
        such as the teacher's terrain encoder and decoder. Gradients and clipping are unchanged.
        """
        heads = [p for m in modules for p in m.parameters()]
        fixed = {id(p) for p in heads}
        rest = [p for p in self.optimizer.param_groups[0]["params"] if id(p) not in fixed]
        self.optimizer = type(self.optimizer)(
            [{"params": rest}, {"params": heads, "lr": learning_rate, "fixed_lr": True}], lr=self.learning_rate
        )
