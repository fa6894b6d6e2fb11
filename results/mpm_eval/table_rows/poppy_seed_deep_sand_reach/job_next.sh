#!/usr/bin/env bash
# Prepared in the reach-window runs (issue 9); ran in the basalt and rough-sand runs, unchanged (results: ../basalt_rough_square_window/). Any machine of 1-4 H200s:
# `python -m gmloco.eval.g1_eval_queue --tasks` runs one evaluation per GPU from the task file below, in order, each
# time-boxed to END and resumable. A row is four shares (--shard I/4: one speed each). Since the reach-window runs every cell is
# fitted into the time box (g1_eval fit_time_box): a share that cannot end in the time left if no robot falls is
# rebuilt after ~30 s with the lanes that can, so the last task on each GPU keeps what it walks instead of losing it.
#   1. basalt at the square window (the per-terrain runs at the tables' window: 50 of 100, 94 % turned out of it; the reach-window runs'
#      shares 0-1 were dropped whole by the time box): the td student walks the 10 s there, so a share takes ~18 min;
#   2. the two circle shares cut by earlier time boxes: ppo_rigid 1.0 m/s (23 of 25), clr50 1.0 m/s (24 of 25):
#      ~3-5 min each (two or one lanes);
#   3. rough dry sand at the square window (the rough-and-circles runs at the tables' window: 31 % early exits, 20 % by turn);
#   4. the clr50 student on dry sand at the reach window (22 % early exits at the tables' window, 18 of them within
#      0.75 s before the fall; its walks fall in ~2 s, a share takes ~3 min): a check, on a third policy, of the rule
#      the reach-window runs drew from poppy seed and deep sand (exits that come with the fall leave a row unchanged), by which
#      tables_todo no longer lists this rerun.
#   The 10 s retire-lanes A/B (the square-window runs' job_next.sh) is left out: the time-box fit would cut it unevenly.
#   `python -m gmloco.eval.tables_todo` (../tables/todo_tasks.txt) lists the same rows; its windows hold the 97.5th
#   percentile of the recorded reach (basalt 1.45 x 1.45, rough 1.65 x 1.65); here basalt and rough keep the
#   dry-sand row's square (one window for the per-terrain rows): of rough's 31 early exits 16 came with the fall
#   (g1_eval.exit_in_fall) and 13 by turn, which the square holds, leaving 2 (2 %); basalt's walks stay upright and
#   trail their soles 0.27-0.4 m (its exits were turns).
#   Before (here): scripts/gpu/snapshot_src.sh && cp results/mpm_eval/table_rows/poppy_seed_deep_sand_reach/job_next.sh .devsrc/job.sh &&
#     rm -rf .devsrc/row && mkdir -p .devsrc/row &&
#     cp -r results/mpm_eval/table_rows/ablation_circles/runs/table_{ppo_rigid,clr50}_dry_sand_circle_share0of4 .devsrc/row/
#     and the Warp cache (scripts/gpu/warm_cache.py -> .devcache/warpcache.tgz; scripts/gpu/README.md).
#   Launch (there, in the last wheel part's call): bash scripts/gpu/launch_job.sh SECONDS
#   Poll and fetch: bash scripts/gpu/wait_fetch.sh 560 s22 (again while it answers rc 3)
#   Check on a CPU (writes and parses the task file, runs nothing): DRY=1 bash job_next.sh 0
END=$1
cd ~/src || exit 1
mkdir -p ~/chunks
source scripts/gpu/queue_rows.sh  # TD CLR50 RIGID RFT ROW SQ WIDE REACH, shares()
row() { echo "table_td_${1}_sq_share${2}of4 --policy $TD --terrains $1 $ROW $SQ --shard $2/4"; }
{
  for i in 0 1 2 3; do row basalt $i; done
  echo "table_ppo_rigid_dry_sand_circle_share0of4 --policy $RIGID --terrains dry_sand --scenarios circle $ROW $WIDE --shard 0/4"
  echo "table_clr50_dry_sand_circle_share0of4 --policy $CLR50 --terrains dry_sand --scenarios circle $ROW --shard 0/4"
  for i in 0 1 2 3; do row dry_sand_rough $i; done
  for i in 0 1 2 3; do
    echo "table_clr50_dry_sand_reach_share${i}of4 --policy $CLR50 --terrains dry_sand $ROW $REACH --shard $i/4"
  done
} > ~/chunks/tasks.txt
bash scripts/gpu/run_queue.sh ~/chunks/tasks.txt "$END"
