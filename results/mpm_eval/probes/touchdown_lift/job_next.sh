#!/usr/bin/env bash
# Prepared in the touchdown-lift study for a later GPU run (issue 9); NOT yet run.
# The resolution check of the touchdown-lift study (README.md) accepts only 3 cm / 250 iterations / 5 ms frames for the walking
# student (gm_loco_student_td, it 672); 5 cm falls at any iteration count. This job:
# 1. g1_eval, dry sand, 1.0 m/s, at that setting with 16 robots per MPM solver, time-boxed and resumable: the
#    success rate over as many 10 s episodes as fit, and the throughput (summary.json) at the accepted setting;
# 2. if time is left, two GPU resolution probes of the same walk: 2 cm / 250 (finer) and 3 cm / 150 (cheaper).
# Usage (in ~/src): bash job_next.sh END_EPOCH
END=$1
cd ~/src && source scripts/gpu/env.sh && mkdir -p ~/chunks/probe ~/chunks/g1_eval
log() { echo "$* at $(date +%T)" >> ~/chunks/job.log; }
left() { python3 -c "import time;print(round(($END-time.time())/60 - $1,2))"; }
POL=artifacts/gm_loco_student_td/policy.onnx
M=$(left 6)
timeout $(python3 -c "print(int(max(60,$M*60)))") python3 -m gmloco.eval.g1_eval_cli --out $HOME/chunks/g1_eval/td_dry --policy $POL --terrains dry_sand --speeds 1.0 --num-episodes 100 --robots-per-batch 16 --voxel 0.03 --iters 250 --frame-dt 0.005 --substeps 1 --bed-depth 0.3 --max-minutes $(python3 -c "print(max(1,$M-0.5))") > ~/chunks/g1_eval/td_dry.log 2>&1; log "g1_eval rc=$?"
P="python3 results/mpm_eval/policy_probe.py --window eval --vx 1.0 --duration 10 --every 4 --handover predict --depth 0.3 --policy $POL"
for cfg in "0.03 150 0.005 1" "0.02 250 0.005 1"; do
  set -- $cfg
  L="student_td_B_v${1}_i${2}_dt${3}_sub${4}_10s"
  timeout $(python3 -c "print(int(max(10,($(left 0.5))*60)))") $P --voxel $1 --iterations $2 --frame-dt $3 --substeps $4 --label $L --log $HOME/chunks/probe/conv.jsonl > ~/chunks/probe/$L.log 2>&1
  log "probe $L rc=$?"
done
touch ~/chunks/FG_DONE
