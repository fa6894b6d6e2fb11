# SPDX-License-Identifier: Apache-2.0
"""``python -m workflows ARGS`` runs ``gmloco ARGS``."""

import sys

from workflows.cli import main

sys.exit(main())
