# SPDX-License-Identifier: Apache-2.0
"""Write the shipped jump references and their manifest: ``python -m gmloco.train.tasks.g1_jump.make_reference``.

Synthesizes every reference of :func:`shipped_references` (CoM / foot profile, whole-body IK on mjlab's G1
MuJoCo model), runs the rigid-ground plausibility checks on it, and writes ``data/jump_<name>.npz`` plus
``data/manifest.json`` (configs, versions, check results, peak torques against the effort limits) atomically.

Options: ``--out DIR`` writes somewhere else (default: the package's ``data/`` folder); ``--check`` rebuilds in
memory and exits 1 when a shipped file differs from a fresh build by more than 1e-6 rad / m.
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import asdict
from pathlib import Path

import numpy as np

from gmloco.deploy.atomic_io import atomic_write_json
from gmloco.train.tasks.g1_jump.ik import IkCfg, load_g1_model
from gmloco.train.tasks.g1_jump.plausibility import check_plausibility
from gmloco.train.tasks.g1_jump.profile import JumpProfileCfg
from gmloco.train.tasks.g1_jump.reference import (
    REFERENCE_DIR,
    JumpSynthesisCfg,
    load_reference,
    save_reference,
    synthesize_reference,
)

__all__ = ["main", "shipped_references"]

MODULE = "gmloco.train.tasks.g1_jump.make_reference"
"""Module path written into the manifest."""


def shipped_references() -> list[JumpSynthesisCfg]:
    """The references the package ships: a vertical jump (12 cm CoM rise in flight) and a 20 cm forward jump.

    Both keep every joint within the G1's effort, velocity and position limits. The zero angular momentum about
    the CoM from push-off to landing is balanced by turning the whole trunk on the hips (waist and arms cost 100
    and 0.3 times the leg motion in the IK); a take-off well below the standing CoM height, a 0.30 s push-off
    and a foot lift spread over half the flight keep the legs' swing in flight, which the trunk must balance,
    small. The forward jump leans the pelvis 0.7 rad into the push with the torso 0.25 rad back on the waist
    (a shorter lever of the torso's weight) and rises 8 cm from a take-off 10 cm low: the feet's forward swing
    in flight turns the trunk, and a 12 cm rise or 25 cm forward needs more than the waist pitch's 50 N m.
    """
    ik = IkCfg(weight_waist=100.0, weight_arms=0.3)
    lift = {"foot_lift_fraction": 0.5, "t_push": 0.30}
    return [
        JumpSynthesisCfg(
            profile=JumpProfileCfg(name="vertical", apex_rise=0.12, takeoff_rise=-0.08, foot_lift=0.07, **lift), ik=ik
        ),
        JumpSynthesisCfg(
            profile=JumpProfileCfg(
                name="forward", distance=0.20, takeoff_rise=-0.10, foot_lift=0.03, t_land=0.40, **lift
            ),
            pelvis_lean=0.7,
            waist_lean=-0.25,
            ik=ik,
        ),
    ]


def _versions() -> dict[str, str]:
    """Versions of the packages that made the references."""
    from importlib.metadata import version

    return {name: version(name) for name in ("mujoco", "mjlab", "numpy")}


def _write_json(path: Path, payload: dict[str, object]) -> None:
    """Write ``payload`` as JSON to ``path`` atomically."""
    atomic_write_json(path, payload, newline=True)


def build(out: Path) -> dict[str, object]:
    """Synthesize, check and write every shipped reference to ``out``; returns the manifest."""
    model = load_g1_model()
    entries = {}
    for cfg in shipped_references():
        ref, ik_error = synthesize_reference(cfg, model)
        report = check_plausibility(model, ref)
        path = out / f"jump_{ref.name}.npz"
        save_reference(ref, path)
        entries[ref.name] = {
            "file": path.name,
            "samples": int(ref.qpos.shape[0]),
            "fps": ref.fps,
            "duration_s": ref.duration,
            "takeoff_s": ref.t_takeoff,
            "touchdown_s": ref.t_touchdown,
            "ik_max_task_error_m": ik_error,
            "synthesis": asdict(cfg),
            "plausibility": report.to_dict(),
        }
    manifest = {
        "command": f"python -m {MODULE}",
        "method": (
            "quintic CoM height per phase (continuous force, zero at take-off and touch-down), ballistic flight, "
            "horizontal force parallel to the vertical one; min-jerk foot lift; whole-body IK on mjlab's G1 MJCF "
            "(CoM and soles as primary tasks; from push-off to the end of the landing also zero angular momentum "
            "about the CoM, solved with a weighted pseudo-inverse that makes waist and arm motion costlier so the "
            "trunk turns on the hips, no pelvis task; pelvis lean primary during crouch and recovery; posture, "
            "with the waist pitch following the lean, in the null space); velocities by central differences; "
            "rigid-ground inverse dynamics (mj_inverse, minimum-norm sole wrenches) for the plausibility report, "
            "every joint against its effort limit"
        ),
        "model": "mjlab asset_zoo unitree_g1 g1.xml (MuJoCo Menagerie lineage, BSD-3-Clause) + mjlab G1 armature",
        "versions": _versions(),
        "references": entries,
    }
    _write_json(out / "manifest.json", manifest)
    return manifest


def _check(out: Path) -> int:
    """Compare the files in ``out`` with a fresh build; 0 if they agree."""
    model = load_g1_model()
    status = 0
    for cfg in shipped_references():
        fresh, _ = synthesize_reference(cfg, model)
        shipped = load_reference(out / f"jump_{fresh.name}.npz")
        diff = float(np.abs(fresh.qpos - shipped.qpos).max()) if fresh.qpos.shape == shipped.qpos.shape else np.inf
        print(f"{fresh.name}: max |qpos difference| = {diff:.2e}")
        status |= int(diff > 1e-6)
    return status


def main(argv: list[str] | None = None) -> int:
    """Command-line entry; returns the exit code (2 on bad arguments)."""
    parser = argparse.ArgumentParser(prog=f"python -m {MODULE}", description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--out", type=Path, default=REFERENCE_DIR, help="output folder (default: package data)")
    parser.add_argument("--check", action="store_true", help="compare the files in --out with a fresh build")
    args = parser.parse_args(argv)
    if args.out.exists() and not args.out.is_dir():
        print(f"error: --out {args.out} is a file; pass a folder", file=sys.stderr)
        return 2
    args.out.mkdir(parents=True, exist_ok=True)
    if args.check:
        return _check(args.out)
    manifest = build(args.out)
    for name, entry in manifest["references"].items():  # type: ignore[union-attr]
        p = entry["plausibility"]
        print(f"{name}: {entry['samples']} samples, max torque / effort limit {p['max_torque_ratio']:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
