# SPDX-License-Identifier: Apache-2.0
"""SCHEMA.md documents every topic and signal defined in code."""

from __future__ import annotations

from pathlib import Path

from gmloco.deploy.logs.schema import TOPICS, UNITS

SCHEMA_MD = Path(__file__).resolve().parents[2] / "SCHEMA.md"


def test_schema_md_lists_every_topic_and_signal() -> None:
    """Each topic name and each ``prefix.field`` signal with its unit appears in SCHEMA.md."""
    text = SCHEMA_MD.read_text()
    missing = [t for t in TOPICS if f"`{t}`" not in text]
    missing += [s for s in UNITS if f"`{s}`" not in text]
    assert not missing, f"SCHEMA.md lacks {missing}"
