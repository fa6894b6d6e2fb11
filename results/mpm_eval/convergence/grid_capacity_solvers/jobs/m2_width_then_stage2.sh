#!/usr/bin/env bash
# Machine 2 of the grid-capacity runs (H200): (1) the window width 1.0 m at the accepted setting (seeds 0, 1; 16 episodes of 5 s)
# against the accepted-setting runs' 0.6 m runs; (2) m2_stage2.sh (the rheology-solver study and the cost cases);
# (3) 2 cm at 500 iterations (lost: the machine was given back before it finished; rerun on machine 4).
END=$1
cd ~/src && source scripts/gpu/env.sh && mkdir -p ~/chunks/sweep13 ~/chunks/g1_eval
log() { echo "$* at $(date +%T)" >> ~/chunks/job.log; }
left() { python3 -c "import time;print(round(($END-time.time())/60 - $1,2))"; }
P="python3 -m gmloco.eval.g1_eval_cli --policy artifacts/gm_loco_student_td/policy.onnx --terrains dry_sand --speeds 1.0 --no-mcap --fresh"
log "start"
for seed in 0 1; do
  L=td_v0.03_it500_d0.3_l1.4_w1.0_r8_5s_seed$seed
  M=$(left 0.5)
  timeout $(python3 -c "print(int(max(30,$M*60)))") $P --window-width 1.0 --episode-s 5 --num-episodes 8 \
    --robots-per-batch 8 --seed $seed --max-minutes $(python3 -c "print(max(0.5,$M-0.2))") \
    --out $HOME/chunks/g1_eval/$L > ~/chunks/g1_eval/$L.log 2>&1
  log "g1_eval $L rc=$?"
done
log "stage2 start"; bash ~/src/stage2.sh $END > ~/chunks/stage2.out 2>&1; log "stage2 rc=$?"
