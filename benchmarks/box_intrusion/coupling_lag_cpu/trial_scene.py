# SPDX-License-Identifier: Apache-2.0
"""The DP-mapping round box probes' shared setup: one box-study trial as an ``MpmBoxScene`` on CPU (not yet run)."""

from __future__ import annotations

from dataclasses import replace

from gmloco.contact import MaterialCfg
from gmloco.eval.box.study import BoxStudyCfg, sample_media
from gmloco.eval.mpm.box_scene import MpmBoxScene, MpmBoxSceneCfg, MpmSolverCfg


def trial_scene(
    trial: int, duration: float, solver: MpmSolverCfg | None = None, at_rest: bool = False
) -> tuple[MaterialCfg, MpmBoxScene]:
    """Return the medium of study trial ``trial`` (seed 0) and its scene with the semi-implicit box integrator.

    Args:
        trial: Box-study trial index (its medium does not depend on the study's size).
        duration: Simulated time [s].
        solver: MPM numerics (default: 5 cm voxels, 250 iterations, 10 ms frames x 4 rigid substeps).
        at_rest: Place the box on the surface without drop or velocity instead of the study's forward launch.
    """
    study = BoxStudyCfg()
    media = sample_media(replace(study, num_trials=trial + 1))
    mat = MaterialCfg(*(float(media[k][trial]) for k in ("bulk_density", "packing", "mu_int", "mu_surf")))
    box = replace(study.box, velocity=(0.0, 0.0), drop_height=0.0) if at_rest else study.box
    cfg = MpmBoxSceneCfg(
        box=replace(box, duration=duration),
        bed=study.bed,
        solver=solver or MpmSolverCfg(voxel_size=0.05, max_iterations=250),
        device="cpu",
        rigid_solver="semi_implicit",
    )
    return mat, MpmBoxScene(cfg, [mat])
