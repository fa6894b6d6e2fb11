# SPDX-License-Identifier: Apache-2.0
"""Former command name of :mod:`gmloco.eval.report.paper_tables`, where the code lives now.

Kept because the commands recorded in ``results/**/manifest.json`` name it: ``python -m gmloco.eval.paper_tables ARGS`` runs
``python -m gmloco.eval.report.paper_tables ARGS``.
"""

if __name__ == "__main__":
    from gmloco.eval.report.paper_tables import main

    main()
