# SPDX-License-Identifier: Apache-2.0
"""Write one concealed-effect recording as MCAP, with its truth key in a separate file.

Usage::

    python -m gmloco.deploy.mismatch.benchmark.make_recording --effect imu.gyro_bias
        --params '{"bias": [0.03, -0.02, 0.015]}' --out real.mcap --key /elsewhere/key.json

Without ``--params`` the benchmark's mid strength is used (the sand suite's with ``--sand``). ``--sand`` makes the
recording on the project's 3D-RFT sand with the walking policy (``artifacts/ppo_rft3d/policy.onnx``) and logs
odometry, as the sand suite does (``--motion composite``: stand, three speeds and a turn, 18 s); analyse it with ``gmloco-mismatch --ground sand``. Only the channels a G1 logs are written (LowState,
LowCmd, IMU; no odometry unless ``--odometry``). ``--chirp`` makes the in-air identification stage instead: the pelvis
held on a gantry (metadata ``support=gantry``), PD-tracked joint chirps on the legs and waist. ``--stage`` records one
stage of the identification protocol (:mod:`gmloco.deploy.mismatch.stages`): ``chirp`` (as ``--chirp``), ``stand``
and ``step`` (scripted, on the plane), ``walk`` (the walking policy at 0.5, 1.0 and 1.5 m/s) and ``turn`` (the
policy turning left and right); ``walk`` and ``turn`` log odometry and also run on ``--sand``. Give the MCAP to
``gmloco-mismatch --real``; keep the key away from it.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

__all__ = ["main"]


def main(argv: list[str] | None = None) -> None:
    """Generate the recording and write the MCAP and the key."""
    from gmloco.deploy.mismatch.benchmark.chirp import ChirpCfg
    from gmloco.deploy.mismatch.benchmark.controller import MotionCfg
    from gmloco.deploy.mismatch.benchmark.episodes import MID, OOL, SAND_MID, SAND_OOL
    from gmloco.deploy.mismatch.benchmark.generator import EpisodeCfg, generate
    from gmloco.deploy.mismatch.benchmark.policy_motion import MOTIONS, motion_cfg
    from gmloco.deploy.mismatch.benchmark.truth import TruthEffect
    from gmloco.deploy.mismatch.io import write_recording
    from gmloco.deploy.mismatch.stages import STAGES

    p = argparse.ArgumentParser(prog="make_recording", description=__doc__)
    p.add_argument("--effect", default="none", help="effect id, 'none', or an ool.* id")
    p.add_argument("--params", default=None, help="JSON dict of parameter lists (default: mid strength)")
    p.add_argument(
        "--duration", type=float, default=None, help="recording length [s] (default 9; with --sand the motion's)"
    )
    p.add_argument("--seed", type=int, default=100)
    p.add_argument("--odometry", action="store_true", help="also log ground-truth base odometry")
    p.add_argument("--sand", action="store_true", help="walking policy on 3D-RFT dry sand, with odometry")
    p.add_argument("--chirp", action="store_true", help="pelvis held on a gantry, joint chirps (in-air stage)")
    p.add_argument("--motion", choices=sorted(MOTIONS), default="walk", help="with --sand: walk (1 m/s) or composite")
    p.add_argument(
        "--stage",
        choices=sorted(STAGES),
        default=None,
        help="identification-protocol stage: " + "; ".join(f"{k}: {v}" for k, v in STAGES.items()),
    )
    p.add_argument("--out", type=Path, required=True, help="MCAP to write")
    p.add_argument("--key", type=Path, required=True, help="truth key JSON (keep it where the tool cannot read it)")
    a = p.parse_args(argv)
    if a.stage is not None and a.chirp:
        p.error("--stage chirp replaces --chirp: give one of them")
    chirp = a.chirp or a.stage == "chirp"
    if chirp and a.sand:
        p.error("--chirp holds the robot in the air: it touches no sand; leave out --sand")
    if a.sand and a.stage in ("stand", "step"):
        p.error(f"--stage {a.stage} is scripted on the plane; on --sand record the policy stages walk or turn")
    policy_motion = {"walk": "walk_speeds", "turn": "turn"}.get(a.stage or "", a.motion if a.sand else None)
    table = {**SAND_MID, **SAND_OOL} if a.sand else {**MID, **OOL}
    params = json.loads(a.params) if a.params else table.get(a.effect, {})
    duration = a.duration if a.duration is not None else MOTIONS[policy_motion] if policy_motion else 9.0
    rec, key = generate(
        EpisodeCfg(
            effect=TruthEffect(a.effect, params),
            duration=duration,
            seed=a.seed,
            odometry=a.odometry or a.sand or policy_motion is not None,
            ground="sand" if a.sand else "plane",
            policy=motion_cfg(policy_motion) if policy_motion else None,
            motion=MotionCfg(kind="stand" if a.stage == "stand" else "step"),
            support="gantry" if chirp else "free",
            chirp=ChirpCfg() if chirp else None,
        )
    )
    controller = "policy:ppo_rft3d" if policy_motion else rec.meta["controller"]
    if a.stage is not None:  # the stage label lets the tool say which protocol stages a set of recordings covers
        controller = f"stage_{a.stage}: {controller}"
    a.out.parent.mkdir(parents=True, exist_ok=True)
    write_recording(rec, a.out, controller=controller, overwrite=True)
    a.key.parent.mkdir(parents=True, exist_ok=True)
    a.key.write_text(json.dumps(key, indent=2))
    print(json.dumps({"mcap": str(a.out), "key": str(a.key), "duration_s": rec.n * rec.dt}))


if __name__ == "__main__":
    main()
