#!/usr/bin/env bash
# The batched-cuts runs phase 2: 10 s episodes of the td student (dry sand, 1.0 m/s, 3 cm / 250 its / 5 ms frames):
# the reduced window (1.2 x 0.7 m, 20 cm bed, 32 robots per solver) against the touchdown-lift study window (1.8 x 1.0 m,
# 30 cm bed, 8 robots). Usage (in ~/src): bash phase2.sh END_EPOCH
END=$1
cd ~/src && source scripts/gpu/env.sh && mkdir -p ~/chunks/g1_eval
log() { echo "$* at $(date +%T)" >> ~/chunks/job.log; }
left() { python3 -c "import time;print(round(($END-time.time())/60 - $1,2))"; }
C="python3 -m gmloco.eval.g1_eval_cli --policy artifacts/gm_loco_student_td/policy.onnx --terrains dry_sand --speeds 1.0 --voxel 0.03 --iters 250 --frame-dt 0.005 --substeps 1 --fresh"
for cfg in "32 1.2 0.7 0.2" "8 1.8 1.0 0.3"; do
  set -- $cfg
  L="td_r$1_w$2x$3_d$4"
  M=$(left 1)
  timeout $(python3 -c "print(int(max(30,$M*60)))") $C --out $HOME/chunks/g1_eval/$L --num-episodes $1 --robots-per-batch $1 --window-length $2 --window-width $3 --bed-depth $4 --max-minutes $(python3 -c "print(max(0.5,$M-0.3))") > ~/chunks/g1_eval/$L.log 2>&1
  log "g1_eval $L rc=$?"
done
touch ~/chunks/P2_DONE
