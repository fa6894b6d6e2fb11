# SPDX-License-Identifier: Apache-2.0
"""Typed configuration of the GM-Loco teacher, student and distillation, and their rsl-rl dicts.

Pure data. ``TeacherCfg.to_rsl_rl`` and ``DistillCfg.to_rsl_rl`` return the ``actor`` / ``critic`` /
(``teacher``) / ``algorithm`` / ``obs_groups`` entries of an rsl-rl train cfg; merge them onto a runner cfg, e.g.
``asdict(RslRlOnPolicyRunnerCfg(...)) | teacher.to_rsl_rl(groups)``. Network sizes follow Kamohara et al.,
arXiv 2603.13707; values the paper does not give are marked "ours".

The dataclasses are also the pipeline's structured configs (``workflows/schemas.py``): closed choices are ``str``
enums, and a numeric field's valid range is written in its ``metadata`` (``ge`` / ``gt`` / ``le`` / ``lt``), checked
when a config is composed.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from enum import Enum, StrEnum

__all__ = [
    "CRITIC_CLASS",
    "DEFAULT_HISTORY_LENGTH",
    "STUDENT_ACTOR_CLASS",
    "STUDENT_PPO_CLASS",
    "STUDENT_RUNNER_CLASS",
    "TEACHER_ACTOR_CLASS",
    "TEACHER_PPO_CLASS",
    "ActorLatent",
    "DistillCfg",
    "ObsGroupsCfg",
    "PpoCfg",
    "PpoOptimizer",
    "PpoSchedule",
    "StudentCfg",
    "TeacherCfg",
    "student_train_entries",
]

_PKG = "gmloco.train.teacher_student"
TEACHER_ACTOR_CLASS = f"{_PKG}.teacher:TeacherActor"
"""rsl-rl ``class_name`` of the teacher actor."""
TEACHER_PPO_CLASS = f"{_PKG}.teacher_ppo:TeacherPPO"
"""rsl-rl ``class_name`` of the teacher algorithm (run by mjlab's / rsl-rl's on-policy runner)."""
STUDENT_ACTOR_CLASS = f"{_PKG}.student:StudentActor"
"""rsl-rl ``class_name`` of the student actor."""
STUDENT_PPO_CLASS = f"{_PKG}.student_ppo:StudentPPO"
"""rsl-rl ``class_name`` of the DAgger + PPO distillation algorithm."""
STUDENT_RUNNER_CLASS = f"{_PKG}.runner:StudentRunner"
"""Runner class for distillation (loads the teacher checkpoint)."""
CRITIC_CLASS = "MLPModel"
"""The asymmetric critic is rsl-rl's stock MLP model on the privileged group."""
DEFAULT_HISTORY_LENGTH = 50
"""N: proprioceptive history frames seen by the student (1.0 s at 50 Hz)."""


class PpoSchedule(StrEnum):
    """Learning-rate schedule of rsl-rl's PPO."""

    adaptive = "adaptive"
    """Scale the rate so that the policy KL per update stays near ``desired_kl``."""
    fixed = "fixed"
    """Keep ``learning_rate``."""


class ActorLatent(StrEnum):
    """Latent the teacher's actor reads."""

    mean = "mean"
    """mu of q(z | .): deterministic in z, so the PPO ratio is exact (ours)."""
    sample = "sample"
    """A reparameterised sample of q(z | .)."""


class PpoOptimizer(StrEnum):
    """Optimizer names rsl-rl resolves."""

    adam = "adam"
    adamw = "adamw"
    sgd = "sgd"
    rmsprop = "rmsprop"


@dataclass
class ObsGroupsCfg:
    """Names of the environment's observation groups (defined by the env) and where eta sits."""

    policy: tuple[str, ...] = ("actor",)
    """Groups concatenated into o_t, ``[num_envs, obs_dim]``: base ang vel, projected gravity, command,
    joint pos, joint vel, last action (96 for the 29-DoF G1)."""
    critic: tuple[str, ...] = ("critic",)
    """Groups of the asymmetric critic: o_t plus base lin vel, foot heights, contact state and forces, swing time,
    eta."""
    privileged: tuple[str, ...] = ("critic",)
    """Groups forming s_t for the teacher's terrain encoder (with the history appended)."""
    history: str = "history"
    """Group holding o_{t-N:t}: ``[num_envs, N, obs_dim]`` (mjlab ``flatten_history_dim=False``, oldest first,
    current frame last), or flattened term-major with ``StudentCfg.history_term_dims`` set."""
    eta_group: str = "critic"
    """Group holding eta = xi / xi_max, the normalized stiffness in [0, 1]."""
    eta_index: int = -1
    """Column of eta in ``eta_group`` (-1: last column)."""

    def to_rsl_rl(self) -> dict[str, list[str]]:
        """Return rsl-rl observation sets: actor, critic, teacher, encoder, history."""
        return {
            "actor": list(self.policy),
            "critic": list(self.critic),
            "teacher": list(self.policy),
            "encoder": [*self.privileged, self.history],
            "history": [self.history],
        }


