# SPDX-License-Identifier: Apache-2.0
"""Checks of the selected stages' inputs that need no stage to run: recordings, effect ids, ranges, task paths.

Each check returns ``(dotted key, message)`` for the first problem, or None; the entry point turns it into one
exit-2 paragraph before anything runs, so a typo never becomes a failed stage or a silent ``unexplained``.
"""

from __future__ import annotations

from pathlib import Path

from omegaconf import DictConfig, ListConfig

__all__ = ["MCAP_MAGIC", "input_problem", "mcap_problem"]

MCAP_MAGIC = b"\x89MCAP0\r\n"
"""First bytes of every MCAP file (MCAP specification, "Magic")."""


def mcap_problem(path: str | Path) -> str | None:
    """Why ``path`` is not an MCAP recording (one clause), or None."""
    p = Path(path)
    if not p.is_file():
        return f"'{p}' {'is a directory' if p.is_dir() else 'does not exist'}"
    with p.open("rb") as f:
        head = f.read(len(MCAP_MAGIC))
    return None if head == MCAP_MAGIC else f"'{p}' is not an MCAP recording (its first bytes are not MCAP's magic)"


def _mismatch_problem(section: DictConfig) -> tuple[str, str] | None:
    """``mismatch.real`` must be an MCAP file and ``mismatch.effects`` ids of the library."""
    from gmloco.deploy.mismatch.effects import check_effect_ids

    if (problem := mcap_problem(str(section.real))) is not None:
        return "mismatch.real", f"bad value for 'mismatch.real': {problem}; set it to a G1 recording (.mcap)."
    if section.effects is not None:
        try:
            check_effect_ids(str(e) for e in section.effects)
        except ValueError as exc:
            return "mismatch.effects", f"bad value for 'mismatch.effects': {exc}"
    return None


def _analyze_logs_problem(section: DictConfig) -> tuple[str, str] | None:
    """Every ``analyze_logs.inputs`` entry must be a recording or a folder holding some."""
    from gmloco.deploy.logs.analysis.report import expand_paths

    for item in section.inputs:
        try:
            files = expand_paths([str(item)])
        except ValueError as exc:
            return "analyze_logs.inputs", f"bad value for 'analyze_logs.inputs': {exc}"
        bad = next((m for f in files if (m := mcap_problem(f)) is not None), None)
        if bad is not None:
            return "analyze_logs.inputs", f"bad value for 'analyze_logs.inputs': {bad}; pass .mcap recordings."
    return None


def _calibrated_problem(section: DictConfig) -> tuple[str, str] | None:
    """``contact_model=rft3d_calibrated`` needs the fitted extensions an accepted calibration fit writes."""
    if str(getattr(section.contact_model, "value", section.contact_model)) != "rft3d_calibrated":
        return None
    from gmloco.train.config import GranularTaskCfg

    path = Path(GranularTaskCfg().rft_extensions_file)
    if path.is_file():
        return None
    return "train_teacher.contact_model", (
        f"bad value for 'train_teacher.contact_model': rft3d_calibrated reads the fitted terms from '{path}', which "
        "does not exist; make the MPM calibration dataset and fit it first (docs/sand_calibration.md: python -m "
        "gmloco.eval.calibration.fit_cli ... --write-default), or train with contact_model=rft3d."
    )


def _jump_problem(section: DictConfig) -> tuple[str, str] | None:
    """The jump imitation task trains vanilla PPO only."""
    if section.get("jump") is not None and str(section.algorithm.value) != "ppo":
        return "train_teacher.algorithm", (
            f"bad value for 'train_teacher.algorithm': {section.algorithm.value}; train_teacher.jump needs "
            "algorithm=ppo (the jump imitation task, +exp=jump_rft3d or +exp=jump_rigid)."
        )
    return None


def _material_problem(section: DictConfig) -> tuple[str, str] | None:
    """Each range of ``train_teacher.material`` is ``[low, high]`` with low <= high; a preset is a known medium."""
    material = section.get("material")
    if material is None:
        return None
    for name, value in material.items():
        key = f"train_teacher.material.{name}"
        if not isinstance(value, ListConfig):
            continue
        if len(value) != 2 or value[0] > value[1]:
            return key, f"bad value for '{key}': {list(value)} is not a range; give [low, high] with low <= high."
    if material.preset is None:
        return None
    from gmloco.contact import MATERIAL_PRESETS  # imports Warp: only when a preset is named

    if str(material.preset) not in MATERIAL_PRESETS:
        return "train_teacher.material.preset", (
            f"bad value for 'train_teacher.material.preset': '{material.preset}' is not a material preset; "
            f"choose one of {', '.join(sorted(MATERIAL_PRESETS))}."
        )
    return None


def _task_problem(section: DictConfig) -> tuple[str, str] | None:
    """``train_teacher.task`` must name fields of the velocity task, leave no range empty, and not meet the jump."""
    if not section.get("task"):
        return None
    if section.get("jump") is not None:
        return "train_teacher.task", (
            "bad value for 'train_teacher.task': it sets fields of the velocity task, and train_teacher.jump trains "
            "the jump task instead; set the jump task's fields at train_teacher.jump.<field>, or drop the jump."
        )
    from workflows.policy_training import task_cfg  # builds the task: imports gmloco.train, only when one is set
    from workflows.stage_runner import PipelineConfigError

    try:
        task_cfg(section)
    except PipelineConfigError as exc:
        return exc.key, f"bad value for '{exc.key}': {str(exc).removeprefix(f'{exc.key}: ')}"
    return None


def _gpus_problem(cfg: DictConfig, name: str) -> tuple[str, str] | None:
    """``<stage>.gpus`` must name distinct CUDA devices this machine has."""
    gpus = [int(g) for g in cfg[name].get("gpus", [])]
    if not gpus:
        return None
    from gmloco.train.multi_gpu import cuda_device_count, gpus_problem

    if (problem := gpus_problem(gpus, cuda_device_count())) is None:
        return None
    return f"{name}.gpus", f"bad value for '{name}.gpus' {gpus}: {problem}."


def input_problem(cfg: DictConfig) -> tuple[str, str] | None:
    """First problem with the inputs of the selected stages, as ``(key, message)``; else None."""
    for name in ("train_teacher", "distill"):
        if name in cfg.stages and (found := _gpus_problem(cfg, name)) is not None:
            return found
    if "train_teacher" in cfg.stages and (found := _jump_problem(cfg.train_teacher)) is not None:
        return found
    if "train_teacher" in cfg.stages and (found := _calibrated_problem(cfg.train_teacher)) is not None:
        return found
    if "train_teacher" in cfg.stages and (found := _material_problem(cfg.train_teacher)) is not None:
        return found
    if "train_teacher" in cfg.stages and (found := _task_problem(cfg.train_teacher)) is not None:
        return found
    if "mismatch" in cfg.stages and (found := _mismatch_problem(cfg.mismatch)) is not None:
        return found
    if "analyze_logs" in cfg.stages:
        return _analyze_logs_problem(cfg.analyze_logs)
    return None
