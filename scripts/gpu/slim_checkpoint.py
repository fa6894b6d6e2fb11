"""Copy a training checkpoint without its optimizer state (for bringing it back through ``$OUT``, 16 MiB a file).

    python3 scripts/gpu/slim_checkpoint.py runs/gpu/<run>/model_<it>.pt $OUT/<run>_model_<it>.pt

A run resumed from the copy starts a fresh Adam (``train_ts_chunk.py`` / ``train_chunk.py`` accept it). The copy is
``train_ts_chunk.py``'s own slim copy, the one its chunks bring back.
"""

from __future__ import annotations

import sys
from pathlib import Path

from train_ts_chunk import _copy_checkpoint  # this script's folder is on sys.path when run as a script


def main(argv: list[str] | None = None) -> None:
    """Write ``argv[0]`` without ``optimizer_state_dict`` to ``argv[1]``."""
    src, dst = (argv if argv is not None else sys.argv[1:])[:2]
    _copy_checkpoint(Path(src), Path(dst), slim=True)


if __name__ == "__main__":
    main()
