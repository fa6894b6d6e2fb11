# SPDX-License-Identifier: Apache-2.0
"""Paper figures, one module per figure (matplotlib imported lazily)."""
