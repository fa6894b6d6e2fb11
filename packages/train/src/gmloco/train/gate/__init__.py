# SPDX-License-Identifier: Apache-2.0
"""The training gate: a delivered policy scored per material and command in the granular training simulator.

``python -m gmloco.train.gate --policy artifacts/<run> --out results/training_gate/summary.json`` writes issue 34's
keys (``success_pct``, ``vel_error_mps``, ``yaw_rate_ratio``, ``heading_drift_deg``, ``circle_dtw_m``,
``swing_apex_cm``, ``eta_r2_heldout``, ``gpu_minutes``) and a ``pass`` map against :class:`GateThresholdsCfg`;
beside them, to tell why, ``failures`` (each failed forward episode's term and time), ``stance_sink_cm`` and
``turn_falls`` (falls in the yaw and circle cells; a fall fails its cell's key).
``--contact-model`` picks the simulator's contact model (``rft3d_calibrated``: the fitted terms of
``--rft-extensions``) and ``--parts`` the parts measured (``success`` alone: success by material and speed).
"""

from gmloco.train.gate.config import GateCfg, GateThresholdsCfg
from gmloco.train.gate.run import run_gate

__all__ = ["GateCfg", "GateThresholdsCfg", "run_gate"]
