# SPDX-License-Identifier: Apache-2.0
"""The held-out (rho_c, mu_int) region: membership, the DR re-draw that avoids it, and the R^2 metrics."""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch

import gmloco.contact as gc
from gmloco.contact.materials import DR_RANGES_CODE
from gmloco.train.teacher_student import DEFAULT_HELD_OUT, HeldOutRegionCfg, r2_score, redraw_outside
from gmloco.train.teacher_student.teacher_ppo import batch_r2


def _dr_draw(n: int, gen: torch.Generator) -> tuple[torch.Tensor, torch.Tensor]:
    """rho_c = packing * bulk density and mu_int, as the training DR draws them (GM-Loco code ranges)."""
    u = lambda lo_hi: lo_hi[0] + (lo_hi[1] - lo_hi[0]) * torch.rand(n, generator=gen, dtype=torch.float64)  # noqa: E731
    return u(DR_RANGES_CODE.packing) * u(DR_RANGES_CODE.bulk_density), u(DR_RANGES_CODE.mu_int)


def test_named_presets_lie_outside_and_the_grid_inside_the_region() -> None:
    """Presets are a separate test set; every grid point of the held-out evaluation is inside the rectangle."""
    for name, p in gc.MATERIAL_PRESETS.items():
        assert not DEFAULT_HELD_OUT.contains(np.asarray(p.rho_c), np.asarray(p.mu_int)), name
    rho, mu = DEFAULT_HELD_OUT.grid(3, 4)
    assert rho.shape == mu.shape == (12,)
    assert DEFAULT_HELD_OUT.contains(rho, mu).all()
    assert len(set(zip(rho.tolist(), mu.tolist(), strict=True))) == 12


def test_redraw_leaves_no_draw_inside_and_keeps_the_rest() -> None:
    """After the re-draw no sample is inside; rho_c and the samples outside are untouched; ~3.5 % are moved."""
    gen = torch.Generator().manual_seed(0)
    rho, mu = _dr_draw(200_000, gen)
    torch.manual_seed(1)
    new_mu = redraw_outside(DEFAULT_HELD_OUT, rho, mu, DR_RANGES_CODE.mu_int)
    inside = torch.as_tensor(DEFAULT_HELD_OUT.contains(rho, mu))
    assert not DEFAULT_HELD_OUT.contains(rho, new_mu).any()
    torch.testing.assert_close(new_mu[~inside], mu[~inside], rtol=0.0, atol=0.0)
    assert 0.025 < inside.double().mean().item() < 0.045  # the module docstring's "about 3.5 %"
    lo, hi = DR_RANGES_CODE.mu_int
    assert ((new_mu >= lo) & (new_mu <= hi)).all()


def test_redraw_is_uniform_over_the_rest_of_the_mu_int_range() -> None:
    """Given rho_c in the region's range, mu_int is U([0.2, 0.65) U (0.8, 0.9]): P(mu < 0.65) = 0.45 / 0.55."""
    n = 100_000
    rho = torch.full((n,), 2200.0, dtype=torch.float64)
    mu = torch.full((n,), 0.7, dtype=torch.float64)  # all inside: every one is re-drawn
    torch.manual_seed(0)
    new_mu = redraw_outside(DEFAULT_HELD_OUT, rho, mu, DR_RANGES_CODE.mu_int)
    frac_low = (new_mu < 0.65).double().mean().item()
    # Binomial standard error sqrt(p (1 - p) / n) = 1.2e-3; 5 sigma.
    np.testing.assert_allclose(frac_low, 0.45 / 0.55, atol=5 * math.sqrt(0.818 * 0.182 / n))
    np.testing.assert_allclose(new_mu[new_mu < 0.65].mean().item(), 0.425, atol=5e-3)  # midpoint of [0.2, 0.65)


def test_region_must_be_inside_the_dr_range_and_non_empty() -> None:
    """A held-out mu_int range outside the DR's, or an inverted range, is refused."""
    with pytest.raises(ValueError, match="inside the DR range"):
        redraw_outside(HeldOutRegionCfg(mu_int=(0.8, 0.95)), torch.ones(1), torch.ones(1), (0.2, 0.9))
    with pytest.raises(ValueError, match="low < high"):
        HeldOutRegionCfg(rho_c=(2400.0, 2000.0))


def test_r2_hand_computed() -> None:
    """R^2 by hand: y = (1, 2, 3), y_hat = (1, 2, 4): SS_res = 1, SS_tot = 2 -> R^2 = 0.5; constant y -> nan."""
    assert r2_score([1.0, 2.0, 4.0], [1.0, 2.0, 3.0]) == pytest.approx(0.5)
    assert math.isnan(r2_score([1.0, 2.0], [3.0, 3.0]))
    pred, target = torch.tensor([[1.0], [2.0], [4.0]]), torch.tensor([[1.0], [2.0], [3.0]])
    assert batch_r2(pred, target) == pytest.approx(0.5)
    assert math.isnan(batch_r2(pred, torch.ones(3, 1)))


def test_material_writer_never_draws_the_held_out_region() -> None:
    """The training DR (MaterialWriter over a real contact model) with the region set draws nothing inside it."""
    from gmloco.train.config import MaterialRangeCfg

    if "held_out_rho_c" not in MaterialRangeCfg.__dataclass_fields__:
        pytest.skip("MaterialRangeCfg has no held_out_rho_c / held_out_mu_int yet (DR change pending)")
    from gmloco.train.contact_models import MaterialWriter

    num_envs = 4096
    model = gc.make_contact_model(gc.ContactRFT3DCfg(), num_envs, 2, "cpu")
    region = DEFAULT_HELD_OUT
    ranges = MaterialRangeCfg(held_out_rho_c=region.rho_c, held_out_mu_int=region.mu_int)  # type: ignore[call-arg]
    writer = MaterialWriter(model, ranges, "cpu")
    torch.manual_seed(0)
    ids = torch.arange(num_envs)
    inside = 0
    for _ in range(5):
        writer.draw(ids)
        rho, mu = writer.views["rho_c"], writer.views["mu_int"]
        inside += int(region.contains(rho, mu).sum())
        assert ((mu >= 0.2) & (mu <= 0.9)).all()
    assert inside == 0  # ~3.5 % of 20,480 draws (~700) would be inside without the re-draw


def test_with_held_out_sets_the_dr_fields_or_refuses() -> None:
    """The task's DR gets the rectangle; a DR whose mu_int range excludes it (deep sand) is refused."""
    from dataclasses import replace

    from gmloco.train.config import GranularTaskCfg, MaterialRangeCfg
    from gmloco.train.teacher_student.heldout import with_held_out

    task = GranularTaskCfg()
    if "held_out_rho_c" not in MaterialRangeCfg.__dataclass_fields__:
        with pytest.raises(NotImplementedError, match="held_out_rho_c"):
            with_held_out(task)
        return
    held = with_held_out(task).material
    assert (held.held_out_rho_c, held.held_out_mu_int) == (DEFAULT_HELD_OUT.rho_c, DEFAULT_HELD_OUT.mu_int)  # type: ignore[attr-defined]
    deep = replace(task, material=replace(task.material, mu_int=(0.1, 0.4)))
    with pytest.raises(ValueError, match="outside the task's DR range"):
        with_held_out(deep)
