# SPDX-License-Identifier: Apache-2.0
"""MaterialWriter: every drawn, preset or pinned material reaches the contact model with its eta and eta_log."""

from __future__ import annotations

import numpy as np
import pytest
import torch

import gmloco.contact as gc
from gmloco.train.config import MaterialRangeCfg
from gmloco.train.contact_models import MaterialWriter

W = 8


def _assert_eta_follows(model: gc.ContactModel) -> None:
    """Eta and eta_log of every world equal materials.eta of its (rho_c, mu_int) (float32 on the device)."""
    rho, mu = model.rho_c.numpy(), model.mu_int.numpy()
    np.testing.assert_allclose(model.eta.numpy(), gc.eta(rho, mu), rtol=1e-5)
    np.testing.assert_allclose(model.eta_log.numpy(), gc.eta(rho, mu, "log"), rtol=1e-5, atol=1e-6)


def test_logged_eta_follows_a_randomized_material() -> None:
    """A uniform DR draw on half the worlds changes their material, and eta_log (the log scale) follows it."""
    model = gc.make_contact_model(gc.ContactRFT3DCfg(), W, 2, "cpu")
    writer = MaterialWriter(model, MaterialRangeCfg(), "cpu")
    before = model.eta_log.numpy().copy()
    torch.manual_seed(0)
    ids = torch.arange(0, W, 2)
    writer.draw(ids)
    assert (model.eta_log.numpy()[ids.numpy()] != before[ids.numpy()]).all()
    np.testing.assert_array_equal(model.eta_log.numpy()[1::2], before[1::2])  # untouched worlds keep theirs
    _assert_eta_follows(model)
    torch.testing.assert_close(writer.eta, torch.as_tensor(model.eta.numpy()))  # the view reads the model


def test_preset_and_pinned_materials_go_the_same_way() -> None:
    """A preset and a pinned material land in the model with eta and eta_log; the cone also gets its sigmas."""
    model = gc.make_contact_model(gc.ContactConeSingleCfg(), W, 2, "cpu")
    writer = MaterialWriter(model, MaterialRangeCfg(preset="poppy_seed"), "cpu")
    writer.draw(torch.arange(W))
    np.testing.assert_allclose(model.mu_int.numpy(), gc.MATERIAL_PRESETS["poppy_seed"].mu_int, rtol=1e-7)
    assert model.sigma_flat.numpy().std() > 0.0
    _assert_eta_follows(model)
    rho, mu, ms = torch.full((W,), 2000.0), torch.linspace(0.2, 0.9, W), torch.full((W,), 0.4)
    writer.pin(rho, mu, ms)
    writer.draw(torch.tensor([3, 5]))
    np.testing.assert_allclose(model.mu_int.numpy()[[3, 5]], mu[[3, 5]].numpy())
    _assert_eta_follows(model)


def test_soft_share_draws_that_share_from_the_soft_range() -> None:
    """soft_share=0.5 puts ~half the draws in soft_rho_c (the product of uniforms alone: ~8 % below 800 kg/m^3)."""
    n = 4000
    model = gc.make_contact_model(gc.ContactRFT3DCfg(), n, 2, "cpu")
    torch.manual_seed(0)
    MaterialWriter(model, MaterialRangeCfg(), "cpu").draw(torch.arange(n))
    plain = model.rho_c.numpy().copy()
    assert 0.05 < (plain < 800.0).mean() < 0.11
    writer = MaterialWriter(model, MaterialRangeCfg(soft_share=0.5, soft_rho_c=(550.0, 750.0)), "cpu")
    writer.draw(torch.arange(n))
    rho = model.rho_c.numpy()
    soft = (rho >= 550.0) & (rho <= 750.0)
    assert 0.5 < soft.mean() < 0.6  # the soft half plus the plain draws that land there anyway
    assert rho.min() >= 500.0 - 1e-3  # nothing below either range
    _assert_eta_follows(model)


@pytest.mark.parametrize(
    ("bad", "field"),
    [
        (MaterialRangeCfg(soft_share=1.5), "soft_share"),
        (MaterialRangeCfg(soft_share=0.2, soft_rho_c=(800.0, 500.0)), "soft_rho_c"),
    ],
)
def test_bad_soft_share_is_refused(bad: MaterialRangeCfg, field: str) -> None:
    """A share outside [0, 1] or an empty soft range is a ValueError naming the field."""
    model = gc.make_contact_model(gc.ContactRFT3DCfg(), W, 2, "cpu")
    with pytest.raises(ValueError, match=field):
        MaterialWriter(model, bad, "cpu")
