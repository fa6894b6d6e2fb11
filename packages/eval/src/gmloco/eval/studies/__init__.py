# SPDX-License-Identifier: Apache-2.0
"""Studies over evaluation runs: convergence, solver, throughput, the table rows left to run, study records."""
