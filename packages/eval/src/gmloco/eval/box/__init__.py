# SPDX-License-Identifier: Apache-2.0
"""The box intrusion study: the box, its MPM and reduced-order runs, checks, summary and figure."""

from gmloco.eval.box.config import BoxCfg, box_lateral_variant, box_roll_variant, box_size_variant

__all__ = ["BoxCfg", "box_lateral_variant", "box_roll_variant", "box_size_variant"]
