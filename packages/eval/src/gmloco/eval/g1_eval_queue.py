# SPDX-License-Identifier: Apache-2.0
"""Former command name of :mod:`gmloco.eval.g1.queue`, where the code lives now.

Kept because the commands recorded in ``results/**/manifest.json`` name it: ``python -m gmloco.eval.g1_eval_queue ARGS`` runs
``python -m gmloco.eval.g1.queue ARGS``.
"""

if __name__ == "__main__":
    from gmloco.eval.g1.queue import main

    main()
