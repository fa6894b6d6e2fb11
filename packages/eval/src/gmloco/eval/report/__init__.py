# SPDX-License-Identifier: Apache-2.0
"""Paper tables and figures of MPM evaluation runs (matplotlib imported lazily)."""
