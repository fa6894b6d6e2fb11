#!/usr/bin/env bash
# Machine 3 of the grid-capacity runs (H200): the first 100-episode row (td student, dry sand, straight, speeds 1.0-2.5 m/s
# cycled) at the accepted setting, grid capacity 1.5x, 36 lanes; resumable (m4_resume_and_2cm.sh finished it).
END=$1
cd ~/src && source scripts/gpu/env.sh && mkdir -p ~/chunks/g1_eval
log() { echo "$* at $(date +%T)" >> ~/chunks/job.log; }
left() { python3 -c "import time;print(round(($END-time.time())/60 - $1,2))"; }
log "start"
M=$(left 0.7)
L=table_td_dry_sand
timeout $(python3 -c "print(int(max(30,$M*60+20)))") python3 -m gmloco.eval.g1_eval_cli \
  --policy artifacts/gm_loco_student_td/policy.onnx --terrains dry_sand --scenarios straight \
  --speeds 1.0 1.5 2.0 2.5 --num-episodes 100 --robots-per-batch 36 --cell-capacity-factor 1.5 --max-minutes $M \
  --out $HOME/chunks/g1_eval/$L > ~/chunks/g1_eval/$L.log 2>&1
log "g1_eval $L rc=$?"
touch ~/chunks/DONE
