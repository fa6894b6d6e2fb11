# SPDX-License-Identifier: Apache-2.0
"""Sim-vs-real mismatch discovery for the G1: locate the difference, name the missing physics, fit it.

Pipeline (:func:`analyze`): data-contract checks (:mod:`.contract`) -> multiple-shooting replay of the logged
LowCmd from the logged states in MuJoCo C (:mod:`.replay`, base state from odometry or leg odometry,
:mod:`.baseest`) -> normalised residuals over a noise floor (:mod:`.problem`) -> stance/swing segmentation
(:mod:`.segmentation`) and localisation (:mod:`.localize`) -> screening, confirmatory fits and model selection
over the effect library (:mod:`.effects`, :mod:`.attribution`) -> ``report.json`` / ``report.md`` / config patch
(:mod:`.report`). Several recordings of one robot: :func:`analyze_many` (:mod:`.multi`, :mod:`.stack`); which
protocol stage excites which effect: :mod:`.stages`. CLI: ``gmloco.deploy.mismatch.cli:main``. MuJoCo, SciPy and Matplotlib are imported lazily.
"""

from gmloco.deploy.mismatch.effects import (
    EFFECT_IDS,
    EFFECTS,
    OUTCOME_IDS,
    EffectSpec,
    ParamSpec,
    check_effect_ids,
    effect,
)
from gmloco.deploy.mismatch.multi import analyze_many
from gmloco.deploy.mismatch.pipeline import AnalysisCfg, AnalysisResult, analyze
from gmloco.deploy.mismatch.recording import Recording

__all__ = [
    "EFFECTS",
    "EFFECT_IDS",
    "OUTCOME_IDS",
    "AnalysisCfg",
    "AnalysisResult",
    "EffectSpec",
    "ParamSpec",
    "Recording",
    "analyze",
    "analyze_many",
    "check_effect_ids",
    "effect",
]
