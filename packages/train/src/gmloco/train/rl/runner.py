# SPDX-License-Identifier: Apache-2.0
"""rsl-rl on-policy runner with a wall-clock budget, atomic checkpoints and run summaries."""

from __future__ import annotations

import os
import re
import statistics
import time
from collections.abc import Callable
from pathlib import Path

import torch
from mjlab.rl import MjlabOnPolicyRunner

from gmloco.train.multi_gpu import any_rank, rank_info

__all__ = [
    "CHECKPOINT_PATTERN",
    "ENV_STATE_OWNERS",
    "GmlocoOnPolicyRunner",
    "env_state",
    "latest_checkpoint",
    "restore_env_state",
]

CHECKPOINT_PATTERN = re.compile(r"^model_(\d+)\.pt$")
"""File names of checkpoints: ``model_<iteration>.pt``."""

STEP_REWARD_LIMIT = 100.0
"""Bound on one env step's reward (the reward manager's weighted sum, already x step dt). A healthy step stays
within +-20 (the -200 termination penalty is -4); a world whose simulation blew up can reach -1e10 in the step
before ``physics_diverged`` resets it, which would wreck the critic."""


def bounded_step_reward(rewards: torch.Tensor, limit: float = STEP_REWARD_LIMIT) -> torch.Tensor:
    """Clamp each env's step reward to [-limit, limit] (non-finite values are zeroed by mjlab's reward manager)."""
    return rewards.clamp(-limit, limit)


ENV_STATE_OWNERS = ("sand", "jump_assist")
"""Env attributes whose ``state_dict()`` a checkpoint keeps under the same name (curriculum state that the env step
counter does not carry: floor levels, the jump assist's scale)."""


def env_state(env: object) -> dict[str, dict]:
    """The ``state_dict()`` of each of the env's :data:`ENV_STATE_OWNERS` it has, by name."""
    owners = {name: getattr(env, name, None) for name in ENV_STATE_OWNERS}
    return {name: owner.state_dict() for name, owner in owners.items() if owner is not None}


def restore_env_state(env: object, infos: dict) -> None:
    """Load each saved owner's state into the env's owner of that name; skip owners either side lacks.

    An older checkpoint's ``sand_floor_level`` reads as the sand's state.
    """
    saved = dict(infos)
    if saved.get("sand_floor_level") is not None and "sand" not in saved:
        saved["sand"] = {"floor_level": saved["sand_floor_level"]}
    for name in ENV_STATE_OWNERS:
        owner = getattr(env, name, None)
        if owner is not None and saved.get(name) is not None:
            owner.load_state_dict(saved[name])


def latest_checkpoint(run_dir: str | Path) -> Path | None:
    """Return the checkpoint with the highest iteration in ``run_dir`` (None if there is none)."""
    found = [(int(m.group(1)), p) for p in Path(run_dir).glob("model_*.pt") if (m := CHECKPOINT_PATTERN.match(p.name))]
    return max(found)[1] if found else None


