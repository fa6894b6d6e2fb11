# SPDX-License-Identifier: Apache-2.0
"""MPM walks as calibration records: each foot's sole kinematics and sand force along a recorded walk.

The sole experiments load a sole the way a press does; a walking foot lands, rolls, slides and lifts. The MPM
evaluation records every group's first episode (``recordings/<terrain>__<scenario>__v<speed>.mcap``, 50 Hz): the
pelvis pose and twist (``/odometry``), the joint angles and rates, and the sand force on each foot
(``/sim/foot_contact``). Forward kinematics of the G1 model puts each foot's sole box (the box the particles see,
``gmloco.eval.g1.soles.SoleCfg``) where the walk had it, with its velocity, so a walk becomes two
:class:`~gmloco.eval.calibration.protocol.SoleRecord` (left, right) that any sand model can replay
(:func:`gmloco.eval.calibration.fit.replay_forces`) and the fitter can fit (``fit_cli --rate-hz 50``).

Frames from the first one whose pelvis is below ``WalkRecordsCfg.min_pelvis_height`` are dropped: a falling robot
meets the sand with more than its soles. The record's depth is the sole's lowest corner below z = 0, the bed's top
(flat beds only: a rough or transition terrain is refused). The recorded sinkage is the same quantity; forward
kinematics reproduces it (checked on every file, ``WalkRecordsCfg.depth_tolerance``).

    python -m gmloco.eval.calibration.walk_records --material dry_sand --out walks/dry_sand.npz [--force momentum] \
        --recordings results/mpm_eval/table_rows/*/runs/table_td_dry_sand*/recordings/dry_sand__straight__v*.mcap

``--force momentum`` takes each foot's force from the robot's momentum instead of the log
(:mod:`gmloco.eval.calibration.walk_momentum`): single-support frames only, NaN in double support; the force of
recordings made before the scene logged the policy step's mean is aliased.

Exit codes: 0 written, 2 bad input (no or unreadable recording, a terrain of another material or not flat, a file
whose kinematics do not reproduce its recorded sinkage).
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import asdict, dataclass, field, replace
from functools import cache
from pathlib import Path
from typing import Any, Literal

import numpy as np

from gmloco.contact import MATERIAL_PRESETS
from gmloco.deploy.config_cli import field_doc
from gmloco.deploy.g1 import G1_FOOT_BODIES, G1_SOLE_BOX_CENTER, G1_SOLE_BOX_HALF_EXTENTS
from gmloco.eval.calibration.dataset import CalibrationDataset, assign_split, save_dataset
from gmloco.eval.calibration.protocol import SoleProtocolCfg, SoleRecord
from gmloco.eval.calibration.walk_momentum import MomentumForceCfg, foot_forces, momentum_force
from gmloco.eval.g1.soles import SoleCfg, sole_box_corners

__all__ = [
    "WALK_FRAME_DT",
    "WalkRecordsCfg",
    "foot_records",
    "logged_over_momentum",
    "main",
    "walk_dataset",
    "walk_terrain",
]

WALK_FRAME_DT = 0.02
"""Frame time of the MPM recordings: the 50 Hz policy rate [s]."""
FEET = ("left", "right")


@dataclass(frozen=True)
class WalkRecordsCfg:
    """How a recorded walk becomes sole records."""

    min_pelvis_height: float = 0.5
    """Frames from the first one with the pelvis below this height are dropped (the fall) [m]."""
    sole_center: tuple[float, float, float] = G1_SOLE_BOX_CENTER
    """Sole-box centre in the ankle-roll link's frame [m] (the box the MPM particles see)."""
    sole_half_extents: tuple[float, float, float] = G1_SOLE_BOX_HALF_EXTENTS
    """Half sizes of the sole box [m]."""
    depth_tolerance: float = 1e-3
    """Largest difference between the kinematics' depth and the recorded sinkage that a file may show [m]."""
    min_frames: int = 10
    """Fewest frames a walk must keep (shorter ones are refused) [-]."""
    force_source: Literal["logged", "momentum"] = "logged"
    """The records' sand force: the logged per-foot force (the policy step's mean in recordings made since the MPM
    evaluation logs it; one aliased 5 ms frame in older ones), or the robot's momentum
    (:mod:`gmloco.eval.calibration.walk_momentum`: single-support frames only, NaN in double support)."""
    momentum: MomentumForceCfg = field(default_factory=MomentumForceCfg)
    """Contact rule of the momentum forces."""


def walk_terrain(path: str | Path) -> str:
    """Return the terrain of a recording from its name ``<terrain>__<scenario>__v<speed>.mcap``."""
    return Path(path).name.split("__")[0]


@cache
def _g1_model() -> Any:
    """The nominal G1 ``mujoco.MjModel``, compiled once for every file."""
    from gmloco.deploy.mismatch.g1model import build_model

    return build_model()


