"""Drop the embedded frozen teacher from a committed student checkpoint; it then names the teacher file instead.

    uv run python scripts/gpu/detach_teacher.py --checkpoint artifacts/gm_loco_student_clr50/checkpoint.pt \
        --teacher artifacts/gm_loco_teacher_clr50/checkpoint.pt

The student checkpoint shrinks from ~8.5 to ~2.2 MB (the teacher's history encoder is most of it), which keeps the
committed tree plus one wheel part under a device call's 64 MiB. Refuses a teacher file whose tensors differ from
the embedded teacher. Loading (``StudentPPO.load``: resume, evaluation, export) puts the teacher back from the
named file, relative to the repository root, and checks its digest. Rewrites the file atomically.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path


def main(argv: list[str] | None = None) -> None:
    """Detach the teacher of ``--checkpoint`` in place."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--checkpoint", type=Path, required=True, help="student checkpoint (rewritten in place)")
    p.add_argument("--teacher", type=Path, required=True, help="TeacherPPO checkpoint, path from the repository root")
    a = p.parse_args(argv)
    import torch

    from gmloco.train.teacher_student.checkpoint_teacher import detach_teacher

    before = a.checkpoint.stat().st_size
    slim = detach_teacher(torch.load(a.checkpoint, map_location="cpu", weights_only=False), a.teacher)
    tmp = a.checkpoint.with_suffix(".pt.tmp")
    torch.save(slim, tmp)
    os.replace(tmp, a.checkpoint)
    print(f"{a.checkpoint}: {before / 1e6:.1f} -> {a.checkpoint.stat().st_size / 1e6:.1f} MB, teacher {a.teacher}")


if __name__ == "__main__":
    main()