class GmlocoOnPolicyRunner(MjlabOnPolicyRunner):
    """mjlab's runner plus: time-boxed ``learn``, tmp + ``os.replace`` saves, floor levels and assist in checkpoints.

    After :meth:`learn`, :meth:`summary` returns the run's metrics. Under several ranks (``gmloco.train.multi_gpu``)
    it keeps rsl-rl's contract: parameters broadcast from rank 0 before learning, gradients all-reduced by the
    algorithm, files written by rank 0 only; the time box stops every rank at the same iteration.
    """

    keep_checkpoints: int = 3
    """Number of most recent ``model_*.pt`` files kept in the run directory."""

    def learn(  # type: ignore[override]
        self,
        num_learning_iterations: int,
        init_at_random_ep_len: bool = False,
        deadline: float | None = None,
        on_iteration: Callable[[int, int], None] | None = None,
    ) -> None:
        """Run PPO iterations until ``num_learning_iterations`` are done or ``deadline`` is near.

        Args:
            num_learning_iterations: Iterations to run in this call.
            init_at_random_ep_len: Randomize initial episode lengths (fresh runs).
            deadline: ``time.monotonic()`` value by which the call must have saved and returned; the loop
                stops when one more iteration (1.5x the slowest so far) would cross it.
            on_iteration: Called after each iteration with (iterations done in total, the run's last iteration),
                e.g. to drive a progress bar.
        """
        if init_at_random_ep_len:
            self.env.episode_length_buf = torch.randint_like(
                self.env.episode_length_buf, high=int(self.env.max_episode_length)
            )
        obs = self.env.get_observations().to(self.device)
        self.alg.train_mode()
        if self.is_distributed:  # every rank starts from rank 0's weights (rsl-rl ``OnPolicyRunner.learn``)
            self.alg.broadcast_parameters()
        self.logger.init_logging_writer()
        start_it = self.current_learning_iteration
        self._times: list[tuple[float, float]] = []
        self.stopped_by_deadline = False
        for it in range(start_it, start_it + num_learning_iterations):
            if self._deadline_near(deadline):
                self.stopped_by_deadline = True
                break
            obs = self._iteration(it, start_it, start_it + num_learning_iterations, obs)
            self.current_learning_iteration = it + 1
            if it % self.cfg["save_interval"] == 0:
                self.save_checkpoint()
            if on_iteration is not None:
                on_iteration(it + 1, start_it + num_learning_iterations)
        self.save_checkpoint()
        self.logger.stop_logging_writer()

    def _iteration(self, it: int, start_it: int, total_it: int, obs: object) -> object:
        """Collect one rollout, update the policy and log (rsl-rl ``OnPolicyRunner.learn`` body)."""
        start = time.time()
        with torch.inference_mode():
            # Rollout: act, step the env, store the transition, book-keep episode returns.
            for _ in range(self.cfg["num_steps_per_env"]):
                actions = self.alg.act(obs)
                obs, rewards, dones, extras = self.env.step(actions.to(self.env.device))
                obs, rewards, dones = obs.to(self.device), rewards.to(self.device), dones.to(self.device)
                rewards = bounded_step_reward(rewards)
                self.alg.process_env_step(obs, rewards, dones, extras)
                self.logger.process_env_step(rewards, dones, extras, None)
            collect_time = time.time() - start
            start = time.time()
            self.alg.compute_returns(obs)
        # Learning: PPO epochs over the rollout.
        loss_dict = self.alg.update()
        learn_time = time.time() - start
        self._times.append((collect_time, learn_time))
        self.logger.log(
            it=it,
            start_it=start_it,
            total_it=total_it,
            collect_time=collect_time,
            learn_time=learn_time,
            loss_dict=loss_dict,
            learning_rate=self.alg.learning_rate,
            action_std=self.alg.get_policy().output_std,
            rnd_weight=None,
        )
        return obs

    def _slowest(self) -> float:
        """Slowest iteration so far [s]."""
        return max(c + learn for c, learn in self._times)

    def _deadline_near(self, deadline: float | None) -> bool:
        """Whether one more iteration (1.5x the slowest so far) would cross ``deadline`` on any rank."""
        if deadline is None or not self._times:
            return False
        near = time.monotonic() + 1.5 * self._slowest() > deadline
        return any_rank(near, self.device) if self.is_distributed else near

    def _configure_multi_gpu(self) -> None:
        """rsl-rl's rank set-up; CPU ranks (the multi-process tests) open a gloo group where rsl-rl opens NCCL.

        rsl-rl requires ``device == cuda:<LOCAL_RANK>`` and the NCCL backend; on CPU the same rank contract runs with
        gloo, so the data-parallel path is tested without a GPU.
        """
        ranks = rank_info()
        if not self.device.startswith("cpu") or not ranks.distributed:
            super()._configure_multi_gpu()
            return
        self.gpu_world_size, self.is_distributed = ranks.world_size, True
        self.gpu_local_rank, self.gpu_global_rank = ranks.local_rank, ranks.rank
        self.cfg["multi_gpu"] = {
            "global_rank": ranks.rank,
            "local_rank": ranks.local_rank,
            "world_size": ranks.world_size,
        }
        torch.distributed.init_process_group(backend="gloo", rank=ranks.rank, world_size=ranks.world_size)

    # Checkpoints.

    def save_checkpoint(self) -> Path | None:
        """Save ``model_<iteration>.pt`` atomically in the log dir and prune old ones."""
        if self.logger.log_dir is None or self.logger.disable_logs:
            return None
        path = Path(self.logger.log_dir) / f"model_{self.current_learning_iteration}.pt"
        self.save(str(path))
        self._prune()
        return path

    def save(self, path: str, infos: dict | None = None) -> None:
        """Write the checkpoint to ``path + '.tmp'`` then ``os.replace`` it (a kill never leaves half a file)."""
        infos = {**(infos or {}), **env_state(self.env.unwrapped)}
        tmp = f"{path}.tmp"
        super().save(tmp, infos)
        os.replace(tmp, path)

    def load(
        self, path: str, load_cfg: dict | None = None, strict: bool = True, map_location: str | None = None
    ) -> dict:
        """Load a checkpoint, restoring the floor levels and the jump assist state.

        mjlab's runner restores the env step counter.

        A slim checkpoint (saved without ``optimizer_state_dict``, as the committed artifacts are) restores the
        weights and the iteration and starts a fresh optimizer.
        """
        # peek at the keys through a memory map: the tensors are read once, by the load below
        peek = torch.load(path, map_location="cpu", weights_only=False, mmap=True)
        if load_cfg is None and "optimizer_state_dict" not in peek:
            load_cfg = {"actor": True, "critic": True, "iteration": True, "optimizer": False, "rnd": False}
        infos = super().load(path, load_cfg, strict, map_location or self.device)
        restore_env_state(self.env.unwrapped, infos or {})
        return infos

    def _prune(self) -> None:
        """Delete all but the newest :attr:`keep_checkpoints` checkpoints."""
        found = sorted(
            (int(m.group(1)), p)
            for p in Path(self.logger.log_dir).glob("model_*.pt")  # type: ignore[arg-type]
            if (m := CHECKPOINT_PATTERN.match(p.name))
        )
        for _, p in found[: -self.keep_checkpoints]:
            p.unlink(missing_ok=True)

    # Summary.

    def summary(self) -> dict[str, float]:
        """Metrics of the last :meth:`learn` call (means over its iterations)."""
        times = self._times or [(float("nan"), float("nan"))]
        n = len(self._times)
        collect = sum(c for c, _ in times) / len(times)
        learn = sum(lt for _, lt in times) / len(times)
        # every rank steps its own num_envs (rsl-rl's logger counts the collection size the same way)
        steps = self.cfg["num_steps_per_env"] * self.env.num_envs * self.gpu_world_size
        rew, length = self.logger.rewbuffer, self.logger.lenbuffer
        return {
            "iterations_done": float(n),
            "iteration": float(self.current_learning_iteration),
            "mean_reward": statistics.mean(rew) if rew else float("nan"),
            "mean_episode_length": statistics.mean(length) if length else float("nan"),
            "seconds_per_iteration": collect + learn,
            "collection_seconds_per_iteration": collect,
            "learning_seconds_per_iteration": learn,
            "env_steps_per_second": steps / (collect + learn),
            "collection_env_steps_per_second": steps / collect,
            "env_steps": float(steps * n),
            "stopped_by_deadline": float(self.stopped_by_deadline),
        }
