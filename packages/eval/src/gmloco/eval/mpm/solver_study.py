# SPDX-License-Identifier: Apache-2.0
"""Former command name of :mod:`gmloco.eval.studies.solver_study`, where the code lives now.

Kept because the commands recorded in ``results/**/manifest.json`` name it: ``python -m gmloco.eval.mpm.solver_study ARGS`` runs
``python -m gmloco.eval.studies.solver_study ARGS``.
"""

if __name__ == "__main__":
    from gmloco.eval.studies.solver_study import main

    main()
