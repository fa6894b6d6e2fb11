# SPDX-License-Identifier: Apache-2.0
"""Extract the G1 data the log analyses need (joint ranges, leg kinematics, sole points) from the MJCF.

Writes ``src/gmloco/deploy/logs/g1_model.json`` so that log analysis runs on numpy alone (no mujoco, no mjlab).
Source: ``mjlab/asset_zoo/robots/unitree_g1/xmls/g1.xml`` (mjlab 1.6.0, Apache-2.0; descends from MuJoCo
Menagerie's ``unitree_g1``, BSD-3-Clause). Run: ``uv run python packages/deploy/scripts/extract_g1_model.py``.
"""

from __future__ import annotations

import json
from pathlib import Path

import mujoco
import numpy as np

from gmloco.deploy.g1 import G1_FEET, G1_JOINT_NAMES, G1_LEG_JOINTS, g1_mjcf_path

OUT = Path(__file__).resolve().parents[1] / "src/gmloco/deploy/logs/g1_model.json"


def main() -> None:
    """Write the JSON file."""
    m = mujoco.MjModel.from_xml_path(str(g1_mjcf_path()))
    ranges = {m.joint(i).name: m.jnt_range[i].tolist() for i in range(1, m.njnt)}
    assert tuple(m.joint(i).name for i in range(1, m.njnt)) == G1_JOINT_NAMES, "MJCF joint order changed"
    legs = {}
    for foot in G1_FEET:
        chain = []
        for jname in G1_LEG_JOINTS[foot]:
            j = m.joint(jname).id
            b = m.jnt_bodyid[j]
            assert not m.jnt_pos[j].any(), "joint anchors off the body origin are not supported"
            chain.append(
                {
                    "joint": jname,
                    "body": m.body(b).name,
                    "pos": m.body_pos[b].tolist(),
                    "quat": m.body_quat[b].tolist(),
                    "axis": m.jnt_axis[j].tolist(),
                }
            )
        # Sole points: both ends of each foot capsule, lowered by the capsule radius (ankle_roll_link frame).
        sole = []
        for g in range(m.ngeom):
            if m.geom(g).name.startswith(f"{foot}_foot") and m.geom(g).name.endswith("_collision"):
                c, q, r, h = m.geom_pos[g], m.geom_quat[g], m.geom_size[g][0], m.geom_size[g][1]
                rot = np.zeros(9)
                mujoco.mju_quat2Mat(rot, q)
                axis = rot.reshape(3, 3)[:, 2]
                for s in (-1.0, 1.0):
                    p = c + s * h * axis
                    sole.append([float(p[0]), float(p[1]), float(p[2] - r)])
        legs[foot] = {"chain": chain, "sole_points": sole}
    site = m.site("imu_in_pelvis")
    data = {
        "source": "mjlab 1.6.0 asset_zoo/robots/unitree_g1/xmls/g1.xml (from MuJoCo Menagerie unitree_g1)",
        "joint_ranges": ranges,
        "legs": legs,
        "imu_in_pelvis": {"pos": m.site_pos[site.id].tolist(), "quat": m.site_quat[site.id].tolist()},
        "mass": float(m.body_subtreemass[1]),
    }
    OUT.write_text(json.dumps(data, indent=1) + "\n")
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
