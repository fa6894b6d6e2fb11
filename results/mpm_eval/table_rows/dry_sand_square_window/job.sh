#!/usr/bin/env bash
# The square-window runs' job (issue 9), for the machine lent this study: nvidia-h200-x2 (two H200s; the x4 kind was not lent).
# The transition-course runs' job_next.sh cut to what two GPUs can finish in one 30-minute device allotment's ~26 minutes of queue: the td student's
# dry-sand row at the square 1.4 x 1.4 m window (the ablation-circle runs at the tables' 1.4 x 0.6 m window: 17 of 25 walks at
# 1.0 m/s turned out of it), resuming the transition-course runs' shares 1 and 2 (1 episode each), shares 0 and 3 fresh. The
# 1.0 m/s share walks longest (~18 min), so it starts first; 2.5 m/s (~8 min) follows the 1.5 m/s share on the
# other GPU. Basalt, rough and the cut circle shares follow in case time is left. The 10 s retire-lanes A/B of
# job_next.sh waits for a four-GPU machine (it would take both GPUs for ~8 minutes).
#   Before (here): scripts/gpu/snapshot_src.sh && cp results/mpm_eval/table_rows/dry_sand_square_window/job.sh .devsrc/job.sh &&
#     rm -rf .devsrc/row && mkdir -p .devsrc/row &&
#     cp -r results/mpm_eval/table_rows/transition_course/runs/table_td_dry_sand_sq_share[12]of4 .devsrc/row/
#   Launch (there, in the last wheel part's call): bash scripts/gpu/launch_job.sh SECONDS
#   Poll and fetch: bash scripts/gpu/wait_fetch.sh 560 s20 (again while it answers rc 3)
#   Check on a CPU (writes and parses the task file, runs nothing): DRY=1 bash job.sh 0
END=$1
cd ~/src || exit 1
mkdir -p ~/chunks
source scripts/gpu/queue_rows.sh  # TD CLR50 RIGID RFT ROW SQ WIDE, shares()
row() { echo "table_td_${1}_sq_share${2}of4 --policy $TD --terrains $1 $ROW $SQ --shard $2/4"; }
{
  for i in 0 1 3 2; do row dry_sand $i; done
  for i in 0 1 2 3; do row basalt $i; done
  for i in 0 1 2 3; do row dry_sand_rough $i; done
} > ~/chunks/tasks.txt
bash scripts/gpu/run_queue.sh ~/chunks/tasks.txt "$END"
