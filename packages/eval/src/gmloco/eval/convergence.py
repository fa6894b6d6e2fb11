# SPDX-License-Identifier: Apache-2.0
"""Former command name of :mod:`gmloco.eval.studies.convergence`, where the code lives now.

Kept because the commands recorded in ``results/**/manifest.json`` name it: ``python -m gmloco.eval.convergence ARGS`` runs
``python -m gmloco.eval.studies.convergence ARGS``.
"""

if __name__ == "__main__":
    from gmloco.eval.studies.convergence import main

    main()
