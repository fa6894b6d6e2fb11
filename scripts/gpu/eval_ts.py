"""Held-out evaluation of the distilled GM-Loco student (and its teacher) in the granular training simulator.

    python scripts/gpu/eval_ts.py --out $OUT/eval_ts

Runs :func:`gmloco.train.evaluation_ts.evaluate_teacher_student` on ``--student`` (default the committed
``artifacts/gm_loco_student_clr50/checkpoint.pt``): R^2 of the decoded vs true eta for the teacher encoder and the student
TCN on a grid over the held-out (rho_c, mu_int) region and on the named presets; student-vs-teacher action error;
success rate and tracking error per material and speed, next to the PPO-3D-RFT baseline (``--baseline``) on the
presets; the adaptation walk basalt -> dry sand -> poppy seed. Writes ``summary.json``, ``materials.csv``,
``adaptation.png`` and ``adaptation_env0.json`` to ``--out``.

    python scripts/gpu/eval_ts.py --actor teacher --teacher runs/s6/teacher_clr50/model_XXXX.pt --device cpu \
        --adaptation-envs 16 --out <dir>

``--actor teacher`` walks only the adaptation course, with the teacher of a ``TeacherPPO`` checkpoint acting
(``--teacher``, default the committed ``artifacts/gm_loco_teacher_clr50/checkpoint.pt``) on ``--adaptation-envs`` envs,
and writes ``summary.json`` (per material: left-foot swing apex mean / std / 90th percentile and count, forward
speed, true and decoded eta), ``adaptation.png`` and ``adaptation_env0.json``. Reward weights do not enter a
rollout, so a teacher trained with ``--reward-weight`` overrides needs none here.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path
from typing import Any


def _floats(text: str) -> tuple[float, ...]:
    """Parse ``"1.0,1.5"``."""
    return tuple(float(x) for x in text.split(",") if x)


def _parse(argv: list[str] | None) -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--actor", choices=["student", "teacher"], default="student", help="teacher: adaptation walk only")
    p.add_argument("--student", default="artifacts/gm_loco_student_clr50/checkpoint.pt")
    p.add_argument("--teacher", default="artifacts/gm_loco_teacher_clr50/checkpoint.pt", help="TeacherPPO checkpoint")
    p.add_argument("--baseline", default="artifacts/ppo_rft3d/policy.onnx", help="'none' to skip")
    p.add_argument("--contact-model", default="rft3d")
    p.add_argument("--foot-faces", choices=["sole", "box"], default="sole", help="foot-box faces the RFT models sample")
    p.add_argument("--latent-dim", type=int, default=16)
    p.add_argument("--history-length", type=int, default=50)
    p.add_argument("--held-out-grid", default="3,3", help="grid points along rho_c, mu_int")
    p.add_argument("--presets", default="basalt,dry_sand,beach_sand,poppy_seed")
    p.add_argument("--speeds", default="1.0", help="commanded forward speeds [m/s], comma-separated")
    p.add_argument("--repeats", type=int, default=8, help="envs per (material, speed) cell")
    p.add_argument("--duration-s", type=float, default=10.0)
    p.add_argument("--warmup-s", type=float, default=1.0)
    p.add_argument("--adaptation-duration-s", type=float, default=10.0, help="0 skips the adaptation walk")
    p.add_argument("--adaptation-edges", default="3.0,6.0")
    p.add_argument("--adaptation-speed", type=float, default=1.0)
    p.add_argument("--adaptation-envs", type=int, default=16, help="envs of the walk with --actor teacher")
    p.add_argument("--device", default="cuda:0")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--out", type=Path, required=True)
    return p.parse_args(argv)


def main(argv: list[str] | None = None) -> dict[str, Any]:
    """Evaluate and write the files that come back; return the summary."""
    args = _parse(argv)
    t0 = time.monotonic()
    from gmloco.train.evaluation_ts import TsEvalCfg, evaluate_teacher_student

    n_rho, n_mu = (int(x) for x in args.held_out_grid.split(","))
    cfg = TsEvalCfg(
        actor=args.actor,
        student_checkpoint=args.student,
        teacher_checkpoint=args.teacher,
        baseline_policy=None if args.baseline == "none" else args.baseline,
        contact_model=args.contact_model,
        foot_faces=args.foot_faces,
        latent_dim=args.latent_dim,
        history_length=args.history_length,
        held_out_grid=(n_rho, n_mu),
        presets=tuple(x for x in args.presets.split(",") if x),
        speeds=_floats(args.speeds),
        repeats=args.repeats,
        duration_s=args.duration_s,
        eta_warmup_s=args.warmup_s,
        adaptation_duration_s=args.adaptation_duration_s,
        adaptation_edges=_floats(args.adaptation_edges),
        adaptation_speed=args.adaptation_speed,
        adaptation_envs=args.adaptation_envs,
        device=args.device,
        seed=args.seed,
        out_dir=str(args.out),
    )
    summary = evaluate_teacher_student(cfg)
    summary["wall_s"] = time.monotonic() - t0
    from gmloco.train.evaluation_ts import finite_json

    (args.out / "summary.json").write_text(json.dumps(finite_json(summary), indent=1, default=str))
    if args.actor == "teacher":
        print(json.dumps(finite_json(summary["adaptation"]), indent=1))
        print(f"survived {summary['adaptation_survived']}/{args.adaptation_envs}, wall {summary['wall_s']:.0f} s")
        return summary
    keys = ("held_out", "presets", "all")
    print(json.dumps({k: v for k, v in finite_json(summary["metrics"]).items() if k.split("/")[0] in keys}, indent=1))
    return summary


if __name__ == "__main__":
    main()
