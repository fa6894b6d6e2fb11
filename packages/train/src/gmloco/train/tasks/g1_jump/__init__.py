# SPDX-License-Identifier: Apache-2.0
"""G1 jump on sand (issue 39): kinematic jump references, the imitation task with an assistive base wrench, scoring.

Modules, imported on use:

* ``profile``, ``ik``, ``reference``, ``plausibility``: the references (CoM / foot profile, whole-body IK on
  mjlab's G1 MJCF, rigid-ground inverse dynamics); mujoco and numpy only.
  ``python -m gmloco.train.tasks.g1_jump.make_reference`` rewrites ``data/`` and its ``manifest.json``.
* ``config`` (``JumpTaskCfg``, ``g1_jump_task``), ``command``, ``assist``, ``mdp``, ``env_cfgs``
  (``make_g1_jump_env_cfg``): the mjlab env; ``gmloco.train.TrainRunCfg(jump=...)`` trains it, and the pipeline
  does with ``+exp=jump_rft3d`` / ``+exp=jump_rigid``.
* ``metrics``, ``evaluation``: landing success, height / distance against the reference, take-off slip, sinkage,
  the base-height / foot-depth figure; ``python -m gmloco.train.tasks.g1_jump.evaluate`` scores training runs.
"""
