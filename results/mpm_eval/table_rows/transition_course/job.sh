#!/usr/bin/env bash
# The transition-course runs' job (issue 9): the ablation-circle runs' job_next.sh with the transition course moved ahead of the square-window
# reruns (it is the one paper table not scored at all yet). For a machine of several GPUs (nvidia-h100-x4
# or larger; one GPU works too, slower): `python -m gmloco.eval.g1_eval_queue --tasks` runs one evaluation per GPU
# from the task file below, in order, each time-boxed to END and resumable. Rows split into four shares
# (--shard I/4: with four speeds, one speed each) run on four GPUs at once.
#   1. retiring idle lanes, side by side on GPUs 0 and 1 of one host: the td student on dry sand at 1.5 m/s, 25
#      episodes in 25 lanes, 6 s episodes, once with idle lanes retired (the default since the ablation-circle runs) and once with
#      --keep-idle-lanes (the cost before). Most robots fall within ~5 s at 1.5 m/s (the ablation-circle runs: 20 of 25), so the
#      tail runs with few robots: the wall-clock and solver rates say what retiring buys. Beside them, on GPUs 2-3,
#      ppo_rigid's circles resumed (shares 1 and 2: 6 and 5 of 25 in the ablation-circle runs);
#   2. ppo_rigid's circle at 2.5 m/s (the ablation table's last circle cell);
#   3. the td student on dry sand at the square 1.4 x 1.4 m window: in the ablation-circle runs' row at the tables' window 17 of
#      the 25 walks at 1.0 m/s turned out of the window (heading drift 36 degrees median);
#   4. the transition course, basalt and rough dry sand at the square window (basalt left the tables' window in 94 %
#      of its episodes in the per-terrain runs, rough in 31 %).
#   Before (here): scripts/gpu/snapshot_src.sh && cp results/mpm_eval/table_rows/transition_course/job.sh .devsrc/job.sh &&
#     mkdir -p .devsrc/row && cp -r results/mpm_eval/table_rows/ablation_circles/runs/table_ppo_rigid_dry_sand_circle_share[12]of4 .devsrc/row/
#     and the Warp cache (scripts/gpu/warm_cache.py -> .devcache/warpcache.tgz; scripts/gpu/README.md).
#   Launch (there, in the last wheel part's call): bash scripts/gpu/launch_job.sh SECONDS
#   Poll and fetch: bash scripts/gpu/wait_fetch.sh 560 s19 (again while it answers rc 3)
#   Check on a CPU (writes and parses the task file, runs nothing): DRY=1 bash job_next.sh 0
END=$1
cd ~/src || exit 1
mkdir -p ~/chunks
source scripts/gpu/queue_rows.sh  # TD CLR50 RIGID RFT ROW SQ WIDE, shares()
AB="--policy $TD --terrains dry_sand --speeds 1.5 --num-episodes 25 --robots-per-batch 25 --episode-s 6 --no-mcap --fresh"
{
  echo "retire_ab_on $AB"
  echo "retire_ab_keep $AB --keep-idle-lanes"
  for i in 1 2 3; do
    echo "table_ppo_rigid_dry_sand_circle_share${i}of4 --policy $RIGID --terrains dry_sand --scenarios circle $ROW $WIDE --shard $i/4"
  done
  shares table_td_transition_sq --policy $TD --terrains transition $ROW $SQ
  shares table_td_dry_sand_sq --policy $TD --terrains dry_sand $ROW $SQ
  shares table_td_basalt_sq --policy $TD --terrains basalt $ROW $SQ
  shares table_td_dry_sand_rough_sq --policy $TD --terrains dry_sand_rough $ROW $SQ
} > ~/chunks/tasks.txt
bash scripts/gpu/run_queue.sh ~/chunks/tasks.txt "$END"
