# SPDX-License-Identifier: Apache-2.0
"""Pure-numpy metrics (numpy in, float out)."""

from gmloco.eval.metrics.box import (
    metric_grf_profile_error,
    metric_lateral_force,
    metric_relative_error,
    metric_sinkage,
    metric_travel,
)
from gmloco.eval.metrics.locomotion import (
    EpisodeOutcome,
    FailureCfg,
    circular_path,
    dtw_distance,
    episode_outcome,
    failure_step,
    metric_heading_error_deg,
    metric_path_error,
    metric_velocity_tracking_error,
    metric_yaw_tracking_error,
    quat_wxyz_to_roll_pitch_yaw,
)

__all__ = [
    "EpisodeOutcome",
    "FailureCfg",
    "circular_path",
    "dtw_distance",
    "episode_outcome",
    "failure_step",
    "metric_grf_profile_error",
    "metric_heading_error_deg",
    "metric_lateral_force",
    "metric_path_error",
    "metric_relative_error",
    "metric_sinkage",
    "metric_travel",
    "metric_velocity_tracking_error",
    "metric_yaw_tracking_error",
    "quat_wxyz_to_roll_pitch_yaw",
]
