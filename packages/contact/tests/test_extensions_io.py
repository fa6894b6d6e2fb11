# SPDX-License-Identifier: Apache-2.0
"""Fitted extension files: round trip, permissions, bad input."""

from __future__ import annotations

import json
import stat
from pathlib import Path

import pytest

from gmloco.contact import RftExtensionsCfg
from gmloco.contact.extensions_io import load_rft_extensions, save_rft_extensions


def test_round_trip_and_readable_by_all(tmp_path: Path) -> None:
    """A saved file loads back to the same terms and is 0644 like every other result file; no temporary is left."""
    ext = RftExtensionsCfg(erosion_length=0.002, erosion_keep=0.1, added_mass=3.0)
    path = save_rft_extensions(ext, tmp_path / "fit" / "terms.json", {"made_by": "test"})
    assert load_rft_extensions(path) == ext
    assert stat.S_IMODE(path.stat().st_mode) == 0o644
    assert [p.name for p in path.parent.iterdir()] == ["terms.json"]


def test_missing_and_unknown_fields_are_named(tmp_path: Path) -> None:
    """A missing file says how to make one; an unknown field is named."""
    with pytest.raises(FileNotFoundError, match="fit_cli --write-default"):
        load_rft_extensions(tmp_path / "none.json")
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"extensions": {"erosion_lenght": 0.01}}))
    with pytest.raises(ValueError, match="erosion_lenght"):
        load_rft_extensions(bad)