def _log_arrays(path: Path) -> dict[str, np.ndarray]:
    """The signals a walk needs, at the joint-state times."""
    from gmloco.deploy.logs.reader import read_log

    log = read_log(path)
    need = ("lowstate.q", "lowstate.dq", "odom.position", "odom.orientation", "odom.linear_velocity",
            "odom.angular_velocity", "sim.force", "sim.sinkage")  # fmt: skip
    missing = [s for s in need if not log.has(s)]
    if missing:
        raise ValueError(f"{path}: no {missing}; a walk record needs an MPM evaluation recording")
    out = {s: log.signal(s)[1].astype(np.float64) for s in need}
    out["time"] = log.signal("lowstate.q")[0]
    n = min(len(v) for v in out.values())
    return {k: v[:n] for k, v in out.items()}


def foot_records(path: str | Path, cfg: WalkRecordsCfg | None = None) -> dict[str, SoleRecord]:
    """Return ``{"left": record, "right": record}`` of one MPM walk recording (see the module docstring).

    Raises:
        ValueError: If the file lacks a signal, keeps fewer than ``cfg.min_frames`` frames, or its kinematics do not
            reproduce its recorded sinkage within ``cfg.depth_tolerance``.
    """
    return _walk(Path(path), cfg or WalkRecordsCfg())[0]


def _walk(path: Path, cfg: WalkRecordsCfg) -> tuple[dict[str, SoleRecord], np.ndarray]:
    """:func:`foot_records`' records and the logged per-foot force of the kept frames [N], [T, 2, 3]."""
    import mujoco

    from gmloco.deploy.mismatch.frames import quat_rotate

    a = _log_arrays(path)
    low = np.flatnonzero(a["odom.position"][:, 2] < cfg.min_pelvis_height)
    n = int(low[0]) if len(low) else len(a["time"])
    if n < cfg.min_frames:
        raise ValueError(f"{path}: {n} frames before the pelvis fell below {cfg.min_pelvis_height} m")
    model = _g1_model()
    data = mujoco.MjData(model)
    feet = [model.body(name).id for name in G1_FOOT_BODIES]
    centre = np.asarray(cfg.sole_center)
    corners = sole_box_corners(SoleCfg(center=cfg.sole_center, half_extents=cfg.sole_half_extents))  # link frame
    jacp, jacr, jac_com = np.zeros((3, model.nv)), np.zeros((3, model.nv)), np.zeros((3, model.nv))
    pos, rot, lin, ang, depth = (np.zeros((2, n, *s)) for s in ((3,), (3, 3), (3,), (3,), ()))
    com_vel = np.zeros((n, 3))
    v_world = quat_rotate(a["odom.orientation"][:n], a["odom.linear_velocity"][:n])
    qpos_all = np.concatenate([a["odom.position"][:n], a["odom.orientation"][:n], a["lowstate.q"][:n]], axis=1)
    qvel_all = np.concatenate([v_world, a["odom.angular_velocity"][:n], a["lowstate.dq"][:n]], axis=1)
    momentum = cfg.force_source == "momentum"
    for k in range(n):
        data.qpos[:] = qpos_all[k]
        qvel = qvel_all[k]
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        if momentum:  # the same kinematics give the centre-of-mass velocity (walk_momentum.com_velocity)
            mujoco.mj_jacSubtreeCom(model, data, jac_com, 0)
            com_vel[k] = jac_com @ qvel
        for f, body in enumerate(feet):
            r = data.xmat[body].reshape(3, 3)
            pos[f, k] = data.xpos[body] + r @ centre
            rot[f, k] = r
            mujoco.mj_jac(model, data, jacp, jacr, pos[f, k], body)
            lin[f, k], ang[f, k] = jacp @ qvel, jacr @ qvel
            depth[f, k] = -(data.xpos[body, 2] + (corners @ r.T)[:, 2]).min()
    off = np.abs(depth.T - a["sim.sinkage"][:n]).max()
    if off > cfg.depth_tolerance:
        raise ValueError(f"{path}: the kinematics' sole depth differs from the recorded sinkage by {off:.4f} m")
    time = WALK_FRAME_DT * np.arange(n)
    logged = force = a["sim.force"][:n]
    if momentum:
        total = momentum_force(com_vel, float(model.body_subtreemass[0]), model.opt.gravity, WALK_FRAME_DT)
        force = foot_forces(total, logged, depth.T, cfg.momentum)
    records = {foot: SoleRecord(time, pos[f], rot[f], lin[f], ang[f], force[:, f].copy(), depth[f])
               for f, foot in enumerate(FEET)}  # fmt: skip
    return records, logged


def _logged_over_stance(logged: np.ndarray, records: dict[str, SoleRecord]) -> float:
    """Logged over momentum mean vertical force on the single-support frames of momentum ``records`` [-]."""
    f_mom = np.stack([records[f].force[:, 2] for f in FEET], axis=1)
    single = np.isfinite(f_mom).all(axis=1)
    return float(logged[single, :, 2].sum() / f_mom[single].sum()) if single.any() else float("nan")


def logged_over_momentum(path: str | Path, cfg: WalkRecordsCfg | None = None) -> float:
    """Return the logged stance force over the momentum's, mean vertical force of the single-support frames [-].

    1 means the recording's per-foot force log is sound (the policy step's mean); the aliased logs of older
    recordings read 0.5-1.0.
    """
    records, logged = _walk(Path(path), replace(cfg or WalkRecordsCfg(), force_source="momentum"))
    return _logged_over_stance(logged, records)