@dataclass
class PpoCfg:
    """PPO hyper-parameters, the keyword arguments of rsl-rl's ``PPO`` (same names and defaults as mjlab's cfg)."""

    num_learning_epochs: int = field(default=5, metadata={"ge": 1})
    """Passes over the rollout per update."""
    num_mini_batches: int = field(default=4, metadata={"ge": 1})
    """Mini-batches per pass; mini-batch size = num_envs * num_steps_per_env / num_mini_batches."""
    learning_rate: float = field(default=1e-3, metadata={"gt": 0})
    """Adam learning rate (initial value under the adaptive schedule)."""
    schedule: PpoSchedule = PpoSchedule.adaptive
    """Learning-rate schedule; adaptive keeps the policy KL near ``desired_kl``."""
    gamma: float = field(default=0.99, metadata={"ge": 0, "le": 1})
    """Discount factor per policy step."""
    lam: float = field(default=0.95, metadata={"ge": 0, "le": 1})
    """GAE lambda."""
    entropy_coef: float = field(default=0.005, metadata={"ge": 0})
    """Entropy bonus weight."""
    desired_kl: float = field(default=0.01, metadata={"gt": 0})
    """Target KL divergence per update [nats] for the adaptive schedule."""
    max_grad_norm: float = field(default=1.0, metadata={"gt": 0})
    """Gradient-norm clip, applied to actor and critic separately."""
    value_loss_coef: float = field(default=1.0, metadata={"ge": 0})
    """Weight of the value loss."""
    use_clipped_value_loss: bool = True
    """Clip the value update around the rollout values."""
    clip_param: float = field(default=0.2, metadata={"gt": 0})
    """PPO ratio clip epsilon."""
    normalize_advantage_per_mini_batch: bool = False
    """Normalize advantages per mini-batch instead of over the whole rollout."""
    optimizer: PpoOptimizer = PpoOptimizer.adam
    """Optimizer name resolved by rsl-rl."""

    def to_rsl_rl(self) -> dict:
        """Return the fields as rsl-rl's ``PPO`` keyword arguments (enums as their names)."""
        return {k: v.value if isinstance(v, Enum) else v for k, v in asdict(self).items()}


def _gaussian(init_std: float) -> dict:
    """Return rsl-rl's state-independent Gaussian action distribution cfg."""
    return {"class_name": "GaussianDistribution", "init_std": init_std, "std_type": "scalar"}


def _ppo_kwargs(ppo: PpoCfg, class_name: str) -> dict:
    """Return PPO keyword arguments with our algorithm class."""
    kwargs = ppo.to_rsl_rl()
    kwargs.update(class_name=class_name, rnd_cfg=None, symmetry_cfg=None)
    return kwargs


