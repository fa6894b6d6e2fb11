#!/usr/bin/env bash
# Prepared in the basalt and rough-sand runs (issue 9); ran in the last-row runs, unchanged (results: ../last_rows_retire_lanes/). Any machine of 1-4 H200s:
# `python -m gmloco.eval.g1_eval_queue --tasks` runs one evaluation per GPU from the task file below, in order, each
# time-boxed to END, resumable, and fitted into the time box (g1_eval fit_time_box).
#   1. rough dry sand at the square window, the basalt and rough-sand runs' four shares resumed (3 / 5 / 4 / 4 of 25 kept): share 0
#      (1.0 m/s; its robots walk up to the 10 s: ~18 min with 22 lanes) first, then shares 1-3 (1.5-2.5 m/s; every
#      walk so far fell within 1.9-5.5 s: a few minutes each). This completes the tables' last row;
#   2. the clr50 student on dry sand at the reach window (the basalt and rough-sand runs had no time left for it; ~3 min a share): a
#      check, on a third policy, of the reach-window runs' rule that window exits coming with the fall leave a row unchanged;
#   3. (four GPUs only, last) the 10 s retire-lanes A/B timed by the wall clock, side by side: the td student on dry
#      sand at 1.5 m/s, 25 episodes in 25 lanes at the tables' window, idle lanes retired vs --keep-idle-lanes
#      (~9 min each if no robot fell; on four GPUs they start ~9 min in, with ~16 left).
#   Before (here): scripts/gpu/snapshot_src.sh && cp results/mpm_eval/table_rows/basalt_rough_square_window/job_next.sh .devsrc/job.sh &&
#     rm -rf .devsrc/row && mkdir -p .devsrc/row &&
#     cp -r results/mpm_eval/table_rows/basalt_rough_square_window/runs/table_td_dry_sand_rough_sq_share*of4 .devsrc/row/
#     and the Warp cache (scripts/gpu/warm_cache.py -> .devcache/warpcache.tgz; scripts/gpu/README.md).
#   Launch (there, in the last wheel part's call): bash scripts/gpu/launch_job.sh SECONDS
#   Poll and fetch: bash scripts/gpu/wait_fetch.sh 560 s23 (again while it answers rc 3)
#   Check on a CPU (writes and parses the task file, runs nothing): DRY=1 bash job_next.sh 0
END=$1
cd ~/src || exit 1
mkdir -p ~/chunks
source scripts/gpu/queue_rows.sh  # TD CLR50 RIGID RFT ROW SQ WIDE REACH, shares()
AB="--policy $TD --terrains dry_sand --speeds 1.5 --num-episodes 25 --robots-per-batch 25 --no-mcap --fresh"
NGPU=$( (nvidia-smi -L 2>/dev/null || true) | wc -l)
{
  for i in 0 1 2 3; do
    echo "table_td_dry_sand_rough_sq_share${i}of4 --policy $TD --terrains dry_sand_rough $ROW $SQ --shard $i/4"
  done
  for i in 0 1 2 3; do
    echo "table_clr50_dry_sand_reach_share${i}of4 --policy $CLR50 --terrains dry_sand $ROW $REACH --shard $i/4"
  done
  if [ "$NGPU" -ge 4 ]; then
    echo "retire_ab10_on $AB"
    echo "retire_ab10_keep $AB --keep-idle-lanes"
  fi
} > ~/chunks/tasks.txt
bash scripts/gpu/run_queue.sh ~/chunks/tasks.txt "$END"
