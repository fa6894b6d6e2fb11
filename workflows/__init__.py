# SPDX-License-Identifier: Apache-2.0
"""gmloco's Hydra workflows: the pipeline, one entry point per stage, sweeps and ablations, and the ``gmloco`` command.

Each workflow module is a thin ``@hydra.main`` entry around ``run(cfg)``; they read the configuration tree in the
checkout's ``conf/``. The root project installs this package (editable) with ``uv sync``; every module also runs as
a script, ``python workflows/<name>.py``. The command line: :mod:`workflows.cli`.
"""