@dataclass
class TeacherCfg:
    """GM-Loco teacher: actor/critic MLPs, VAE terrain encoder, eta decoder, PPO + VAE loss."""

    actor_hidden_dims: tuple[int, ...] = field(default=(512, 256, 128), metadata={"ge": 1, "integer": True})
    """Actor MLP hidden widths (paper)."""
    critic_hidden_dims: tuple[int, ...] = field(default=(512, 256, 128), metadata={"ge": 1, "integer": True})
    """Critic MLP hidden widths (paper)."""
    activation: str = "elu"
    """Activation of every network (paper: ELU)."""
    encoder_hidden_dims: tuple[int, ...] = field(default=(256, 128, 64), metadata={"ge": 1, "integer": True})
    """Terrain encoder MLP widths (paper); linear mu / log-variance heads follow."""
    decoder_hidden_dims: tuple[int, ...] = field(default=(64, 128, 256), metadata={"ge": 1, "integer": True})
    """Stiffness decoder MLP widths (paper); output is eta, shape ``[num_envs, 1]``."""
    latent_dim: int = field(default=16, metadata={"ge": 1})
    """Size of the terrain latent z (ours; not given by the paper)."""
    encoder_history_steps: int | None = field(default=None, metadata={"ge": 1, "integer": True})
    """Newest history frames fed to the encoder (None: all N)."""
    obs_normalization: bool = True
    """Running mean/std normalization of o_t, the encoder input and the critic input."""
    init_std: float = field(default=1.0, metadata={"gt": 0})
    """Initial action std [normalized action units]."""
    actor_latent: ActorLatent = ActorLatent.mean
    """Latent fed to the actor: mu (exact PPO ratio; ours) or a reparameterised sample."""
    kl_weight: float = field(default=1e-4, metadata={"ge": 0})
    """beta, weight of KL(q(z|.) || N(0, I)) (ours; small to avoid posterior collapse: eta's spread over the DR is
    ~0.09, so encoding it to 0.01 costs ~2 nats of KL against ~0.008 of squared error; at 1e-3 the two nearly
    cancel and the first teacher run's decoder stayed at the mean, R^2 < 0)."""
    reconstruction_weight: float = field(default=1.0, metadata={"ge": 0})
    """Weight of (eta - psi(z))^2 (paper: 1)."""
    decoder_learning_rate: float | None = field(default=1e-3, metadata={"gt": 0})
    """Fixed Adam learning rate of the eta decoder (ours; None: the policy's KL-adaptive rate). The decoder is off
    the action path, so a fixed rate cannot move the policy. The encoder is on it (z feeds the actor) and always
    follows the adaptive rate: at a fixed 1e-3 it alone moved the G1 teacher's policy 40-70x past the KL target
    and held the actor's rate at the schedule's 1e-5 floor for every iteration of the first teachers."""
    ppo: PpoCfg = field(default_factory=PpoCfg)
    """PPO hyper-parameters of the teacher."""

    def actor_dict(self, groups: ObsGroupsCfg) -> dict:
        """Return the rsl-rl model cfg of the teacher actor."""
        del groups  # the encoder reads the "encoder" observation set built by ObsGroupsCfg.to_rsl_rl
        return {
            "class_name": TEACHER_ACTOR_CLASS,
            "hidden_dims": self.actor_hidden_dims,
            "activation": self.activation,
            "obs_normalization": self.obs_normalization,
            "distribution_cfg": _gaussian(self.init_std),
            "encoder_obs_set": "encoder",
            "encoder_hidden_dims": self.encoder_hidden_dims,
            "decoder_hidden_dims": self.decoder_hidden_dims,
            "latent_dim": self.latent_dim,
            "encoder_history_steps": self.encoder_history_steps,
            "encoder_obs_normalization": self.obs_normalization,
            "actor_latent": str(self.actor_latent),
        }

    def critic_dict(self) -> dict:
        """Return the rsl-rl model cfg of the asymmetric critic."""
        return {
            "class_name": CRITIC_CLASS,
            "hidden_dims": self.critic_hidden_dims,
            "activation": self.activation,
            "obs_normalization": self.obs_normalization,
        }

    def to_rsl_rl(self, groups: ObsGroupsCfg) -> dict:
        """Return the actor, critic, algorithm and obs_groups entries of the teacher's rsl-rl train cfg."""
        algorithm = _ppo_kwargs(self.ppo, TEACHER_PPO_CLASS)
        algorithm.update(
            eta_group=groups.eta_group,
            eta_index=groups.eta_index,
            kl_weight=self.kl_weight,
            reconstruction_weight=self.reconstruction_weight,
            decoder_learning_rate=self.decoder_learning_rate,
        )
        return {
            "actor": self.actor_dict(groups),
            "critic": self.critic_dict(),
            "algorithm": algorithm,
            "obs_groups": groups.to_rsl_rl(),
        }


@dataclass
class StudentCfg:
    """GM-Loco student: temporal-convolution history encoder and an actor over ``[o_t, z_hat]``."""

    actor_hidden_dims: tuple[int, ...] = field(default=(512, 256, 128), metadata={"ge": 1, "integer": True})
    """Actor MLP widths; equal to the teacher's so distillation can start from the teacher's actor."""
    history_length: int = field(default=DEFAULT_HISTORY_LENGTH, metadata={"ge": 1})
    """N, history frames (ours: 50 = 1.0 s at the 50 Hz policy rate)."""
    history_term_dims: tuple[int, ...] | None = field(default=None, metadata={"ge": 1, "integer": True})
    """Per-term frame sizes when the history group is flattened (mjlab term-major), else None."""
    tcn_channels: tuple[int, int, int] = field(default=(32, 32, 32), metadata={"ge": 1, "integer": True})
    """Output channels of the three 1-D convolutions (ours)."""
    tcn_kernel_sizes: tuple[int, int, int] = field(default=(8, 5, 5), metadata={"ge": 1, "integer": True})
    """Kernel sizes [frames] (ours; N = 50 -> 11 -> 7 -> 3 frames)."""
    tcn_strides: tuple[int, int, int] = field(default=(4, 1, 1), metadata={"ge": 1, "integer": True})
    """Strides [frames] (ours)."""
    tcn_mlp_hidden_dims: tuple[int, ...] = field(default=(128,), metadata={"ge": 1, "integer": True})
    """Hidden widths of the MLP after the convolutions (ours)."""
    obs_normalization: bool = True
    """Running normalization of o_t (starts from the teacher's statistics)."""
    history_obs_normalization: bool = True
    """Per-feature running normalization of the history frames."""

    def actor_dict(self, teacher: TeacherCfg) -> dict:
        """Return the rsl-rl model cfg of the student actor (latent and decoder sizes from the teacher)."""
        return {
            "class_name": STUDENT_ACTOR_CLASS,
            "hidden_dims": self.actor_hidden_dims,
            "activation": teacher.activation,
            "obs_normalization": self.obs_normalization,
            "distribution_cfg": _gaussian(teacher.init_std),
            "history_obs_set": "history",
            "history_length": self.history_length,
            "history_term_dims": self.history_term_dims,
            "history_obs_normalization": self.history_obs_normalization,
            "latent_dim": teacher.latent_dim,
            "tcn_channels": self.tcn_channels,
            "tcn_kernel_sizes": self.tcn_kernel_sizes,
            "tcn_strides": self.tcn_strides,
            "tcn_mlp_hidden_dims": self.tcn_mlp_hidden_dims,
            "decoder_hidden_dims": teacher.decoder_hidden_dims,
        }


