# SPDX-License-Identifier: Apache-2.0
"""Export a student policy with its history encoder to ONNX, attach deploy metadata, verify with onnxruntime.

torch and onnxruntime are imported inside the functions (deploy's ``export`` extra), so importing this module
stays light. The model is duck-typed: anything with rsl-rl's ``as_onnx(verbose)`` returning a module with
``input_names``, ``output_names`` and ``get_dummy_inputs()`` (e.g. ``gmloco.train.teacher_student.StudentActor``).

rsl-rl's stock ``MLPModel.as_onnx`` copies only the normalizer and the MLP; on a model that also owns an encoder
that export would silently drop it. :func:`check_export_keeps_encoder` refuses such a model before exporting, and
the onnxruntime parity check afterwards catches any other mismatch.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from gmloco.deploy.export.metadata import PolicyMetadata, write_policy_metadata

if TYPE_CHECKING:
    import torch

__all__ = ["EncoderDroppedError", "ParityError", "check_export_keeps_encoder", "export_policy_onnx", "verify_parity"]

REQUIRED_INPUTS = ("obs", "history")
"""ONNX input names of a student policy: the current frame and the history."""


class EncoderDroppedError(ValueError):
    """The export wrapper would leave out part of the policy (typically the history encoder)."""


class ParityError(AssertionError):
    """onnxruntime output differs from the torch export wrapper beyond tolerance."""


def _tensor_numel(module: torch.nn.Module, skip: str | None = None) -> dict[str, int]:
    """Return numel of parameters + buffers per top-level child (``skip``: a child to leave out)."""
    counts: dict[str, int] = {}
    for name, t in [*module.named_parameters(), *module.named_buffers()]:
        child = name.split(".", 1)[0]
        if child != skip:
            counts[child] = counts.get(child, 0) + t.numel()
    return counts


def check_export_keeps_encoder(model: torch.nn.Module, wrapper: torch.nn.Module) -> None:
    """Refuse an export wrapper that has no history input or fewer weights than the policy.

    The policy's weights are counted without its ``distribution`` (action noise is not exported).

    Raises:
        EncoderDroppedError: If ``wrapper`` lacks an ``obs``/``history`` input or holds fewer tensors than ``model``.
    """
    names = list(getattr(wrapper, "input_names", []))
    if any(n not in names for n in REQUIRED_INPUTS):
        raise EncoderDroppedError(
            f"{type(model).__name__}.as_onnx() gives inputs {names}, not {list(REQUIRED_INPUTS)}: the history encoder "
            "would be dropped. Override as_onnx() so the wrapper takes the history (see StudentActor)."
        )
    model_counts, wrapper_counts = _tensor_numel(model, skip="distribution"), _tensor_numel(wrapper)
    if sum(wrapper_counts.values()) < sum(model_counts.values()):
        missing = sorted(set(model_counts) - set(wrapper_counts))
        raise EncoderDroppedError(
            f"{type(model).__name__}.as_onnx() keeps {sum(wrapper_counts.values())} of "
            f"{sum(model_counts.values())} weights; modules not exported: {missing}."
        )


def export_policy_onnx(
    model: torch.nn.Module,
    path: str | Path,
    metadata: PolicyMetadata,
    *,
    opset: int = 18,
    verify: bool = True,
    atol: float = 1e-5,
) -> Path:
    """Export ``model`` to ``path`` with named inputs ``obs`` and ``history`` and the deploy metadata.

    Args:
        model: Policy with an encoder-aware ``as_onnx`` (checked by :func:`check_export_keeps_encoder`).
        path: Output ``.onnx`` file.
        metadata: Deploy metadata; its layout must be ``"frame_and_history"`` and its history length and frame
            width must match the model's inputs.
        opset: ONNX opset.
        verify: Compare onnxruntime with torch on random inputs (needs onnxruntime).
        atol: Absolute tolerance of the parity check.

    Returns:
        The path written.

    Raises:
        EncoderDroppedError: If the encoder would be dropped.
        ValueError: If the metadata disagrees with the model's input shapes.
        ParityError: If onnxruntime and torch disagree beyond ``atol``.
    """
    import torch

    wrapper = model.as_onnx(verbose=False)  # type: ignore[operator]
    check_export_keeps_encoder(model, wrapper)
    wrapper = wrapper.to("cpu").eval()
    obs, history = wrapper.get_dummy_inputs()
    spec = metadata.observation
    if spec.layout != "frame_and_history" or history.shape[1] != spec.history_length or obs.shape[-1] != spec.obs_dim:
        raise ValueError(
            f"Model takes obs {tuple(obs.shape)} and history {tuple(history.shape)}, metadata says layout "
            f"{spec.layout!r}, obs_dim={spec.obs_dim}, history_length={spec.history_length}."
        )
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    names_in, names_out = list(wrapper.input_names), list(wrapper.output_names)
    torch.onnx.export(
        wrapper,
        (obs, history),
        str(path),
        input_names=names_in,
        output_names=names_out,
        dynamic_axes={n: {0: "batch"} for n in names_in + names_out},
        opset_version=opset,
        dynamo=False,  # the TorchScript exporter, as mjlab uses; keeps the named dynamic batch axis
    )
    write_policy_metadata(path, metadata)
    if verify:
        verify_parity(wrapper, path, atol=atol)
    return path


def verify_parity(wrapper: torch.nn.Module, path: str | Path, atol: float = 1e-5, batch: int = 8) -> float:
    """Run torch and onnxruntime on the same random ``obs``/``history``; return the max abs difference.

    The tolerance scales with the outputs: ``atol * max(1, max |output|)``. Standard-normal probe inputs reach a
    trained policy's normalizer un-normalised (some of its std are ~1e-2), so its outputs run to tens and float32
    rounding with them (a GPU-trained student: 1.7e-5 absolute on outputs of that size). The rollout check on real
    observations (``rollout_parity_check``) keeps an absolute tolerance.

    Raises:
        ParityError: If any output differs by more than ``atol * max(1, max |output|)``.
    """
    import numpy as np
    import onnxruntime as ort
    import torch

    obs0, hist0 = wrapper.get_dummy_inputs()  # type: ignore[operator]
    gen = torch.Generator().manual_seed(0)
    obs = torch.randn(batch, obs0.shape[-1], generator=gen)
    history = torch.randn(batch, *hist0.shape[1:], generator=gen)
    with torch.no_grad():
        ref = wrapper(obs, history)
    ref = [ref] if isinstance(ref, torch.Tensor) else list(ref)
    session = ort.InferenceSession(str(path), providers=["CPUExecutionProvider"])
    got = session.run(None, {"obs": obs.numpy(), "history": history.numpy()})
    err = max(float(np.max(np.abs(g - r.numpy()))) for g, r in zip(got, ref, strict=True))
    scale = max(1.0, *(float(r.abs().max()) for r in ref))
    if err > atol * scale:
        raise ParityError(
            f"onnxruntime vs torch max abs difference {err:.3g} > {atol:.1g} x max(1, max |output| = {scale:.3g}) ({path})."
        )
    return err
