# SPDX-License-Identifier: Apache-2.0
"""``gmloco-policy-info <policy.onnx>``: print an exported policy's metadata readably (``--json``: the document).

Exit codes: 0 printed; 2 the file is missing, not ONNX, or carries no readable gmloco policy metadata.
Also runs as ``python -m gmloco.deploy.export.info``.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Sequence
from pathlib import Path

from gmloco.deploy.export.metadata import PolicyMetadata, PolicyMetadataError, read_policy_metadata

__all__ = ["format_metadata", "main"]


def _fmt(values: Sequence[float] | float) -> str:
    """Short text of a number or list of numbers."""
    if isinstance(values, int | float):
        return f"{values:g}"
    return "[" + ", ".join(f"{v:g}" for v in values) + "]"


def _observation_lines(meta: PolicyMetadata) -> list[str]:
    """Observation section: layout, history, one line a term."""
    obs = meta.observation
    lines = [
        f"observation: {obs.obs_dim} per frame, history {obs.history_length} frames {obs.history_order} "
        f"(current frame last), padding after reset {obs.history_padding}, input layout {obs.layout}",
        f"  {'term (frame order)':<20} {'dim':>4}  {'slice':<9} {'clip':<15} {'scale':<15} description",
    ]
    start = 0
    for t in obs.terms:
        clip, scale, where = "-" if t.clip is None else _fmt(t.clip), _fmt(t.scale), f"[{start}:{start + t.dim}]"
        lines.append(f"  {t.name:<20} {t.dim:>4}  {where:<9} {clip:<15} {scale:<15} {t.description}")
        start += t.dim
    return lines


def _joint_lines(meta: PolicyMetadata) -> list[str]:
    """Joint table: one line a joint, action order."""
    j = meta.joints
    lines = ["joints (action order)        kp [N m/rad]  kd [N m s/rad]  q0 [rad]  scale [rad]  effort [N m]"]
    for i, name in enumerate(j.names):
        lines.append(
            f"  {name:<27} {j.stiffness[i]:>10.3f}  {j.damping[i]:>14.3f}  {j.default_pos[i]:>8.3f}  "
            f"{j.action_scale[i]:>11.3f}  {j.effort_limit[i]:>12.1f}"
        )
    return lines


def _task_lines(meta: PolicyMetadata) -> list[str]:
    """Timing, contact, commands."""
    t, c, cmd, col = meta.timing, meta.contact, meta.command, meta.contact.foot_collider
    lines = [
        f"timing: physics dt {t.physics_dt:g} s, decimation {t.decimation}, policy dt {t.policy_dt:g} s",
        f"contact model: {c.model}, contact threshold {c.contact_force_threshold:g} N",
        f"  foot collider on {', '.join(col.body_names)}: box x {_fmt(col.x_range)} y {_fmt(col.y_range)} "
        f"z {_fmt(col.z_range)} m, faces {col.faces}, cells {col.resolution}",
        f"  terrain: {json.dumps(c.terrain)}",
        f"  materials: {json.dumps(c.materials)}",
        f"  robot randomization: {json.dumps(c.robot_randomization)}",
        f"command {cmd.name!r}: lin_vel_x {_fmt(cmd.lin_vel_x)} m/s, lin_vel_y {_fmt(cmd.lin_vel_y)} m/s, "
        f"ang_vel_z {_fmt(cmd.ang_vel_z)} rad/s; {cmd.description}",
        f"  heading rule: {cmd.yaw_command}, heading stiffness {cmd.heading_stiffness:g} 1/s",
    ]
    lines += [f"  stage from env step {s['step']}: {json.dumps({k: v for k, v in s.items() if k != 'step'})}"
              for s in cmd.stages]  # fmt: skip
    return lines


def format_metadata(meta: PolicyMetadata) -> str:
    """Return the metadata as readable text."""
    head = [
        f"schema {meta.schema} version {meta.schema_version}; {meta.policy_class}, latent {meta.latent_dim}",
        f"run {meta.run_path}, commit {meta.commit}",
    ]
    return "\n".join(head + _observation_lines(meta) + _joint_lines(meta) + _task_lines(meta))


def _load(path: Path) -> PolicyMetadata:
    """Read the metadata or raise ``PolicyMetadataError`` with a one-paragraph reason."""
    if not path.is_file():
        raise PolicyMetadataError(f"{path} does not exist or is not a file. Pass the path of an exported policy.onnx.")
    try:
        return read_policy_metadata(path)
    except PolicyMetadataError:
        raise
    except Exception as err:  # onnx raises protobuf's DecodeError (and others) on a file that is not ONNX
        raise PolicyMetadataError(
            f"{path} is not a readable ONNX model ({type(err).__name__}: {err}). Pass an exported policy.onnx."
        ) from err


def main(argv: Sequence[str] | None = None) -> int:
    """Print the metadata of one exported policy; return the exit code."""
    parser = argparse.ArgumentParser(prog="gmloco-policy-info", description=(__doc__ or "").splitlines()[0])
    parser.add_argument("policy", type=Path, help="exported policy (.onnx)")
    parser.add_argument("--json", action="store_true", help="print the metadata document as JSON")
    args = parser.parse_args(argv)
    try:
        meta = _load(args.policy)
    except PolicyMetadataError as err:
        print(f"gmloco-policy-info: {err}", file=sys.stderr)
        return 2
    print(json.dumps(meta.to_dict(), indent=1) if args.json else format_metadata(meta))
    return 0


if __name__ == "__main__":
    sys.exit(main())
