#!/usr/bin/env bash
# Prepared in the square-window runs (issue 9); ran in the reach-window runs, unchanged (results: ../poppy_seed_deep_sand_reach/). Any machine of 1-4 H200s:
# `python -m gmloco.eval.g1_eval_queue --tasks` runs one evaluation per GPU from the task file below, in order, each
# time-boxed to END and resumable. A row is four shares (--shard I/4: one speed each); at the square window a share
# whose robots walk the full 10 s takes ~17-19 min on an H200 (the square-window runs), one whose robots all fall ~6 min.
#   1. (four GPUs only) retiring idle lanes, side by side on two GPUs of one host, timed by the episodes' wall
#      clock: the td student on dry sand at 1.5 m/s, 25 episodes of the full 10 s in 25 lanes (the transition-course runs' 6 s
#      A/B left no tail), idle lanes retired vs --keep-idle-lanes;
#   2. the td student's dry-sand row at the square window: the square-window runs' 2.0 m/s share resumed (13 of 25);
#   3. poppy seed and deep sand at the reach window (1.7 x 0.8 m: rear 0.8 m behind the pelvis, front 0.9 ahead):
#      at the tables' window 54 % and 37 % of their walks left it at ~0.7 s by a trailing sole 0.6-0.73 m behind the pelvis (its rear is
#      0.5 m behind), 0.3 s before they fell; the square window would not help (same rear). They fall within
#      ~1-2 s, so a share takes a few minutes: two rows done early;
#   4. basalt at the square window (the per-terrain runs at the tables' window: 50 of 100, 94 % turned out of it), resuming
#      the square-window runs' share 0 (started, no episode ended), then rough dry sand (31 % exits, 20 % by turn);
#   5. the two circle shares cut by earlier time boxes: ppo_rigid 1.0 m/s (23 of 25), clr50 1.0 m/s (24 of 25).
#   The rows' windows: `python -m gmloco.eval.tables_todo` (../tables/todo_tasks.txt) lists the same rows; its
#   windows hold the 97.5th percentile of the recorded reach, fall included (basalt 1.45 x 1.45, rough 1.65 x 1.65,
#   poppy seed / deep sand 1.7 x 0.7 m). Here basalt and rough keep the dry-sand row's square (one window for the
#   per-terrain rows; their reach exits past its rear came at 2.0-2.5 m/s while stumbling, as on dry sand's 11 %).
#   Before (here): scripts/gpu/snapshot_src.sh && cp results/mpm_eval/table_rows/dry_sand_square_window/job_next.sh .devsrc/job.sh &&
#     rm -rf .devsrc/row && mkdir -p .devsrc/row &&
#     cp -r results/mpm_eval/table_rows/dry_sand_square_window/runs/table_td_{dry_sand_sq_share2,basalt_sq_share0}of4 \
#       results/mpm_eval/table_rows/ablation_circles/runs/table_{ppo_rigid,clr50}_dry_sand_circle_share0of4 .devsrc/row/
#     and the Warp cache (scripts/gpu/warm_cache.py -> .devcache/warpcache.tgz; scripts/gpu/README.md).
#   Launch (there, in the last wheel part's call): bash scripts/gpu/launch_job.sh SECONDS
#   Poll and fetch: bash scripts/gpu/wait_fetch.sh 560 s21 (again while it answers rc 3)
#   Check on a CPU (writes and parses the task file, runs nothing): DRY=1 bash job_next.sh 0
END=$1
cd ~/src || exit 1
mkdir -p ~/chunks
source scripts/gpu/queue_rows.sh  # TD CLR50 RIGID RFT ROW SQ WIDE REACH, shares()
AB="--policy $TD --terrains dry_sand --speeds 1.5 --num-episodes 25 --robots-per-batch 25 --no-mcap --fresh"
row() { echo "table_td_${1}_sq_share${2}of4 --policy $TD --terrains $1 $ROW $SQ --shard $2/4"; }
NGPU=$( (nvidia-smi -L 2>/dev/null || true) | wc -l)
{
  if [ "$NGPU" -ge 4 ]; then
    echo "retire_ab10_on $AB"
    echo "retire_ab10_keep $AB --keep-idle-lanes"
  fi
  row dry_sand 2
  for t in poppy_seed dry_sand_deep; do
    for i in 0 1 2 3; do echo "table_td_${t}_reach_share${i}of4 --policy $TD --terrains $t $ROW $REACH --shard $i/4"; done
  done
  for t in basalt dry_sand_rough; do
    for i in 0 1 2 3; do row $t $i; done
  done
  echo "table_ppo_rigid_dry_sand_circle_share0of4 --policy $RIGID --terrains dry_sand --scenarios circle $ROW $WIDE --shard 0/4"
  echo "table_clr50_dry_sand_circle_share0of4 --policy $CLR50 --terrains dry_sand --scenarios circle $ROW --shard 0/4"
} > ~/chunks/tasks.txt
bash scripts/gpu/run_queue.sh ~/chunks/tasks.txt "$END"
