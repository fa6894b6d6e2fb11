#!/usr/bin/env bash
# Prepared in the per-terrain runs for the next run (issue 9); NOT yet run. For a machine of several GPUs (nvidia-h100-x4
# or larger; one GPU works too, slower): `python -m gmloco.eval.g1_eval_queue --tasks` runs one evaluation per GPU
# from the task file below, in order, each time-boxed to END and resumable. Rows split into four shares
# (--shard I/4: with four speeds, one speed each) run on four GPUs at once.
#   1. basalt at the square 1.4 x 1.4 m window (lead 0.2; it contains the tables' 1.4 x 0.6 m window at every
#      heading): the per-terrain runs' basalt row left the window in 94 % of its episodes because the student turns
#      35-69 degrees in 10 s and the window does not turn;
#   2. the lanes case (32 / 50 / 100 robots per solver, 0.3 s, side by side on three GPUs at the same time: the last
#      throughput lever not measured on one machine), with the ppo_rigid wide row's last 16 episodes (resumed);
#   3. the rough row (resumed), the transition course (square window: it starts on basalt, where the student turns);
#   4. the td student on dry sand at the square window (does the grid-capacity runs' 22 % row, scored before exits were
#      recorded, hold?); then the circles of the four ablation policies (their window is square by construction;
#      the policies that fall within ~2 s get one task each).
#   Before: mkdir -p .devsrc/row && cp -r results/mpm_eval/table_rows/per_terrain/runs/table_ppo_rigid_wide_dry_sand \
#           results/mpm_eval/table_rows/per_terrain/runs/table_td_dry_sand_rough .devsrc/row/   (the two resumed rows)
#   Usage (in ~/src, after the wheels and the Warp cache): bash job_next.sh END_EPOCH
#   Fetch: cd ~/chunks && tar czf - g1_eval job.log | split -b 15M - $OUT/s17.tgz.part
#   Check on a CPU (writes and parses the task file, runs nothing): DRY=1 bash job_next.sh 0
END=$1
cd ~/src || exit 1
[ -n "${DRY:-}" ] || source scripts/gpu/env.sh
mkdir -p ~/chunks/g1_eval
[ -d ~/src/.devsrc/row ] && cp -r ~/src/.devsrc/row/* ~/chunks/g1_eval/
TD=artifacts/gm_loco_student_td/policy.onnx
RIGID=artifacts/ppo_rigid/policy.onnx
RFT=artifacts/ppo_rft3d/policy.onnx
ROW="--speeds 1.0 1.5 2.0 2.5 --num-episodes 100 --robots-per-batch 50"
SQ="--window-length 1.4 --window-width 1.4 --window-lead 0.2"
WIDE="--window-length 1.4 --window-width 1.3 --window-lead 0.0"
shares() {  # shares NAME ARGS...: the row as four task lines, one per share
  local N=$1; shift
  for i in 0 1 2 3; do echo "${N}_share${i}of4 $* --shard $i/4"; done
}
{
  shares table_td_basalt_sq --policy $TD --terrains basalt $ROW $SQ
  for R in 32 50 100; do
    echo "cost_r$R --policy $TD --terrains dry_sand --speeds 1.0 --no-mcap --fresh --episode-s 0.3 --num-episodes $R --robots-per-batch $R"
  done
  echo "table_ppo_rigid_wide_dry_sand --policy $RIGID --terrains dry_sand $ROW $WIDE"
  echo "table_td_dry_sand_rough --policy $TD --terrains dry_sand_rough $ROW"
  shares table_td_transition_sq --policy $TD --terrains transition $ROW $SQ
  shares table_td_dry_sand_sq --policy $TD --terrains dry_sand $ROW $SQ
  shares table_td_dry_sand_circle --policy $TD --terrains dry_sand --scenarios circle $ROW
  shares table_ppo_rft3d_dry_sand_circle --policy $RFT --terrains dry_sand --scenarios circle $ROW
  echo "table_clr50_dry_sand_circle --policy artifacts/gm_loco_student_clr50/policy.onnx --terrains dry_sand --scenarios circle $ROW"
  echo "table_ppo_rigid_dry_sand_circle --policy $RIGID --terrains dry_sand --scenarios circle $ROW $WIDE"
} > ~/chunks/tasks.txt
if [ -n "${DRY:-}" ]; then  # every line must parse as the queue and g1_eval_cli read it
  python3 - <<'PY'
from pathlib import Path
from gmloco.eval.g1_eval_cli import _parse
from gmloco.eval.g1_eval_queue import file_tasks
tasks = file_tasks(Path.home() / "chunks" / "tasks.txt", [])
for t in tasks:
    _parse([*t.argv, "--out", "x"])
print(f"{len(tasks)} tasks parse:", ", ".join(t.name for t in tasks))
PY
  exit
fi
NGPU=$(nvidia-smi -L | wc -l)
M=$(python3 -c "import time; print(round(($END - time.time()) / 60 - 0.7, 2))")
echo "start: $NGPU GPUs, $M min at $(date +%T)" > ~/chunks/job.log
python3 -m gmloco.eval.g1_eval_queue --gpus $(seq -s ' ' 0 $((NGPU - 1))) --out ~/chunks/g1_eval \
  --tasks ~/chunks/tasks.txt --max-minutes "$M" >> ~/chunks/job.log 2>&1
echo "queue rc=$? at $(date +%T)" >> ~/chunks/job.log
touch ~/chunks/DONE
