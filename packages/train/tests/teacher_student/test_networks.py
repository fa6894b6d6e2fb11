# SPDX-License-Identifier: Apache-2.0
"""Tests of the encoder building blocks: KL closed form, reparameterisation, TCN shapes, history layouts."""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch

from gmloco.train.teacher_student.networks import (
    GaussianEncoder,
    TemporalConvEncoder,
    history_to_time_major,
    kl_standard_normal,
    reparameterize,
)


def test_kl_matches_hand_computed_case() -> None:
    """KL(N(mu, sigma^2) || N(0, 1)) on a hand case, and zero at the prior."""
    # dim 1: mu = 1, sigma^2 = 1   -> 0.5 * (1 + 1 - 1 - 0)            = 0.5
    # dim 2: mu = 0, sigma^2 = e^2 -> 0.5 * (0 + e^2 - 1 - 2)          = 0.5 * (e^2 - 3)
    mu = torch.tensor([[1.0, 0.0]])
    logvar = torch.tensor([[0.0, 2.0]])
    expected = 0.5 + 0.5 * (math.e**2 - 3.0)
    np.testing.assert_allclose(kl_standard_normal(mu, logvar).numpy(), [expected], rtol=1e-6)
    np.testing.assert_allclose(kl_standard_normal(torch.zeros(4, 3), torch.zeros(4, 3)).numpy(), np.zeros(4))


def test_kl_matches_torch_distributions() -> None:
    """The closed form equals torch's KL between Normals, summed over latent dims."""
    torch.manual_seed(0)
    mu, logvar = torch.randn(6, 4), torch.randn(6, 4)
    q = torch.distributions.Normal(mu, torch.exp(0.5 * logvar))
    p = torch.distributions.Normal(torch.zeros_like(mu), torch.ones_like(mu))
    ref = torch.distributions.kl_divergence(q, p).sum(-1)
    np.testing.assert_allclose(kl_standard_normal(mu, logvar).numpy(), ref.numpy(), rtol=1e-5, atol=1e-6)


def test_reparameterize_is_differentiable_and_has_the_right_moments() -> None:
    """Samples carry gradients to mu and logvar and have mean mu, std exp(logvar / 2)."""
    torch.manual_seed(0)
    mu = torch.full((20000, 1), 2.0, requires_grad=True)
    logvar = torch.full((20000, 1), math.log(0.25), requires_grad=True)
    z = reparameterize(mu, logvar)
    z.sum().backward()
    assert mu.grad is not None and logvar.grad is not None
    # standard error of the mean = 0.5 / sqrt(20000) ~ 0.0035; 5 sigma tolerance
    np.testing.assert_allclose(z.mean().item(), 2.0, atol=0.02)
    np.testing.assert_allclose(z.std().item(), 0.5, atol=0.02)


def test_gaussian_encoder_shapes() -> None:
    """The encoder maps [B, in] to mu and logvar of shape [B, latent]."""
    enc = GaussianEncoder(10, 4, (32, 16), "elu")
    mu, logvar = enc(torch.randn(7, 10))
    assert mu.shape == logvar.shape == (7, 4)


def test_tcn_shapes_for_the_default_fifty_frame_history() -> None:
    """Three convolutions over N = 50 frames (50 -> 11 -> 7 -> 3) then an MLP to the latent."""
    tcn = TemporalConvEncoder(50, 96, 16, (32, 32, 32), (8, 5, 5), (4, 1, 1), (128,), "elu")
    assert sum(isinstance(m, torch.nn.Conv1d) for m in tcn.modules()) == 3
    assert tcn.flat_dim == 32 * 3
    assert tcn(torch.randn(2, 50, 96)).shape == (2, 16)


def test_tcn_refuses_a_too_short_history() -> None:
    """A history shorter than the kernels is a configuration error."""
    with pytest.raises(ValueError, match="too short"):
        TemporalConvEncoder(4, 3, 2, (4, 4, 4), (3, 3, 3), (1, 1, 1), (8,), "elu")


def test_history_term_major_layout_is_rearranged_time_major() -> None:
    """Rearrange mjlab's flattened term-major history [A_t0..A_tN-1, B_t0..] becomes [B, N, dA + dB]."""
    n, d_a, d_b = 3, 2, 1
    frames = torch.arange(n * (d_a + d_b), dtype=torch.float32).reshape(1, n, d_a + d_b)  # ground truth
    flat = torch.cat([frames[:, :, :d_a].reshape(1, -1), frames[:, :, d_a:].reshape(1, -1)], dim=-1)
    np.testing.assert_array_equal(history_to_time_major(flat, n, (d_a, d_b)).numpy(), frames.numpy())
    np.testing.assert_array_equal(history_to_time_major(frames, n, None).numpy(), frames.numpy())
    with pytest.raises(ValueError, match="history_term_dims"):
        history_to_time_major(flat, n, None)
