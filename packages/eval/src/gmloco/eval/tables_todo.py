# SPDX-License-Identifier: Apache-2.0
"""Former command name of :mod:`gmloco.eval.studies.tables_todo`, where the code lives now.

Kept because the commands recorded in ``results/**/manifest.json`` name it: ``python -m gmloco.eval.tables_todo ARGS`` runs
``python -m gmloco.eval.studies.tables_todo ARGS``.
"""

if __name__ == "__main__":
    from gmloco.eval.studies.tables_todo import main

    main()