@dataclass
class DistillCfg:
    """DAgger + PPO distillation: loss weights, their curriculum, and the teacher checkpoint."""

    w_ppo_start: float = field(default=0.0, metadata={"ge": 0})
    """w_PPO at the start (ours: pure imitation first)."""
    w_ppo_end: float = field(default=1.0, metadata={"ge": 0})
    """w_PPO after the curriculum."""
    w_dist_start: float = field(default=1.0, metadata={"ge": 0})
    """w_dist, weight of ||a - a_hat||^2, at the start."""
    w_dist_end: float = field(default=0.1, metadata={"ge": 0})
    """w_dist after the curriculum (ours)."""
    curriculum_begin: int = field(default=0, metadata={"ge": 0})
    """Learning iteration at which both weights start to ramp."""
    curriculum_finish: int = field(default=1000, metadata={"ge": 1})
    """Learning iteration at which both weights reach their end values (ours)."""
    latent_loss_weight: float = field(default=1.0, metadata={"ge": 0})
    """Weight of ||z - z_hat||^2 (paper: 1)."""
    decoder_loss_weight: float = field(default=1.0, metadata={"ge": 0})
    """Weight of (psi(z) - psi(z_hat))^2 (paper: 1)."""
    init_from_teacher: bool = True
    """Start the student's actor MLP, o_t normalizer, action std and critic from the teacher (ours)."""
    teacher_checkpoint: str | None = None
    """Path of the TeacherPPO checkpoint (``model_<it>.pt``); StudentRunner loads it at construction."""
    ppo: PpoCfg = field(
        default_factory=lambda: PpoCfg(learning_rate=5e-4, schedule=PpoSchedule.fixed, entropy_coef=0.001)
    )
    """PPO hyper-parameters of the student (ours: fixed learning rate, the distillation terms dominate early)."""

    def to_rsl_rl(self, teacher: TeacherCfg, student: StudentCfg, groups: ObsGroupsCfg) -> dict:
        """Return the actor, critic, teacher, algorithm, obs_groups, runner class and teacher path entries."""
        algorithm = _ppo_kwargs(self.ppo, STUDENT_PPO_CLASS)
        algorithm.update(
            w_ppo_start=self.w_ppo_start,
            w_ppo_end=self.w_ppo_end,
            w_dist_start=self.w_dist_start,
            w_dist_end=self.w_dist_end,
            curriculum_begin=self.curriculum_begin,
            curriculum_finish=self.curriculum_finish,
            latent_loss_weight=self.latent_loss_weight,
            decoder_loss_weight=self.decoder_loss_weight,
            init_from_teacher=self.init_from_teacher,
            eta_group=groups.eta_group,
            eta_index=groups.eta_index,
        )
        return {
            "class_name": STUDENT_RUNNER_CLASS,
            "actor": student.actor_dict(teacher),
            "critic": teacher.critic_dict(),
            "teacher": teacher.actor_dict(groups),
            "algorithm": algorithm,
            "obs_groups": groups.to_rsl_rl(),
            "teacher_checkpoint": self.teacher_checkpoint,
        }


def student_train_entries(
    teacher: TeacherCfg, student: StudentCfg, distill: DistillCfg, groups: ObsGroupsCfg | None = None
) -> dict:
    """Return the student's rsl-rl entries for ``gmloco.train.train`` (``TrainRunCfg.rsl_rl_overrides``).

    ``DistillCfg.to_rsl_rl`` also names :class:`StudentRunner` and a teacher path; both are dropped: the time-boxed
    runner of ``gmloco.train.train`` runs ``StudentPPO``, and ``TrainRunCfg.init_checkpoint`` loads the teacher
    through ``StudentPPO.load`` (which calls ``load_teacher``), as ``StudentRunner`` would.
    """
    entries = distill.to_rsl_rl(teacher, student, groups or ObsGroupsCfg())
    for key in ("class_name", "teacher_checkpoint"):
        entries.pop(key)
    return entries
