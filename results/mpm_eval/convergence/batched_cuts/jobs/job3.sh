#!/usr/bin/env bash
# Machine 3 of the batched-cuts runs: iteration check at 3 cm: the narrow window (1.8 x 0.6 m, 30 cm bed) with 150 rheology
# iterations instead of 250, 16 robots, 10 s at 1.0 m/s (compare runs/td_v03_r16_w18x06_d03). Usage: bash job3.sh END
END=$1
cd ~/src && source scripts/gpu/env.sh && mkdir -p ~/chunks/g1_eval
log() { echo "$* at $(date +%T)" >> ~/chunks/job.log; }
left() { python3 -c "import time;print(round(($END-time.time())/60 - $1,2))"; }
M=$(left 0.7)
L=td_v03_it150_r16_w18x06_d03
timeout $(python3 -c "print(int(max(30,$M*60)))") python3 -m gmloco.eval.g1_eval_cli --policy artifacts/gm_loco_student_td/policy.onnx --terrains dry_sand --speeds 1.0 --frame-dt 0.005 --substeps 1 --fresh --voxel 0.03 --iters 150 --num-episodes 16 --robots-per-batch 16 --window-length 1.8 --window-width 0.6 --bed-depth 0.3 --max-minutes $(python3 -c "print(max(0.5,$M-0.2))") --out $HOME/chunks/g1_eval/$L > ~/chunks/g1_eval/$L.log 2>&1
log "g1_eval $L rc=$?"
touch ~/chunks/FG_DONE
