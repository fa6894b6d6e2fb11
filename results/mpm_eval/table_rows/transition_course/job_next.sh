#!/usr/bin/env bash
# Prepared in the transition-course runs for the next run (issue 9); NOT yet run. For a machine of several GPUs (nvidia-h200-x4;
# one GPU works too, slower): `python -m gmloco.eval.g1_eval_queue --tasks` runs one evaluation per GPU from the task
# file below, in order, each time-boxed to END and resumable. A row is four shares (--shard I/4: one speed each);
# the 1.0 m/s share (share 0) walks longest (~18 min at the square window in the transition-course runs, shares 1-3 ~12/9/8 min),
# so the first lines start two rows' share 0 while the retire A/B runs beside them.
#   1. retiring idle lanes, side by side on two GPUs of one host, now timed by the episodes' wall clock
#      (elapsed_s; the transition-course runs' records missed the frames in flight at each episode end): the td student on dry sand
#      at 1.5 m/s, 25 episodes of the full 10 s in 25 lanes (the ablation-circle runs: 5 of 25 walk the 10 s, most fall at 3-6 s,
#      so the batch has a tail of few walkers), idle lanes retired vs --keep-idle-lanes;
#   2. the td student on dry sand at the square 1.4 x 1.4 m window (the ablation-circle runs: 17 of 25 walks at 1.0 m/s turned out
#      of the tables' window), resuming the transition-course runs' cut shares (1 episode each in shares 1 and 2);
#   3. basalt and rough dry sand at the square window (basalt left the tables' window in 94 % of its episodes in
#      the per-terrain runs, rough in 31 %);
#   4. the two circle shares cut by earlier time boxes: ppo_rigid 1.0 m/s (23 of 25), clr50 1.0 m/s (24 of 25).
#   Before (here): scripts/gpu/snapshot_src.sh && cp results/mpm_eval/table_rows/transition_course/job_next.sh .devsrc/job.sh &&
#     mkdir -p .devsrc/row && cp -r results/mpm_eval/table_rows/transition_course/runs/table_td_dry_sand_sq_share[12]of4 \
#       results/mpm_eval/table_rows/ablation_circles/runs/table_ppo_rigid_dry_sand_circle_share0of4 \
#       results/mpm_eval/table_rows/ablation_circles/runs/table_clr50_dry_sand_circle_share0of4 .devsrc/row/
#     and the Warp cache (scripts/gpu/warm_cache.py -> .devcache/warpcache.tgz; scripts/gpu/README.md).
#   Launch (there, in the last wheel part's call): bash scripts/gpu/launch_job.sh SECONDS
#   Poll and fetch: bash scripts/gpu/wait_fetch.sh 560 s20 (again while it answers rc 3)
#   Check on a CPU (writes and parses the task file, runs nothing): DRY=1 bash job_next.sh 0
END=$1
cd ~/src || exit 1
mkdir -p ~/chunks
source scripts/gpu/queue_rows.sh  # TD CLR50 RIGID RFT ROW SQ WIDE, shares()
AB="--policy $TD --terrains dry_sand --speeds 1.5 --num-episodes 25 --robots-per-batch 25 --no-mcap --fresh"
row() { echo "table_td_${1}_sq_share${2}of4 --policy $TD --terrains $1 $ROW $SQ --shard $2/4"; }
{
  echo "retire_ab10_on $AB"
  echo "retire_ab10_keep $AB --keep-idle-lanes"
  row dry_sand 0
  row basalt 0
  for i in 1 2 3; do row dry_sand $i; done
  for i in 1 2 3; do row basalt $i; done
  for i in 0 1 2 3; do row dry_sand_rough $i; done
  echo "table_ppo_rigid_dry_sand_circle_share0of4 --policy $RIGID --terrains dry_sand --scenarios circle $ROW $WIDE --shard 0/4"
  echo "table_clr50_dry_sand_circle_share0of4 --policy $CLR50 --terrains dry_sand --scenarios circle $ROW --shard 0/4"
} > ~/chunks/tasks.txt
bash scripts/gpu/run_queue.sh ~/chunks/tasks.txt "$END"
