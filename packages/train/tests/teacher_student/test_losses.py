# SPDX-License-Identifier: Apache-2.0
"""Shapes, values and gradients of every teacher and student loss term."""

from __future__ import annotations

import numpy as np
import torch

from gmloco.train.teacher_student.losses import distill_terms, squared_error, surrogate_loss, vae_terms, value_loss


def test_squared_error_hand_case() -> None:
    """mean_b ||x_b - y_b||^2: rows (3, 4) and (0, 0) against zero -> (25 + 0) / 2 = 12.5."""
    x = torch.tensor([[3.0, 4.0], [0.0, 0.0]])
    np.testing.assert_allclose(squared_error(x, torch.zeros_like(x)).item(), 12.5)


def test_surrogate_loss_clips_the_ratio() -> None:
    """Positive advantage: the objective stops growing once the ratio passes 1 + eps."""
    adv = torch.ones(1, 1)
    old = torch.zeros(1, 1)
    # ratio = e^1 = 2.718 > 1.2 -> loss = -1.2 (clipped) ; ratio = e^0.1 = 1.105 -> loss = -1.105
    np.testing.assert_allclose(surrogate_loss(torch.tensor([1.0]), old, adv, 0.2).item(), -1.2, rtol=1e-6)
    np.testing.assert_allclose(surrogate_loss(torch.tensor([0.1]), old, adv, 0.2).item(), -np.exp(0.1), rtol=1e-6)


def test_value_loss_clipped_and_unclipped() -> None:
    """Unclipped: (R - V)^2 ; clipped: max of the raw and the clipped-update error."""
    v, v_old, ret = torch.tensor([[1.0]]), torch.tensor([[0.0]]), torch.tensor([[2.0]])
    np.testing.assert_allclose(value_loss(v, v_old, ret, 0.2, clipped=False).item(), 1.0)
    # clipped value = 0 + clamp(1, -0.2, 0.2) = 0.2 -> (0.2 - 2)^2 = 3.24 > 1
    np.testing.assert_allclose(value_loss(v, v_old, ret, 0.2, clipped=True).item(), 3.24, rtol=1e-6)


def test_vae_terms_shapes_and_gradients() -> None:
    """Reconstruction and KL are scalars; both reach the encoder outputs, reconstruction reaches the decoder."""
    torch.manual_seed(0)
    decoder = torch.nn.Linear(3, 1)
    mu = torch.randn(8, 3, requires_grad=True)
    logvar = torch.randn(8, 3, requires_grad=True)
    terms = vae_terms(torch.rand(8, 1), mu, logvar, decoder)
    assert terms.reconstruction.shape == terms.kl.shape == ()
    (terms.reconstruction + terms.kl).backward()
    assert mu.grad is not None and mu.grad.abs().sum() > 0
    assert logvar.grad is not None and logvar.grad.abs().sum() > 0
    assert decoder.weight.grad is not None and decoder.weight.grad.abs().sum() > 0


def test_vae_reconstruction_uses_the_mean_when_not_sampling() -> None:
    """With sample=False and psi = identity on one dim, the term is mean (eta - mu)^2."""
    decoder = torch.nn.Linear(1, 1, bias=False)
    torch.nn.init.ones_(decoder.weight)
    eta, mu = torch.tensor([[0.5], [1.0]]), torch.tensor([[0.0], [1.0]])
    terms = vae_terms(eta, mu, torch.zeros_like(mu), decoder, sample=False)
    np.testing.assert_allclose(terms.reconstruction.item(), 0.125)  # (0.25 + 0) / 2


def test_distill_terms_shapes_and_gradient_routing() -> None:
    """All three terms are scalars; gradients reach the student only, never the teacher or the frozen psi."""
    torch.manual_seed(0)
    decoder = torch.nn.Sequential(torch.nn.Linear(3, 4), torch.nn.ELU(), torch.nn.Linear(4, 1)).requires_grad_(False)
    a_student = torch.randn(8, 2, requires_grad=True)
    z_student = torch.randn(8, 3, requires_grad=True)
    a_teacher = torch.randn(8, 2, requires_grad=True)
    z_teacher = torch.randn(8, 3, requires_grad=True)
    terms = distill_terms(a_student, a_teacher, z_teacher, z_student, decoder)
    for t in (terms.action, terms.latent, terms.decoded):
        assert t.shape == () and t.item() > 0
    (terms.action + terms.latent + terms.decoded).backward()
    assert a_student.grad is not None and z_student.grad is not None
    assert a_teacher.grad is None and z_teacher.grad is None
    assert all(p.grad is None for p in decoder.parameters())


def test_distill_decoded_term_alone_reaches_the_student_latent() -> None:
    """(psi(z) - psi(z_hat))^2 has a non-zero gradient w.r.t. z_hat through the frozen decoder."""
    decoder = torch.nn.Linear(3, 1).requires_grad_(False)
    z_student = torch.zeros(4, 3, requires_grad=True)
    terms = distill_terms(torch.zeros(4, 2), torch.zeros(4, 2), torch.ones(4, 3), z_student, decoder)
    terms.decoded.backward()
    assert z_student.grad is not None and z_student.grad.abs().sum() > 0