def _record_name(path: Path) -> str:
    """A record-name stem unique per recording (no slash, as the npz keys need).

    ``<study>__<run>__<file stem>`` for ``<study>/runs/<run>/recordings/<file>``, else the two folders above the file.
    """
    parts = path.resolve().parts
    up = [x for x in parts[-5:-1] if x not in ("runs", "recordings")][-2:]
    return "__".join([*up, path.stem]).replace(".", "p")


def walk_dataset(
    paths: list[str | Path],
    material: str,
    cfg: WalkRecordsCfg | None = None,
    split_seed: int = 0,
    log_check: dict[str, float] | None = None,
) -> CalibrationDataset:
    """Return the walks of ``paths`` on ``material`` as a calibration dataset (both feet of a walk share a split).

    ``log_check``, if given, receives each recording's :func:`logged_over_momentum` (momentum records only), from the
    same pass over the file.

    Raises:
        ValueError: If a terrain is not the material's flat bed, a file fails :func:`foot_records`, or two files
            give one record name.
    """
    cfg = cfg or WalkRecordsCfg()
    if material not in MATERIAL_PRESETS:
        raise ValueError(f"unknown material {material!r}; choose from {sorted(MATERIAL_PRESETS)}")
    records: dict[str, SoleRecord] = {}
    walks: dict[str, list[str]] = {}
    for p in map(Path, paths):
        terrain = walk_terrain(p)
        if terrain not in (material, f"{material}_deep"):
            raise ValueError(f"{p}: terrain {terrain!r} is not a flat {material} bed ({material} or {material}_deep)")
        stem = _record_name(p)
        if stem in walks:
            raise ValueError(f"{p}: a second recording named {stem!r}")
        walks[stem] = []
        feet, logged = _walk(p, cfg)
        if log_check is not None and cfg.force_source == "momentum":
            log_check[str(p)] = _logged_over_stance(logged, feet)
        for foot, rec in feet.items():
            records[f"{stem}__{foot}"] = rec
            walks[stem].append(f"{stem}__{foot}")
    by_walk = assign_split(sorted(walks), split_seed)
    split = {name: by_walk[stem] for stem, names in walks.items() for name in names}
    mat = MATERIAL_PRESETS[material]
    sole = tuple(2.0 * h for h in cfg.sole_half_extents)
    return CalibrationDataset(
        material=material,
        material_params={"rho_c": mat.rho_c, "mu_int": mat.mu_int, "mu_surf": mat.mu_surf},
        source="mpm",
        protocol=SoleProtocolCfg(sole_size=sole, frame_dt=WALK_FRAME_DT),  # type: ignore[arg-type]
        records=records,
        split=split,
        split_seed=split_seed,
        extra={"kind": "walks", "recordings": [str(p) for p in paths], "walk_records": _cfg_dict(cfg)},
    )


def _cfg_dict(cfg: WalkRecordsCfg) -> dict[str, Any]:
    """The settings as JSON values."""
    return {k: list(v) if isinstance(v, tuple) else v for k, v in asdict(cfg).items()}


def main(argv: list[str] | None = None) -> int:
    """Command line: write the walk dataset of ``--recordings`` on ``--material`` to ``--out`` (exit 2 on bad input)."""
    p = argparse.ArgumentParser(
        prog="python -m gmloco.eval.calibration.walk_records", description=(__doc__ or "").split("\n")[0]
    )
    p.add_argument("--recordings", nargs="+", required=True, help="MPM evaluation recordings (.mcap)")
    p.add_argument("--material", required=True, help=f"medium of the beds, one of {sorted(MATERIAL_PRESETS)}")
    p.add_argument(
        "--out", required=True, help="dataset file (.npz), e.g. results/sand_calibration/dataset/walks/dry_sand.npz"
    )
    p.add_argument("--split-seed", type=int, default=0, help="seed of the fit / held-out split by walk (default 0)")
    p.add_argument(
        "--force", choices=("logged", "momentum"), default="logged", help=field_doc(WalkRecordsCfg, "force_source")
    )
    args = p.parse_args(argv)
    missing = [r for r in args.recordings if not Path(r).is_file()]
    if missing:
        print(f"error: no recording {missing}; MPM evaluations write them under <run>/recordings/", file=sys.stderr)
        return 2
    check: dict[str, float] = {}
    try:
        ds = walk_dataset(
            args.recordings, args.material, WalkRecordsCfg(force_source=args.force), args.split_seed, check
        )
    except (ValueError, KeyError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    out = save_dataset(ds, args.out)
    frames = sum(len(r.time) for r in ds.records.values())
    print(f"{len(ds.records)} foot records ({frames} frames) of {len(args.recordings)} walks -> {out}")
    for path, ratio in check.items():  # momentum records: how each recording's force log compares (1: sound)
        print(f"  {path}: logged / momentum stance force {ratio:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
