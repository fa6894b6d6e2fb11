# SPDX-License-Identifier: Apache-2.0
"""Materials held out from training, and the metrics of the decoded stiffness eta on them.

Issue 6 asks how well the student's decoded eta tracks the true eta on materials never seen in training: a
rectangle of (rho_c, mu_int) that the training DR never draws, plus the named presets. The default rectangle sits
inside the DR box (an interpolation test, not an extrapolation one) and away from every named preset:

=============== ================= ============ ===========================
region          rho_c [kg/m^3]    mu_int [-]   eta = xi / xi_max (linear)
=============== ================= ============ ===========================
held out        2000 .. 2400      0.65 .. 0.80 0.17 .. 0.38
=============== ================= ============ ===========================

Under the training DR (rho_c = packing * bulk density, U[0.5, 1] x U[1000, 3000]; mu_int U[0.2, 0.9]) about 3.5 %
of draws fall into it. How training avoids it: :func:`redraw_outside` (used by the DR's material draw) keeps rho_c
and re-draws mu_int uniformly over the rest of its range for the draws that fall inside, so the rectangle has zero
probability and no host synchronisation is needed.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, fields, replace
from typing import TYPE_CHECKING

import numpy as np
import torch

if TYPE_CHECKING:
    from gmloco.train.config import GranularTaskCfg

__all__ = ["DEFAULT_HELD_OUT", "HeldOutRegionCfg", "r2_score", "redraw_outside", "with_held_out"]


@dataclass(frozen=True)
class HeldOutRegionCfg:
    """A rectangle of (rho_c, mu_int) that training never samples."""

    rho_c: tuple[float, float] = (2000.0, 2400.0)
    """Critical density range [kg/m^3] (inclusive)."""
    mu_int: tuple[float, float] = (0.65, 0.80)
    """Internal friction range [-] (inclusive)."""

    def __post_init__(self) -> None:
        """Refuse empty or inverted ranges."""
        if not (self.rho_c[0] < self.rho_c[1] and self.mu_int[0] < self.mu_int[1]):
            raise ValueError(f"held-out region needs low < high, got rho_c={self.rho_c}, mu_int={self.mu_int}")

    def contains(
        self, rho_c: np.ndarray | torch.Tensor, mu_int: np.ndarray | torch.Tensor
    ) -> np.ndarray | torch.Tensor:
        """Return whether each (rho_c, mu_int) lies in the rectangle (numpy or torch, elementwise)."""
        (r0, r1), (m0, m1) = self.rho_c, self.mu_int
        return (rho_c >= r0) & (rho_c <= r1) & (mu_int >= m0) & (mu_int <= m1)

    def grid(self, n_rho: int, n_mu: int, margin: float = 0.05) -> tuple[np.ndarray, np.ndarray]:
        """Return a ``n_rho x n_mu`` grid of (rho_c, mu_int) inside the rectangle, ``margin`` of each side left out.

        Returns:
            ``(rho_c, mu_int)``, each ``[n_rho * n_mu]`` (rho_c-major).
        """
        (r0, r1), (m0, m1) = self.rho_c, self.mu_int
        dr, dm = margin * (r1 - r0), margin * (m1 - m0)
        rho = np.linspace(r0 + dr, r1 - dr, n_rho) if n_rho > 1 else np.array([0.5 * (r0 + r1)])
        mu = np.linspace(m0 + dm, m1 - dm, n_mu) if n_mu > 1 else np.array([0.5 * (m0 + m1)])
        rr, mm = np.meshgrid(rho, mu, indexing="ij")
        return rr.ravel(), mm.ravel()


DEFAULT_HELD_OUT = HeldOutRegionCfg()
"""The held-out rectangle used by training (DR) and by the held-out evaluation."""


def redraw_outside(
    region: HeldOutRegionCfg, rho_c: torch.Tensor, mu_int: torch.Tensor, mu_int_range: tuple[float, float]
) -> torch.Tensor:
    """Return ``mu_int`` with every draw inside ``region`` re-drawn uniformly from ``mu_int_range`` minus the region.

    rho_c is kept, so the rho_c marginal is the DR's; given a rho_c in the region's rho_c range, mu_int is uniform
    over ``[lo, m0) U (m1, hi]``. Runs on the tensors' device without host synchronisation.

    Args:
        region: The held-out rectangle.
        rho_c: Drawn critical densities [kg/m^3], ``[n]``.
        mu_int: Drawn internal friction [-], ``[n]``.
        mu_int_range: The DR range of mu_int ``(lo, hi)``; must contain the region's mu_int range.

    Raises:
        ValueError: If the region's mu_int range is not inside ``mu_int_range``.
    """
    lo, hi = mu_int_range
    m0, m1 = region.mu_int
    if not (lo <= m0 and m1 <= hi) or (m1 - m0) >= (hi - lo):
        raise ValueError(f"held-out mu_int {region.mu_int} must lie inside the DR range {mu_int_range}")
    gap = m1 - m0
    u = lo + (hi - lo - gap) * torch.rand_like(mu_int)
    alt = torch.where(u < m0, u, u + gap)
    return torch.where(region.contains(rho_c, mu_int), alt, mu_int)  # type: ignore[arg-type]


def r2_score(predicted: Sequence[float] | np.ndarray, target: Sequence[float] | np.ndarray) -> float:
    """Coefficient of determination R^2 = 1 - sum (y - y_hat)^2 / sum (y - mean y)^2 (nan if y is constant)."""
    y_hat = np.asarray(predicted, dtype=np.float64).ravel()
    y = np.asarray(target, dtype=np.float64).ravel()
    ss_tot = float(np.sum((y - y.mean()) ** 2))
    if y.size == 0 or ss_tot == 0.0:
        return float("nan")
    return 1.0 - float(np.sum((y - y_hat) ** 2)) / ss_tot


def with_held_out(task: GranularTaskCfg, region: HeldOutRegionCfg = DEFAULT_HELD_OUT) -> GranularTaskCfg:
    """Return ``task`` whose material DR never draws ``region`` (``MaterialRangeCfg.held_out_rho_c / _mu_int``).

    Raises:
        NotImplementedError: If ``MaterialRangeCfg`` has no held-out fields (the DR cannot leave the region out).
        ValueError: If the region's mu_int range is not inside the task's DR range (e.g. the deep terrain's).
    """
    material = task.material
    if "held_out_rho_c" not in {f.name for f in fields(material)}:
        raise NotImplementedError("MaterialRangeCfg has no held_out_rho_c / held_out_mu_int: the DR cannot skip it")
    lo, hi = material.mu_int
    if not lo <= region.mu_int[0] < region.mu_int[1] <= hi:
        raise ValueError(f"held-out mu_int {region.mu_int} is outside the task's DR range {material.mu_int}")
    held = replace(material, held_out_rho_c=region.rho_c, held_out_mu_int=region.mu_int)  # type: ignore[call-arg]
    return replace(task, material=held)
