# SPDX-License-Identifier: Apache-2.0
"""G1 jump on sand: kinematic jump references, the imitation task with an assistive base wrench, evaluation.

Submodules are imported on use: ``profile``, ``ik``, ``reference``, ``plausibility`` and ``make_reference`` need
only mujoco and numpy; the env modules import mjlab.
"""
