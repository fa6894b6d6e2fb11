#!/usr/bin/env bash
# Prepared in the rough-and-circles runs for the next run (issue 9); NOT yet run. For a machine of several GPUs (nvidia-h100-x4
# or larger; one GPU works too, slower): `python -m gmloco.eval.g1_eval_queue --tasks` runs one evaluation per GPU
# from the task file below, in order, each time-boxed to END and resumable. Rows split into four shares
# (--shard I/4: with four speeds, one speed each) run on four GPUs at once.
#   1. the td student on dry sand at the tables' window in four shares, started together: one row's wall-clock on
#      four GPUs (the route to the 10-minute target that one GPU cannot reach), and the grid-capacity runs' 22 % row rescored
#      with the window exits recorded;
#   2. the circles still missing from the ablation table: td at 2.5 m/s, ppo_rft3d, clr50 and ppo_rigid in four
#      shares each (the circle's window is square by construction);
#   3. the transition course (square window: it starts on basalt, where the student turns);
#   4. basalt at the square 1.4 x 1.4 m window (lead 0.2; the per-terrain runs' basalt row left the window in 94 % of its
#      episodes because the student turns 35-69 degrees in 10 s and the window does not turn), then the rough row at
#      the square window (13 of its 24 walks at 1.0 m/s turned out of the tables' window in the rough-and-circles runs; the whole
#      row, so the tables can take it in place of the old one; the shares above 1.0 m/s fall within ~3 s).
#   What the time box leaves undone resumes from the fetched folders (copy them to .devsrc/row/).
#   This script writes the task file and hands it to scripts/gpu/run_queue.sh (one queue process per machine).
#   Usage (in ~/src, after the wheels and the Warp cache): bash job_next.sh END_EPOCH
#   Fetch: cd ~/chunks && tar czf - g1_eval job.log job.out tasks.txt | split -b 15M - $OUT/s18.tgz.part
#   Check on a CPU (writes and parses the task file, runs nothing): DRY=1 bash job_next.sh 0
END=$1
cd ~/src || exit 1
mkdir -p ~/chunks
source scripts/gpu/queue_rows.sh  # TD CLR50 RIGID RFT ROW SQ WIDE, shares()
{
  shares table_td_dry_sand_x4 --policy $TD --terrains dry_sand $ROW
  echo "table_td_dry_sand_circle_share3of4 --policy $TD --terrains dry_sand --scenarios circle $ROW --shard 3/4"
  shares table_ppo_rft3d_dry_sand_circle --policy $RFT --terrains dry_sand --scenarios circle $ROW
  shares table_clr50_dry_sand_circle --policy $CLR50 --terrains dry_sand --scenarios circle $ROW
  shares table_ppo_rigid_dry_sand_circle --policy $RIGID --terrains dry_sand --scenarios circle $ROW $WIDE
  shares table_td_transition_sq --policy $TD --terrains transition $ROW $SQ
  shares table_td_basalt_sq --policy $TD --terrains basalt $ROW $SQ
  shares table_td_dry_sand_rough_sq --policy $TD --terrains dry_sand_rough $ROW $SQ
} > ~/chunks/tasks.txt
bash scripts/gpu/run_queue.sh ~/chunks/tasks.txt "$END"
