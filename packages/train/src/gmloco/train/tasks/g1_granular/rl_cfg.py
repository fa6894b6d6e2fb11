# SPDX-License-Identifier: Apache-2.0
"""PPO settings of GM-Loco (Dec-2025 snapshot, spec section 4) on mjlab's rsl-rl config types."""

from __future__ import annotations

from mjlab.rl import RslRlModelCfg, RslRlOnPolicyRunnerCfg, RslRlPpoAlgorithmCfg

__all__ = ["make_g1_granular_ppo_cfg"]


def make_g1_granular_ppo_cfg(
    experiment_name: str = "g1_granular", hidden_dims: tuple[int, ...] = (512, 256, 128)
) -> RslRlOnPolicyRunnerCfg:
    """Return GM-Loco's PPO runner config.

    [512, 256, 128] ELU, lr 1e-3 adaptive (KL 0.01), gamma 0.99, lambda 0.95, clip 0.2, entropy 0.005,
    24 steps/env, 5 epochs x 4 minibatches.
    """
    return RslRlOnPolicyRunnerCfg(
        actor=RslRlModelCfg(
            hidden_dims=hidden_dims,
            activation="elu",
            obs_normalization=True,
            distribution_cfg={"class_name": "GaussianDistribution", "init_std": 1.0, "std_type": "scalar"},
        ),
        critic=RslRlModelCfg(hidden_dims=hidden_dims, activation="elu", obs_normalization=True),
        algorithm=RslRlPpoAlgorithmCfg(
            value_loss_coef=1.0,
            use_clipped_value_loss=True,
            clip_param=0.2,
            entropy_coef=0.005,
            num_learning_epochs=5,
            num_mini_batches=4,
            learning_rate=1.0e-3,
            schedule="adaptive",
            gamma=0.99,
            lam=0.95,
            desired_kl=0.01,
            max_grad_norm=1.0,
        ),
        experiment_name=experiment_name,
        logger="tensorboard",
        save_interval=50,
        num_steps_per_env=24,
        max_iterations=30_000,
        upload_model=False,
    )
