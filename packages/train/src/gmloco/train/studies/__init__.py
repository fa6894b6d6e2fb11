# SPDX-License-Identifier: Apache-2.0
"""Diagnostic studies of trained policies in the training simulator (``python -m gmloco.train.studies.<name>``).

- :mod:`~gmloco.train.studies.noise_cost`: what the rewards charge for exploration noise on the actions.
"""
