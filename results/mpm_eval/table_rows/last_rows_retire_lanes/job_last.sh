#!/usr/bin/env bash
# The last-row runs' second job (issue 9): the one walk the first job's time box left out of the clr50 reach check
# (share 3 of 4, 2.5 m/s: 24 of 25), resumed so the row is complete. The task line is the one
# `python -m gmloco.eval.tables_todo` wrote to results/mpm_eval/tables/todo_tasks.txt (copied to .devsrc/tasks_todo.txt).
#   Before (here): scripts/gpu/snapshot_src.sh && cp results/mpm_eval/table_rows/last_rows_retire_lanes/job_last.sh .devsrc/job.sh &&
#     cp results/mpm_eval/tables/todo_tasks.txt .devsrc/tasks_todo.txt && rm -rf .devsrc/row && mkdir -p .devsrc/row &&
#     cp -r results/mpm_eval/table_rows/last_rows_retire_lanes/runs/table_clr50_dry_sand_reach_share3of4 .devsrc/row/
#   Check on a CPU: DRY=1 bash job_last.sh 0 (from a tree with .devsrc/tasks_todo.txt)
END=$1
cd ~/src || exit 1
mkdir -p ~/chunks
grep -v '^#' .devsrc/tasks_todo.txt | grep -v '^$' > ~/chunks/tasks.txt
bash scripts/gpu/run_queue.sh ~/chunks/tasks.txt "$END"
