"""Copy a training checkpoint without its optimizer state (for bringing it back through ``$OUT``, 16 MiB a file).

    python3 scripts/gpu/slim_checkpoint.py runs/gpu/<run>/model_<it>.pt $OUT/<run>_model_<it>.pt

A run resumed from the copy starts a fresh Adam (``train_ts_chunk.py`` / ``train_chunk.py`` accept it).
"""

from __future__ import annotations

import sys


def main(argv: list[str] | None = None) -> None:
    """Write ``argv[1]`` without ``optimizer_state_dict`` to ``argv[2]``."""
    src, dst = (argv if argv is not None else sys.argv[1:])[:2]
    import torch

    ckpt = torch.load(src, map_location="cpu", weights_only=False)
    ckpt.pop("optimizer_state_dict", None)
    torch.save(ckpt, dst)


if __name__ == "__main__":
    main()
