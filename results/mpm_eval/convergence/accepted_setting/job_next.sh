#!/usr/bin/env bash
# Prepared in the accepted-setting runs for a later GPU run (issue 9); NOT yet run.
# The first 100-episode table row at the accepted setting (the defaults of g1_eval_cli since the accepted-setting runs: 3 cm, 500
# iterations, 5 ms frames x 1, bed 30 cm, window 1.4 x 0.6 m): the td student on dry sand, straight, speeds cycled
# 1.0 / 1.5 / 2.0 / 2.5 m/s (25 each), one MCAP recording per speed. Run job_next_checks.sh first: if it rejects
# the 0.6 m window width against 1.0 m, add --window-width 1.0 below (~1.7x the cells: ~30 lanes per machine).
# Cost (results/mpm_eval/convergence/accepted_setting/README.md): ~73 robot-frames/s on an H200 (~60 on an H100) from ~32 lanes, so
# 50 lanes finish their 10 s episodes in ~23 min (H200): one machine scores ~50 episodes. The run folder resumes
# from its episodes.jsonl: carry it to the second machine (tar it into $OUT at the end of the first; it is small)
# and run the same command; the episodes in flight at a time box are dropped and rerun, never faked.
# Poll with poll_next.sh (copy both scripts into ~/src with the launch): it copies the run folder into $OUT each call.
# Usage (in ~/src, after the wheels and the Warp cache): bash job_next.sh END_EPOCH [RUN_TGZ]
END=$1
cd ~/src && source scripts/gpu/env.sh && mkdir -p ~/chunks/g1_eval
[ -n "$2" ] && tar xzf "$2" -C ~/chunks/g1_eval
left() { python3 -c "import time;print(round(($END-time.time())/60 - $1,2))"; }
M=$(left 1.0)
OUTDIR=$HOME/chunks/g1_eval/table_td_dry_sand
timeout $(python3 -c "print(int(max(30,$M*60)))") python3 -m gmloco.eval.g1_eval_cli \
  --policy artifacts/gm_loco_student_td/policy.onnx --terrains dry_sand --scenarios straight \
  --speeds 1.0 1.5 2.0 2.5 --num-episodes 100 --robots-per-batch 50 --max-minutes $M \
  --out $OUTDIR > ~/chunks/g1_eval/table_td_dry_sand.log 2>&1
echo "g1_eval table_td_dry_sand rc=$? at $(date +%T)" >> ~/chunks/job.log
tar czf ~/chunks/table_td_dry_sand.tgz -C ~/chunks/g1_eval table_td_dry_sand
touch ~/chunks/FG_DONE
