# SPDX-License-Identifier: Apache-2.0
"""Pure-numpy metrics (numpy in, float out)."""

from gmloco.eval.metrics.box import (
    metric_grf_profile_error,
    metric_lateral_force,
    metric_relative_error,
    metric_sinkage,
    metric_travel,
)

__all__ = [
    "metric_grf_profile_error",
    "metric_lateral_force",
    "metric_relative_error",
    "metric_sinkage",
    "metric_travel",
]
