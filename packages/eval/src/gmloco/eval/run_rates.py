# SPDX-License-Identifier: Apache-2.0
"""Former command name of :mod:`gmloco.eval.studies.run_rates`, where the code lives now.

Kept because the commands recorded in ``results/**/manifest.json`` name it: ``python -m gmloco.eval.run_rates ARGS`` runs
``python -m gmloco.eval.studies.run_rates ARGS``.
"""

if __name__ == "__main__":
    from gmloco.eval.studies.run_rates import main

    main()
