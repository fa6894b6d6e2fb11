# SPDX-License-Identifier: Apache-2.0
"""GPU lists and ranks of data-parallel training (``gmloco.train.multi_gpu``), without starting any worker."""

from __future__ import annotations

from pathlib import Path

import pytest

from gmloco.train.multi_gpu import GpuSelectionError, RankInfo, any_rank, check_gpus, gpus_problem, rank_info


@pytest.mark.parametrize(
    ("gpus", "words"),
    [
        ([0, 1, 0], "[0] are named more than once"),
        ([1, -1], "negative GPU ids [-1]"),
        ([0, 4], "GPU ids [4] do not exist: this machine has 2 CUDA device(s)"),
    ],
)
def test_bad_gpu_lists_are_named(gpus: list[int], words: str) -> None:
    """Duplicates, negative ids and ids past the device count are refused with a clause naming them."""
    problem = gpus_problem(gpus, device_count=2)
    assert problem is not None and words in problem
    with pytest.raises(GpuSelectionError, match="bad value for 'gpus'"):
        check_gpus(gpus, device_count=2)


def test_good_gpu_lists_pass() -> None:
    """Distinct existing ids pass; an empty list (train on ``device``) passes even without CUDA."""
    assert gpus_problem([1, 0], device_count=2) is None
    check_gpus([0, 1], device_count=2)
    check_gpus([], device_count=0)


def test_gpus_without_cuda_is_refused() -> None:
    """A machine without CUDA refuses any GPU list and says how to train on the configured device."""
    problem = gpus_problem([0], device_count=0)
    assert problem is not None and "no CUDA device" in problem and "leave gpus empty" in problem


def test_train_refuses_gpus_without_cuda_before_writing(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """train() with ``gpus`` on a machine without CUDA raises before the run directory is created."""
    import gmloco.train.multi_gpu as multi_gpu
    from gmloco.train import TrainRunCfg, train

    monkeypatch.setattr(multi_gpu, "cuda_device_count", lambda: 0)
    run_dir = tmp_path / "run"
    with pytest.raises(GpuSelectionError, match="no CUDA device"):
        train(TrainRunCfg(gpus=(0, 1), run_dir=str(run_dir)))
    assert not run_dir.exists()


def test_rank_info_reads_the_rsl_rl_variables(monkeypatch: pytest.MonkeyPatch) -> None:
    """RANK / LOCAL_RANK / WORLD_SIZE give the rank; without them the process is the one writing rank."""
    for name in ("RANK", "LOCAL_RANK", "WORLD_SIZE"):
        monkeypatch.delenv(name, raising=False)
    assert rank_info() == RankInfo(0, 0, 1) and rank_info().writes and not rank_info().distributed
    monkeypatch.setenv("RANK", "3")
    monkeypatch.setenv("LOCAL_RANK", "1")
    monkeypatch.setenv("WORLD_SIZE", "4")
    ranks = rank_info()
    assert ranks == RankInfo(3, 1, 4) and ranks.distributed and not ranks.writes


def test_any_rank_outside_a_process_group_is_the_flag() -> None:
    """Without a process group the stop decision is this process's own."""
    assert any_rank(True, "cpu") and not any_rank(False, "cpu")


def test_visible_devices_maps_ids_through_cuda_visible_devices(monkeypatch: pytest.MonkeyPatch) -> None:
    """The ids index ``CUDA_VISIBLE_DEVICES`` (mjlab's ``select_gpus``): [0, 1] of "3,5,6" are GPUs 3 and 5."""
    from gmloco.train.multi_gpu import visible_devices

    monkeypatch.setenv("CUDA_VISIBLE_DEVICES", "3,5,6")
    assert visible_devices([0, 1]) == "3,5" and visible_devices([2]) == "6"


def test_train_hands_several_gpus_to_the_launcher(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """train() with two GPUs checks the run directory, sets a damaged checkpoint aside, then starts two ranks."""
    import gmloco.train.multi_gpu as multi_gpu
    import gmloco.train.training as training
    from gmloco.train import TrainRunCfg, train

    monkeypatch.setattr(multi_gpu, "cuda_device_count", lambda: 2)
    monkeypatch.setattr(training, "visible_devices", lambda gpus: ",".join(str(g) for g in gpus))
    launched: list[tuple] = []
    monkeypatch.setattr(training, "launch_ranks", lambda *a: launched.append(a) or {"iteration": 0.0})
    run_dir = tmp_path / "run"
    run_dir.mkdir()
    import torch

    torch.save({"iter": 3}, run_dir / "model_3.pt")
    (run_dir / "model_5.pt").write_bytes(b"truncated")
    metrics = train(TrainRunCfg(gpus=(0, 1), run_dir=str(run_dir)))
    ((fn, cfg, workers, visible, log_dir),) = launched
    assert fn is training.train_rank and cfg.gpus == (0, 1) and workers == 2 and visible == "0,1"
    assert log_dir == str(run_dir / "torchrunx")
    assert (run_dir / "train_cfg.json").exists() and (run_dir / "model_5.pt.corrupt").exists()
    assert metrics["corrupt_checkpoints_skipped"] == 1.0


def _rank_env(names: tuple[str, ...]) -> dict[str, str | None]:
    """The worker's values of ``names`` (run in each torchrunx worker)."""
    import os

    return {name: os.environ.get(name) for name in names}


@pytest.mark.slow
def test_launch_ranks_sets_the_rsl_rl_variables(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Two workers get RANK / LOCAL_RANK / WORLD_SIZE from torchrunx; their logs go to this launch's folder."""
    import os
    import sys

    import cloudpickle

    from gmloco.train.multi_gpu import launch_ranks

    cloudpickle.register_pickle_by_value(sys.modules[__name__])  # the workers cannot import a test module
    monkeypatch.delenv("TORCHRUNX_LOG_DIR", raising=False)
    names = ("RANK", "LOCAL_RANK", "WORLD_SIZE", "CUDA_VISIBLE_DEVICES")
    seen = launch_ranks(_rank_env, names, 2, "", str(tmp_path / "logs"))
    assert seen == {"RANK": "0", "LOCAL_RANK": "0", "WORLD_SIZE": "2", "CUDA_VISIBLE_DEVICES": ""}
    assert list((tmp_path / "logs").rglob("*.log"))
    assert "TORCHRUNX_LOG_DIR" not in os.environ
