# SPDX-License-Identifier: Apache-2.0
"""Setup shared by every rigid-body + implicit-MPM scene: the sand model, the MPM solver, the coupled states."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from gmloco.eval.mpm.bed import SandBedCfg, emit_sand_bed
from gmloco.eval.mpm.materials import MpmMaterialCfg, apply_mpm_material

__all__ = ["CoupledStates", "build_sand_model", "make_coupled_states", "make_mpm_solver", "rheology_solver_arg"]


@dataclass
class CoupledStates:
    """Rigid double buffer, rigid control, sand state (own copies of the body arrays) and the sand wrench."""

    state_0: Any
    """Rigid state at the start of a frame."""
    state_1: Any
    """Rigid state scratch for the substeps."""
    control: Any
    """Rigid control (joint targets / forces)."""
    sand_state: Any
    """MPM state; ``body_q`` / ``body_qd`` are the colliders' poses and velocities [m, m/s]."""
    sand_wrench: Any
    """Sand wrench on every rigid body, ``wp.array[wp.spatial_vector]`` [N, N m]."""


def build_sand_model(newton: Any, bed: SandBedCfg, voxel_size: float, mat: MpmMaterialCfg) -> tuple[Any, int]:
    """Return ``(sand model, particle_count)``: particles at the mapped density with the mapped rheology."""
    builder = newton.ModelBuilder()
    newton.solvers.SolverImplicitMPM.register_custom_attributes(builder)
    particle_count = emit_sand_bed(builder, bed, voxel_size, mat.density)
    model = builder.finalize()
    apply_mpm_material(model, mat)
    return model, particle_count


def make_mpm_solver(newton: Any, sand_model: Any, solver: Any, mat: MpmMaterialCfg) -> Any:
    """Return ``SolverImplicitMPM`` configured from an ``MpmSolverCfg`` and the material's critical fraction."""
    config = newton.solvers.SolverImplicitMPM.Config(
        voxel_size=solver.voxel_size,
        max_iterations=solver.max_iterations,
        tolerance=solver.tolerance,
        grid_type=solver.grid_type,
        grid_padding=solver.grid_padding,
        max_active_cell_count=solver.max_active_cell_count,
        strain_basis=solver.strain_basis,
        critical_fraction=mat.critical_fraction,
        solver=rheology_solver_arg(solver.rheology_solver),
    )
    return newton.solvers.SolverImplicitMPM(sand_model, config=config)


def rheology_solver_arg(name: str) -> str | tuple[str, ...]:
    """``SolverImplicitMPM.Config.solver`` from ``MpmSolverCfg.rheology_solver``: ``"cr,gs"`` -> ``("cr", "gs")``."""
    parts = tuple(p.strip() for p in name.split(",") if p.strip())
    if not parts:
        raise ValueError(f"rheology_solver={name!r}: name a solver (e.g. 'auto', 'gs', 'cr,gs')")
    return parts[0] if len(parts) == 1 else parts


def make_coupled_states(newton: Any, wp: Any, model: Any, sand_model: Any) -> CoupledStates:
    """Allocate the states of one coupled scene, rigid state evaluated by forward kinematics."""
    state_0, state_1 = model.state(), model.state()
    newton.eval_fk(model, model.joint_q, model.joint_qd, state_0)
    sand_state = sand_model.state()
    sand_state.body_q = wp.clone(state_0.body_q)
    sand_state.body_qd = wp.clone(state_0.body_qd)
    sand_wrench = wp.zeros(model.body_count, dtype=wp.spatial_vector)
    return CoupledStates(state_0, state_1, model.control(), sand_state, sand_wrench)
