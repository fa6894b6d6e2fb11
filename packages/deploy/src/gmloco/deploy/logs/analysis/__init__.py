# SPDX-License-Identifier: Apache-2.0
"""Hardware-style analyses of G1 logs: segmentation, base velocity, tracking, ankle torque, clearance, figures."""

from gmloco.deploy.logs.analysis.kinematics import G1LegKinematics, g1_model, sole_heights
from gmloco.deploy.logs.analysis.metrics import (
    MetricsCfg,
    stance_ankle_torque,
    swing_clearance,
    velocity_tracking,
)
from gmloco.deploy.logs.analysis.report import analyze, expand_paths
from gmloco.deploy.logs.analysis.run_analysis import AnalysisCfg, RunAnalysis, analyze_log
from gmloco.deploy.logs.analysis.segmentation import SegmentationCfg, phase_windows, relative_heights, segment_stance

__all__ = [
    "AnalysisCfg",
    "G1LegKinematics",
    "MetricsCfg",
    "RunAnalysis",
    "SegmentationCfg",
    "analyze",
    "analyze_log",
    "expand_paths",
    "g1_model",
    "phase_windows",
    "relative_heights",
    "segment_stance",
    "sole_heights",
    "stance_ankle_torque",
    "swing_clearance",
    "velocity_tracking",
]
