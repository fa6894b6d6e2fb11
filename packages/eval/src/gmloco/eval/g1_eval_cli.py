# SPDX-License-Identifier: Apache-2.0
"""Former command name of :mod:`gmloco.eval.g1.cli`, where the code lives now.

Kept because the commands recorded in ``results/**/manifest.json`` name it: ``python -m gmloco.eval.g1_eval_cli ARGS`` runs
``python -m gmloco.eval.g1.cli ARGS``.
"""

if __name__ == "__main__":
    from gmloco.eval.g1.cli import main

    main()
